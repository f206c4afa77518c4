#!/usr/bin/env python3
"""gym-electric-motor's measured PMSM flux map (`Reforce_PMSM_LUT.mat`) converted to fado's
flux-map CSV (the format of `[motor] flux_map`), cropped to the largest rectangle of nodes the
measurement covers.

Source: upb-lea/gym-electric-motor (MIT licence), commit 1a93acca6aac4f12e0f091cbba065e6ebbd042b3,
examples/environment_features/saturated_pmsm/Reforce_PMSM_LUT.mat (MATLAB 5 file of 2022-08-12,
the flux map of that repository's saturated-PMSM example environment). It holds `Psi_d_map`,
`Psi_q_map` (Vs) and the differential inductances on a 33 × 18 grid whose axes
`i_d_grid_k` (−16 … +1 A) and `i_q_grid_k` (−16 … +16 A), both in 1 A steps, are stored beside
it; rows are i_q and columns i_d. The nodes outside |i| ≤ 16 A are NaN: the measurement covers a
disc of 16 A. The file does not say how the map was obtained; the disc, the scatter of the
differential inductances and the asymmetry in i_q are those of a measurement. fado's CSV
needs a full rectangular grid, so the converter keeps the largest
rectangle of measured nodes around the origin, i_d −10 … +1 A and i_q −12 … +12 A (12 × 25
nodes, corner at 15.6 A), and makes it symmetric about the d axis node by node (ψd even, ψq odd
in i_q: each node the mean of itself and its mirror in i_q), as a machine symmetric about its
d axis is and as motulator's measured maps are. As measured, ψq(i_d, 0) is −2.5 … −6.0 mVs in
the kept rectangle (the no-load flux 3.7° from d), which no d axis on the magnet allows: the
estimator's rotor flux ψ − L_q,s·i is d-aligned only where ψq(i_d, 0) = 0, and the unsymmetrised
map replayed open loop at no load (crates/fado-core/tests/saturated_replay.rs) loses 1.24 rad
near zero speed. Nothing is interpolated, filled, smoothed or rotated.
The drive and the plant extrapolate a map linearly from its edge cells beyond it.

The script prints the values a preset takes from the map: ψd, incremental Ld and Lq at zero
current, the secant Lq at i_d = 0, and the torque 1.5·p·(ψd·i_q − ψq·i_d) on the
maximum-torque-per-ampere curve at a given current (bilinear in the map, the drive's own
interpolation).

Usage: python3 scripts/flux-map-gem.py Reforce_PMSM_LUT.mat OUT.csv [--pole-pairs 3]
  [--rated-current 8]   (scipy reads the MATLAB file: pip install scipy)
"""

import argparse
import sys
from pathlib import Path

import numpy as np

import flux_map_csv

SOURCE = ("gym-electric-motor (upb-lea/gym-electric-motor 1a93acca, MIT licence), "
          "examples/environment_features/saturated_pmsm/Reforce_PMSM_LUT.mat: "
          "measured PMSM flux map, 1 A grid over |i| <= 16 A")
D_RANGE = (-10.0, 1.0)   # A, the kept rectangle (all nodes measured)
Q_RANGE = (-12.0, 12.0)  # A


