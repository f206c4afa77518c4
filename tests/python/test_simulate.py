"""`fado.simulate`: the closed-loop simulator of `fado-sim` from Python.

The bindings must give what the `fado-sim` command line gives, bit for bit (traces.csv is
written by the csv crate with Rust's shortest round-trip float formatting, so parsing it with
Python's `float` recovers every f64 exactly), and the trace must carry the estimator's inputs
so that `fado.Estimator` replays the in-loop estimator.
"""

from __future__ import annotations

import csv
import json
import math
import os
import shutil
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import fado

ROOT = Path(__file__).resolve().parents[2]
SHORT = "[simulation]\nduration = 0.6\ndecimation = 3\n"


@pytest.fixture(scope="session")
def fado_sim_cli() -> Path:
    """The `fado-sim` binary of this checkout, built in release mode (as the wheel is)."""
    cargo = shutil.which("cargo")
    if cargo is None:
        pytest.skip("cargo is not installed: cannot build the fado-sim CLI to compare with")
    proc = subprocess.run(
        [cargo, "build", "--release", "--quiet", "-p", "fado-sim", "--bin", "fado-sim"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=1200,
    )
    assert proc.returncode == 0, proc.stderr
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    exe = target / "release" / ("fado-sim.exe" if os.name == "nt" else "fado-sim")
    assert exe.is_file(), exe
    return exe


def read_traces_csv(path: Path) -> tuple[list[str], dict[str, np.ndarray]]:
    with path.open(newline="", encoding="utf-8") as f:
        reader = csv.reader(f)
        header = next(reader)
        rows = [[float(x) for x in row] for row in reader]
    table = np.array(rows, dtype=np.float64).reshape(len(rows), len(header))
    return header, {name: table[:, k] for k, name in enumerate(header)}


def run_cli(exe: Path, tmp_path: Path, scenario: str, config: str, averaged: bool) -> Path:
    cfg = tmp_path / "config.toml"
    cfg.write_text(config, encoding="utf-8")
    out = tmp_path / "out"
    args = [str(exe), "run", scenario, "--config", str(cfg), "--out", str(out)]
    if averaged:
        args.append("--averaged")
    proc = subprocess.run(args, capture_output=True, text=True, timeout=300)
    assert proc.returncode in (0, 1), proc.stderr  # 1 = criteria failed (short run)
    return out


@pytest.mark.parametrize(
    ("scenario", "averaged"), [("fig11", True), ("fig11", False), ("fig9", True)]
)
def test_simulate_is_bit_identical_to_the_cli(
    fado_sim_cli: Path, tmp_path: Path, scenario: str, averaged: bool
) -> None:
    out = run_cli(fado_sim_cli, tmp_path, scenario, SHORT, averaged)
    result = fado.simulate(scenario, SHORT, averaged)

    header, columns = read_traces_csv(out / "traces.csv")
    assert header == fado.TRACE_COLUMNS == list(result.traces)
    assert len(result) == len(columns["time"]) == 2000  # 0.6 s at 10 kHz, one row in 3
    for name in header:
        np.testing.assert_array_equal(result.traces[name], columns[name], err_msg=name)
        assert result.traces[name].dtype == np.float64

    cli_metrics = json.loads((out / "metrics.json").read_text(encoding="utf-8"))
    ours = result.metrics
    # The wall-clock time is the only thing allowed to differ.
    assert cli_metrics.pop("wall_seconds") > 0 and ours.pop("wall_seconds") > 0
    assert ours == cli_metrics
    assert result.passed == cli_metrics["passed"]
    assert result.checks == cli_metrics["checks"]


def test_dump_config_is_default_config(fado_sim_cli: Path) -> None:
    for averaged in (False, True):
        args = [str(fado_sim_cli), "run", "fig10", "--dump-config"]
        if averaged:
            args.append("--averaged")
        proc = subprocess.run(args, capture_output=True, text=True, check=True, timeout=60)
        assert proc.stdout == fado.default_config("fig10", averaged)


def test_estimator_replay_reproduces_the_in_loop_estimate() -> None:
    """The trace's voltage reference and measured current are the estimator's inputs: the
    voltage realised at n−2 is the one applied over [n−1, n] (one sample of computational
    delay), the current is sampled at n (docs/method/estimator.md, section 1). Replaying them through `fado.Estimator`
    must give the drive's θ̂ (the whole fig11 run: start-up, both modes, the zero crossing
    under 7.5 N·m)."""
    # Without the start-up offset and gain calibrations, so that the estimator runs from sample 0
    # on the raw measured currents the trace records.
    config = {
        "simulation": {"decimation": 1},
        "controller": {"offset_calibration": {"time": 0.0}, "gain_calibration": {"time": 0.0}},
    }
    result = fado.simulate("fig11", config, averaged=True)
    tr = result.traces
    assert not tr["tripped"].any()
    n = len(result)
    assert n == 55_000

    def delayed(x: np.ndarray) -> np.ndarray:
        return np.concatenate(([0.0, 0.0], x[:-2]))

    assert result.machine == fado.Machine.paper().replace(rs=result.machine.rs)
    assert result.ts == 1e-4 and result.theta0 == 0.3
    est = fado.Estimator(result.machine, result.estimator_config, ts=result.ts)
    # The drive aligns at the plant's initial angle (align_error = 0) with zero current.
    est.align(float(tr["theta"][0]), 0.0, 0.0)
    out = est.run(
        delayed(tr["v_alpha_ref"]), delayed(tr["v_beta_ref"]), tr["i_alpha"], tr["i_beta"]
    )
    # Same code, same f64 inputs, same order of operations: bit for bit, not just ~1e-9.
    np.testing.assert_array_equal(out.theta, tr["theta_hat"])
    np.testing.assert_array_equal(out.lambda1_alpha, tr["lambda1_alpha"])
    np.testing.assert_array_equal(out.disturbance_beta, tr["dist_beta"])
    np.testing.assert_array_equal(out.lambda_r_alpha, tr["lambda_r_alpha"])
    assert np.array_equal(out.flag_limit, tr["flag_limit"] == 1.0)
    pole_pairs = float(result.machine.pole_pairs)
    rpm = out.omega / pole_pairs * 60.0 / (2.0 * math.pi)
    np.testing.assert_allclose(rpm, tr["speed_hat1_rpm"], rtol=1e-12, atol=1e-9)
    # The replay is meaningful: the estimator did track the true angle near zero speed.
    assert result.metrics["max_angle_error_zero_speed"] < 0.25


@pytest.mark.parametrize("offset", [(0.1, 0.0), (0.0, 0.1), (-0.1, 0.0), (0.0, -0.1)])
def test_replay_with_a_voltage_offset_stays_within_the_papers_bound(
    offset: tuple[float, float],
) -> None:
    """The paper's reversal with a constant 0.1 V offset on one stationary-axis
    voltage, replayed, stays below 0.25 rad near zero speed. The replay is the one above
    (bit-identical to the drive's estimator without the offset), switching-resolved, with the
    offset added to the voltage the estimator is given (the drive does not react to the
    estimator's error). Measured: 0.066 / 0.044 / 0.031 / 0.113 rad for
    +α / +β / −α / −β, 0.090 without the offset; 0.51 rad with the paper's fixed-gain path."""
    config = {
        "simulation": {"decimation": 1},
        "controller": {"offset_calibration": {"time": 0.0}, "gain_calibration": {"time": 0.0}},
    }
    result = fado.simulate("fig11", config)
    tr = result.traces

    def delayed(x: np.ndarray) -> np.ndarray:
        return np.concatenate(([0.0, 0.0], x[:-2]))

    est = fado.Estimator(result.machine, result.estimator_config, ts=result.ts)
    est.align(float(tr["theta"][0]), 0.0, 0.0)
    out = est.run(
        delayed(tr["v_alpha_ref"]) + offset[0],
        delayed(tr["v_beta_ref"]) + offset[1],
        tr["i_alpha"],
        tr["i_beta"],
    )
    error = np.angle(np.exp(1j * (tr["theta"] - out.theta)))
    near_zero = (np.abs(tr["speed_rpm"]) < 30.0) & (tr["time"] >= 2.5)
    assert near_zero.sum() > 1000
    assert np.max(np.abs(error[near_zero])) < 0.25


def test_config_forms_agree(tmp_path: Path) -> None:
    text = "[simulation]\nduration = 0.2\n\n[mismatch]\nrs_ratio = 1.01\n"
    path = tmp_path / "c.toml"
    path.write_text(text, encoding="utf-8")
    forms = [
        text,
        path,
        str(path),
        {"simulation": {"duration": 0.2}, "mismatch": {"rs_ratio": 1.01}},
        {"simulation.duration": 0.2, "mismatch.rs_ratio": np.float64(1.01)},
    ]
    configs = {fado.simulate("fig11", form, averaged=True).config_toml for form in forms}
    assert len(configs) == 1
    (config,) = configs
    assert "rs_ratio = 1.01" in config and "duration = 0.2" in config


def test_default_config_round_trips() -> None:
    for name in fado.scenarios():
        text = fado.default_config(name)
        short = text.replace(
            next(line for line in text.splitlines() if line.startswith("duration =")),
            "duration = 0.05",
        )
        result = fado.simulate(name, short, averaged=False)
        assert result.config_toml == short
        assert not result.averaged
    assert 'model = "averaged"' in fado.default_config("fig8", averaged=True)


def test_dict_config_with_lists_of_lists() -> None:
    windows = [[0.05, 0.1], [0.15, 0.2]]
    result = fado.simulate(
        "fig9",
        {"simulation": {"duration": 0.25, "disturbance_feedback_off": windows}},
        averaged=True,
    )
    assert "disturbance_feedback_off = [[0.05, 0.1], [0.15, 0.2]]" in result.config_toml


def test_unknown_scenario_is_a_value_error() -> None:
    with pytest.raises(ValueError, match="fig99") as info:
        fado.simulate("fig99")
    assert isinstance(info.value, fado.InputError)
    assert info.value.argument == "scenario"
    with pytest.raises(ValueError, match="fig99"):
        fado.default_config("fig99")
    with pytest.raises(ValueError, match="fig99"):
        fado.describe_scenario("fig99")


@pytest.mark.parametrize(
    ("config", "field"),
    [
        ({"inverter": {"dead_tme": 1e-6}}, "inverter.dead_tme"),
        ({"simulation": {"duration": -1.0}}, "simulation.duration"),
        ({"mismatch.rs_ratio": "high"}, "mismatch.rs_ratio"),
        ("[simulation\nduration = 1\n", "<file>"),
    ],
)
def test_bad_config_names_the_key(config: object, field: str) -> None:
    with pytest.raises(fado.ConfigError) as info:
        fado.simulate("fig11", config, averaged=True)  # type: ignore[arg-type]
    assert info.value.field == field
    assert isinstance(info.value, ValueError)
    if field != "<file>":
        assert field in str(info.value)


@pytest.mark.parametrize(
    ("config", "field", "place"),
    [
        ({"controller": {"lock_stall_time": 0.01}}, "controller.lock_stall_time", "[controller.stall] time"),
        ({"controller.mtpa": False}, "controller.mtpa", "[controller.mtpa] enabled"),
        (
            {"controller": {"acceleration_feedforward": True}},
            "controller.acceleration_feedforward",
            "[controller.tracker_feedforward] enabled",
        ),
    ],
)
def test_a_flat_controller_key_names_its_new_place(config: dict[str, object], field: str, place: str) -> None:
    with pytest.raises(fado.ConfigError) as info:
        fado.simulate("fig11", config, averaged=True)
    assert info.value.field == field
    table = place.split("]")[0] + "]"
    assert f"`{field}` belongs in `{table}`: write it as `{place}`" in str(info.value)
    assert info.value.line is not None


def test_nested_controller_tables_reach_the_drive() -> None:
    text = fado.default_config("fig11")
    assert "[controller.stall]" in text
    config = {"simulation": {"duration": 0.05}, "controller": {"stall": {"time": 0.01}, "mtpa": {"enabled": False}}}
    result = fado.simulate("fig11", config, averaged=True)
    assert "[controller.stall]\nspeed_ratio = 0.003\ntime = 0.01\n" in result.config_toml
    assert "[controller.mtpa]\nenabled = false\n" in result.config_toml


def test_unwritable_dict_value_is_a_config_error() -> None:
    with pytest.raises(fado.ConfigError) as info:
        fado.simulate("fig11", {"simulation": {"duration": object()}})
    assert info.value.field == "simulation.duration"


def test_missing_config_file_is_reported() -> None:
    with pytest.raises(FileNotFoundError):
        fado.simulate("fig11", "no-such-file.toml")


def test_sim_result_api() -> None:
    result = fado.simulate("fig10", {"simulation": {"duration": 0.3}}, averaged=True)
    assert fado.scenarios() == [
        "fig8",
        "fig9",
        "fig10",
        "fig11",
        "fig12",
        "steady300",
        "lowspeed",
        "reversal",
        "stops",
        "rated-reversal",
        "loaded-start",
        "fullrange",
        "regen-stop",
        "custom",
    ]
    assert "Fig. 10" in fado.describe_scenario("fig10")["title"]
    assert list(result.traces) == fado.TRACE_COLUMNS
    np.testing.assert_allclose(result.time, np.arange(len(result)) * 1e-3, rtol=0, atol=1e-12)
    assert result["flag_limit"] is result.traces["flag_limit"]
    assert result.scenario == "fig10" and result.averaged
    assert result.metrics["scenario"] == "fig10"
    assert result.metrics["inverter_model"] == "averaged"
    assert result.checks == result.metrics["checks"]
    assert isinstance(result.passed, bool)
    # Copies: mutating them does not change the result.
    result.metrics["scenario"] = "x"
    result.traces.clear()
    assert result.metrics["scenario"] == "fig10" and len(result.traces) == 40
    text = repr(result)
    assert "fig10" in text and "rows=300" in text
    with pytest.raises(KeyError):
        result["nope"]


def test_to_pandas() -> None:
    pd = pytest.importorskip("pandas")
    result = fado.simulate("fig11", {"simulation": {"duration": 0.1}}, averaged=True)
    frame = result.to_pandas()
    assert isinstance(frame, pd.DataFrame)
    assert list(frame.columns) == fado.TRACE_COLUMNS[1:]
    assert frame.index.name == "time"
    np.testing.assert_array_equal(frame["theta_hat"].to_numpy(), result.traces["theta_hat"])


def test_progress_goes_to_stderr(capfd: pytest.CaptureFixture[str]) -> None:
    fado.simulate("fig11", {"simulation": {"duration": 0.2}}, averaged=True, progress=True)
    err = capfd.readouterr().err
    assert "fig11" in err and "100%" in err
    fado.simulate("fig11", {"simulation": {"duration": 0.2}}, averaged=True)
    assert capfd.readouterr().err == ""


def test_simulation_releases_the_gil() -> None:
    """While a long simulation runs in one thread, another Python thread keeps running: its
    longest pause is a small part of the simulation's wall time (it would be all of it if the
    GIL were held)."""
    done = threading.Event()
    wall: list[float] = []

    def worker() -> None:
        started = time.perf_counter()
        fado.simulate("fig9", {"simulation": {"duration": 40.0}}, averaged=True)
        wall.append(time.perf_counter() - started)
        done.set()

    thread = threading.Thread(target=worker)
    stamps = [time.perf_counter()]
    thread.start()
    while not done.is_set():
        stamps.append(time.perf_counter())
        time.sleep(0.001)
    thread.join()
    gaps = np.diff(stamps)
    assert wall[0] > 0.05, "the simulation was too short to judge"
    assert gaps.max() < 0.5 * wall[0], (gaps.max(), wall[0])


def test_motor_preset_is_the_cli_with_the_preset_file(fado_sim_cli: Path, tmp_path: Path) -> None:
    """`simulate(motor="ipmsm-2k2")` is `fado-sim run --config motors/ipmsm-2k2.toml`: the
    preset's file under the user's configuration, bit for bit."""
    preset = (ROOT / "motors" / "ipmsm-2k2.toml").read_text(encoding="utf-8")
    out = run_cli(fado_sim_cli, tmp_path, "reversal", preset + "\n" + SHORT, True)
    result = fado.simulate("reversal", SHORT, averaged=True, motor="ipmsm-2k2")
    _, columns = read_traces_csv(out / "traces.csv")
    for name in ("theta", "theta_hat", "speed_rpm", "i_alpha", "v_alpha_ref"):
        np.testing.assert_array_equal(result.traces[name], columns[name], err_msg=name)
    cli_metrics = json.loads((out / "metrics.json").read_text(encoding="utf-8"))
    ours = result.metrics
    assert cli_metrics.pop("wall_seconds") > 0 and ours.pop("wall_seconds") > 0
    assert ours == cli_metrics
    ipm = fado.Machine.preset("ipmsm-2k2")
    assert result.machine.pole_pairs == 3 and result.machine.lq == ipm.lq
    assert result.machine.dc_voltage == 540.0


def test_motor_machine_sets_motor_and_dc_link() -> None:
    ipm = fado.Machine.preset("ipmsm-2k2")
    short = {"simulation": {"duration": 0.05}}
    by_machine = fado.simulate("reversal", short, averaged=True, motor=ipm)
    assert by_machine.machine.ld == ipm.ld and by_machine.machine.dc_voltage == 540.0
    assert "rated_torque = 14.0" in by_machine.config_toml
    assert "dc_voltage = 540.0" in by_machine.config_toml
    # The user's keys win over the motor's.
    hot = fado.simulate("reversal", dict(short, motor={"rs": 4.0}), averaged=True, motor=ipm)
    assert "rs = 4.0" in hot.config_toml
    # The same motor as default_config sees it.
    assert "rated_current = 6.08" in fado.default_config("reversal", motor=ipm)
    assert "rated_current = 6.08" in fado.default_config("stops", motor="ipmsm-2k2")


def test_motor_as_a_dict_of_machine_fields_is_the_machine() -> None:
    # As `fado.commission` and `fado.estimate` take it.
    ipm = fado.Machine.preset("ipmsm-2k2")
    fields = {"rs": ipm.rs, "ld": ipm.ld, "lq": ipm.lq, "flux_linkage": ipm.flux_linkage,
              "pole_pairs": ipm.pole_pairs, "inertia": ipm.inertia,
              "viscous_friction": ipm.viscous_friction, "rated_current": ipm.rated_current,
              "rated_speed_rpm": ipm.rated_speed_rpm, "rated_torque": ipm.rated_torque,
              "dc_voltage": ipm.dc_voltage}
    by_dict = fado.default_config("reversal", motor=fields)
    assert by_dict == fado.default_config("reversal", motor=fado.Machine(**fields))
    assert "rated_current = 6.08" in by_dict
    with pytest.raises(ValueError, match="rss"):
        fado.simulate("reversal", motor=dict(fields, rss=1.0))


def test_bad_motor_raises_naming_it() -> None:
    with pytest.raises(ValueError, match="ipmsm-2k2") as info:
        fado.simulate("reversal", motor="no-such-motor")
    assert isinstance(info.value, fado.InputError) and info.value.argument == "motor"
    with pytest.raises(TypeError, match="motor"):
        fado.simulate("reversal", motor=3.0)  # type: ignore[arg-type]


def test_cli_lists_motors_and_simulates_one(capsys: pytest.CaptureFixture[str]) -> None:
    from fado.__main__ import main

    assert main(["motors"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in lines] == fado.machine_presets()
    assert main(["default-config", "reversal", "--motor", "ipmsm-2k2"]) == 0
    assert "rated_current = 6.08" in capsys.readouterr().out
    assert main(["default-config", "reversal", "--motor", "nope"]) == 2
    assert "ipmsm-2k2" in capsys.readouterr().err
