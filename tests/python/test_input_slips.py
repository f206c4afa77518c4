"""Inputs a Python user gives by slip: each is refused or warned about naming the field it
blames and the likely cause (`fado_core::machine_checks`, `fado_core::datasheet`)."""

from __future__ import annotations

import math
import warnings

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
