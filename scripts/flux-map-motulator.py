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

import flux_map_csv


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
    flux_map_csv.write(args.out, [args.provenance,
                                  f"Converted by scripts/flux-map-motulator.py from "
                                  f"{args.source.name}: {len(d_axis)} × {len(q_axis)} nodes, "
                                  "one row each, no interpolation."],
                       d_axis, q_axis, psi.real, psi.imag)
    zero = flux_map_csv.zero_current(d_axis, q_axis, psi.real, psi.imag)
    if zero is None:
        print(f"wrote {args.out} (the grid has no interior node at zero current)")
        return
    print(f"wrote {args.out}: {len(d_axis)} × {len(q_axis)} nodes; at zero current "
          f"flux_linkage = {zero[0]:.4f} Wb, incremental ld = {zero[1] * 1e3:.2f} mH, "
          f"lq = {zero[2] * 1e3:.2f} mH")


if __name__ == "__main__":
    main()
