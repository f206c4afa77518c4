"""`fado.EstimatorConfig`: defaults, immutability, round trips and field-naming errors."""

from __future__ import annotations

import copy
import inspect
import math
import pickle
from pathlib import Path

import numpy as np
import pytest

import fado
from fado import EstimatorConfig

# The values the paper (section V) and SPEC.md fix; the Rust `Default` must give exactly these.
PAPER_DEFAULTS = {
    "ts": 100e-6,  # 10 kHz sampling [P]
    "rs_hat": 0.327,  # [P]
    "lq_hat": 2.63e-3,  # [P]
    "flux_linkage_hat": 0.088,  # SPEC §6 [A]
    "k_df": 0.5,  # [P]
    "k_df_ramp_time": 0.0,  # abrupt, as in the paper
    "k_af": 2 * math.pi * 100,  # [P]
    "limiter_radius_ratio": 1.15,  # [P]
    "mode_threshold_hz": 1.5,  # [P]
    "mode_hysteresis_hz": 0.2,  # SPEC §1 [A]
    "t2s1_bandwidth_hz": 60.0,  # [P]
    "t2s2_bandwidth_hz": 35.0,  # [P]
    "tracker_damping": 1 / math.sqrt(2),  # SPEC §3 [A]
    "bandwidth_definition": "-3dB",  # SPEC §3
    "tracker_hold_ratio": 0.2,  # SPEC §3 [A]
    "average_current": True,  # SPEC §1 [A]
    "observer_on_rotor_flux": True,  # fado's improvement [A]; False = paper's Fig. 5
    "limiter_recentring": True,  # fado's improvement [A]; False = the paper
    "initial_angle": 0.0,  # SPEC §1 [A]
    "rs_adaptation": True,  # fado's extension [A]; False = the paper's fixed R̂s
    "rs_adaptation_rate": 1.0,  # [A]
    "rs_adaptation_excitation_floor": 0.2,  # [A]
    "rs_adaptation_min_ratio": 0.5,  # [A]
    "rs_adaptation_max_ratio": 2.0,  # [A]
    "flux_linkage_adaptation_rate": 0.0,  # [A]
}


def assert_fields(actual: dict[str, object], expected: dict[str, object]) -> None:
    assert list(actual) == list(expected)
    for field, value in expected.items():
        got = actual[field]
        assert type(got) is type(value), field
        if isinstance(value, float):
            assert math.isclose(got, value, rel_tol=1e-15), field  # type: ignore[arg-type]
        else:
            assert got == value, field


def test_defaults_are_the_papers() -> None:
    assert_fields(EstimatorConfig().to_dict(), PAPER_DEFAULTS)
    assert list(EstimatorConfig.fields) == list(PAPER_DEFAULTS)


def test_every_field_is_a_keyword_only_argument_and_an_attribute() -> None:
    params = inspect.signature(EstimatorConfig).parameters
    assert list(params) == list(EstimatorConfig.fields)
    assert all(p.kind is inspect.Parameter.KEYWORD_ONLY for p in params.values())
    cfg = EstimatorConfig()
    assert {f: getattr(cfg, f) for f in cfg.fields} == cfg.to_dict()


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("ts", 50e-6),
        ("rs_hat", 0.4),
        ("k_df", 1.0),
        ("bandwidth_definition", "natural"),
        ("average_current", False),
        ("initial_angle", -1.0),
    ],
)
def test_keyword_sets_only_that_field(field: str, value: object) -> None:
    cfg = EstimatorConfig(**{field: value})
    expected = dict(PAPER_DEFAULTS, **{field: value})
    assert_fields(cfg.to_dict(), expected)


def test_immutable_and_replace() -> None:
    cfg = EstimatorConfig(rs_hat=0.3)
    with pytest.raises(AttributeError):
        cfg.rs_hat = 1.0  # type: ignore[misc]
    changed = cfg.replace(k_df=2.0)
    assert changed.k_df == 2.0 and changed.rs_hat == 0.3
    assert cfg.k_df == PAPER_DEFAULTS["k_df"]
    assert cfg != changed and cfg == EstimatorConfig(rs_hat=0.3)
    with pytest.raises(fado.ConfigError):
        cfg.replace(k_df=-1.0)


