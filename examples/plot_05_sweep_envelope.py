"""
An operating envelope
=====================

How far can the drive's resistance estimate be off before the loaded reversal of Fig. 11
fails? ``fado.sweep`` runs the scenario once per point of a grid (here the R̂s error and the
load torque) on all cores with the GIL released, and ``fado.plot.envelope`` draws the pass
region. The paper's estimator with its fixed R̂s (left) passes only a wedge around the
matched value that closes with load; fado's online R̂s adaptation (right) passes the whole
grid. The results pages show the same envelope on a fine grid with the switching-resolved
inverter.

**Reference**: Park and Sul (2014), Fig. 11; the results page on operating envelopes.
"""

from matplotlib.figure import Figure

import fado
import fado.plot

grid = {"rs_error": [-0.2, -0.1, -0.05, -0.02, 0.0, 0.02, 0.05, 0.1, 0.2],
        "load_torque": [0.0, 2.5, 5.0, 7.5, 10.0]}
fixed = fado.sweep(grid, "fig11", config={"estimator": {"rs_adaptation": {"enabled": False}}}, averaged=True)
adaptive = fado.sweep(grid, "fig11", averaged=True)
print("passed:", int(fixed["passed"].sum()), "of", len(fixed), "with a fixed R̂s;",
      int(adaptive["passed"].sum()), "of", len(adaptive), "with R̂s adaptation")

figure = Figure(figsize=(11, 4.2), layout="constrained")
left, right = figure.subplots(1, 2)
fado.plot.envelope(fixed, "rs_error", "load_torque", ax=left, title="fixed R̂s (the paper)")
fado.plot.envelope(adaptive, "rs_error", "load_torque", ax=right, title="R̂s adaptation")
