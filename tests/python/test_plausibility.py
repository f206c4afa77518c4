"""Inputs a user can trust from Python: no silent default, the same derived values as the CLI,
numpy scalars, and every slip refused or warned about by its real cause."""

from __future__ import annotations

import math
import tomllib
import warnings

import numpy as np
import pytest

import fado

# A 24 V multirotor outrunner from its circuit and ratings: 14 pole pairs, 25 µH, 6000 r/min.
DRONE = dict(
    rs=0.05,
    ld=25e-6,
    lq=25e-6,
    flux_linkage=1.1e-3,
    pole_pairs=14,
    rated_current=30.0,
    rated_speed_rpm=6000.0,
    rated_torque=0.69,
)
DRONE_TOML = "[motor]\n" + "".join(f"{k} = {v!r}\n" for k, v in DRONE.items())


def test_machine_derives_friction_and_inertia_as_the_cli_does() -> None:
    m = fado.Machine(**DRONE, dc_voltage=24.0)
    omega_mech = DRONE["rated_speed_rpm"] * math.pi / 30.0
    # 1 % of the rated torque at rated speed, not 0 (and not the paper's 1e-3).
    assert m.viscous_friction * omega_mech == pytest.approx(0.01 * DRONE["rated_torque"], rel=1e-12)
    assert m.inertia * omega_mech / DRONE["rated_torque"] == pytest.approx(0.15, rel=1e-12)
    # The simulator, from the same motor as a TOML file: the same values, bit for bit.
    r = fado.simulate("fig11", DRONE_TOML + "[simulation]\nduration = 0.01\n", averaged=True)
    motor = tomllib.loads(r.config_toml)["motor"]
    assert motor["viscous_friction"] == m.viscous_friction
    assert motor["inertia"] == m.inertia
    # Given explicitly, they are kept.
    assert fado.Machine(**DRONE, dc_voltage=24.0, viscous_friction=0.0).viscous_friction == 0.0


def test_machine_derives_the_dc_link_as_the_cli_does() -> None:
    # Left out, the DC link comes from the rated point (fado_core::ratings), bit for bit the
    # simulator's `[inverter] dc_voltage` for the same `[motor]` table.
    m = fado.Machine(**DRONE)
    r = fado.simulate("fig11", DRONE_TOML + "[simulation]\nduration = 0.01\n", averaged=True)
    assert tomllib.loads(r.config_toml)["inverter"]["dc_voltage"] == m.dc_voltage
    assert fado.Machine(**DRONE, dc_voltage=None) == m


def test_machine_without_ratings_names_them_not_what_they_give() -> None:
    circuit = {k: v for k, v in DRONE.items() if not k.startswith("rated")}
    with pytest.raises(TypeError, match="'rated_current', 'rated_speed_rpm', 'rated_torque'"):
        fado.Machine(**circuit)


def test_machine_accepts_numpy_0d_arrays_and_whole_float_counts() -> None:
    # A value read from an array (`np.array(0.05)`, a reduction) or a float column (4.0).
    fields = {k: np.array(v) for k, v in DRONE.items()}
    fields["pole_pairs"] = 14.0
    m = fado.Machine(**fields)
    assert m == fado.Machine(**DRONE)
    assert m.replace(rs=np.array(0.06)).rs == 0.06
    with pytest.raises(TypeError, match="pole_pairs"):
        fado.Machine(**{**DRONE, "pole_pairs": 14.5})


def test_a_simulator_motor_file_without_ratings_is_refused_naming_them() -> None:
    text = "".join(line + "\n" for line in DRONE_TOML.splitlines()[:6])
    with pytest.raises(fado.ConfigError, match="rated_current") as info:
        fado.simulate("fig11", text, averaged=True)
    assert info.value.field == "motor.rated_current"
    for k in ("rated_speed_rpm", "rated_torque"):
        assert k in str(info.value)


def test_machine_accepts_numpy_scalars() -> None:
    m = fado.Machine(
        rs=np.float32(0.327),
        ld=np.float64(2.63e-3),
        lq=np.float64(2.63e-3),
        flux_linkage=np.float32(0.088),
        pole_pairs=np.int64(4),
        inertia=np.float64(0.012),
        rated_current=np.float64(21.78),
        rated_speed_rpm=np.int32(1500),
        rated_torque=np.float64(11.5),
        dc_voltage=np.float32(311.0),
    )
    assert m.pole_pairs == 4 and isinstance(m.pole_pairs, int)
    assert m.rs == float(np.float32(0.327))
    assert m.replace(rs=np.float32(0.5)).rs == 0.5


