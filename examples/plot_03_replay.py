"""
Replaying recorded data
=======================

The estimator can run over recorded voltages and currents. The voltage it needs at sample n
is the one that acted over the interval [n−1, n]: with a drive that computes its reference at
n and applies it from the next PWM update, that is the reference computed two samples
earlier. Here the "recording" is the simulator's trace, which holds the drive's own
reference and measured currents, so the replay can be checked against the drive's own
estimate: with the two-sample shift it agrees bit for bit, with a one-sample shift it does
not.

**References**: Park and Sul (2014), Fig. 5; B.-H. Bae and S.-K. Sul, "A Compensation Method
for Time Delay of Full-Digital Synchronous Frame Current Regulator of PWM AC Drives," IEEE
Trans. Ind. Appl., vol. 39, no. 3, pp. 802–810, 2003.
"""

import numpy as np
from matplotlib.figure import Figure

import fado

rec = fado.simulate(
    "fig11",
    {
        "simulation": {"decimation": 1},
        "controller": {"offset_calibration": {"time": 0.0}, "gain_calibration": {"time": 0.0}},
    },
    averaged=True,
)

def delayed(x, k):
    """x[n − k], zero before the first sample."""
    return np.concatenate((np.zeros(k), x[:-k]))

def replay(k):
    est = fado.Estimator(rec.machine, rec.estimator_config, ts=rec.ts)
    est.align(rec["theta"][0])
    return est.run(
        delayed(rec["v_alpha_ref"], k),
        delayed(rec["v_beta_ref"], k),
        rec["i_alpha"],
        rec["i_beta"],
    )

right, wrong = replay(2), replay(1)
print("two-sample shift equals the drive:", np.array_equal(right.theta, rec["theta_hat"]))

# %%
# The angle error of each replay against the true rotor angle.
wrap = lambda x: (x + np.pi) % (2 * np.pi) - np.pi  # noqa: E731
figure = Figure(figsize=(8, 3.5), layout="constrained")
ax = figure.subplots()
ax.plot(rec.time, wrap(rec["theta"] - right.theta), label="v*[n − 2] (right)")
ax.plot(rec.time, wrap(rec["theta"] - wrong.theta), label="v*[n − 1]", alpha=0.7)
ax.set_xlabel("time (s)")
ax.set_ylabel("θ − θ̂ (rad)")
ax.legend()
ax.grid(True, alpha=0.4)
