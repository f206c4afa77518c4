#!/usr/bin/env python3
"""A flux map in motulator's `.npz` form converted to fado's flux-map CSV (the format of
`[motor] flux_map`, crates/fado-sim/src/magnetics_file.rs).

motulator (Aalto-Electric-Drives/motulator, MIT licence) stores a measured or computed flux map
as two complex arrays on a rectangular current grid: `i_s_dq` (A, i_d + j·i_q, peak) and
`psi_s_dq` (Vs, ψd + j·ψq, peak), both in the rotor frame with d on the magnet (motulator's
`MagneticModel`, `utils.MagneticModel(i_s_dq=…, psi_s_dq=…, type="flux_map")`). fado's CSV is
the same data one node per row: `i_d,i_q,psi_d,psi_q`. Nothing is interpolated, smoothed or
extrapolated: each node of the source is one row, so the CSV is the source's data.

The script checks what fado's reader refuses (a grid that is not rectangular, a non-finite
value, a map not strictly increasing in its own current) and prints the zero-current values a
preset's `[motor] ld`, `lq`, `flux_linkage` take.

Usage: python3 scripts/flux-map-motulator.py SOURCE.npz OUT.csv --source "TEXT"
(numpy: the project's own dependency, `pip install numpy`).
"""

import argparse
import sys
from pathlib import Path

import numpy as np


def grid(i_s_dq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The d and q axes of a rectangular grid (i_d along axis 0, i_q along axis 1), or exit."""
    i_d, i_q = i_s_dq.real, i_s_dq.imag
    if not (np.allclose(i_d, i_d[:, :1]) and np.allclose(i_q, i_q[:1, :])):
        sys.exit("i_s_dq is not a rectangular grid with i_d along axis 0 and i_q along axis 1")
    return i_d[:, 0], i_q[0, :]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("source", type=Path, help="motulator .npz with i_s_dq and psi_s_dq")
    ap.add_argument("out", type=Path, help="fado flux-map CSV to write")
    ap.add_argument("--source", dest="provenance", required=True,
                    help="where the data come from (written as the CSV's first comment)")
    args = ap.parse_args()
    data = np.load(args.source)
    i_s, psi = data["i_s_dq"], data["psi_s_dq"]
    if i_s.shape != psi.shape or i_s.ndim != 2:
        sys.exit(f"i_s_dq {i_s.shape} and psi_s_dq {psi.shape}: two arrays of one 2-D grid")
    if not (np.isfinite(i_s).all() and np.isfinite(psi).all()):
        sys.exit("a non-finite value in the source")
    d_axis, q_axis = grid(i_s)
    if np.any(np.diff(d_axis) <= 0) or np.any(np.diff(q_axis) <= 0):
        sys.exit("the grid's axes are not strictly increasing")
    if np.any(np.diff(psi.real, axis=0) <= 0) or np.any(np.diff(psi.imag, axis=1) <= 0):
        sys.exit("ψd is not strictly increasing in i_d or ψq in i_q: the map has no inverse")
    lines = [f"# {args.provenance}",
             f"# Converted by scripts/flux-map-motulator.py from {args.source.name}: "
             f"{len(d_axis)} × {len(q_axis)} nodes, one row each, no interpolation.",
             "i_d,i_q,psi_d,psi_q"]
    for k, i_d in enumerate(d_axis):
        for m, i_q in enumerate(q_axis):
            p = psi[k, m]
            lines.append(f"{i_d:.6g},{i_q:.6g},{p.real:.9g},{p.imag:.9g}")
    tmp = args.out.with_suffix(args.out.suffix + ".tmp")
    tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    tmp.replace(args.out)
    # The zero-current values of a preset's [motor] keys (central differences at the origin).
    k0, m0 = int(np.argmin(abs(d_axis))), int(np.argmin(abs(q_axis)))
    if d_axis[k0] != 0 or q_axis[m0] != 0 or not (0 < k0 < len(d_axis) - 1) \
            or not (0 < m0 < len(q_axis) - 1):
        print(f"wrote {args.out} (the grid has no interior node at zero current)")
        return
    ld = (psi.real[k0 + 1, m0] - psi.real[k0 - 1, m0]) / (d_axis[k0 + 1] - d_axis[k0 - 1])
    lq = (psi.imag[k0, m0 + 1] - psi.imag[k0, m0 - 1]) / (q_axis[m0 + 1] - q_axis[m0 - 1])
    print(f"wrote {args.out}: {len(d_axis)} × {len(q_axis)} nodes; at zero current "
          f"flux_linkage = {psi.real[k0, m0]:.4f} Wb, incremental ld = {ld * 1e3:.2f} mH, "
          f"lq = {lq * 1e3:.2f} mH")


if __name__ == "__main__":
    main()