def test_a_pole_count_for_pole_pairs_is_refused_naming_it() -> None:
    with pytest.raises(fado.ConfigError, match="`pole_pairs` = 28 looks like a pole count: 14?") as info:
        fado.Machine(**{**DRONE, "pole_pairs": 28}, dc_voltage=24.0)
    assert info.value.field == "pole_pairs"


def test_an_inductance_in_mh_is_refused_naming_it() -> None:
    paper = fado.Machine.paper()
    with pytest.raises(fado.ConfigError, match="mH where H is meant") as info:
        paper.replace(ld=2.63, lq=2.63)
    assert info.value.field == "ld"


def test_ratings_divided_by_ten_are_refused() -> None:
    paper = fado.Machine.paper()
    with pytest.raises(fado.ConfigError, match="divided by 10") as info:
        paper.replace(
            rated_current=paper.rated_current / 10,
            rated_speed_rpm=paper.rated_speed_rpm / 10,
            rated_torque=paper.rated_torque / 10,
        )
    assert info.value.field == "rated_speed_rpm"


def test_absurd_magnitudes_blame_their_own_field() -> None:
    paper = fado.Machine.paper()
    for field, value in (("flux_linkage", 1e300), ("pole_pairs", 4_000_000_000), ("rated_speed_rpm", 1e6)):
        with pytest.raises(fado.ConfigError) as info:
            paper.replace(**{field: value})
        assert info.value.field == field


def test_swapped_inductances_warn_naming_both() -> None:
    ipm = fado.Machine.preset("ipmsm-2k2")
    with pytest.warns(UserWarning, match="swapped") as record:
        swapped = ipm.replace(ld=ipm.lq, lq=ipm.ld)
    assert "`ld`" in str(record[0].message) and "`lq`" in str(record[0].message)
    rng = np.random.default_rng(1)
    with pytest.warns(UserWarning, match="swapped"):
        fado.estimate(*[rng.normal(size=100) for _ in range(4)], machine=swapped)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fado.Machine.preset("ipmsm-2k2")


def test_a_sampling_period_in_ms_is_refused_naming_ts() -> None:
    rng = np.random.default_rng(2)
    signals = [rng.normal(size=100) for _ in range(4)]
    with pytest.raises(fado.ConfigError, match="ms where s is meant") as info:
        fado.estimate(*signals, machine="paper", ts=0.025)
    assert info.value.field == "ts"


def test_estimate_refuses_plant_tables_naming_the_functions_that_take_them() -> None:
    rng = np.random.default_rng(3)
    signals = [rng.normal(size=100) for _ in range(4)]
    with pytest.raises(fado.ConfigError, match="fado.estimate") as info:
        fado.estimate(*signals, machine="paper", config={"motor": {"rs": 0.3}})
    assert info.value.field == "motor"
    assert "machine=" in str(info.value) and "fado.simulate" in str(info.value)


IPM = dict(
    rs=3.6, ld=0.036, lq=0.051, flux_linkage=0.545, pole_pairs=3,
    rated_current=6.08, rated_speed_rpm=1500.0, rated_torque=14.0,
)


def test_a_bool_where_a_quantity_is_meant_is_refused_naming_the_argument() -> None:
    # float(True) is 1.0: ts=True would be a one-second sampling period.
    signals = [np.zeros(10) for _ in range(4)]
    for kwargs, name in (
        (dict(ts=True), "ts"),
        (dict(ts=np.True_), "ts"),
        (dict(theta0=False), "theta0"),
    ):
        with pytest.raises(fado.InputError, match="bool") as info:
            fado.estimate(*signals, machine="paper", **kwargs)
        assert info.value.argument == name
    with pytest.raises(fado.InputError, match="bool"):
        fado.Estimator("paper", ts=True)
    with pytest.raises(fado.InputError, match="i_alpha"):
        fado.Estimator("paper").align(0.0, True)
    # numpy real scalars are numbers.
    r = fado.estimate(*signals, machine="paper", ts=np.float32(1e-4), theta0=np.float64(0.5))
    assert len(r) == 10


def test_ratings_scaled_with_a_derived_dc_link_and_ipm_flux_slips_warn() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fado.Machine(**IPM)
    tenth = dict(IPM, rated_current=0.608, rated_speed_rpm=150.0, rated_torque=1.4)
    with pytest.warns(UserWarning, match="divided by 10"):
        fado.Machine(**tenth)
    with pytest.warns(UserWarning, match="rms where peak"):
        fado.Machine(**dict(IPM, flux_linkage=0.545 / math.sqrt(2)))
    with pytest.warns(UserWarning, match="line-to-line"):
        fado.Machine(**dict(IPM, flux_linkage=0.545 * math.sqrt(3)))


