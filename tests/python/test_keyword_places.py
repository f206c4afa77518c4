"""A keyword or key given to the wrong function or table is refused naming the user's own
name, the closest one the function takes, and where it belongs (`fado.elsewhere` in the
bindings; `fado_sim::suggest::top_level_hint` for the simulator's configuration, so that
`fado-sim` and Python agree).

The motor is one fado's repository does not hold: a Maxon EC 45 flat 70 W, 24 V (datasheet
397172): terminal resistance 0.608 Ω and inductance 0.463 mH (line to line), speed constant
259 r/min/V, 8 pole pairs, nominal current 3.21 A (taken as rms), nominal speed 4,860 r/min,
nominal torque 128 mN·m, rotor inertia 181 g·cm² (1.81 kg·cm²)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import fado

EC45 = {
    "rs_line_to_line": 0.608,
    "l_line_to_line": 0.463e-3,
    "kv_rpm_per_volt": 259.0,
    "pole_pairs": 8,
    "rated_current_arms": 3.21,
    "rated_speed_rpm": 4860.0,
    "rated_torque": 0.128,
    "inertia_kg_cm2": 1.81,
    "dc_voltage": 24.0,
}


@pytest.fixture(scope="module")
def ec45() -> fado.Machine:
    return fado.Machine.from_datasheet(**EC45)


@pytest.fixture(scope="module")
def fields(ec45: fado.Machine) -> dict:
    return {k: v for k, v in ec45.to_dict().items() if k != "flux_map"}


@pytest.fixture(scope="module")
def replay(ec45: fado.Machine) -> tuple[list[np.ndarray], float]:
    result = fado.simulate(
        "reversal",
        {"simulation": {"duration": 0.6, "decimation": 1}},
        averaged=True,
        motor=ec45,
    )
    t = result.traces
    signals = [
        np.ascontiguousarray(t[k])
        for k in ("v_alpha_ref", "v_beta_ref", "i_alpha", "i_beta")
    ]
    return signals, float(np.median(np.diff(t["time"])))


def test_ts_given_to_machine_names_estimate_and_the_closest_field(fields: dict) -> None:
    with pytest.raises(TypeError) as e:
        fado.Machine(**fields, ts=1e-4)
    text = str(e.value)
    assert "`ts`" in text and "sampling period" in text, text
    assert "fado.estimate" in text and "fado.Estimator" in text, text
    assert "did you mean `rs`?" in text, text
    # The place comes first: the sampling period is what `ts` is.
    assert text.index("sampling period") < text.index("did you mean"), text


def test_switching_frequency_given_to_machine_points_to_the_inverter_table(fields: dict) -> None:
    with pytest.raises(TypeError) as e:
        fado.Machine(**fields, switching_frequency=20e3)
    text = str(e.value)
    assert '{"inverter": {"switching_frequency": …}}' in text, text
    assert "fado.simulate" in text, text


def test_a_machine_dict_with_ts_names_it_too(ec45: fado.Machine, replay) -> None:
    signals, ts = replay
    with pytest.raises(fado.ConfigError) as e:
        fado.estimate(*signals, machine=dict(ec45.to_dict(), ts=ts), ts=ts)
    assert e.value.field == "ts"
    assert "sampling period" in str(e.value) and "`ts=` argument" in str(e.value)


@pytest.mark.parametrize(
    ("call", "function"),
    [
        (lambda m: fado.simulate("reversal", motor=m, averaged=True, switching_frequency=2e4), "simulate"),
        (lambda m: fado.commission(m, switching_frequency=2e4), "commission"),
        (lambda m: fado.sweep({"rs_error": [0.0]}, "reversal", switching_frequency=2e4), "sweep"),
    ],
)
def test_switching_frequency_as_a_keyword_points_to_the_config(call, function: str, ec45) -> None:
    with pytest.raises(TypeError) as e:
        call(ec45)
    text = str(e.value)
    assert text.startswith(f"{function}() got an unexpected keyword argument `switching_frequency`"), text
    assert '{"inverter": {"switching_frequency": …}}' in text, text


def test_switching_frequency_given_to_estimate_names_ts(ec45: fado.Machine, replay) -> None:
    signals, ts = replay
    with pytest.raises(TypeError) as e:
        fado.estimate(*signals, machine=ec45, switching_frequency=1.0 / ts)
    text = str(e.value)
    assert "estimate() got an unexpected keyword argument `switching_frequency`" in text, text
    assert "`ts=`" in text, text
    with pytest.raises(TypeError) as e:
        fado.Estimator(ec45, switching_frequency=1.0 / ts)
    assert "Estimator() got an unexpected keyword argument `switching_frequency`" in str(e.value)


def test_ts_given_to_simulate_or_commission_names_the_switching_frequency(ec45) -> None:
    for call in (
        lambda: fado.simulate("reversal", motor=ec45, averaged=True, ts=1e-4),
        lambda: fado.commission(ec45, ts=1e-4),
    ):
        with pytest.raises(TypeError) as e:
            call()
        text = str(e.value)
        assert "`ts`" in text and "switching_frequency" in text and "[inverter]" in text, text


def test_a_misspelt_keyword_of_simulate_names_the_one_it_looks_like(ec45) -> None:
    with pytest.raises(TypeError) as e:
        fado.simulate("reversal", motor=ec45, averagd=True)
    assert "did you mean `averaged`?" in str(e.value)


def test_a_key_outside_its_table_names_its_table(ec45) -> None:
    with pytest.raises(fado.ConfigError) as e:
        fado.simulate("reversal", {"switching_frequency": 2e4}, motor=ec45, averaged=True)
    assert e.value.field == "switching_frequency"
    assert '{"inverter": {"switching_frequency": …}}' in str(e.value), e.value
    with pytest.raises(fado.ConfigError) as e:
        fado.simulate("reversal", {"rs": 0.3}, motor=ec45, averaged=True)
    assert "[motor]" in str(e.value), e.value


def test_commission_sends_an_inverter_key_to_its_table(ec45) -> None:
    # An [inverter] key is the plant's: commissioning takes it, in its table.
    with pytest.raises(fado.ConfigError) as e:
        fado.commission(ec45, config={"switching_frequency": 2e4})
    text = str(e.value)
    assert "not used by" not in text, text
    assert '{"inverter": {"switching_frequency": …}}' in text, text


def test_ts_in_an_estimator_config_names_the_argument(ec45, replay) -> None:
    signals, ts = replay
    with pytest.raises(fado.ConfigError) as e:
        fado.estimate(*signals, machine=ec45, ts=ts, config={"ts": ts})
    assert e.value.field == "ts"
    assert "`ts=` argument of fado.estimate" in str(e.value), e.value
    with pytest.raises(TypeError) as e:
        fado.EstimatorConfig(ts=1e-4)
    assert "`ts=` argument of fado.estimate" in str(e.value), e.value


def test_an_estimator_setting_given_to_machine_names_estimator_config(fields: dict) -> None:
    with pytest.raises(TypeError) as e:
        fado.Machine(**fields, limiter={"k_af": 1.0})
    assert "fado.EstimatorConfig(limiter=…)" in str(e.value), e.value


def test_a_machine_field_in_an_estimator_config_names_machine(ec45, replay) -> None:
    signals, ts = replay
    with pytest.raises(fado.ConfigError) as e:
        fado.estimate(*signals, machine=ec45, ts=ts, config={"pole_pairs": 8})
    assert "a Machine field" in str(e.value), e.value


def test_a_one_element_array_where_a_series_is_meant(ec45, replay) -> None:
    signals, ts = replay
    with pytest.raises(fado.InputError) as e:
        fado.estimate(*signals[:3], np.array([0.0]), machine=ec45, ts=ts)
    assert e.value.argument == "i_beta"
    text = str(e.value)
    assert "a single value where a series is meant?" in text, text
    assert f"numpy.full({len(signals[0])}, x)" in text, text


def test_a_one_element_array_for_a_machine_field(fields: dict) -> None:
    with pytest.raises(TypeError) as e:
        fado.Machine(**dict(fields, rs=np.array([fields["rs"]])))
    text = str(e.value)
    assert "`rs` must be one number, got an array of shape (1,)" in text, text
    assert "x.item()" in text, text
    # A numpy scalar and a 0-d array are numbers.
    m = fado.Machine(**dict(fields, rs=np.float32(0.304), pole_pairs=np.int64(8), ld=np.array(fields["ld"])))
    assert m.pole_pairs == 8 and m.rs == pytest.approx(0.304)


def test_a_fractional_count_is_named_as_a_count(fields: dict) -> None:
    with pytest.raises(TypeError) as e:
        fado.Machine(**dict(fields, pole_pairs=8.5))
    assert "`pole_pairs` is a count: it must be a whole number, got 8.5" in str(e.value)


def test_the_ec45_replays_with_its_own_model(ec45, replay) -> None:
    # The audit's baseline: the datasheet machine and its own replay are accepted as given.
    signals, ts = replay
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = fado.estimate(*signals, machine=ec45, ts=ts)
    assert len(out) == len(signals[0])
