"""`fado.EstimatorConfig` (the tuning) and `fado.Machine` (the motor): defaults, immutability,
round trips and field-naming errors."""

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
# Speeds are ratios of the rated electrical frequency (the paper's motor: 100 Hz). One dict per
# block the tuning tunes (the nested tables of the simulator's `[estimator]`).
PAPER_DEFAULTS = {
    "integrator": {
        "average_current": True,  # docs/method/estimator.md, section 1
    },
    "disturbance_feedback": {
        "k_df": 0.5,  # [P]
        "ramp_time": 0.0,  # abrupt, as in the paper
    },
    "limiter": {
        "k_af": 2 * math.pi * 100,  # [P]
        "radius_ratio": 1.15,  # [P]
        "recentring": True,  # fado's improvement [A]; False = the paper
    },
    "mode": {
        "threshold_ratio": 0.015,  # [P]: 1.5 Hz of the paper motor's 100 Hz
        "hysteresis_ratio": 0.002,  # 0.2 Hz of 100 Hz (docs/method/estimator.md, section 5)
    },
    "tracker": {
        "t2s1_bandwidth_hz": 60.0,  # [P]
        "t2s2_bandwidth_hz": 35.0,  # [P]
        "damping": 1 / math.sqrt(2),  # docs/method/estimator.md, section 4
        "bandwidth_definition": "minus3_db",  # docs/method/estimator.md, section 4
        "hold_ratio": 0.2,  # docs/method/estimator.md, section 4
        "load_pole_ratio": 0.0,  # [A] 0: the paper's type-2 trackers
        "t2s1_running_bandwidth_hz": 0.0,  # [A] 0: T2S-1's one bandwidth (the paper)
    },
    "observer": {
        "on_rotor_flux": True,  # fado's improvement [A]; False = paper's Fig. 5
        "lag_compensation": True,  # fado's improvement [A]; False = the paper
        "gain_period": 4e-4,  # [A] (gains held over 4 samples at 10 kHz); 0 = the paper
        "frame_ripple_notch": True,  # [A] saturating models only; False = the paper
    },
    "rs_adaptation": {
        "enabled": True,  # fado's extension [A]; False = the paper's fixed R̂s
        "rate": 1.0,  # [A]
        "excitation_floor": 0.2,  # [A]
        "min_ratio": 0.5,  # [A]
        "max_ratio": 2.0,  # [A]
        "standstill_angle_rate": 2.0,  # [A]
        "model_flux_uncertainty": 0.0,  # [A] 0: the model is the machine's
        "model_flux_uncertainty_rated": 0.0,  # [A] 0: the model is the machine's
    },
    "flux_linkage_adaptation": {
        "rate": 5.0,  # [A] (revolution mean, 1 % dead zone)
    },
    "offset_adaptation": {
        "rate": 2.0,  # [A]
        "min_revolution_samples": 64.0,  # [A] (offset law held above 2π/(64·Ts))
    },
    "plausibility": {
        "current_ratio": 4.0,  # [A]
        "voltage_ratio": 1.5,  # [A]
        "current_step_ratio": 2.0,  # [A]
    },
    "lock": {
        "flux_low_ratio": 0.7,  # [A]
        "flux_low_fast_ratio": 0.6,  # [A]
        "flux_high_ratio": 1.5,  # [A]
        "innovation_limit": 0.5,  # [A]
        "detection_time": 5e-3,  # [A]
        "heal_time": 0.1,  # [A]
        "limiter_clamping": False,  # [A]
        "handover_count": 5.0,  # [A] (docs/method/lock.md)
        "handover_time": 0.1,  # [A]
    },
}



def nested(path: str, value: object) -> dict[str, dict[str, object]]:
    """The keyword of the tuning field at `path` (`lock.heal_time`): its record's dict."""
    record, field = path.split(".")
    return {record: {field: value}}


def default(path: str) -> object:
    record, field = path.split(".")
    return PAPER_DEFAULTS[record][field]


