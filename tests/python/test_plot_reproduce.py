"""`fado.plot` (the paper's Fig. 8–12) and `python -m fado reproduce`."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

import fado
from fado import _toml

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def averaged_runs() -> dict[str, fado.SimResult]:
    """Every paper scenario, full length, averaged inverter (about 0.2 s for all five)."""
    paper = [name for name in fado.scenarios() if name.startswith("fig")]
    assert paper == ["fig8", "fig9", "fig10", "fig11", "fig12"]
    return {name: fado.simulate(name, averaged=True) for name in paper}


def test_every_figure_is_written(
    tmp_path: Path, averaged_runs: dict[str, fado.SimResult]
) -> None:
    pytest.importorskip("matplotlib")
    import fado.plot

    panels = {"fig8": 5, "fig9": 5, "fig10": 6, "fig11": 5, "fig12": 4}
    for name, result in averaged_runs.items():
        path = tmp_path / f"{name}.png"
        fig = getattr(fado.plot, f"plot_{name}")(result, path)
        data = path.read_bytes()
        assert data.startswith(PNG_MAGIC), name
        assert len(data) > 20_000, (name, len(data))
        axes = fig.get_axes()
        assert len(axes) == panels[name], name
        # One shared time axis spanning the run.
        t_end = float(result.time[-1])
        for ax in axes:
            lo, hi = ax.get_xlim()
            assert lo <= 0.0 + 0.1 and hi >= t_end - 0.1, (name, lo, hi)
        # The dispatcher picks the same figure.
        same = fado.plot.plot_scenario(result)
        assert len(same.get_axes()) == panels[name]


def test_figure_content(averaged_runs: dict[str, fado.SimResult]) -> None:
    pytest.importorskip("matplotlib")
    import fado.plot

    fig = fado.plot.plot_fig11(averaged_runs["fig11"])
    error_axis = fig.get_axes()[1]
    levels = sorted(
        round(float(line.get_ydata()[0]), 6)
        for line in error_axis.get_lines()
        if len(set(line.get_ydata())) == 1
    )
    assert levels == [-fado.plot.ANGLE_CRITERION, fado.plot.ANGLE_CRITERION]
    fig10 = fado.plot.plot_fig10(averaged_runs["fig10"])
    run = averaged_runs["fig10"]
    radius = round(run.estimator_config.limiter["radius_ratio"] * run.machine.flux_linkage, 9)
    flux_axis = fig10.get_axes()[3]
    assert radius in {
        round(float(line.get_ydata()[0]), 9) for line in flux_axis.get_lines()
    }
    # fig9 shades the k_df-off window [3 s, 5 s].
    assert fado.plot._k_df_off_windows(averaged_runs["fig9"]) == [(3.0, 5.0)]


def test_plot_scenario_rejects_unknown() -> None:
    pytest.importorskip("matplotlib")
    import fado.plot

    class Fake:
        scenario = "fig99"

    with pytest.raises(ValueError, match="fig99"):
        fado.plot.plot_scenario(Fake())  # type: ignore[arg-type]


def test_reproduce_cli_on_a_subset(tmp_path: Path) -> None:
    pytest.importorskip("matplotlib")
    out = tmp_path / "repro"
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "fado",
            "reproduce",
            "--out",
            str(out),
            "--averaged",
            "--scenarios",
            "fig10,fig11",
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "[1/2] fig10" in proc.stdout and "[2/2] fig11" in proc.stdout
    assert "100%" in proc.stderr  # the progress bar
    for name in ("fig10", "fig11"):
        assert (out / f"{name}.png").read_bytes().startswith(PNG_MAGIC)
        metrics = json.loads((out / f"{name}_metrics.json").read_text(encoding="utf-8"))
        assert metrics["scenario"] == name
        assert metrics["inverter_model"] == "averaged"
    table = (out / "metrics.md").read_text(encoding="utf-8").splitlines()
    assert table[0].startswith("| scenario | inverter | passed |")
    assert len(table) == 4
    assert table[2].startswith("| fig10 | averaged |")
    assert table[3].startswith("| fig11 | averaged | yes |")
    assert not (out / "fig8.png").exists()


def test_cli_errors_and_helpers(tmp_path: Path) -> None:
    def run(*args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            [sys.executable, "-m", "fado", *args], capture_output=True, text=True, timeout=120
        )

    bad = run("reproduce", "--out", str(tmp_path / "x"), "--scenarios", "fig99", "--no-plots")
    assert bad.returncode == 2 and "fig99" in bad.stderr
    assert run("default-config", "fig12").stdout == fado.default_config("fig12")
    listed = run("scenarios").stdout
    assert all(name in listed for name in fado.scenarios())
    cfg = tmp_path / "bad.toml"
    cfg.write_text("[inverter]\ndead_tme = 1e-6\n", encoding="utf-8")
    bad = run("simulate", "fig11", "--averaged", "--config", str(cfg))
    assert bad.returncode == 2 and "inverter.dead_tme" in bad.stderr
    ok = run("simulate", "fig11", "--averaged", "--out", str(tmp_path / "one"))
    assert ok.returncode == 0, ok.stderr
    assert (tmp_path / "one" / "traces.csv").read_text().startswith("time,theta,")


def test_toml_writer() -> None:
    text = _toml.dumps(
        {
            "simulation": {"duration": 1e-5, "decimation": 2, "flag": True},
            "a.b": {"name": 'say "hi"\n', "x": [1, 2.5]},
            "a": {"c": float("inf")},
        }
    )
    assert "[simulation]\nduration = 1e-05\ndecimation = 2\nflag = true\n" in text
    tomllib = pytest.importorskip("tomllib")  # 3.11+: the writer's output must parse back
    parsed = tomllib.loads(text)
    assert parsed["simulation"] == {"duration": 1e-5, "decimation": 2, "flag": True}
    assert parsed["a"]["b"] == {"name": 'say "hi"\n', "x": [1, 2.5]}
    assert parsed["a"]["c"] == float("inf")
    with pytest.raises(fado.ConfigError) as info:
        _toml.dumps({"x": {"y": 1}, "x.y": 2})
    assert info.value.field == "x.y"
    # The same key both ways is refused in either order (one order used to win silently).
    for both in (
        {"motor.rs": 0.3, "motor": {"rs": 0.4}},
        {"motor": {"rs": 0.4}, "motor.rs": 0.3},
        {"a.b.c": 1, "a": {"b": {"c": 2}}},
        {"a": {"b.c": 1}, "a.b": {"c": 2}},
    ):
        with pytest.raises(fado.ConfigError, match="given twice") as info:
            _toml.dumps(both)
        assert info.value.field in ("motor.rs", "a.b.c"), both
    # Different keys given both ways merge.
    merged = tomllib.loads(_toml.dumps({"motor.rs": 0.3, "motor": {"ld": 1e-3}}))
    assert merged["motor"] == {"rs": 0.3, "ld": 1e-3}


def test_plot_scenario_draws_every_scenario(tmp_path: Path) -> None:
    """Every scenario has a figure, the ratings-scaled ones on a motor other than the paper's
    included (a short run: the figure, not the result, is under test)."""
    pytest.importorskip("matplotlib")
    import fado.plot

    for name in fado.scenarios():
        result = fado.simulate(
            name,
            {"simulation": {"duration": 0.3, "decimation": 20}},
            averaged=True,
            motor="ipmsm-2k2",
        )
        path = tmp_path / f"{name}.png"
        fig = fado.plot.plot_scenario(result, path)
        assert path.read_bytes().startswith(PNG_MAGIC), name
        assert len(fig.get_axes()) >= 4, name