def load(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The kept rectangle as (d_axis, q_axis, psi_d, psi_q), fluxes indexed [d, q]."""
    try:
        from scipy.io import loadmat
    except ImportError:
        sys.exit("reading a MATLAB file needs scipy: pip install scipy")
    mat = loadmat(path)
    i_d_grid, i_q_grid = mat["i_d_grid_k"], mat["i_q_grid_k"]
    d_axis, q_axis = np.nanmax(i_d_grid, axis=0), np.nanmax(i_q_grid, axis=1)
    if not (np.allclose(d_axis, np.arange(-16, 2)) and np.allclose(q_axis, np.arange(-16, 17))):
        sys.exit(f"{path}: not the 1 A grid, i_d −16…1 A by i_q −16…16 A, this converter reads")
    keep_d = (d_axis >= D_RANGE[0]) & (d_axis <= D_RANGE[1])
    keep_q = (q_axis >= Q_RANGE[0]) & (q_axis <= Q_RANGE[1])
    psi_d = mat["Psi_d_map"][np.ix_(keep_q, keep_d)].T
    psi_q = mat["Psi_q_map"][np.ix_(keep_q, keep_d)].T
    return d_axis[keep_d], q_axis[keep_q], psi_d, psi_q


def symmetrise(grid):
    """The map made even (ψd) and odd (ψq) in i_q node by node, the mean of each node and its
    mirror: what a machine symmetric about its d axis has, and the form of motulator's
    measured maps (ψq(i_d, 0) = 0). The measurement's own asymmetry is what a constant-speed
    test's iron losses and a residual angle offset leave; printed before it is removed."""
    d_axis, q_axis, psi_d, psi_q = grid
    if not np.allclose(q_axis, -q_axis[::-1]):
        sys.exit("the kept i_q axis is not symmetric about 0: cannot symmetrise")
    m0 = len(q_axis) // 2
    print(f"measured asymmetry: ψq(i_d, 0) {psi_q[:, m0].min() * 1e3:.2f} … "
          f"{psi_q[:, m0].max() * 1e3:.2f} mVs; ψd(0, ±{q_axis[-1]:g} A) = "
          f"{psi_d[np.argmin(abs(d_axis)), 0]:.4f} / {psi_d[np.argmin(abs(d_axis)), -1]:.4f} Wb")
    return (d_axis, q_axis, 0.5 * (psi_d + psi_d[:, ::-1]), 0.5 * (psi_q - psi_q[:, ::-1]))


def bilinear(axis_d, axis_q, table, i_d: float, i_q: float) -> float:
    """The map at (i_d, i_q), linear in each cell and extrapolated from the edge cells."""
    k = int(np.clip(np.searchsorted(axis_d, i_d) - 1, 0, len(axis_d) - 2))
    m = int(np.clip(np.searchsorted(axis_q, i_q) - 1, 0, len(axis_q) - 2))
    u = (i_d - axis_d[k]) / (axis_d[k + 1] - axis_d[k])
    v = (i_q - axis_q[m]) / (axis_q[m + 1] - axis_q[m])
    return ((1 - u) * (1 - v) * table[k, m] + u * (1 - v) * table[k + 1, m]
            + (1 - u) * v * table[k, m + 1] + u * v * table[k + 1, m + 1])


def mtpa_torque(grid, pole_pairs: int, current: float) -> tuple[float, float]:
    """(torque, current angle from +q toward −d in degrees) of the largest torque at |i|."""
    d_axis, q_axis, psi_d, psi_q = grid
    best = (-np.inf, 0.0)
    for beta in np.radians(np.linspace(-30.0, 60.0, 901)):
        i_d, i_q = -current * np.sin(beta), current * np.cos(beta)
        tau = 1.5 * pole_pairs * (bilinear(d_axis, q_axis, psi_d, i_d, i_q) * i_q
                                  - bilinear(d_axis, q_axis, psi_q, i_d, i_q) * i_d)
        best = max(best, (tau, np.degrees(beta)))
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("source", type=Path, help="Reforce_PMSM_LUT.mat")
    ap.add_argument("out", type=Path, help="fado flux-map CSV to write")
    ap.add_argument("--pole-pairs", type=int, default=3)
    ap.add_argument("--rated-current", type=float, default=8.0, help="A peak")
    args = ap.parse_args()
    grid = symmetrise(load(args.source))
    d_axis, q_axis, psi_d, psi_q = grid
    note = (f"Converted by scripts/flux-map-gem.py: the {len(d_axis)} × {len(q_axis)} measured "
            f"nodes with i_d {D_RANGE[0]:g}…{D_RANGE[1]:g} A and i_q {Q_RANGE[0]:g}…"
            f"{Q_RANGE[1]:g} A, one row each, symmetrised in i_q, no interpolation.")
    flux_map_csv.write(args.out, [SOURCE, note], d_axis, q_axis, psi_d, psi_q)
    lf, ld, lq = flux_map_csv.zero_current(d_axis, q_axis, psi_d, psi_q)
    psi_q0 = bilinear(d_axis, q_axis, psi_q, 0.0, 0.0)
    print(f"wrote {args.out}: {len(d_axis)} × {len(q_axis)} nodes; at zero current "
          f"flux_linkage = {lf:.4f} Wb, incremental ld = {ld * 1e3:.3f} mH, "
          f"lq = {lq * 1e3:.3f} mH; ψq(0, 0) = {psi_q0 * 1e3:.2f} mVs "
          f"({np.degrees(np.arctan2(psi_q0, lf)):.1f}° from d)")
    rated = args.rated_current
    for share in (0.3, 0.65, 1.0, 1.5):
        i_q = share * rated
        secant = (bilinear(d_axis, q_axis, psi_q, 0.0, i_q) - psi_q0) / i_q
        print(f"  i_q = {i_q:5.2f} A ({share * 100:3.0f} % of rated), i_d = 0: secant lq "
              f"{secant * 1e3:.3f} mH, ψd {bilinear(d_axis, q_axis, psi_d, 0.0, i_q):.4f} Wb")
    tau, beta = mtpa_torque(grid, args.pole_pairs, rated)
    print(f"  MTPA at {rated:g} A: {tau:.3f} N·m at β = {beta:.1f}° (p = {args.pole_pairs})")


if __name__ == "__main__":
    main()
