"""`fado.Estimator`: state handling, run-time switches and fault reporting."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import Recording

import fado
from fado import Mode


def test_initial_state_is_the_configured_alignment() -> None:
    cfg = fado.EstimatorConfig(initial_angle=1.0)
    est = fado.Estimator(cfg)
    last = est.last
    assert last.theta == pytest.approx(1.0)
    assert math.hypot(last.lambda_r_alpha, last.lambda_r_beta) == pytest.approx(
        cfg.flux_linkage_hat
    )
    assert last.mode == Mode.LIMITER and last.flag_limit
    assert est.config == cfg and est.dtype == "float64"


def test_align_sets_the_flux_with_the_present_current() -> None:
    est = fado.Estimator()
    est.align(0.5, i_alpha=3.0, i_beta=-1.0)
    last = est.last
    cfg = est.config
    assert last.lambda1_alpha == pytest.approx(
        cfg.flux_linkage_hat * math.cos(0.5) + cfg.lq_hat * 3.0
    )
    assert last.lambda1_beta == pytest.approx(
        cfg.flux_linkage_hat * math.sin(0.5) - cfg.lq_hat * 1.0
    )
    assert last.theta == pytest.approx(0.5)


def test_reset_returns_to_the_start(spin_up: Recording) -> None:
    est = fado.Estimator()
    first = est.run(*(s[:100] for s in spin_up.signals()))
    est.reset()
    again = est.run(*(s[:100] for s in spin_up.signals()))
    np.testing.assert_array_equal(first.theta, again.theta, strict=True)


def test_copy_is_independent(spin_up: Recording) -> None:
    est = fado.Estimator()
    est.run(*(s[:500] for s in spin_up.signals()))
    twin = est.copy()
    a = est.run(*(s[500:900] for s in spin_up.signals()))
    b = twin.run(*(s[500:900] for s in spin_up.signals()))
    np.testing.assert_array_equal(a.lambda1_alpha, b.lambda1_alpha, strict=True)
    est.step(1.0, 2.0, 3.0, 4.0)
    assert est.last != twin.last


def test_non_finite_input_is_rejected_and_counted() -> None:
    est = fado.Estimator()
    good = est.step(1.0, 0.0, 2.0, 0.0)
    bad = est.step(float("nan"), 0.0, 2.0, 0.0)
    assert bad.input_fault and not good.input_fault
    assert bad.theta == good.theta and bad.lambda1_alpha == good.lambda1_alpha
    assert est.rejected_samples == 1
    est.reset()
    assert est.rejected_samples == 0


def test_disabling_disturbance_feedback_changes_the_flux(spin_up: Recording) -> None:
    signals = spin_up.signals()
    on = fado.Estimator()
    off = fado.Estimator()
    off.set_disturbance_feedback_enabled(False)
    a = on.run(*signals)
    b = off.run(*signals)
    spinning = a.mode == Mode.DISTURBANCE_FEEDBACK
    assert spinning.any()
    first = int(np.argmax(spinning))
    # Identical until k_df first acts, different after.
    np.testing.assert_array_equal(a.lambda1_alpha[:first], b.lambda1_alpha[:first])
    assert not np.array_equal(a.lambda1_alpha[first + 1 :], b.lambda1_alpha[first + 1 :])


def test_set_rs_hat(spin_up: Recording) -> None:
    est = fado.Estimator()
    est.set_rs_hat(0.5)
    assert est.config.rs_hat == 0.5
    same = fado.Estimator(fado.EstimatorConfig(rs_hat=0.5))
    a = est.run(*(s[:200] for s in spin_up.signals()))
    b = same.run(*(s[:200] for s in spin_up.signals()))
    np.testing.assert_array_equal(a.lambda1_alpha, b.lambda1_alpha, strict=True)
    with pytest.raises(fado.ConfigError) as info:
        est.set_rs_hat(float("nan"))
    assert info.value.field == "rs_hat"
    assert est.config.rs_hat == 0.5


def test_step_result_containers() -> None:
    out = fado.Estimator().step(1.0, 0.0, 2.0, 0.0)
    d = out.to_dict()
    assert list(d) == list(fado.OUTPUT_NAMES)
    assert d["theta"] == out.theta
    assert repr(out).startswith("StepResult(theta=")
    with pytest.raises(AttributeError):
        out.theta = 1.0  # type: ignore[misc]


def test_float32_estimator_steps_in_single_precision() -> None:
    est = fado.Estimator(dtype="float32")
    assert est.dtype == "float32"
    out = est.step(1.0, 0.1, 2.0, 0.3)
    for name in ("theta", "lambda1_alpha", "lambda_r_beta"):
        value = getattr(out, name)
        assert float(np.float32(value)) == value, name  # exactly representable in f32
    wide = fado.Estimator().step(1.0, 0.1, 2.0, 0.3)
    assert out.lambda1_alpha != wide.lambda1_alpha
    assert out.lambda1_alpha == pytest.approx(wide.lambda1_alpha, rel=1e-6)


def test_mode_names_match_the_native_codes() -> None:
    assert Mode.LIMITER == fado._fado.MODE_LIMITER
    assert Mode.DISTURBANCE_FEEDBACK == fado._fado.MODE_DISTURBANCE_FEEDBACK
    assert len(set(Mode)) == 2
