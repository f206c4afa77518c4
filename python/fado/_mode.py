"""Names for the ``mode`` codes the estimator reports."""

from __future__ import annotations

import enum

from fado import _fado


class Mode(enum.IntEnum):
    """Which feedback closes the flux integrator (paper, section V).

    The ``mode`` field of :class:`fado.StepResult` and the ``mode`` array of
    :class:`fado.EstimateResult` hold these codes (``int8`` in arrays), so
    ``result.mode == Mode.LIMITER`` works on both.
    """

    LIMITER = _fado.MODE_LIMITER
    """|f̂| below the threshold: the flux limiter of Fig. 6 (FLAG_limit high)."""
    DISTURBANCE_FEEDBACK = _fado.MODE_DISTURBANCE_FEEDBACK
    """|f̂| above the threshold: the disturbance feedback k_df of Fig. 3."""
