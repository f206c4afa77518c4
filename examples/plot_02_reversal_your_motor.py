"""
A reversal on your motor
========================

A motor entered from its datasheet (see the guide's page "Your motor from its datasheet"):
a 14-pole 24 V outrunner with Kv = 100 r/min/V, 0.12 Ω and 60 µH phase to phase and 20 A rms
of continuous current. Every default of the drive is a ratio of these ratings, so the
paper's Fig. 11 runs on it scaled: ∓6 % of rated speed under 65 % of rated torque
(scenario ``reversal``).

**Reference**: Park and Sul (2014), Fig. 11; the guide's page on entering a motor.
"""

import math

import fado
import fado.plot

poles, kv = 14, 100.0  # r/min per volt of peak line-to-line back-EMF
p = poles // 2
flux_linkage = 60.0 / (2 * math.pi * math.sqrt(3) * p * kv)  # Wb peak per phase
rated_current = 20.0 * math.sqrt(2)  # A peak
motor = fado.Machine(
    rs=0.12 / 2,
    ld=60e-6 / 2,
    lq=60e-6 / 2,
    flux_linkage=flux_linkage,
    pole_pairs=p,
    inertia=5e-4,
    viscous_friction=1.2e-4,
    rated_current=rated_current,
    rated_speed_rpm=1800.0,
    rated_torque=1.5 * p * flux_linkage * rated_current,
    dc_voltage=24.0,
)
print(motor)

# %%
# A 30 µH motor needs a fast sampling rate: 20 kHz switching, sampled at 40 kHz.
result = fado.simulate(
    "reversal",
    {"inverter": {"switching_frequency": 20000.0}},
    motor=motor,
    averaged=True,
)
print(result.passed, round(result.metrics["max_angle_error_zero_speed"], 3), "rad")
figure = fado.plot.plot_scenario(result)
