"""fado: sensorless PMSM control with a frequency-adaptive disturbance observer.

Reference implementation of Y. Park and S.-K. Sul, "Sensorless Control Method for PMSM
Based on Frequency-Adaptive Disturbance Observer". The estimator runs in Rust
(``fado._fado``); this package is its Python face.

Replay a recording (1-D float64 or float32 arrays, one sample per sampling period)::

    import fado
    result = fado.estimate(v_alpha, v_beta, i_alpha, i_beta, ts=100e-6)
    result.theta, result.omega_control, result.lambda1_alpha, result.mode, ...

or step it yourself::

    est = fado.Estimator(fado.EstimatorConfig(rs_hat=0.33))
    out = est.step(v_alpha, v_beta, i_alpha, i_beta)

Compare fado with the baseline estimators in the simulator (same plant, seed, controllers)::

    rows = fado.compare(scenarios=["fig11"], averaged=True)   # list of dicts
    fado.compare.plot_angle_errors("fig11.png")                 # needs matplotlib

Errors derive from :class:`FadoError`; :class:`ConfigError` (a bad configuration field,
named by ``.field``) and :class:`InputError` (a bad array or argument, named by
``.argument``) are also :class:`ValueError`.
"""

from __future__ import annotations

from fado._fado import (
    OUTPUT_NAMES,
    ConfigError,
    EstimateResult,
    Estimator,
    EstimatorConfig,
    FadoError,
    InputError,
    SimulationError,
    StepResult,
    __version__,
    estimate,
)
from fado._mode import Mode
from fado import compare

__all__ = [
    "OUTPUT_NAMES",
    "ConfigError",
    "EstimateResult",
    "Estimator",
    "EstimatorConfig",
    "FadoError",
    "InputError",
    "Mode",
    "SimulationError",
    "StepResult",
    "__version__",
    "compare",
    "estimate",
]
