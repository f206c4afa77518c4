r"""
Your own speed and load profile
===============================

A hoist on the paper's motor: after its start-up (offset and gain calibration, alignment) it
holds still while the cable takes up a gravity load of 7 N·m over half a second, lifts at
150 r/min, stops and holds the load at zero speed
for a second, and lowers it at −150 r/min (positive load torque opposes positive rotation,
so lowering is generating). Profiles
are piecewise-linear ``[time, value]`` breakpoints; two breakpoints at one time make a step.
While the cable takes up the load the 5 Hz speed loop lets the rotor sag by about 50 r/min
(a hoist's brake would hold it), so the run is judged from the lift on (``eval_start``).
The base scenario, ``fig12``, supplies the criteria (\|θ − θ̂\| < 0.25 rad over the evaluated
time) and every key not given. The same keys in a TOML file run with
``fado-sim run fig12 --config examples/profiles/hoist.toml``.

**Reference**: Park and Sul (2014), Fig. 12; the guide's page on speed and load profiles.
"""

import fado
import fado.plot

hoist = {
    "simulation": {"duration": 7.0, "eval_start": 2.0},  # judged from the lift on
    "speed_reference": {
        "points": [
            [0.0, 0.0], [2.0, 0.0], [3.0, 150.0], [4.0, 150.0],
            [4.5, 0.0], [5.5, 0.0], [6.0, -150.0], [7.0, -150.0],
        ]
    },
    "load": {"torque": {"points": [[0.0, 0.0], [1.0, 0.0], [1.5, 7.0]]}},
}
result = fado.simulate("fig12", hoist, averaged=True)
print(result.passed, round(result.metrics["max_angle_error"], 3), "rad")
figure = fado.plot.plot_run(result)