# The paper's motor (section V; λf, J, B as docs/method/estimator.md states them; rated current from its rated torque).
PAPER_MACHINE = {
    "rs": 0.327,
    "ld": 2.63e-3,
    "lq": 2.63e-3,
    "flux_linkage": 0.088,
    "pole_pairs": 4,
    "inertia": 0.012,
    "viscous_friction": 1e-3,
    "rated_current": 11.5 / (1.5 * 4 * 0.088),
    "rated_speed_rpm": 1500.0,
    "rated_torque": 11.5,
    "dc_voltage": 311.0,
}

# The 2.2 kW interior-magnet motor (motulator's example), entered by hand.
IPMSM = {
    "rs": 3.6,
    "ld": 36e-3,
    "lq": 51e-3,
    "flux_linkage": 0.545,
    "pole_pairs": 3,
    "inertia": 0.015,
    "rated_current": 6.08,
    "rated_speed_rpm": 1500.0,
    "rated_torque": 14.0,
    "dc_voltage": 540.0,
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
    got = EstimatorConfig().to_dict()
    assert list(got) == list(PAPER_DEFAULTS)
    for record, fields in PAPER_DEFAULTS.items():
        assert_fields(got[record], fields)
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
        ("disturbance_feedback.ramp_time", 0.1),
        ("mode.threshold_ratio", 0.02),
        ("disturbance_feedback.k_df", 1.0),
        ("tracker.bandwidth_definition", "natural_frequency"),
        ("integrator.average_current", False),
        ("rs_adaptation.enabled", False),
    ],
)
def test_keyword_sets_only_that_field(field: str, value: object) -> None:
    cfg = EstimatorConfig(**nested(field, value))
    record, name = field.split(".")
    for r, fields in PAPER_DEFAULTS.items():
        expected = dict(fields, **{name: value}) if r == record else fields
        assert_fields(cfg.to_dict()[r], expected)


def test_immutable_and_replace() -> None:
    cfg = EstimatorConfig(limiter={"k_af": 300.0})
    with pytest.raises(AttributeError):
        cfg.limiter = {"k_af": 1.0}  # type: ignore[misc]
    changed = cfg.replace(disturbance_feedback={"k_df": 2.0})
    assert changed.disturbance_feedback["k_df"] == 2.0 and changed.limiter["k_af"] == 300.0
    assert cfg.disturbance_feedback["k_df"] == default("disturbance_feedback.k_df")
    assert cfg != changed and cfg == EstimatorConfig(limiter={"k_af": 300.0})
    # A dict changes only the fields it names.
    assert changed.limiter["radius_ratio"] == default("limiter.radius_ratio")
    with pytest.raises(fado.ConfigError):
        cfg.replace(disturbance_feedback={"k_df": -1.0})


def test_round_trips() -> None:
    cfg = EstimatorConfig(
        limiter={"k_af": 300.0},
        tracker={"bandwidth_definition": "natural_frequency"},
        integrator={"average_current": False},
    )
    assert EstimatorConfig(**cfg.to_dict()) == cfg
    assert eval(repr(cfg), {"EstimatorConfig": EstimatorConfig}) == cfg
    assert pickle.loads(pickle.dumps(cfg)) == cfg
    assert copy.deepcopy(cfg) == cfg


def test_bandwidth_definition_has_one_spelling_per_value_the_tomls() -> None:
    minus3 = EstimatorConfig(tracker={"bandwidth_definition": "minus3_db"})
    assert minus3.tracker["bandwidth_definition"] == "minus3_db"
    natural = EstimatorConfig(tracker={"bandwidth_definition": "natural_frequency"})
    assert natural.tracker["bandwidth_definition"] == "natural_frequency"
    # The spelling of the simulator's TOML ([estimator.tracker] bandwidth_definition), nothing else.
    assert 'bandwidth_definition = "minus3_db"' in fado.default_config("fig11")
    for other in ["-3dB", "natural", "Minus3_dB", "NATURAL_FREQUENCY"]:
        with pytest.raises(fado.ConfigError) as info:
            EstimatorConfig(tracker={"bandwidth_definition": other})
        assert info.value.field == "tracker.bandwidth_definition"


