"""fado: sensorless PMSM control with a frequency-adaptive disturbance observer.

Reference implementation of Y. Park and S.-K. Sul, "Sensorless Control Method for PMSM
Based on Frequency-Adaptive Disturbance Observer". The estimator runs in Rust
(``fado._fado``); this package is its Python face.

Describe the motor (its parameters and ratings), or pick a preset of the repository's
``motors/`` folder (:func:`machine_presets`; ``"paper"`` is the paper's motor)::

    import fado
    motor = fado.Machine(rs=3.6, ld=36e-3, lq=51e-3, flux_linkage=0.545, pole_pairs=3,
                         inertia=0.015, rated_current=6.08, rated_speed_rpm=1500.0,
                         rated_torque=14.0, dc_voltage=540.0)

Replay a recording (1-D float64 or float32 arrays, one sample per sampling period)::

    result = fado.estimate(v_alpha, v_beta, i_alpha, i_beta, machine=motor, ts=100e-6)
    result.theta, result.omega_control, result.lambda1_alpha, result.mode, ...

or step it yourself::

    est = fado.Estimator("paper", fado.EstimatorConfig(disturbance_feedback={"k_df": 1.0}))
    out = est.step(v_alpha, v_beta, i_alpha, i_beta)

Simulate the paper's experiments (Fig. 8–12) on the closed-loop drive model (Rust,
``fado-sim``) and plot them like the paper's oscilloscope captures::

    result = fado.simulate("fig11", {"simulation": {"duration": 5.5}}, averaged=False)
    result = fado.simulate("reversal", motor="ipmsm-2k2")   # scaled by any motor's ratings
    result.passed, result.metrics["max_angle_error_zero_speed"], result.traces["theta_hat"]
    import fado.plot; fado.plot.plot_scenario(result, "fig11.png")   # needs fado[plot]

``python -m fado reproduce --out DIR`` runs all five and writes the figures and a table.

Compare fado with the baseline estimators in the simulator (same plant, seed, controllers)::

    rows = fado.compare(scenarios=["fig11"], averaged=True)   # list of dicts
    fado.compare.plot_angle_errors("fig11.png")                 # needs matplotlib

Map the operating envelope: one run per point of a grid over model and sensor errors, load
and profile (Rust on all cores, or one task per point on a process pool or Dask cluster)::

    df = fado.sweep({"rs_error": [-0.1, 0, 0.1], "load_torque": [0, 7.5]}, "fig11")
    fado.plot.envelope(df, "rs_error", "load_torque", path="envelope.png")

Identify a motor with the commissioning procedure on the simulated plant (Rs, Ld, Lq, λf,
J, B and the inverter's voltage error, each against the plant's truth)::

    result = fado.commission("ipmsm-2k2")
    result.machine, result.errors["rs"], result["i_alpha"]
    fado.commissioning.plot(result, "commission.png")            # needs fado[plot]

Errors derive from :class:`FadoError`; :class:`ConfigError` (a bad configuration field,
named by ``.field``) and :class:`InputError` (a bad array or argument, named by
``.argument``) are also :class:`ValueError`.
"""

from __future__ import annotations

from fado._fado import (
    COMMISSION_PHASES,
    COMMISSION_TRACE_COLUMNS,
    OUTPUT_NAMES,
    TRACE_COLUMNS,
    CommissionResult,
    ConfigError,
    EstimateResult,
    Estimator,
    EstimatorConfig,
    FadoError,
    InputError,
    Machine,
    SimResult,
    SimulationError,
    StepResult,
    __version__,
    default_config,
    describe_scenario,
    estimate,
    machine_presets,
    scenarios,
)
from fado._mode import Mode
from fado._simulation import simulate
from fado._sweep import sweep
from fado import commissioning, compare
from fado.commissioning import commission

__all__ = [
    "COMMISSION_PHASES",
    "COMMISSION_TRACE_COLUMNS",
    "CommissionResult",
    "OUTPUT_NAMES",
    "TRACE_COLUMNS",
    "ConfigError",
    "EstimateResult",
    "Estimator",
    "EstimatorConfig",
    "FadoError",
    "InputError",
    "Machine",
    "Mode",
    "SimResult",
    "SimulationError",
    "StepResult",
    "__version__",
    "default_config",
    "describe_scenario",
    "commission",
    "commissioning",
    "compare",
    "estimate",
    "machine_presets",
    "scenarios",
    "simulate",
    "sweep",
]
