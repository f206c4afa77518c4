"""Reproduces the paper's experiments (Fig. 8–12): runs the scenarios, draws the figures and
tabulates the metrics. Used by ``python -m fado reproduce``; callable from Python too::

    from fado.reproduce import reproduce
    rows = reproduce("out", scenarios=["fig11"], averaged=True)
"""

from __future__ import annotations

import json
import os
import sys
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

from fado._fado import scenarios as all_scenarios
from fado._simulation import ConfigLike, simulate

__all__ = ["Row", "metrics_table", "reproduce"]


@dataclass(frozen=True)
class Row:
    """One scenario's line of ``metrics.md``."""

    scenario: str
    metrics: Mapping[str, Any]
    wall_seconds: float
    figure: Path | None


_HEADER = (
    "| scenario | inverter | passed | max err (rad) | rms err (rad) | max err near 0 (rad) "
    "| rms err near 0 (rad) | max speed err (r/min) | tripped | simulated (s) | wall (s) |"
)


def metrics_table(rows: Iterable[Row]) -> str:
    """The markdown table of ``metrics.md``. Wall time is the whole ``simulate`` call; the
    simulator's own loop time is in each ``figN_metrics.json`` (``wall_seconds``)."""
    lines = [_HEADER, "|" + "---|" * _HEADER.count(" | ") + "---|"]
    for r in rows:
        m = r.metrics
        lines.append(
            f"| {r.scenario} | {m['inverter_model']} | {'yes' if m['passed'] else '**no**'} "
            f"| {m['max_angle_error']:.3f} | {m['rms_angle_error']:.3f} "
            f"| {m['max_angle_error_zero_speed']:.3f} | {m['rms_angle_error_zero_speed']:.3f} "
            f"| {m['max_speed_error_rpm']:.1f} | {m['tripped']} "
            f"| {m['simulated_seconds']:.1f} | {r.wall_seconds:.2f} |"
        )
    return "\n".join(lines) + "\n"


def _failed_checks(metrics: Mapping[str, Any]) -> str:
    failed = [c["name"] for c in metrics.get("checks", []) if not c["passed"]]
    return f" (failed: {'; '.join(failed)})" if failed else ""


def reproduce(
    out: str | os.PathLike[str],
    scenarios: Sequence[str] | None = None,
    averaged: bool = False,
    config: ConfigLike = None,
    *,
    plots: bool = True,
    progress: bool = True,
    log: IO[str] | None = None,
) -> list[Row]:
    """Runs `scenarios` (default: all five), writing ``OUT/figN.png`` (if `plots`),
    ``OUT/figN_metrics.json`` and ``OUT/metrics.md``; returns the table's rows.

    `config` (TOML, path or dict, as for :func:`fado.simulate`) applies to every scenario,
    e.g. ``{"mismatch": {"rs_ratio": 1.01}}`` for a robustness run. `progress` draws a
    progress bar per scenario on stderr; a line per finished scenario goes to `log`
    (default stdout).
    """
    log = sys.stdout if log is None else log
    # Default: the paper's five experiments (fig8 … fig12); the comparison scenarios
    # (steady300, lowspeed) have no paper figure.
    paper = [n for n in all_scenarios() if n.startswith("fig")]
    names = list(paper if scenarios is None else scenarios)
    known = set(all_scenarios())
    unknown = [n for n in names if n not in known]
    if unknown:
        raise ValueError(f"unknown scenario(s) {unknown}; one of {sorted(known)}")
    plot: Callable[[Any, Path], object] | None = None
    if plots:
        from fado.plot import _matplotlib, plot_scenario

        _matplotlib()  # no matplotlib: say so before the long runs, not after the first
        plot = plot_scenario
    out_dir = Path(out)
    out_dir.mkdir(parents=True, exist_ok=True)
    rows = []
    started_all = time.perf_counter()
    for k, name in enumerate(names, 1):
        started = time.perf_counter()
        result = simulate(name, config, averaged, progress=progress)
        wall = time.perf_counter() - started
        metrics = result.metrics
        (out_dir / f"{name}_metrics.json").write_text(
            json.dumps(metrics, indent=2) + "\n", encoding="utf-8"
        )
        figure = None
        if plot is not None:
            figure = out_dir / f"{name}.png"
            plot(result, figure)
        rows.append(Row(name, metrics, wall, figure))
        verdict = "passed" if result.passed else "FAILED" + _failed_checks(metrics)
        print(
            f"[{k}/{len(names)}] {name}: {verdict}; max |θ−θ̂| near 0 = "
            f"{metrics['max_angle_error_zero_speed']:.3f} rad; "
            f"{metrics['simulated_seconds']:.1f} s simulated in {wall:.2f} s",
            file=log,
            flush=True,
        )
    (out_dir / "metrics.md").write_text(metrics_table(rows), encoding="utf-8")
    total = time.perf_counter() - started_all
    print(f"wrote {out_dir}/metrics.md ({len(rows)} scenarios, {total:.1f} s)", file=log)
    return rows
