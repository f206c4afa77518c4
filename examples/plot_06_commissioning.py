"""
Commissioning a motor
=====================

When a datasheet is missing or doubtful, the drive identifies its motor: the current sensors'
offsets and gain ratio, a two-level DC test (Rs and the inverter's voltage error), square-wave
injections along d and q (Ld, Lq), an I-f spin and coasts for the back-EMF (λf), and torque
steps for the inertia and friction. ``fado.commission`` runs the procedure on the simulated
plant and compares what it identifies with the truth; the identified model then runs the
drive.

**Reference**: the guide's commissioning page and its accuracy results.
"""

import fado
import fado.commissioning

com = fado.commission("servo-1ft6084", averaged=True)
print(com.status)
for name, error in com.errors.items():
    print(f"{name:>18}: {100 * error:+.2f} %")
figure = fado.commissioning.plot(com)

# %%
# The identified model drives the motor through the scaled reversal.
drive = fado.simulate("reversal", com.identified_toml, averaged=True)
print(drive.passed, round(drive.metrics["max_angle_error_zero_speed"], 3), "rad")
