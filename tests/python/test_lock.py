"""Implausible samples, the loss-of-lock output, and non-finite scalar arguments."""

from __future__ import annotations

import math

import numpy as np
import pytest

import fado

PAPER = fado.Machine.paper()

TS = 100e-6
RS, L, LF = 0.327, 2.63e-3, 0.088


def machine(n: int, speed_hz: float = 5.0, iq: float = 10.0):
    """v and i of the paper's SPMSM turning at `speed_hz` with a constant q current."""
    w = 2 * math.pi * speed_hz
    th = w * TS * np.arange(n)
    i = iq * np.exp(1j * (th + math.pi / 2))
    flux = LF * np.exp(1j * th) + L * i
    v = RS * i + 1j * w * flux
    return v.real.copy(), v.imag.copy(), i.real.copy(), i.imag.copy()


@pytest.mark.parametrize(
    "column,value",
    [(0, 1e4), (2, 1e4), (2, 1e5), (3, -1e6), (2, 1e300)],
)
def test_absurd_sample_is_refused_and_the_angle_is_unchanged(column, value):
    signals = machine(20_000)
    reference = fado.estimate(*signals, machine=PAPER, theta0=0.0)
    glitched = [s.copy() for s in signals]
    glitched[column][10_000] = value
    out = fado.estimate(*glitched, machine=PAPER, theta0=0.0)
    assert out.input_fault.sum() == 1 and out.input_fault[10_000]
    diff = np.angle(np.exp(1j * (out.theta - reference.theta)))
    assert np.abs(diff).max() < 0.05


def test_lock_output_is_locked_on_a_healthy_recording_and_lost_on_nonsense():
    out = fado.estimate(*machine(20_000), machine=PAPER, theta0=0.0)
    assert out.lock.dtype == np.int8
    assert (out.lock[5000:] == 0).all()
    # The voltage of a machine turning the other way: the estimate is inconsistent.
    va, vb, ia, ib = machine(20_000)
    bad = fado.estimate(va, -vb, ia, ib, machine=PAPER, theta0=0.0)
    assert (bad.lock == 2).any()
    est = fado.Estimator(PAPER)
    step = est.step(0.0, 0.0, 0.0, 0.0)
    assert step.lock in (0, 1, 2) and "lock" in step.to_dict()


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_non_finite_scalar_arguments_are_refused_by_name(bad):
    signals = machine(100)
    with pytest.raises(fado.InputError, match="theta0"):
        fado.estimate(*signals, machine=PAPER, theta0=bad)
    with pytest.raises(ValueError, match="ts"):
        fado.estimate(*signals, machine=PAPER, ts=bad)
    est = fado.Estimator(PAPER)
    for name, args in [
        ("theta0", (bad,)),
        ("i_alpha", (0.0, bad, 0.0)),
        ("i_beta", (0.0, 0.0, bad)),
    ]:
        with pytest.raises(fado.InputError, match=name):
            est.align(*args)
    with pytest.raises(ValueError, match="rs_hat"):
        est.set_rs_hat(bad)
    for record, field in [
        ("plausibility", "current_ratio"),
        ("lock", "detection_time"),
        ("lock", "flux_high_ratio"),
    ]:
        with pytest.raises(fado.ConfigError, match=f"{record}.{field}"):
            fado.EstimatorConfig(**{record: {field: bad}})
