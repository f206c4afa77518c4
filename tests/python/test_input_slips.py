"""Inputs a Python user gives by slip: each is refused or warned about naming the field it
blames and the likely cause (`fado_core::machine_checks`, `fado_core::datasheet`)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import fado

# The 14-pole outrunner of examples/motors/my-outrunner.toml (Kv 100 r/min/V).
OUTRUNNER = {
    "rs": 0.06,
    "ld": 30e-6,
    "lq": 30e-6,
    "flux_linkage": 7.88e-3,
    "pole_pairs": 7,
    "rated_current": 28.3,
    "rated_speed_rpm": 1800.0,
    "rated_torque": 2.34,
    "dc_voltage": 24.0,
}

# motors/ipmsm-gem-50k.toml: a 6-pole IPMSM with Lq/Ld 3.2.
GEM = {
    "rs": 0.018,
    "ld": 0.37e-3,
    "lq": 1.2e-3,
    "flux_linkage": 0.066,
    "pole_pairs": 3,
    "rated_current": 240.0,
    "rated_speed_rpm": 3000.0,
    "rated_torque": 160.6,
    "dc_voltage": 520.0,
}


def without(fields: dict, key: str) -> dict:
    return {k: v for k, v in fields.items() if k != key}


def test_a_kv_keyword_is_named_and_pointed_to_from_datasheet() -> None:
    with pytest.raises(TypeError) as e:
        fado.Machine(**without(OUTRUNNER, "flux_linkage"), Kv=100.0)
    text = str(e.value)
    assert text.startswith("`Kv` is not a Machine field"), text
    assert "kv_rpm_per_volt" in text and "from_datasheet" in text, text


@pytest.mark.parametrize(
    ("call", "slip", "meant"),
    [
        (lambda: fado.Machine(**without(OUTRUNNER, "rs"), rss=0.06), "rss", "rs"),
        (lambda: fado.Machine(**OUTRUNNER, viscous_fricton=0.0), "viscous_fricton", "viscous_friction"),
        (lambda: fado.EstimatorConfig(limter={"k_af": 1.0}), "limter", "limiter"),
        (
            lambda: fado.Machine.from_datasheet(**without(OUTRUNNER, "flux_linkage"), kv_rpm_per_vol=100.0),
            "kv_rpm_per_vol",
            "kv_rpm_per_volt",
        ),
    ],
)
def test_a_misspelt_keyword_names_the_one_it_looks_like(call, slip: str, meant: str) -> None:
    with pytest.raises(TypeError) as e:
        call()
    text = str(e.value)
    assert f"`{slip}`" in text and f"did you mean `{meant}`?" in text, text


def test_a_misspelt_config_key_names_the_one_it_looks_like() -> None:
    with pytest.raises(fado.ConfigError) as e:
        fado.simulate("fig11", {"inverter": {"swiching_frequency": 5000.0}}, averaged=True)
    assert e.value.field == "inverter.swiching_frequency", e.value
    assert "did you mean `switching_frequency`?" in str(e.value)


def test_kv_and_kg_cm2_are_converted_as_the_cli_converts_them() -> None:
    m = fado.Machine.from_datasheet(
        **without(OUTRUNNER, "flux_linkage"), kv_rpm_per_volt=100.0, inertia_kg_cm2=5.0
    )
    assert m.flux_linkage == pytest.approx(60.0 / (2.0 * math.pi * math.sqrt(3.0) * 7 * 100.0))
    assert m.inertia == pytest.approx(5e-4)


def test_a_datasheet_value_that_is_not_positive_names_its_own_key() -> None:
    with pytest.raises(fado.ConfigError) as e:
        fado.Machine.from_datasheet(**without(OUTRUNNER, "flux_linkage"), kv_rpm_per_volt=0.0)
    assert e.value.field == "kv_rpm_per_volt", e.value
    assert "flux_linkage" not in str(e.value)


def test_an_unknown_datasheet_keyword_lists_the_datasheet_keys() -> None:
    with pytest.raises(TypeError) as e:
        fado.Machine.from_datasheet(**without(OUTRUNNER, "flux_linkage"), kt_nm_per_apeak=0.08)
    text = str(e.value)
    assert "`kt_nm_per_apeak`" in text and "kt_nm_per_arms" in text, text


def test_a_line_to_line_flux_on_a_salient_ipm_is_a_warning_naming_it() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fado.Machine(**GEM)
    with pytest.warns(UserWarning, match="line-to-line") as record:
        fado.Machine(**dict(GEM, flux_linkage=0.066 * math.sqrt(3.0)))
    assert any("`flux_linkage`" in str(w.message) for w in record)


def test_a_dc_link_given_as_the_mains_rms_voltage_warns_with_the_rectified_link() -> None:
    # motors/servo-1ft6084.toml on "400 V" (its drive's mains) where its 565 V link is meant:
    # the rated point needs 1.08 of 400 V's linear range (0.76 of 565 V's).
    servo = fado.Machine.preset("servo-1ft6084")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        servo.replace(dc_voltage=420.0)  # no mains' voltage: a link like any other
    with pytest.warns(UserWarning, match="mains' rms voltage") as record:
        servo.replace(dc_voltage=400.0)
    text = " ".join(str(w.message) for w in record)
    assert "dc_voltage = 566?" in text, text


def test_a_winding_given_line_to_line_names_its_phase_values() -> None:
    # motors/ipmsm-2k2.toml with rs, ld, lq between two terminals (2 × the phase's): its
    # rated point then needs 1.22 × its 540 V link's linear range.
    ipm = fado.Machine.preset("ipmsm-2k2")
    with pytest.warns(UserWarning, match="line-to-line") as record:
        ipm.replace(rs=2 * ipm.rs, ld=2 * ipm.ld, lq=2 * ipm.lq)
    text = " ".join(str(w.message) for w in record)
    assert "rs = 3.6e0 Ω, ld = 3.6e-2 H, lq = 5.1e-2 H" in text, text


def test_a_burst_of_nan_in_a_recording_warns_naming_the_column_and_where() -> None:
    # 50 NaN in a row (5 ms at 10 kHz, 0.9 % of the samples: below the share that warns
    # alone); a single glitch per column, as an ADC gives, does not warn.
    rng = np.random.default_rng(3)
    signals = [rng.normal(size=5500) * 0.1 for _ in range(4)]
    signals[2][700] = np.nan
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        fado.estimate(*signals, machine="paper")
    assert not [w for w in record if "non-finite" in str(w.message)], record
    signals[1][1000:1050] = np.nan
    with pytest.warns(UserWarning, match="non-finite") as record:
        out = fado.estimate(*signals, machine="paper")
    text = " ".join(str(w.message) for w in record if "non-finite" in str(w.message))
    assert "`v_beta` has 50 non-finite" in text and "from sample 1000 (5.0000 ms)" in text, text
    assert "`i_alpha`" not in text, text
    assert np.count_nonzero(out.input_fault) == 51


def test_a_signal_of_another_length_is_the_one_named() -> None:
    rng = np.random.default_rng(4)
    signals = [rng.normal(size=64) for _ in range(4)]
    with pytest.raises(fado.InputError, match="length 63 differs from v_beta's length 64") as e:
        fado.estimate(signals[0][:-1], *signals[1:], machine="paper")
    assert e.value.argument == "v_alpha"
    with pytest.raises(fado.InputError) as e:
        fado.estimate(*signals[:3], signals[3][:-1], machine="paper")
    assert e.value.argument == "i_beta"


def test_a_reference_beyond_the_motors_limits_is_a_warning_naming_it() -> None:
    # The outrunner's rated 1,800 r/min given as electrical r/min (× 7 pole pairs).
    config = {
        "simulation": {"duration": 0.02},
        "speed_reference": {"points": [[0.0, 0.0], [1.0, 12600.0]]},
    }
    with pytest.warns(UserWarning, match="speed_reference.points") as record:
        fado.simulate("reversal", config, averaged=True, motor=fado.Machine(**OUTRUNNER))
    assert any("electrical r/min" in str(w.message) for w in record)