def test_round_trips() -> None:
    cfg = EstimatorConfig(rs_hat=0.31, bandwidth_definition="natural", average_current=False)
    assert EstimatorConfig(**cfg.to_dict()) == cfg
    assert eval(repr(cfg), {"EstimatorConfig": EstimatorConfig}) == cfg
    assert pickle.loads(pickle.dumps(cfg)) == cfg
    assert copy.deepcopy(cfg) == cfg


def test_bandwidth_definition_is_case_insensitive_and_canonical() -> None:
    assert EstimatorConfig(bandwidth_definition="-3DB").bandwidth_definition == "-3dB"
    assert EstimatorConfig(bandwidth_definition="Natural").bandwidth_definition == "natural"


def test_bandwidth_definition_changes_the_trackers() -> None:
    rng = np.random.default_rng(0)
    signals = [rng.normal(size=2000) for _ in range(4)]
    a = fado.estimate(*signals, config=EstimatorConfig(bandwidth_definition="-3dB"))
    b = fado.estimate(*signals, config=EstimatorConfig(bandwidth_definition="natural"))
    np.testing.assert_array_equal(a.theta_direct[:1], b.theta_direct[:1])
    assert not np.array_equal(a.theta, b.theta)


FLOAT_FIELDS = [f for f, v in PAPER_DEFAULTS.items() if isinstance(v, float)]


@pytest.mark.parametrize("field", FLOAT_FIELDS)
@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_non_finite_values_raise_naming_the_field(field: str, bad: float) -> None:
    with pytest.raises(ValueError, match=field) as info:
        EstimatorConfig(**{field: bad})
    assert isinstance(info.value, fado.ConfigError)
    assert isinstance(info.value, fado.FadoError)
    assert info.value.field == field


@pytest.mark.parametrize(
    ("field", "bad"),
    [
        ("ts", 0.0),
        ("ts", -1e-4),
        ("rs_hat", -0.1),
        ("lq_hat", -1e-3),
        ("flux_linkage_hat", 0.0),
        ("k_df", -0.5),
        ("k_df_ramp_time", -1.0),
        ("k_af", -1.0),
        ("limiter_radius_ratio", 0.0),
        ("mode_threshold_hz", -1.5),
        ("mode_hysteresis_hz", 2.0),  # wider than the threshold
        ("t2s1_bandwidth_hz", 0.0),
        ("t2s2_bandwidth_hz", -35.0),
        ("tracker_damping", 0.0),
        ("tracker_hold_ratio", 1.0),
        ("bandwidth_definition", "fast"),
    ],
)
def test_out_of_range_values_raise_naming_the_field(field: str, bad: object) -> None:
    with pytest.raises(fado.ConfigError, match=field) as info:
        EstimatorConfig(**{field: bad})
    assert info.value.field == field


def test_wrong_types_and_unknown_fields_are_type_errors() -> None:
    with pytest.raises(TypeError):
        EstimatorConfig(ts="fast")  # type: ignore[arg-type]
    with pytest.raises(TypeError):
        EstimatorConfig(rs=0.3)  # type: ignore[call-arg]
    with pytest.raises(TypeError):
        EstimatorConfig(100e-6)  # type: ignore[misc]


def test_ts_argument_of_estimate_is_validated() -> None:
    x = np.zeros(3)
    with pytest.raises(fado.ConfigError) as info:
        fado.estimate(x, x, x, x, ts=0.0)
    assert info.value.field == "ts"


def test_float32_validates_in_single_precision() -> None:
    tiny = EstimatorConfig(ts=1e-50)  # fine in f64, zero in f32
    fado.Estimator(tiny)
    with pytest.raises(fado.ConfigError) as info:
        fado.Estimator(tiny, dtype="float32")
    assert info.value.field == "ts"


