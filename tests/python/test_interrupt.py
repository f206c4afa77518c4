"""Ctrl-C stops the long calls (`fado.simulate`, `fado.sweep`, `fado.estimate`,
`Estimator.run`) within 0.5 s, and an interrupted sweep resumes from the points it finished.

SIGINT is sent to this process from a timer thread while the call runs; Python runs its
handler on the main thread, which the bindings poll while the work runs without the GIL.
Each call below would run for several seconds (at least ten times the 0.5 s budget) if the
signal were ignored, which the first assertion of every test checks.
"""

from __future__ import annotations

import os
import signal
import threading
import time
import warnings
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pytest

import fado

# Seconds after the call starts at which SIGINT is sent, and the most the call may then take.
SEND_AFTER = 0.4
BUDGET = 0.5

pytestmark = pytest.mark.skipif(
    not hasattr(signal, "SIGINT") or os.name != "posix", reason="needs POSIX signals"
)


def interrupted_after(call: Callable[[], Any]) -> float:
    """Seconds from SIGINT to the KeyboardInterrupt out of `call`."""
    sent: dict[str, float] = {}

    def fire() -> None:
        sent["at"] = time.perf_counter()
        os.kill(os.getpid(), signal.SIGINT)

    timer = threading.Timer(SEND_AFTER, fire)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            call()
    finally:
        timer.cancel()
    return time.perf_counter() - sent["at"]


def test_simulate_stops_on_ctrl_c() -> None:
    # 1000 s of the averaged plant: about 10 s of work on one core.
    long = {"simulation": {"duration": 1000.0, "decimation": 1000}}
    assert interrupted_after(lambda: fado.simulate("fig11", long, averaged=True)) < BUDGET
    # The module still works afterwards.
    short = fado.simulate("fig11", {"simulation": {"duration": 0.05}}, averaged=True)
    assert len(short) > 0


def test_estimate_and_estimator_run_stop_on_ctrl_c() -> None:
    # 40 M samples at ≥ 100 ns each: ≥ 4 s. np.zeros maps its pages lazily (no 1 GB touched).
    z = np.zeros(40_000_000)
    assert interrupted_after(lambda: fado.estimate(z, z, z, z, machine="paper")) < BUDGET
    est = fado.Estimator("paper")
    assert interrupted_after(lambda: est.run(z, z, z, z)) < BUDGET


def test_sweep_stops_on_ctrl_c_and_resumes_with_the_points_finished(tmp_path: Path) -> None:
    pytest.importorskip("pandas")
    out = tmp_path / "sweep"
    # Two quick points, then two of 1000 s (each about 10 s of work).
    grid = [{"simulation.duration": d} for d in (0.02, 0.03, 1000.0, 1000.0)]
    assert (
        interrupted_after(
            lambda: fado.sweep(grid, "fig11", averaged=True, threads=1, out=out)
        )
        < BUDGET
    )
    lines = (out / "sweep.csv").read_text().splitlines()
    finished = sorted(int(line.split(",")[0]) for line in lines[1:])
    assert finished == [0, 1], lines
    # The same call again picks them up (a different sweep would be refused): interrupt it
    # too, and the finished points are still there.
    interrupted_after(lambda: fado.sweep(grid, "fig11", averaged=True, threads=1, out=out))
    lines = (out / "sweep.csv").read_text().splitlines()
    assert sorted(int(line.split(",")[0]) for line in lines[1:]) == [0, 1]


def test_sweep_threads_above_the_cores_are_capped_with_a_warning() -> None:
    pytest.importorskip("pandas")
    grid = {"rs_error": [0.0, 0.01]}
    short = {"simulation": {"duration": 0.02, "eval_start": 0.0}}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        started = time.perf_counter()
        df = fado.sweep(grid, "fig11", config=short, averaged=True, threads=10_000)
        took = time.perf_counter() - started
    assert len(df) == 2
    messages = [str(w.message) for w in caught if issubclass(w.category, RuntimeWarning)]
    assert any("10000 threads asked for" in m for m in messages), messages
    # 10,000 threads took 97 s before the cap; two short points take well under 5 s.
    assert took < 5.0


def test_simulate_refuses_a_trace_too_long_for_memory_before_running() -> None:
    started = time.perf_counter()
    with pytest.raises(fado.ConfigError) as e:
        fado.simulate("fig11", "[simulation]\nduration = 19999.0\ndecimation = 10\n", averaged=True)
    assert e.value.field == "simulation.decimation"
    assert e.value.line == 3
    assert "rows" in str(e.value)
    assert time.perf_counter() - started < 1.0


def test_a_single_sweep_point_stops_on_ctrl_c() -> None:
    # What `fado.sweep(..., executor=...)` runs per task: 1000 s of the averaged plant.
    def one_point() -> Any:
        return fado._fado.sweep_point(
            "fig11", ["simulation.duration"], [1000.0], averaged=True
        )

    assert interrupted_after(one_point) < BUDGET