def test_bandwidth_definition_changes_the_trackers() -> None:
    rng = np.random.default_rng(0)
    signals = [rng.normal(size=2000) for _ in range(4)]
    minus3 = EstimatorConfig(tracker={"bandwidth_definition": "minus3_db"})
    natural = EstimatorConfig(tracker={"bandwidth_definition": "natural_frequency"})
    a = fado.estimate(*signals, machine="paper", config=minus3)
    b = fado.estimate(*signals, machine="paper", config=natural)
    np.testing.assert_array_equal(a.theta_direct[:1], b.theta_direct[:1])
    assert not np.array_equal(a.theta, b.theta)


FLOAT_FIELDS = [
    f"{r}.{f}" for r, fields in PAPER_DEFAULTS.items() for f, v in fields.items() if isinstance(v, float)
]


@pytest.mark.parametrize("field", FLOAT_FIELDS)
@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_non_finite_values_raise_naming_the_field(field: str, bad: float) -> None:
    with pytest.raises(ValueError, match=field) as info:
        EstimatorConfig(**nested(field, bad))
    assert isinstance(info.value, fado.ConfigError)
    assert isinstance(info.value, fado.FadoError)
    assert info.value.field == field


@pytest.mark.parametrize(
    ("field", "bad"),
    [
        ("disturbance_feedback.k_df", -0.5),
        ("disturbance_feedback.ramp_time", -1.0),
        ("limiter.k_af", -1.0),
        ("limiter.radius_ratio", 0.0),
        ("mode.threshold_ratio", -0.015),
        ("mode.hysteresis_ratio", 0.02),  # wider than the threshold
        ("tracker.t2s1_bandwidth_hz", 0.0),
        ("tracker.t2s2_bandwidth_hz", -35.0),
        ("tracker.damping", 0.0),
        ("tracker.hold_ratio", 1.0),
        ("tracker.bandwidth_definition", "fast"),
    ],
)
def test_out_of_range_values_raise_naming_the_field(field: str, bad: object) -> None:
    with pytest.raises(fado.ConfigError, match=field) as info:
        EstimatorConfig(**nested(field, bad))
    assert info.value.field == field


def test_wrong_types_and_unknown_fields_are_type_errors() -> None:
    with pytest.raises(TypeError):
        EstimatorConfig(disturbance_feedback={"k_df": "fast"})
    with pytest.raises(TypeError):
        EstimatorConfig(lock={"heal_tme": 0.1})
    with pytest.raises(TypeError):
        EstimatorConfig(lock=0.1)  # type: ignore[arg-type]
    with pytest.raises(TypeError):
        EstimatorConfig(rs_hat=0.3)  # type: ignore[call-arg]
    with pytest.raises(TypeError):
        EstimatorConfig(0.5)  # type: ignore[misc]


@pytest.mark.parametrize("bad", [0.0, -1e-4])
def test_ts_argument_of_estimate_is_validated(bad: float) -> None:
    x = np.zeros(3)
    with pytest.raises(fado.ConfigError) as info:
        fado.estimate(x, x, x, x, machine="paper", ts=bad)
    assert info.value.field == "ts"


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
@pytest.mark.parametrize("argument", ["ts", "theta0"])
def test_non_finite_scalar_arguments_raise_naming_them(argument: str, bad: float) -> None:
    x = np.zeros(3)
    with pytest.raises(ValueError, match=argument) as info:
        fado.estimate(x, x, x, x, machine="paper", **{argument: bad})  # type: ignore[arg-type]
    assert isinstance(info.value, fado.FadoError)
    with pytest.raises(ValueError, match=argument):
        fado.Estimator("paper", **{argument: bad})  # type: ignore[arg-type]


def test_float32_validates_in_single_precision() -> None:
    tiny = 1e-50  # a sampling period fine in f64, zero in f32
    fado.Estimator("paper", ts=tiny)
    with pytest.raises(fado.ConfigError) as info:
        fado.Estimator("paper", ts=tiny, dtype="float32")
    assert info.value.field == "ts"