def test_a_motor_without_magnet_is_refused_saying_why() -> None:
    with pytest.raises(fado.ConfigError, match="synchronous reluctance") as info:
        fado.Machine(**dict(IPM, flux_linkage=0.0))
    assert info.value.field == "flux_linkage"


def _recording(n: int = 2000) -> list[np.ndarray]:
    """A steady rotation of the paper's motor: 10 A turning at 60 Hz, the voltage it needs."""
    t = np.arange(n) * 1e-4
    w = 2 * math.pi * 60
    i = 10 * np.exp(1j * w * t)
    v = (0.5 + 1j * w * 2.63e-3) * i + 1j * w * 0.088 * np.exp(1j * (w * t - 0.3))
    return [np.ascontiguousarray(x) for x in (v.real, v.imag, i.real, i.imag)]


@pytest.mark.parametrize(
    ("change", "match"),
    [
        (lambda s: [s[0], s[1], s[2] * 1e3, s[3] * 1e3], "mA where A is meant"),
        (lambda s: [s[0] / 1e3, s[1] / 1e3, s[2], s[3]], "kV where V is meant"),
        (lambda s: [s[0], s[1], s[2], np.zeros_like(s[3])], "`i_beta` is 0 in every sample"),
        (lambda s: [s[0], s[1], np.where(np.arange(len(s[2])) % 10 == 0, np.nan, s[2]), s[3]],
         "non-finite"),
    ],
)
def test_a_recording_in_the_wrong_units_warns_naming_the_column(change, match) -> None:
    signals = _recording()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fado.estimate(*signals, machine="paper", ts=1e-4)
    with pytest.warns(UserWarning, match=match):
        fado.estimate(*change(signals), machine="paper", ts=1e-4)


def test_a_start_angle_in_degrees_warns() -> None:
    with pytest.warns(UserWarning, match="degrees where radians"):
        fado.estimate(*_recording(), machine="paper", ts=1e-4, theta0=30.0)


def test_a_bad_rating_is_named_not_the_value_derived_from_it() -> None:
    # A negative rated speed leaves no inertia to derive: the speed is the cause.
    with pytest.raises(fado.ConfigError) as info:
        fado.Machine(**dict(IPM, rated_speed_rpm=-1500.0))
    assert info.value.field == "rated_speed_rpm"
    with pytest.raises(fado.ConfigError) as info:
        fado.Machine(**dict(IPM, rated_torque=0.0))
    assert info.value.field == "rated_torque"


def test_a_paper_figure_on_another_motor_warns_that_its_loads_are_the_papers() -> None:
    # fig11 loads 7.5 N·m, the paper motor's 65 %: 10.87 × this drone motor's 0.69 N·m.
    short = {"simulation": {"duration": 0.01}}
    with pytest.warns(UserWarning, match="paper's experiment in its motor's units") as record:
        fado.simulate("fig11", motor=fado.Machine(**DRONE, dc_voltage=24.0), config=short)
    assert any("10.87 × its `motor.rated_torque`" in str(w.message) for w in record)
    # The scaled scenarios and the paper's own motor: no such warning.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fado.simulate("reversal", motor=fado.Machine(**DRONE, dc_voltage=24.0), config=short)
        fado.simulate("fig11", config=short)


def test_a_start_ups_gates_off_window_is_not_taken_for_a_voltage_in_kv() -> None:
    # The first 0.1 s of a start-up: gates off, so the voltages are 0 while the currents read
    # the sensors' offsets and noise (0.06 % of the rated current here); nothing flows.
    r = fado.simulate("loaded-start", {"simulation": {"decimation": 1}}, motor="ipmsm-2k2",
                      averaged=True)
    k = int(0.1 / r.ts)
    cols = [np.ascontiguousarray(r.traces[c][:k])
            for c in ("v_alpha_ref", "v_beta_ref", "i_alpha", "i_beta")]
    assert np.max(np.abs(cols[0])) == 0.0 and np.max(np.abs(cols[2])) > 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fado.estimate(*cols, machine=r.machine, ts=r.ts)
    # The same window with a current flowing at 10 % of rated and no voltage still warns.
    cols[2] = cols[2] + 0.1 * r.machine.rated_current
    with pytest.warns(UserWarning, match="kV where V is meant"):
        fado.estimate(*cols, machine=r.machine, ts=r.ts)
