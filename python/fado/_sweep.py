"""``fado.sweep``: operating-envelope sweeps of the simulated drive as a pandas DataFrame.

Each point is one scenario run with some parameters changed; the scenario's pass criteria
judge it. In Rust on all cores by default, or one task per point on any
``concurrent.futures.Executor``-like object (a ``ProcessPoolExecutor``, a Dask
``distributed.Client``) to spread a large sweep over processes or machines.
"""

from __future__ import annotations

import itertools
import os
import sys
from collections.abc import Mapping, Sequence
from typing import Any, Protocol, Union

from fado import _fado
from fado._keywords import checked
from fado._simulation import ConfigLike, config_text

#: The derived parameters (besides any TOML key ``section.key``) and what they mean.
PARAMETERS: dict[str, str] = dict(_fado.SWEEP_PARAMETERS)


class _Future(Protocol):
    def result(self) -> Any: ...


class Executor(Protocol):
    """What ``executor`` needs: ``submit(fn, *args, **kwargs)`` returning a future with
    ``.result()`` — :class:`concurrent.futures.Executor` and ``distributed.Client`` both do."""

    def submit(self, fn: Any, /, *args: Any, **kwargs: Any) -> _Future: ...


Grid = Union[Mapping[str, Sequence[Any]], Sequence[Mapping[str, Any]]]


def design(grid: Grid) -> tuple[list[str], list[list[Any]]]:
    """The axes and the points of `grid`: a dict ``{param: values}`` is the cartesian product
    (first key slowest, as ``fado-sim sweep``); a list of dicts (all with the same keys) is
    taken point by point (random or hand-made designs)."""
    if isinstance(grid, Mapping):
        axes = [str(k) for k in grid]
        values = [list(v) for v in grid.values()]
        for name, v in zip(axes, values):
            if not v:
                raise ValueError(f"sweep axis {name!r} has no values")
        return axes, [list(p) for p in itertools.product(*values)]
    points = list(grid)
    if not points:
        raise ValueError("sweep needs at least one point")
    axes = [str(k) for k in points[0]]
    rows = []
    for k, p in enumerate(points):
        if sorted(map(str, p)) != sorted(axes):
            raise ValueError(f"point {k} has keys {sorted(p)}, the first point {sorted(axes)}")
        rows.append([p[a] for a in axes])
    return axes, rows


def run_point(
    scenario: str,
    axes: list[str],
    values: list[Any],
    config: str | None,
    averaged: bool,
    index: int,
) -> dict[str, Any]:
    """Runs one point (module level, so that process pools and Dask can pickle it)."""
    return _fado.sweep_point(
        scenario, axes, values, config=config, averaged=averaged, index=index
    )


@checked
def sweep(
    grid: Grid,
    scenario: str = "fig11",
    *,
    config: ConfigLike = None,
    averaged: bool = False,
    executor: Executor | None = None,
    threads: int = 0,
    out: str | os.PathLike[str] | None = None,
    fresh: bool = False,
    progress: bool = False,
) -> Any:
    """Runs `scenario` once per point of `grid` and returns a pandas DataFrame, one row per
    point in point order.

    `grid` is ``{param: values}`` (cartesian product, first key slowest) or a list of
    ``{param: value}`` dicts. A parameter is any TOML key ``"section.key"`` of
    :func:`fado.default_config` or one of :data:`PARAMETERS` (``rs_error`` = R̂s/Rs − 1,
    ``lq_error``, ``flux_linkage_error``, ``dead_time_comp_error``, ``sensor_offset``,
    ``sensor_gain_error``, ``load_torque`` in N·m, ``reversal_ramp`` in r/min per s).
    `config` (TOML text, path or dict, as for :func:`fado.simulate`) applies before the
    parameters; `averaged` selects the averaged inverter model.

    With ``executor=None`` the points run in Rust on `threads` threads (0: all cores; more
    than the machine's cores are capped, with a ``RuntimeWarning``), with the GIL released;
    Ctrl-C stops them within milliseconds (``KeyboardInterrupt``), the finished points kept
    in `out` for the same call to resume from; `out` then keeps ``sweep.csv`` (rows appended as points finish),
    ``sweep.json``, ``summary.json`` and ``summary.md`` in that directory and resumes a sweep
    interrupted there (``fresh=True`` starts over). With an `executor` (anything with
    ``submit(fn, *args)`` returning futures with ``.result()``: a
    ``concurrent.futures.ProcessPoolExecutor``, a Dask ``distributed.Client``), each point
    is one task running :func:`run_point`; the rows are the same. `progress` prints the
    points done to stderr.

    Columns: ``point``, one per parameter, ``status`` (``ok``, ``diverged`` — tripped or
    non-finite — or ``failed: <message>``), ``passed`` (every criterion of the scenario),
    ``tripped``, ``max_angle_error``, ``rms_angle_error``, ``max_angle_error_zero_speed``,
    ``rms_angle_error_zero_speed`` (rad), ``max_speed_error_rpm``, ``wall_seconds``,
    ``failed_checks``. A failing point never raises; a bad scenario or axis name does.
    """
    try:
        import pandas as pd
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError("fado.sweep needs pandas: pip install 'fado[pandas]'") from e
    axes, points = design(grid)
    text = config_text(config)
    if executor is None:
        rows = _fado.sweep(
            scenario,
            axes,
            points,
            config=text,
            averaged=averaged,
            threads=threads,
            out=None if out is None else os.fspath(out),
            fresh=fresh,
            progress=progress,
        )
    else:
        if out is not None:
            raise ValueError("out (resumable CSV) is only available with executor=None")
        # Check the definition once here: a bad axis name is an error, not n failed rows.
        _fado.sweep(scenario, axes, [], config=text, averaged=averaged)
        futures = [
            executor.submit(run_point, scenario, axes, p, text, averaged, k)
            for k, p in enumerate(points)
        ]
        rows = []
        for k, f in enumerate(futures):
            rows.append(f.result())
            if progress:
                print(f"\rsweep {k + 1}/{len(futures)}", end="", file=sys.stderr, flush=True)
        if progress:
            print(file=sys.stderr)
    columns = [
        "point",
        *axes,
        "status",
        "passed",
        "tripped",
        "max_angle_error",
        "rms_angle_error",
        "max_angle_error_zero_speed",
        "rms_angle_error_zero_speed",
        "max_speed_error_rpm",
        "wall_seconds",
        "failed_checks",
    ]
    return pd.DataFrame(rows, columns=columns)