@pytest.mark.parametrize("spelling", ["float32", "f4", np.float32, np.dtype("float32")])
def test_dtype_spellings(spelling: object) -> None:
    assert fado.Estimator("paper", dtype=spelling).dtype == "float32"  # type: ignore[arg-type]


@pytest.mark.parametrize("bad", ["float16", "int32", "double-ish", np.complex128])
def test_bad_dtype_raises_input_error(bad: object) -> None:
    with pytest.raises(fado.InputError) as info:
        fado.Estimator("paper", dtype=bad)  # type: ignore[arg-type]
    assert info.value.argument == "dtype"
    x = np.zeros(3)
    with pytest.raises(fado.InputError):
        fado.estimate(x, x, x, x, machine="paper", dtype=bad)  # type: ignore[arg-type]


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
RATED_HZ = 100.0  # the paper motor's rated electrical frequency: 1500 r/min, 4 pole pairs


@pytest.mark.parametrize(
    ("field", "bad"),
    [
        # Above what the sampling rate allows (the discrete loops would be unstable): a
        # tuning alone is fine, the estimator sampled at 10 kHz refuses it.
        ("tracker.t2s1_bandwidth_hz", 4000.0),
        ("tracker.t2s2_bandwidth_hz", 4000.0),
        ("limiter.k_af", 1.01 / TS),
        ("disturbance_feedback.k_df", 1.01 / TS),
        ("mode.threshold_ratio", 0.5 / TS / RATED_HZ),
    ],
)
def test_sampling_rate_limits_name_the_field(field: str, bad: float) -> None:
    tuning = EstimatorConfig(**nested(field, bad))
    fado.Estimator("paper", tuning, ts=TS / 10)  # ten times faster: fine
    for make in (
        lambda: fado.Estimator("paper", tuning, ts=TS),
        lambda: fado.estimate(*[np.zeros(2)] * 4, machine="paper", config=tuning, ts=TS),
    ):
        with pytest.raises(ValueError, match=field) as info:
            make()
        assert isinstance(info.value, fado.ConfigError)
        assert info.value.field == field


@pytest.mark.parametrize(
    ("field", "bad"),
    [
        ("limiter.radius_ratio", 0.9),  # the limiter would clamp λ̂f itself
        ("mode.hysteresis_ratio", 0.016),  # wider than the 0.015 threshold
    ],
)
def test_ordering_limits_name_the_field(field: str, bad: float) -> None:
    with pytest.raises(ValueError, match=field) as info:
        EstimatorConfig(**nested(field, bad))
    assert isinstance(info.value, fado.ConfigError)
    assert info.value.field == field


