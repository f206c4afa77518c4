"""Figures of the paper's experiments (Fig. 8–12) from a :class:`fado.SimResult`.

Laid out like the paper's oscilloscope captures: panels stacked on one shared time axis —
speed (true, estimated, reference; r/min), the angle error θ − θ̂ (rad, with the ±0.25 rad
criterion of Fig. 11/12), the fluxes (λ1 and D̂ for Fig. 8/9, λ̂r and the limiter radius
1.15·λ̂f for Fig. 10), the d-q currents and the mode flags. Needs the ``plot`` extra
(matplotlib); the figures are drawn with the Agg canvas, without pyplot, so importing this
module changes no global matplotlib state::

    import fado, fado.plot
    fig = fado.plot.plot_scenario(fado.simulate("fig11"), "fig11.png")
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from fado._fado import SimResult

__all__ = [
    "ANGLE_CRITERION",
    "envelope",
    "plot_fig8",
    "plot_fig9",
    "plot_fig10",
    "plot_fig11",
    "plot_fig12",
    "plot_run",
    "plot_scenario",
]

#: |θ − θ̂| criterion near zero speed of Fig. 11 and 12 (paper §V-B; SPEC §7), rad.
ANGLE_CRITERION = 0.25


def _matplotlib() -> tuple[Any, Any]:
    """``(Figure, FigureCanvasAgg)``, or an ImportError saying how to get them."""
    try:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError(
            "fado.plot needs matplotlib: pip install 'fado[plot]' (or pip install matplotlib)"
        ) from e
    return Figure, FigureCanvasAgg


def _col(result: SimResult, name: str) -> np.ndarray:
    return np.asarray(result[name])


def _k_df_off_windows(result: SimResult) -> list[tuple[float, float]]:
    """The ``simulation.disturbance_feedback_off`` windows (Fig. 9), from the config TOML."""
    match = re.search(r"^disturbance_feedback_off\s*=\s*(\[.*\])\s*$", result.config_toml, re.M)
    if not match:
        return []
    numbers = [float(x) for x in re.findall(r"[-+0-9.eE]+", match.group(1))]
    return list(zip(numbers[0::2], numbers[1::2]))


def _speed(ax: Axes, r: SimResult) -> None:
    t = _col(r, "time")
    ax.plot(t, _col(r, "speed_ref_rpm"), color="0.6", lw=1.0, ls="--", label="reference")
    ax.plot(t, _col(r, "speed_rpm"), color="C0", lw=1.2, label="true n")
    ax.plot(t, _col(r, "speed_hat_rpm"), color="C3", lw=1.0, label="estimated n̂ (T2S-2)")
    ax.set_ylabel("speed\n(r/min)")


def _angle_error(ax: Axes, r: SimResult, criterion: bool) -> None:
    t = _col(r, "time")
    ax.plot(t, _col(r, "angle_error"), color="C2", lw=1.0, label="θ − θ̂")
    if criterion:
        band = float(r.metrics["zero_speed_band_rpm"])
        ax.fill_between(
            t,
            0,
            1,
            where=np.abs(_col(r, "speed_rpm")) < band,
            transform=ax.get_xaxis_transform(),
            color="C1",
            alpha=0.12,
            lw=0,
            label=f"|n| < {band:g} r/min",
        )
        for sign in (1.0, -1.0):
            ax.axhline(
                sign * ANGLE_CRITERION,
                color="C3",
                ls=":",
                lw=1.0,
                label=f"±{ANGLE_CRITERION} rad" if sign > 0 else None,
            )
    ax.set_ylabel("θ − θ̂\n(rad)")


def _angles(ax: Axes, r: SimResult) -> None:
    t = _col(r, "time")
    ax.plot(t, _col(r, "theta"), color="C0", lw=1.0, label="θ")
    ax.plot(t, _col(r, "theta_hat"), color="C3", lw=1.0, ls="--", label="θ̂")
    ax.set_ylabel("angle\n(rad)")


def _flux_and_disturbance(ax: Axes, r: SimResult) -> None:
    t = _col(r, "time")
    ax.plot(t, _col(r, "lambda1_alpha"), color="C0", lw=1.0, label="λ1 α")
    ax.plot(t, _col(r, "lambda1_beta"), color="C1", lw=1.0, label="λ1 β")
    ax.plot(t, _col(r, "dist_alpha"), color="k", lw=1.4, label="D̂ α")
    ax.plot(t, _col(r, "dist_beta"), color="C7", lw=1.4, label="D̂ β")
    ax.set_ylabel("λ1, D̂\n(Wb)")


def _lambda2(ax: Axes, r: SimResult) -> None:
    t = _col(r, "time")
    ax.plot(t, _col(r, "lambda2_alpha"), color="C0", lw=1.0, label="λ2 α")
    ax.plot(t, _col(r, "lambda2_beta"), color="C1", lw=1.0, label="λ2 β")
    ax.axhline(0.0, color="0.5", lw=0.6)
    ax.set_ylabel("λ2 = λ1 − D̂\n(Wb)")


def _rotor_flux(ax: Axes, r: SimResult) -> None:
    t = _col(r, "time")
    ratio = r.estimator_config.limiter["radius_ratio"]
    radius = ratio * r.machine.flux_linkage
    a, b = _col(r, "lambda_r_alpha"), _col(r, "lambda_r_beta")
    ax.plot(t, a, color="C0", lw=1.0, label="λ̂r α")
    ax.plot(t, b, color="C1", lw=1.0, label="λ̂r β")
    ax.plot(t, np.hypot(a, b), color="k", lw=1.2, label="|λ̂r|")
    for sign in (1.0, -1.0):
        ax.axhline(
            sign * radius,
            color="C3",
            ls=":",
            lw=1.0,
            label=f"±{ratio:g}·λ̂f" if sign > 0 else None,
        )
    ax.set_ylabel("λ̂r\n(Wb)")


def _currents(ax: Axes, r: SimResult) -> None:
    t = _col(r, "time")
    ax.plot(t, _col(r, "i_d"), color="C0", lw=1.0, label="i_d")
    ax.plot(t, _col(r, "i_q"), color="C1", lw=1.0, label="i_q")
    ax.plot(t, _col(r, "i_d_ref"), color="C0", lw=0.8, ls="--", label="i_d*")
    ax.plot(t, _col(r, "i_q_ref"), color="C1", lw=0.8, ls="--", label="i_q*")
    ax.set_ylabel("d-q current\n(A)")


def _flags(ax: Axes, r: SimResult) -> None:
    t = _col(r, "time")
    ax.step(t, _col(r, "flag_limit"), where="post", color="C4", lw=1.0, label="FLAG_limit")
    ax.step(
        t,
        0.5 * _col(r, "tracker_hold"),
        where="post",
        color="C5",
        lw=0.8,
        label="tracker hold (×0.5)",
    )
    tripped = _col(r, "tripped")
    if tripped.any():
        ax.step(t, tripped, where="post", color="C3", lw=1.2, label="tripped")
    ax.set_ylim(-0.15, 1.25)
    ax.set_yticks([0, 1])
    ax.set_ylabel("flags")


def _figure(
    result: SimResult,
    panels: Sequence[Callable[[Axes, SimResult], None]],
    title: str,
    path: str | os.PathLike[str] | None,
    shade: Sequence[tuple[float, float]] = (),
) -> Figure:
    figure_class, canvas_class = _matplotlib()
    fig = figure_class(figsize=(10.0, 1.9 * len(panels) + 0.9), layout="constrained")
    canvas_class(fig)
    axes = fig.subplots(len(panels), 1, sharex=True, squeeze=False)[:, 0]
    for k, (ax, draw) in enumerate(zip(axes, panels)):
        draw(ax, result)
        for j, (t0, t1) in enumerate(shade):
            label = "k_df off" if k == 0 and j == 0 else None
            ax.axvspan(t0, t1, color="C3", alpha=0.08, lw=0, label=label)
        ax.grid(True, lw=0.4, alpha=0.5)
        # Channel labels beside the trace, as on an oscilloscope, never over it.
        ax.legend(loc="upper left", bbox_to_anchor=(1.005, 1.0), fontsize=7, frameon=False)
    axes[-1].set_xlabel("time (s)")
    m = result.metrics
    verdict = "passed" if result.passed else "FAILED"
    inverter = "averaged" if result.averaged else "switching-resolved"
    fig.suptitle(
        f"{title}\n{result.scenario}, {inverter} inverter: {verdict}; "
        f"max |θ−θ̂| near zero speed {m['max_angle_error_zero_speed']:.3f} rad, "
        f"overall {m['max_angle_error']:.3f} rad",
        fontsize=9,
    )
    if path is not None:
        fig.savefig(os.fspath(path), dpi=110)
    figure: Figure = fig
    return figure


def _title(result: SimResult) -> str:
    from fado._fado import describe_scenario

    return str(describe_scenario(result.scenario)["title"])


def plot_fig8(result: SimResult, path: str | os.PathLike[str] | None = None) -> Figure:
    """Fig. 8: λ1 and D̂ (the DC of λ1) and λ2 = λ1 − D̂ centred on zero, over the
    +90 → −90 r/min reversal under 2 N·m. Saves a PNG at `path` if given."""
    panels = [_speed, _flux_and_disturbance, _lambda2, _currents, _flags]
    return _figure(result, panels, _title(result), path)


def plot_fig9(result: SimResult, path: str | os.PathLike[str] | None = None) -> Figure:
    """Fig. 9: λ1 drifts while k_df is off (shaded) and recovers after; D̂ follows."""
    panels = [
        _speed,
        _flux_and_disturbance,
        lambda ax, r: _angle_error(ax, r, criterion=False),
        _currents,
        _flags,
    ]
    return _figure(result, panels, _title(result), path, shade=_k_df_off_windows(result))


def plot_fig10(result: SimResult, path: str | os.PathLike[str] | None = None) -> Figure:
    """Fig. 10: no-load standstill held by the limiter: θ and θ̂, λ̂r inside the circle of
    radius 1.15·λ̂f, positive i_d, FLAG_limit high."""
    panels = [
        _speed,
        _angles,
        lambda ax, r: _angle_error(ax, r, criterion=False),
        _rotor_flux,
        _currents,
        _flags,
    ]
    return _figure(result, panels, _title(result), path)


#: Speed, θ − θ̂ against ±0.25 rad, λ1 and D̂, d-q currents, flags: Fig. 11 and any run.
_RUN_PANELS: list[Callable[[Axes, SimResult], None]] = [
    _speed,
    lambda ax, r: _angle_error(ax, r, criterion=True),
    _flux_and_disturbance,
    _currents,
    _flags,
]


def plot_fig11(result: SimResult, path: str | os.PathLike[str] | None = None) -> Figure:
    """Fig. 11: speed reversal −90 → +90 r/min under 7.5 N·m; θ − θ̂ against ±0.25 rad."""
    return _figure(result, _RUN_PANELS, _title(result), path)


def plot_fig12(result: SimResult, path: str | os.PathLike[str] | None = None) -> Figure:
    """Fig. 12: repeated 300 ms stops under 7.5 N·m; θ − θ̂ against ±0.25 rad."""
    panels = [
        _speed,
        lambda ax, r: _angle_error(ax, r, criterion=True),
        _currents,
        _flags,
    ]
    return _figure(result, panels, _title(result), path)


def plot_run(result: SimResult, path: str | os.PathLike[str] | None = None) -> Figure:
    """Any run: speed, θ − θ̂ against ±0.25 rad, λ1 and D̂, d-q currents and the mode flags
    (the layout of Fig. 11, for a scenario of one's own or a run with a custom profile), titled
    with the scenario it started from."""
    return _figure(result, _RUN_PANELS, f"a run based on {result.scenario}", path)


_BY_SCENARIO = {
    "fig8": plot_fig8,
    "fig9": plot_fig9,
    "fig10": plot_fig10,
    "fig11": plot_fig11,
    "fig12": plot_fig12,
    # The paper's experiments scaled by a motor's ratings take their original's layout.
    "reversal": plot_fig11,
    "rated-reversal": plot_fig11,
    "stops": plot_fig12,
    "lowspeed": plot_fig12,
}


def plot_scenario(result: SimResult, path: str | os.PathLike[str] | None = None) -> Figure:
    """The figure of `result.scenario`: ``plot_fig8`` … ``plot_fig12`` for the paper's
    experiments, the layout of the original for the ratings-scaled ones (``reversal`` and
    ``rated-reversal`` as Fig. 11, ``stops`` and ``lowspeed`` as Fig. 12), and
    :func:`plot_run` for any other scenario of :func:`fado.scenarios`."""
    from fado._fado import scenarios

    known = scenarios()
    if result.scenario not in known:
        raise ValueError(f"no figure for scenario {result.scenario!r}; one of {sorted(known)}")
    plot = _BY_SCENARIO.get(result.scenario, plot_run)
    figure: Figure = plot(result, path)
    return figure


def _axis(values: Any) -> tuple[np.ndarray, np.ndarray, list[str] | None]:
    """Sorted distinct values of a swept column, the cell edges around them (midpoints) and,
    for a non-numeric column, its tick labels (cells then sit at 0, 1, 2, …)."""
    distinct = list(dict.fromkeys(values))
    try:
        centres = np.array(sorted(float(v) for v in distinct))
    except (TypeError, ValueError):
        labels = sorted(map(str, distinct))
        return np.arange(len(labels), dtype=float), np.arange(len(labels) + 1) - 0.5, labels
    if len(centres) == 1:
        return centres, np.array([centres[0] - 0.5, centres[0] + 0.5]), None
    mid = (centres[1:] + centres[:-1]) / 2
    edges = np.concatenate(
        [[centres[0] - (mid[0] - centres[0])], mid, [centres[-1] + (centres[-1] - mid[-1])]]
    )
    return centres, edges, None


def _position(values: Any, centres: np.ndarray, labels: list[str] | None) -> np.ndarray:
    if labels is not None:
        return np.array([labels.index(str(v)) for v in values])
    return np.searchsorted(centres, np.asarray(values, dtype=float))


def envelope(
    df: Any,
    x: str,
    y: str,
    *,
    metric: str = "max_angle_error",
    path: str | os.PathLike[str] | None = None,
    ax: Axes | None = None,
    title: str | None = None,
    vmax: float | None = None,
) -> Figure:
    """Heatmap of `metric` (default max |θ − θ̂|, rad) over two swept parameters of a
    :func:`fado.sweep` DataFrame, with the points that failed the scenario's criteria
    hatched and a line around the passing region; points that diverged (tripped) or failed
    to run are drawn black. Several points in one cell (other swept parameters): the cell
    shows the mean of `metric` and is hatched unless all of them passed. A design that is not
    a grid (random samples) is drawn as a scatter instead (○ passed, × failed). `vmax` caps
    the colour scale (default: the largest `metric` of the points that ran, at most π).
    Returns the figure (drawn with the Agg canvas, without pyplot)."""
    figure_class, canvas_class = _matplotlib()
    from matplotlib.colors import ListedColormap

    if ax is None:
        fig = figure_class(figsize=(7.5, 4.8), layout="constrained")
        canvas_class(fig)
        ax = fig.subplots()
    else:
        fig = ax.figure
    xs, xe, xl = _axis(df[x])
    ys, ye, yl = _axis(df[y])
    ix = _position(df[x], xs, xl)
    iy = _position(df[y], ys, yl)
    value = np.asarray(df[metric], dtype=float)
    ran = np.asarray(df["status"] == "ok", dtype=bool)
    passed = np.asarray(df["passed"], dtype=bool)
    total = np.zeros((len(ys), len(xs)))
    count = np.zeros_like(total)
    n_pass = np.zeros_like(total)
    n_bad = np.zeros_like(total)
    for i, j, v, ok, p in zip(iy, ix, value, ran, passed):
        count[i, j] += 1
        n_pass[i, j] += p
        if ok and np.isfinite(v):
            total[i, j] += v
        else:
            n_bad[i, j] += 1
    filled = count > 0
    top = float(np.nanmax(np.where(ran, value, np.nan))) if ran.any() else 1.0
    vmax = vmax if vmax is not None else min(max(top, 1e-9), np.pi)
    cmap = "viridis"
    if filled.mean() < 0.5:
        # Not a grid: one marker per point.
        sc = ax.scatter(
            np.asarray(df[x], dtype=float) if xl is None else ix,
            np.asarray(df[y], dtype=float) if yl is None else iy,
            c=np.where(ran, value, np.nan),
            cmap=cmap,
            vmin=0.0,
            vmax=vmax,
            marker="o",
            s=np.where(passed, 30, 0),
            plotnonfinite=True,
        )
        ax.scatter(
            np.asarray(df[x], dtype=float)[~passed] if xl is None else ix[~passed],
            np.asarray(df[y], dtype=float)[~passed] if yl is None else iy[~passed],
            c=np.where(ran, value, np.nan)[~passed],
            cmap=cmap,
            vmin=0.0,
            vmax=vmax,
            marker="x",
            s=30,
            plotnonfinite=True,
        )
        mesh = sc
    else:
        good = filled & (n_bad < count)
        mean = np.where(good, total / np.maximum(count - n_bad, 1), np.nan)
        mesh = ax.pcolormesh(xe, ye, np.ma.masked_invalid(mean), cmap=cmap, vmin=0.0, vmax=vmax)
        bad = np.ma.masked_where(~(filled & (n_bad > 0)), np.ones_like(total))
        ax.pcolormesh(xe, ye, bad, cmap=ListedColormap(["black"]), vmin=0, vmax=1)
        failed = np.ma.masked_where(~(filled & (n_pass < count)), np.ones_like(total))
        ax.pcolor(xe, ye, failed, hatch="//", facecolor="none", edgecolor="white", lw=0)
        all_pass = (n_pass == count) & filled
        if all_pass.any() and (~all_pass).any():
            ax.contour(
                xs if xl is None else np.arange(len(xs)),
                ys if yl is None else np.arange(len(ys)),
                all_pass.astype(float),
                levels=[0.5],
                colors="red",
                linewidths=1.5,
            )
    fig.colorbar(mesh, ax=ax, label=f"{metric} (rad)" if "angle" in metric else metric,
                 extend="max" if top > vmax else "neither")
    if xl is not None:
        ax.set_xticks(np.arange(len(xl)), xl)
    if yl is not None:
        ax.set_yticks(np.arange(len(yl)), yl)
    ax.set_xlabel(x)
    ax.set_ylabel(y)
    n_ok = int(passed.sum())
    ax.set_title(
        title
        or f"{len(df)} points: {n_ok} passed (hatched: failed the criteria, "
        f"black: diverged or failed to run; red line: pass boundary)",
        fontsize=8,
    )
    if path is not None:
        fig.savefig(os.fspath(path), dpi=120)
    figure: Figure = fig
    return figure
