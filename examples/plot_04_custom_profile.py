r"""
Your own speed and load profile
===============================

A hoist on the paper's motor: it lifts at 150 r/min, stops and holds the load at zero speed
for a second, and lowers it at −150 r/min, with a gravity load of 7 N·m present from the
start (positive load torque opposes positive rotation, so lowering is generating). Profiles
are piecewise-linear ``[time, value]`` breakpoints; two breakpoints at one time make a step.
The base scenario, ``fig12``, supplies the criteria (\|θ − θ̂\| < 0.25 rad over the evaluated
time) and every key not given. The same keys in a TOML file run with
``fado-sim run fig12 --config examples/profiles/hoist.toml``.

**Reference**: Park and Sul (2014), Fig. 12; the guide's page on speed and load profiles.
"""

import fado
import fado.plot

hoist = {
    "simulation": {"duration": 6.0, "eval_start": 1.0},
    "speed_reference": {
        "points": [
            [0.0, 0.0], [0.5, 0.0], [1.5, 150.0], [2.5, 150.0],
            [3.0, 0.0], [4.0, 0.0], [4.5, -150.0], [6.0, -150.0],
        ]
    },
    "load": {"torque": {"points": [[0.0, 7.0]]}},
}
result = fado.simulate("fig12", hoist, averaged=True)
print(result.passed, round(result.metrics["max_angle_error"], 3), "rad")
figure = fado.plot.plot_run(result)
