"""fado against the observers other drives use, in the closed-loop simulator.

Every estimator of the simulator's registry (:data:`ESTIMATORS`: fado and the baselines of
``fado_core::baselines``) runs every scenario (:data:`SCENARIOS`) on the same plant, with the
same non-idealities, controllers and sensor-noise seed; each is tuned once with its
documented defaults. The work runs in Rust (``fado_sim::compare``) with the GIL released::

    import fado
    result = fado.compare(scenarios=["fig11", "lowspeed"], averaged=True)
    for row in result:
        print(row["scenario"], row["estimator"], row["max_angle_error_zero_speed"])
    df = result.to_pandas()                      # needs pandas
    fado.compare.plot_angle_errors("fig11.png")  # needs matplotlib

``fado.compare`` is this module, made callable: ``fado.compare(...)`` is
:func:`compare`. Typed code may prefer ``from fado.compare import compare``.
"""

from __future__ import annotations

import sys
import types
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from fado import _fado

__all__ = ["ESTIMATORS", "SCENARIOS", "CompareResult", "compare", "plot_angle_errors"]

#: Every estimator name, in the order ``compare`` runs them by default (read from the
#: simulator's registry, ``fado_sim::estimators::ESTIMATORS``).
ESTIMATORS: tuple[str, ...] = tuple(_fado.estimators())
#: Every scenario name, in the simulator's order (``fado_sim::scenario::SCENARIOS``).
SCENARIOS: tuple[str, ...] = tuple(_fado.scenarios())


class CompareResult(list[dict[str, Any]]):
    """One dict per (scenario, estimator), scenario-major; a ``list`` with extras."""

    def to_pandas(self) -> Any:
        """The scalar columns as a ``pandas.DataFrame`` (``levels``, ``checks`` and
        ``trace`` stay Python objects in their columns). Needs pandas."""
        import pandas as pd

        return pd.DataFrame(list(self))

    def row(self, scenario: str, estimator: str) -> dict[str, Any]:
        """The row of ``scenario`` run with ``estimator``; ``KeyError`` if absent."""
        for r in self:
            if r["scenario"] == scenario and r["estimator"] == estimator:
                return r
        raise KeyError((scenario, estimator))


def compare(
    scenarios: Sequence[str] | None = None,
    estimators: Sequence[str] | None = None,
    averaged: bool = False,
    *,
    config: str | None = None,
    traces: bool = False,
    threads: int = 2,
) -> CompareResult:
    """Runs every estimator in every scenario; see ``fado_sim::compare`` for the metrics.

    ``scenarios`` defaults to all of :data:`SCENARIOS`, ``estimators`` to all of
    :data:`ESTIMATORS` (``fado-fixed-rs``: fado with the paper's fixed R̂s). ``averaged`` selects the fast
    averaged inverter model. ``config`` is TOML applied over every scenario (its
    ``[simulation] estimator`` is replaced by each estimator). ``traces`` keeps each run's 1 kHz
    trace (a dict of arrays) under ``"trace"``. Raises :class:`fado.ConfigError`.
    """
    rows = _fado.compare(
        None if scenarios is None else list(scenarios),
        None if estimators is None else list(estimators),
        averaged,
        config=config,
        traces=traces,
        threads=threads,
    )
    return CompareResult(rows)


def plot_angle_errors(
    path: str | Path,
    scenario: str = "fig11",
    *,
    estimators: Sequence[str] | None = None,
    averaged: bool = False,
    config: str | None = None,
) -> CompareResult:
    """Plots θ − θ̂ against time for every estimator through ``scenario`` (the fig11
    reversal by default) under the true speed, marks the near-zero-speed band and the
    ±0.25 rad bound, and saves the figure to ``path``. Returns the runs. Needs matplotlib.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    result = compare([scenario], estimators, averaged, config=config, traces=True)
    fig, (ax_err, ax_speed) = plt.subplots(2, 1, sharex=True, figsize=(9, 6))
    first = result[0]["trace"]
    t = first["time"]
    near = np.abs(first["speed_rpm"]) < 30.0
    for r in result:
        tr = r["trace"]
        ax_err.plot(
            tr["time"],
            tr["angle_error"],
            lw=0.8,
            label=f"{r['estimator']} (max near 0: {r['max_angle_error_zero_speed']:.3f} rad)",
        )
    for bound in (-0.25, 0.25):
        ax_err.axhline(bound, color="k", ls="--", lw=0.6)
    if near.any():
        ax_err.fill_between(
            t, -np.pi, np.pi, where=near, color="0.9", step="mid", label="|n| < 30 r/min"
        )
    ax_err.set_ylim(-np.pi, np.pi)
    ax_err.set_ylabel("θ − θ̂ (rad, electrical)")
    ax_err.set_title(f"{scenario}: angle error of every estimator, same plant and seed")
    ax_err.legend(fontsize=8, loc="lower left")
    ax_speed.plot(t, first["speed_ref_rpm"], "k--", lw=0.8, label="reference")
    for r in result:
        tr = r["trace"]
        ax_speed.plot(tr["time"], tr["speed_rpm"], lw=0.8, label=r["estimator"])
    ax_speed.set_ylabel("true speed (r/min)")
    ax_speed.set_xlabel("time (s)")
    ax_speed.legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return result


class _CallableModule(types.ModuleType):
    """Lets ``fado.compare(...)`` call :func:`compare` while ``fado.compare`` stays the
    module (so ``fado.compare.plot_angle_errors`` works too)."""

    def __call__(
        self,
        scenarios: Sequence[str] | None = None,
        estimators: Sequence[str] | None = None,
        averaged: bool = False,
        **kwargs: Any,
    ) -> CompareResult:
        return compare(scenarios, estimators, averaged, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