@pytest.mark.parametrize(
    ("text", "key", "line", "column"),
    [
        ("[simulation]\nduration = 0.1\n\n[motor]\nrs = -1\n", "motor.rs", 5, 6),
        ("[inverter]\ndead_tme = 1e-6\n", "inverter.dead_tme", 2, 1),
        ("[estimator.disturbance_feedback]\n  k_df = 'half'\n", "estimator.disturbance_feedback.k_df", 2, 10),
        ("[estimator.tracker]\nt2s1_bandwidth_hz = 4000.0\n", "estimator.tracker.t2s1_bandwidth_hz", 2, 21),
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


def test_config_as_a_dict_works_as_in_simulate() -> None:
    """Tuning records, the [estimator] table of a simulator config, or dotted keys: the same
    tuning; the simulator's other tables are not the estimator's and are refused, naming the
    functions that take them."""
    rng = np.random.default_rng(3)
    signals = [rng.normal(size=500) for _ in range(4)]
    tuned = EstimatorConfig(disturbance_feedback={"k_df": 1.0})
    expected = fado.estimate(*signals, machine="paper", config=tuned)
    for config in (
        {"disturbance_feedback": {"k_df": 1.0}},
        {"disturbance_feedback.k_df": 1.0},
        {"estimator": {"disturbance_feedback": {"k_df": 1.0}}},
        {"estimator.disturbance_feedback.k_df": 1.0},
    ):
        got = fado.estimate(*signals, machine="paper", config=config)
        np.testing.assert_array_equal(got.theta, expected.theta, strict=True)
        assert fado.Estimator("paper", config).config == tuned
    default = fado.estimate(*signals, machine="paper")
    assert not np.array_equal(default.theta, expected.theta)
    for extra, key in (
        ({"simulation": {"duration": 1.0}}, "simulation"),
        ({"mismatch.rs_ratio": 1.1}, "mismatch.rs_ratio"),
    ):
        with pytest.raises(fado.ConfigError, match="fado.simulate") as info:
            fado.estimate(*signals, machine="paper", config={"estimator": {"disturbance_feedback": {"k_df": 1.0}}, **extra})
        assert info.value.field == key
    # The same dict drives the simulator's estimator.
    sim_config = {"estimator": {"disturbance_feedback": {"k_df": 1.0}}, "simulation": {"duration": 0.05}}
    run = fado.simulate("fig11", sim_config, averaged=True)
    assert run.estimator_config.disturbance_feedback["k_df"] == 1.0


@pytest.mark.parametrize(
    ("config", "key"),
    [
        ({"k_dff": 1.0}, "k_dff"),
        ({"estimator": {"kdf": 1.0}}, "estimator.kdf"),
        ({"disturbance_feedback": {"k_df": -1.0}}, "disturbance_feedback.k_df"),
        ({"estimator": {"disturbance_feedback": {"k_df": -1.0}}}, "estimator.disturbance_feedback.k_df"),
        # A key of the flat table names its new place.
        ({"k_df": 1.0}, "k_df"),
        ({"estimator": {"lock_heal_time": 0.2}}, "estimator.lock_heal_time"),
        ({"estimator": {"rs_adaptation": False}}, "estimator.rs_adaptation"),
        ({"estimator.limiter.k_af": math.nan}, "estimator.limiter.k_af"),
    ],
)
def test_bad_dict_keys_raise_naming_them_as_written(config: dict[str, object], key: str) -> None:
    with pytest.raises(fado.ConfigError) as info:
        fado.Estimator("paper", config)
    assert info.value.field == key
    assert f"`{key}`" in str(info.value)


def test_machine_fields_and_paper_preset() -> None:
    paper = fado.Machine.paper()
    assert_fields(paper.to_dict(), PAPER_MACHINE)
    assert list(fado.Machine.fields) == list(PAPER_MACHINE)
    assert fado.Machine.preset("paper") == paper
    assert fado.Machine(**PAPER_MACHINE) == paper
    assert not paper.salient


def test_machine_is_keyword_only_with_required_fields() -> None:
    params = inspect.signature(fado.Machine).parameters
    assert set(params) == {*PAPER_MACHINE, "flux_map"}
    assert all(p.kind is inspect.Parameter.KEYWORD_ONLY for p in params.values())
    required = {n for n, p in params.items() if p.default is inspect.Parameter.empty}
    assert required == set(PAPER_MACHINE) - {"viscous_friction", "inertia", "dc_voltage"}
    assert params["flux_map"].default is None
    # Left out, friction, inertia and the DC link come from the ratings (fado_core::ratings),
    # as fado-sim derives them for a motor file without them: not 0, not the paper's.
    derived = fado.Machine(
        **{k: v for k, v in IPMSM.items() if k not in ("inertia", "dc_voltage")}
    )
    omega_mech = IPMSM["rated_speed_rpm"] * math.pi / 30
    assert derived.viscous_friction == pytest.approx(0.01 * IPMSM["rated_torque"] / omega_mech)
    assert derived.inertia == pytest.approx(0.15 * IPMSM["rated_torque"] / omega_mech)
    # The rated point's phase voltage at 80 % of Vdc/√3: 652 V, the value `fado-sim run
    # --dump-config` prints for the same [motor] table.
    assert derived.dc_voltage == 652.0
    for missing in required:
        with pytest.raises(TypeError, match=missing):
            fado.Machine(**{k: v for k, v in IPMSM.items() if k != missing})
    # Without its ratings a motor is refused naming every one, not the inertia they give.
    with pytest.raises(TypeError, match="'rated_current', 'rated_speed_rpm', 'rated_torque'"):
        fado.Machine(**{k: v for k, v in IPMSM.items() if not k.startswith("rated")})


def test_machine_immutable_replace_and_round_trips() -> None:
    m = fado.Machine(**IPMSM)
    assert m.salient
    with pytest.raises(AttributeError):
        m.rs = 1.0  # type: ignore[misc]
    hot = m.replace(rs=4.3)
    assert hot.rs == 4.3 and hot.lq == m.lq and m.rs == 3.6
    assert fado.Machine(**m.to_dict()) == m
    assert eval(repr(m), {"Machine": fado.Machine}) == m
    assert pickle.loads(pickle.dumps(m)) == m
    assert copy.deepcopy(m) == m


@pytest.mark.parametrize(
    ("field", "bad"),
    [
        ("rs", -0.1),
        ("ld", 0.0),
        ("lq", math.nan),
        ("flux_linkage", -0.5),
        ("pole_pairs", 0),
        ("pole_pairs", -3),
        ("inertia", math.inf),
        ("viscous_friction", -1e-3),
        ("rated_current", 0.0),
        ("rated_speed_rpm", -1500.0),
        ("rated_torque", math.nan),
        ("dc_voltage", 0.0),
        # Unit slips: a flux linkage in mWb, a current in mA, a 24 V link for a 540 V motor.
        ("flux_linkage", 545.0),
        ("rated_current", 6080.0),
        ("dc_voltage", 24.0),
    ],
)
def test_machine_validation_names_the_field(field: str, bad: float) -> None:
    with pytest.raises(ValueError) as info:
        fado.Machine(**dict(IPMSM, **{field: bad}))
    err = info.value
    assert isinstance(err, fado.ConfigError)
    # A unit slip shows as a rated torque or back-EMF that does not fit the other ratings.
    slips = {"flux_linkage": {"flux_linkage", "rated_torque"}, "rated_current": {"rated_torque"},
             "dc_voltage": {"dc_voltage", "flux_linkage"}}
    assert err.field in slips.get(field, set()) | {field}
    assert err.field in str(err)
    with pytest.raises(fado.ConfigError):
        fado.Machine(**IPMSM).replace(**{field: bad})


def test_machine_presets() -> None:
    names = fado.machine_presets()
    assert names == sorted(names) and len(names) >= 5
    assert {"paper", "ipmsm-2k2"} <= set(names)
    for name in names:
        m = fado.Machine.preset(name)
        assert isinstance(m, fado.Machine) and m == fado.Machine(**m.to_dict())
    ipm = fado.Machine.preset("ipmsm-2k2")
    assert (ipm.ld, ipm.lq, ipm.pole_pairs, ipm.dc_voltage) == (0.036, 0.051, 3, 540.0)
    with pytest.raises(ValueError, match="ipmsm-2k2") as info:
        fado.Machine.preset("ipmsm")
    assert isinstance(info.value, fado.ConfigError)


def test_machine_argument_forms() -> None:
    rng = np.random.default_rng(5)
    signals = [rng.normal(size=300) for _ in range(4)]
    by_object = fado.estimate(*signals, machine=fado.Machine(**IPMSM))
    by_dict = fado.estimate(*signals, machine=IPMSM)
    np.testing.assert_array_equal(by_object.theta, by_dict.theta, strict=True)
    # The preset differs from IPMSM only by its viscous friction, which the estimator does not
    # use; its resistance does matter.
    by_preset = fado.estimate(*signals, machine="ipmsm-2k2")
    np.testing.assert_array_equal(by_preset.theta, by_object.theta, strict=True)
    hot = fado.estimate(*signals, machine=dict(IPMSM, rs=4.3))
    assert not np.array_equal(hot.lambda1_alpha, by_object.lambda1_alpha)
    with pytest.raises(fado.ConfigError) as info:
        fado.estimate(*signals, machine=dict(IPMSM, rs_hat=3.6))
    assert info.value.field == "rs_hat"
    with pytest.raises(fado.ConfigError, match="paper"):
        fado.estimate(*signals, machine="no-such-motor")
    with pytest.raises(TypeError, match="machine"):
        fado.estimate(*signals, machine=3.6)  # type: ignore[arg-type]


def test_estimate_and_estimator_without_machine_raise_naming_it() -> None:
    x = np.zeros(4)
    with pytest.raises(TypeError, match="machine"):
        fado.estimate(x, x, x, x)  # type: ignore[call-arg]
    with pytest.raises(TypeError, match="machine"):
        fado.estimate(x, x, x, x, machine=None)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="machine"):
        fado.Estimator()  # type: ignore[call-arg]


def test_fields_are_the_simulator_tables_keys() -> None:
    # One schema: the Python fields are the serde records' keys, i.e. the keys fado-sim writes
    # for its `[estimator]` and `[motor]` tables (plus the inverter's dc_voltage for a Machine).
    import tomllib

    dumped = tomllib.loads(fado.default_config("fig11"))
    assert list(EstimatorConfig.fields) == list(dumped["estimator"])
    assert EstimatorConfig().to_dict() == dumped["estimator"]
    assert list(fado.Machine.fields) == [*dumped["motor"], "dc_voltage"]
    machine = fado.Machine.paper()
    assert machine.dc_voltage == dumped["inverter"]["dc_voltage"]


@pytest.mark.parametrize(
    ("changes", "error", "field"),
    [
        ({"disturbance_feedback": {"k_df": math.nan}}, fado.ConfigError, "k_df"),
        ({"tracker": {"bandwidth_definition": "minus3db"}}, fado.ConfigError, "bandwidth_definition"),
        ({"rs_adaptation": {"enabled": 1.0}}, TypeError, "rs_adaptation.enabled"),
        ({"limiter": {"k_af": [1.0]}}, TypeError, "limiter.k_af"),
        # A flat keyword names its new place.
        ({"k_df": 1.0}, TypeError, "disturbance_feedback"),
        ({"rs_adaptation": False}, TypeError, "rs_adaptation="),
    ],
)
def test_replace_refuses_naming_the_field(
    changes: dict[str, object], error: type[Exception], field: str
) -> None:
    cfg = EstimatorConfig()
    with pytest.raises(error, match=field):
        cfg.replace(**changes)  # type: ignore[arg-type]
    assert cfg == EstimatorConfig()


def test_machine_counts_and_voltages_by_type() -> None:
    paper = fado.Machine.paper()
    with pytest.raises(TypeError, match="pole_pairs"):
        paper.replace(pole_pairs=4.5)  # type: ignore[arg-type]
    with pytest.raises(fado.ConfigError, match="pole_pairs"):
        paper.replace(pole_pairs=-4)
    with pytest.raises(TypeError, match="dc_voltage"):
        paper.replace(dc_voltage="311")  # type: ignore[arg-type]
    assert paper.replace(dc_voltage=540).dc_voltage == 540.0
    assert paper.replace(rs=0.4).dc_voltage == paper.dc_voltage


def test_paper_path_switches_off_fados_additions_and_keeps_the_rest() -> None:
    cfg = EstimatorConfig(limiter={"k_af": 300.0}, rs_adaptation={"rate": 2.0})
    paper = cfg.paper_path()
    off = {
        "rs_adaptation.enabled": False,
        "observer.lag_compensation": False,
        "observer.on_rotor_flux": False,
        "observer.frame_ripple_notch": False,
        "limiter.recentring": False,
        "disturbance_feedback.ramp_time": 0.0,
        "observer.gain_period": 0.0,
    }
    expected = cfg.to_dict()
    for path, value in off.items():
        record, field = path.split(".")
        expected[record][field] = value
    for record, fields in expected.items():
        assert_fields(paper.to_dict()[record], fields)

    def get(c: EstimatorConfig, path: str) -> object:
        record, field = path.split(".")
        return c.to_dict()[record][field]

    # The defaults have every one of them on (a test that the switch changes something).
    assert all(get(cfg, k) != v for k, v in off.items() if k != "disturbance_feedback.ramp_time")
    assert paper.paper_path() == paper and EstimatorConfig(**paper.to_dict()) == paper
