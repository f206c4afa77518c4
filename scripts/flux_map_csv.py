"""Writing fado's flux-map CSV (the format of `[motor] flux_map`,
crates/fado-sim/src/magnetics_file.rs) from a rectangular grid, shared by the converters
scripts/flux-map-motulator.py and scripts/flux-map-gem.py.

A map is `d_axis` (A, strictly increasing), `q_axis` (A, strictly increasing) and `psi_d`,
`psi_q` (Vs) indexed [d, q], SI peak values in the rotor frame with d on the magnet. Nothing
is interpolated, smoothed or extrapolated: each node is one CSV row.
"""

import sys
from pathlib import Path

import numpy as np


def check(d_axis: np.ndarray, q_axis: np.ndarray, psi_d: np.ndarray, psi_q: np.ndarray) -> None:
    """Exit naming what fado's reader refuses: a non-finite value, axes that do not increase,
    a map not strictly increasing in its own current (no inverse i(ψ))."""
    if psi_d.shape != (len(d_axis), len(q_axis)) or psi_q.shape != psi_d.shape:
        sys.exit(f"ψd {psi_d.shape}, ψq {psi_q.shape}: not a {len(d_axis)} × {len(q_axis)} grid")
    if not (np.isfinite(psi_d).all() and np.isfinite(psi_q).all()):
        sys.exit("a non-finite flux in the grid")
    if np.any(np.diff(d_axis) <= 0) or np.any(np.diff(q_axis) <= 0):
        sys.exit("the grid's axes are not strictly increasing")
    if np.any(np.diff(psi_d, axis=0) <= 0) or np.any(np.diff(psi_q, axis=1) <= 0):
        sys.exit("ψd is not strictly increasing in i_d or ψq in i_q: the map has no inverse")


def write(out: Path, comments: list[str], d_axis: np.ndarray, q_axis: np.ndarray,
          psi_d: np.ndarray, psi_q: np.ndarray) -> None:
    """The CSV, whole or not at all (written beside `out`, then renamed over it)."""
    check(d_axis, q_axis, psi_d, psi_q)
    lines = [f"# {c}" for c in comments] + ["i_d,i_q,psi_d,psi_q"]
    for k, i_d in enumerate(d_axis):
        for m, i_q in enumerate(q_axis):
            lines.append(f"{i_d:.6g},{i_q:.6g},{psi_d[k, m]:.9g},{psi_q[k, m]:.9g}")
    tmp = out.with_suffix(out.suffix + ".tmp")
    tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    tmp.replace(out)


def zero_current(d_axis: np.ndarray, q_axis: np.ndarray, psi_d: np.ndarray,
                 psi_q: np.ndarray) -> tuple[float, float, float] | None:
    """(ψd, incremental Ld, incremental Lq) at zero current by central differences, the values
    of a preset's `[motor] flux_linkage`, `ld`, `lq`; None without an interior node at 0."""
    k0, m0 = int(np.argmin(abs(d_axis))), int(np.argmin(abs(q_axis)))
    if d_axis[k0] != 0 or q_axis[m0] != 0 or not (0 < k0 < len(d_axis) - 1) \
            or not (0 < m0 < len(q_axis) - 1):
        return None
    ld = (psi_d[k0 + 1, m0] - psi_d[k0 - 1, m0]) / (d_axis[k0 + 1] - d_axis[k0 - 1])
    lq = (psi_q[k0, m0 + 1] - psi_q[k0, m0 - 1]) / (q_axis[m0 + 1] - q_axis[m0 - 1])
    return float(psi_d[k0, m0]), float(ld), float(lq)