@pytest.mark.parametrize("spelling", ["float32", "f4", np.float32, np.dtype("float32")])
def test_dtype_spellings(spelling: object) -> None:
    assert fado.Estimator(dtype=spelling).dtype == "float32"  # type: ignore[arg-type]


@pytest.mark.parametrize("bad", ["float16", "int32", "double-ish", np.complex128])
def test_bad_dtype_raises_input_error(bad: object) -> None:
    with pytest.raises(fado.InputError) as info:
        fado.Estimator(dtype=bad)  # type: ignore[arg-type]
    assert info.value.argument == "dtype"
    x = np.zeros(3)
    with pytest.raises(fado.InputError):
        fado.estimate(x, x, x, x, dtype=bad)  # type: ignore[arg-type]


def test_exception_hierarchy() -> None:
    assert issubclass(fado.FadoError, Exception)
    assert issubclass(fado.ConfigError, fado.FadoError)
    assert issubclass(fado.ConfigError, ValueError)
    assert issubclass(fado.InputError, fado.FadoError)
    assert issubclass(fado.InputError, ValueError)
    assert issubclass(fado.SimulationError, fado.FadoError)
    assert not issubclass(fado.SimulationError, ValueError)
    assert fado.ConfigError.__module__ == "fado"
    err = pickle.loads(pickle.dumps(fado.ConfigError("`ts` must be positive")))
    assert type(err) is fado.ConfigError


TS = 100e-6  # the default sampling period: 10 kHz


@pytest.mark.parametrize(
    ("field", "bad"),
    [
        # Above what the sampling rate allows (the discrete loops would be unstable).
        ("t2s1_bandwidth_hz", 4000.0),
        ("t2s2_bandwidth_hz", 4000.0),
        ("k_af", 1.01 / TS),
        ("k_df", 1.01 / TS),
        ("mode_threshold_hz", 0.5 / TS),
        # Out of order.
        ("limiter_radius_ratio", 0.9),  # the limiter would clamp λ̂f itself
        ("mode_hysteresis_hz", 1.6),  # wider than the 1.5 Hz threshold
    ],
)
def test_sampling_rate_and_ordering_limits_name_the_field(field: str, bad: float) -> None:
    with pytest.raises(ValueError, match=field) as info:
        EstimatorConfig(**{field: bad})
    assert isinstance(info.value, fado.ConfigError)
    assert info.value.field == field


@pytest.mark.parametrize(
    ("text", "key", "line", "column"),
    [
        ("[simulation]\nduration = 0.1\n\n[motor]\nrs = -1\n", "motor.rs", 5, 6),
        ("[inverter]\ndead_tme = 1e-6\n", "inverter.dead_tme", 2, 1),
        ("[estimator]\n  k_df = 'half'\n", "estimator.k_df", 2, 10),
        ("[estimator]\nt2s1_bandwidth_hz = 4000.0\n", "estimator.t2s1_bandwidth_hz", 2, 21),
    ],
)
def test_simulate_bad_toml_names_key_and_line(
    text: str, key: str, line: int, column: int, tmp_path: Path
) -> None:
    with pytest.raises(ValueError, match=f"line {line}, column {column}: `{key}`") as info:
        fado.simulate("fig11", text, averaged=True)
    assert isinstance(info.value, fado.ConfigError)
    assert (info.value.field, info.value.line, info.value.column) == (key, line, column)
    # From a file, the message reads like the CLI's: FILE:LINE:COLUMN: `key`: ...
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(fado.ConfigError, match=f":{line}:{column}: `{key}`") as info:
        fado.simulate("fig11", path, averaged=True)
    assert str(info.value).startswith(f"{path}:{line}:{column}: `{key}`: ")
    assert info.value.field == key


def test_dict_config_errors_are_located_in_its_toml() -> None:
    with pytest.raises(fado.ConfigError) as info:
        fado.simulate("fig11", {"mismatch": {"rs_ratio": -1.0}}, averaged=True)
    assert info.value.field == "mismatch.rs_ratio"
    assert info.value.line == 2
