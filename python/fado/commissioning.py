"""``fado.commission``: identify a motor with the commissioning procedure on the simulator.

The procedure (``fado_core::commissioning``, docs/commissioning.md) runs in Rust against the
simulated plant of ``fado-sim commission`` (switching-resolved inverter with dead time and
threshold, current sensors with offset, gain error, noise and ADC), with the GIL released;
the plant's truth is known, so every identified parameter comes with its error::

    import fado
    result = fado.commission("ipmsm-2k2")
    result.machine                  # the identified fado.Machine
    result.errors["rs"], result.confidence["rs"]
    result["time"], result["phase"], result["i_alpha"], result["speed_rpm"]  # numpy arrays
    fado.commissioning.plot(result, "commission.png")   # needs fado[plot]
    fado.simulate("reversal", result.identified_toml)   # the drive with the identified model
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any, Union

import numpy as np

from fado import _fado
from fado._keywords import checked
from fado._simulation import ConfigLike, _config_path, config_text

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    MotorLike = Union[str, _fado.Machine, dict[str, Any]]

__all__ = ["PHASES", "commission", "plot"]

#: The procedure's phases, by the ``phase`` trace column's value.
PHASES: list[str] = list(_fado.COMMISSION_PHASES)


@checked
def commission(
    motor: MotorLike,
    *,
    nameplate: MotorLike | None = None,
    config: ConfigLike = None,
    seed: int = 1,
    averaged: bool = False,
    theta0: float = 1.0,
    decimation: int = 10,
    progress: bool = False,
) -> _fado.CommissionResult:
    """Runs the commissioning procedure on the simulated plant of `motor` (Rust, GIL
    released; Ctrl-C raises ``KeyboardInterrupt`` within milliseconds).

    `motor` is the plant: a preset name of :func:`fado.machine_presets` (its whole
    ``motors/`` file), a :class:`fado.Machine` or a ``dict`` of its fields (on the simulator's
    default inverter at its ``dc_voltage``). `nameplate` is what the procedure is told (same
    forms; default the plant's own record): its ratings set the test currents and speeds,
    its parameters only size the tests. `config` overrides the plant key by key, as TOML
    text, a path or a ``dict`` of tables (``{"inverter": {"dead_time": 1e-6}}``; see
    :func:`fado.default_config`). `seed` is the current sensors' noise seed, `theta0` the
    rotor's initial electrical angle (rad); `averaged` selects the averaged inverter model;
    the trace keeps every `decimation`-th sample; `progress` prints a bar to stderr.

    Returns a :class:`fado.CommissionResult`: ``.machine`` (the identified
    :class:`fado.Machine`), ``.errors`` and ``.confidence`` per parameter, ``.parameters``,
    ``.truth``, the trace columns as float64 arrays (``result["i_alpha"]``, ``.traces``),
    ``.identified_toml``. A procedure that aborts (a typed reason in ``.status``) returns
    ``passed=False`` and no machine. Bad input raises :class:`fado.ConfigError` (a
    configuration key or ``Machine`` field, in ``.field``) or :class:`fado.InputError` (an
    argument, in ``.argument``), both ``ValueError``.
    """
    text = config_text(config)
    try:
        return _fado.commission(
            motor,
            nameplate=nameplate,
            config_toml=text,
            seed=seed,
            averaged=averaged,
            theta0=theta0,
            decimation=decimation,
            progress=progress,
        )
    except _fado.ConfigError as e:
        path = _config_path(config)
        if path is not None and getattr(e, "line", None) is not None:
            rest = str(e).split(": ", 1)[-1]
            e.args = (f"{path}:{e.line}:{e.column}: {rest}",)
        raise


def _phase_spans(t: np.ndarray, phase: np.ndarray) -> list[tuple[float, float, int]]:
    """``(start, end, phase index)`` of each run of one phase in the trace."""
    if len(t) == 0:
        return []
    edges = np.flatnonzero(np.diff(phase)) + 1
    starts = np.concatenate(([0], edges))
    ends = np.concatenate((edges, [len(t)]))
    return [(float(t[s]), float(t[min(e, len(t) - 1)]), int(phase[s])) for s, e in zip(starts, ends)]


def plot(
    result: _fado.CommissionResult, path: str | os.PathLike[str] | None = None
) -> Figure:
    """The procedure's phases on one shared time axis: currents (α, β), commanded voltages,
    true and estimated speed, true and estimated angle; each phase shaded and named, the
    identified-vs-truth errors in the title. Drawn with the Agg canvas (no pyplot), like
    :mod:`fado.plot`; saved to `path` if given. Needs matplotlib (``fado[plot]``)."""
    from fado.plot import _matplotlib

    figure_class, canvas_class = _matplotlib()
    fig = figure_class(figsize=(11.0, 9.0))
    canvas_class(fig)
    axes = list(fig.subplots(4, 1, sharex=True))
    t = np.asarray(result["time"])
    phase = np.asarray(result["phase"]).astype(int)

    def col(name: str) -> np.ndarray:
        return np.asarray(result[name])

    ax_i, ax_v, ax_n, ax_th = axes
    ax_i.plot(t, col("i_alpha"), lw=0.8, label="i_α")
    ax_i.plot(t, col("i_beta"), lw=0.8, label="i_β")
    ax_i.set_ylabel("current (A)")
    ax_v.plot(t, col("v_alpha"), lw=0.6, label="v*_α")
    ax_v.plot(t, col("v_beta"), lw=0.6, label="v*_β")
    ax_v.set_ylabel("voltage\ncommand (V)")
    ax_n.plot(t, col("speed_rpm"), lw=1.0, label="true n")
    ax_n.plot(t, col("speed_hat_rpm"), lw=0.8, label="back-EMF PLL n̂")
    ax_n.set_ylabel("speed (r/min)")
    ax_th.plot(t, col("theta"), lw=0.8, label="true θ")
    ax_th.plot(t, col("theta_hat"), lw=0.8, label="PLL θ̂")
    ax_th.set_ylabel("angle (rad)")
    ax_th.set_xlabel("time (s)")
    for k, (start, end, idx) in enumerate(_phase_spans(t, phase)):
        for ax in axes:
            ax.axvspan(start, end, color="0.92" if k % 2 == 0 else "1.0", zorder=0)
        name = PHASES[idx] if 0 <= idx < len(PHASES) else str(idx)
        ax_i.text(
            0.5 * (start + end), 1.02, name, transform=ax_i.get_xaxis_transform(),
            ha="center", va="bottom", fontsize=7, rotation=30,
        )
    for ax in axes:
        ax.legend(fontsize=7, loc="upper left")
        ax.grid(True, lw=0.3)
    errors = result.errors
    if result.passed:
        rel = ("rs", "ld", "lq", "flux_linkage", "inertia")
        summary = ", ".join(f"{k} {100 * errors[k]:+.2f} %" for k in rel)
        title = f"commissioning: identified vs truth: {summary}"
    else:
        title = f"commissioning: {result.status}"
    fig.suptitle(f"{title} ({result.simulated_seconds:.2f} s)", fontsize=9)
    fig.tight_layout()
    if path is not None:
        fig.savefig(os.fspath(path), dpi=120)
    figure: Figure = fig
    return figure
