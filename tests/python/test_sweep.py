"""`fado.sweep` and `fado.plot.envelope`: operating-envelope sweeps from Python.

Every sweep here is fig11 cut to its start-up (0.3 s) on the averaged plant, so a point
runs in milliseconds; what is checked is the plumbing (design, rows, failures recorded,
executors giving the same rows as the Rust pool, resume), not the drive.
"""

from __future__ import annotations

import json
import multiprocessing
from concurrent.futures import ProcessPoolExecutor
from typing import Any

import pytest

import fado

pd = pytest.importorskip("pandas")

# Without the start-up gain calibration, which would take the whole 0.3 s (the drive would not
# have started, and no parameter of the model would move the run).
SHORT = {
    "simulation": {"duration": 0.3, "eval_start": 0.0},
    "controller": {"gain_calibration": {"time": 0.0}},
}
GRID = {"rs_error": [-0.05, 0.0, 0.05], "lq_error": [0.0, 0.3]}


def short_sweep(grid: Any = GRID, **kw: Any) -> Any:
    return fado.sweep(grid, "fig11", config=SHORT, averaged=True, **kw)


def comparable(df: Any) -> Any:
    """The rows without the wall times (which differ from run to run)."""
    return df.drop(columns=["wall_seconds"]).reset_index(drop=True)


def test_grid_is_the_cartesian_product_with_one_row_per_point() -> None:
    df = short_sweep()
    assert list(df["point"]) == list(range(6))
    assert list(zip(df["rs_error"], df["lq_error"])) == [
        (r, q) for r in GRID["rs_error"] for q in GRID["lq_error"]
    ]
    assert list(df.columns[:3]) == ["point", "rs_error", "lq_error"]
    assert (df["status"] == "ok").all()
    assert df["max_angle_error"].between(0.0, 3.2).all()
    # The start-up with a matched model passes; the rows differ with the parameters.
    assert df.loc[2, "passed"]
    assert df["max_angle_error"].nunique() == 6


def test_a_list_of_points_is_taken_point_by_point() -> None:
    points = [{"rs_error": 0.01, "estimator.disturbance_feedback.k_df": 0.25}, {"rs_error": -0.01, "estimator.disturbance_feedback.k_df": 1.0}]
    df = short_sweep(points)
    assert list(df["estimator.disturbance_feedback.k_df"]) == [0.25, 1.0]
    with pytest.raises(ValueError, match="keys"):
        short_sweep([{"rs_error": 0.0}, {"lq_error": 0.0}])


def test_failing_points_are_rows_not_exceptions() -> None:
    df = short_sweep({"rs_error": [-2.0, 0.0]})
    assert df.loc[0, "status"].startswith("failed: ") and "rs_ratio" in df.loc[0, "status"]
    assert not df.loc[0, "passed"] and pd.isna(df.loc[0, "max_angle_error"])
    assert df.loc[1, "status"] == "ok"


def test_a_bad_parameter_name_raises_before_running() -> None:
    with pytest.raises(fado.ConfigError):
        short_sweep({"no_such_parameter": [1.0]})


def test_process_pool_gives_the_rows_of_the_rust_pool() -> None:
    expected = comparable(short_sweep())
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=2, mp_context=ctx) as pool:
        got = comparable(short_sweep(executor=pool))
    pd.testing.assert_frame_equal(got, expected)


def test_dask_local_cluster_gives_the_rows_of_the_rust_pool() -> None:
    distributed = pytest.importorskip("distributed")
    expected = comparable(short_sweep())
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        got = comparable(short_sweep(executor=client))
    pd.testing.assert_frame_equal(got, expected)


def test_out_keeps_the_csv_and_resumes(tmp_path: Any) -> None:
    first = short_sweep(out=tmp_path)
    csv = pd.read_csv(tmp_path / "sweep.csv")
    assert list(csv["point"]) == list(range(6))
    assert list(csv["max_angle_error"]) == list(first["max_angle_error"])
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["finished"] == 6 and summary["passed"] == int(first["passed"].sum())
    # Nothing left to run: the rows come back from the CSV, wall times included.
    again = short_sweep(out=tmp_path)
    pd.testing.assert_frame_equal(again, first)
    with pytest.raises(ValueError, match="different sweep"):
        short_sweep({"rs_error": [0.0]}, out=tmp_path)
    assert len(short_sweep({"rs_error": [0.0]}, out=tmp_path, fresh=True)) == 1


def test_envelope_draws_the_grid_and_a_random_design(tmp_path: Any) -> None:
    pytest.importorskip("matplotlib")
    import fado.plot

    df = short_sweep({"rs_error": [-2.0, -0.5, 0.0, 0.5], "load_torque": [0.0, 7.5]})
    fig = fado.plot.envelope(df, "rs_error", "load_torque", path=tmp_path / "grid.png")
    assert (tmp_path / "grid.png").stat().st_size > 1000
    assert "8 points" in fig.axes[0].get_title()
    points = [{"rs_error": 0.1 * k - 0.3, "load_torque": 1.3 * k} for k in range(7)]
    fig = fado.plot.envelope(short_sweep(points), "rs_error", "load_torque")
    assert len(fig.axes[0].collections) == 2  # passed and failed markers


def test_every_derived_parameter_is_accepted() -> None:
    from fado._sweep import PARAMETERS

    values = {
        "rs_error": 0.01,
        "lq_error": 0.1,
        "ld_error": 0.1,
        "flux_linkage_error": -0.05,
        "dead_time_comp_error": 0.02,
        "sensor_offset": 0.03,
        "sensor_gain_error": 0.01,
        "load_torque": 2.0,
        "reversal_ramp": 180.0,
    }
    assert set(PARAMETERS) == set(values)
    df = short_sweep([values])
    assert df.loc[0, "status"] == "ok", df.loc[0, "status"]
    # Each parameter moves the run (the matched short run differs from each one-off change).
    matched = short_sweep({"rs_error": [0.0]}).loc[0, "rms_angle_error"]
    for name in ["rs_error", "lq_error", "flux_linkage_error", "sensor_gain_error"]:
        assert short_sweep({name: [values[name]]}).loc[0, "rms_angle_error"] != matched, name
