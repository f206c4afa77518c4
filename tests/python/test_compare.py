"""`fado.compare`: the baseline comparison from Python (averaged inverter, short runs)."""

from __future__ import annotations

import threading
from pathlib import Path

import pytest

import fado
from fado.compare import CompareResult

SHORT = "[simulation]\nduration = 2.7\n"  # steady300 up to 0.2 s past its settling time


def test_compare_returns_one_row_per_scenario_and_estimator() -> None:
    result = fado.compare(["steady300"], ["fado", "ortega"], averaged=True, config=SHORT)
    assert isinstance(result, CompareResult)
    assert [(r["scenario"], r["estimator"]) for r in result] == [
        ("steady300", "fado"),
        ("steady300", "ortega"),
    ]
    for r in result:
        # Both hold the angle at 300 r/min under 7.5 N·m: the sanity check of the comparison.
        assert r["passed"] and not r["tripped"], r["checks"]
        assert 0.0 < r["max_angle_error"] < 0.05
        assert r["rms_angle_error"] <= r["max_angle_error"]
        assert r["lowest_speed_held_rpm"] is None and r["levels"] == []
        assert "trace" not in r
    assert result.row("steady300", "ortega") is result[1]
    with pytest.raises(KeyError):
        result.row("fig11", "fado")


def test_the_default_lists_are_the_registries() -> None:
    assert fado.compare.ESTIMATORS == tuple(fado._fado.estimators())
    assert fado.compare.ESTIMATORS[:2] == ("fado", "fado-fixed-rs")
    assert "ortega" in fado.compare.ESTIMATORS
    assert fado.compare.SCENARIOS == tuple(fado.scenarios())
    assert {"fig8", "fig12", "steady300", "lowspeed", "reversal", "stops"} <= set(
        fado.compare.SCENARIOS
    )
    with pytest.raises(fado.ConfigError, match="one of"):
        fado.compare(["steady300"], ["kalman"], averaged=True, config=SHORT)


def test_compare_matches_the_native_call_and_is_deterministic() -> None:
    a = fado.compare.compare(["steady300"], ["emf-observer"], True, config=SHORT)
    b = fado._fado.compare(["steady300"], ["emf_observer"], True, config=SHORT)
    assert a[0]["max_angle_error"] == b[0]["max_angle_error"]
    assert a[0]["estimator"] == "emf-observer"


def test_compare_releases_the_gil() -> None:
    ticks = 0
    stop = threading.Event()

    def count() -> None:
        nonlocal ticks
        while not stop.is_set():
            ticks += 1

    t = threading.Thread(target=count)
    t.start()
    try:
        fado.compare(["steady300"], averaged=True, config=SHORT, threads=1)
    finally:
        stop.set()
        t.join()
    assert ticks > 1000


def test_traces_hold_the_angle_error_columns() -> None:
    result = fado.compare(["steady300"], ["fado"], True, config=SHORT, traces=True)
    tr = result[0]["trace"]
    assert {"time", "theta", "theta_hat", "angle_error", "speed_rpm", "speed_ref_rpm"} <= set(tr)
    assert tr["time"].shape == tr["angle_error"].shape
    assert abs(tr["time"][-1] - 2.7) < 0.01
    assert float(abs(tr["angle_error"][tr["time"] > 2.5]).max()) == pytest.approx(
        result[0]["max_angle_error"], abs=0.01
    )


def test_bad_names_raise_config_error_naming_the_key() -> None:
    with pytest.raises(fado.ConfigError) as e:
        fado.compare(["steady300"], ["kalman"], averaged=True)
    assert e.value.field == "estimators"
    with pytest.raises(fado.ConfigError) as e:
        fado.compare(["fig99"], averaged=True)
    assert e.value.field == "scenario"


def test_to_pandas() -> None:
    pytest.importorskip("pandas")
    df = fado.compare(["steady300"], ["fado", "lpf-integrator"], True, config=SHORT).to_pandas()
    assert list(df["estimator"]) == ["fado", "lpf-integrator"]
    assert df["max_angle_error"].dtype.kind == "f"


def test_plot_angle_errors_writes_a_figure(tmp_path: Path) -> None:
    pytest.importorskip("matplotlib")
    path = tmp_path / "fig11.png"
    result = fado.compare.plot_angle_errors(
        path,
        "fig11",
        estimators=["fado", "ortega"],
        averaged=True,
        config="[simulation]\nduration = 3.8\n",
    )
    assert path.stat().st_size > 10_000
    assert [r["estimator"] for r in result] == ["fado", "ortega"]
    assert all(r["zero_speed_samples"] > 1000 for r in result)
