"""`fado.Estimator`: state handling, run-time switches and fault reporting."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import Recording

import fado
from fado import Mode


def test_initial_state_is_the_configured_alignment() -> None:
    cfg = fado.EstimatorConfig(disturbance_feedback={"k_df": 1.0})
    est = fado.Estimator("paper", cfg, theta0=1.0)
    last = est.last
    assert last.theta == pytest.approx(1.0)
    assert math.hypot(last.lambda_r_alpha, last.lambda_r_beta) == pytest.approx(
        est.machine.flux_linkage
    )
    assert last.mode == Mode.LIMITER and last.flag_limit
    assert est.config == cfg and est.dtype == "float64"
    assert est.machine == fado.Machine.paper() and est.ts == 1e-4 and est.theta0 == 1.0


def test_align_sets_the_flux_with_the_present_current() -> None:
    est = fado.Estimator("paper")
    est.align(0.5, i_alpha=3.0, i_beta=-1.0)
    last = est.last
    m = est.machine
    assert last.lambda1_alpha == pytest.approx(m.flux_linkage * math.cos(0.5) + m.lq * 3.0)
    assert last.lambda1_beta == pytest.approx(m.flux_linkage * math.sin(0.5) - m.lq * 1.0)
    assert last.theta == pytest.approx(0.5)


def test_reset_returns_to_the_start(spin_up: Recording) -> None:
    est = fado.Estimator("paper")
    first = est.run(*(s[:100] for s in spin_up.signals()))
    est.reset()
    again = est.run(*(s[:100] for s in spin_up.signals()))
    np.testing.assert_array_equal(first.theta, again.theta, strict=True)


def test_copy_is_independent(spin_up: Recording) -> None:
    est = fado.Estimator("paper")
    est.run(*(s[:500] for s in spin_up.signals()))
    twin = est.copy()
    a = est.run(*(s[500:900] for s in spin_up.signals()))
    b = twin.run(*(s[500:900] for s in spin_up.signals()))
    np.testing.assert_array_equal(a.lambda1_alpha, b.lambda1_alpha, strict=True)
    est.step(1.0, 2.0, 3.0, 4.0)
    assert est.last != twin.last


def test_non_finite_input_is_rejected_and_counted() -> None:
    est = fado.Estimator("paper")
    good = est.step(1.0, 0.0, 2.0, 0.0)
    bad = est.step(float("nan"), 0.0, 2.0, 0.0)
    assert bad.input_fault and not good.input_fault
    assert bad.theta == good.theta and bad.lambda1_alpha == good.lambda1_alpha
    assert est.rejected_samples == 1
    est.reset()
    assert est.rejected_samples == 0


def test_disabling_disturbance_feedback_changes_the_flux(spin_up: Recording) -> None:
    signals = spin_up.signals()
    on = fado.Estimator("paper")
    off = fado.Estimator("paper")
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
    est = fado.Estimator("paper")
    est.set_rs_hat(0.5)
    assert est.machine.rs == 0.5
    same = fado.Estimator(fado.Machine.paper().replace(rs=0.5))
    a = est.run(*(s[:200] for s in spin_up.signals()))
    b = same.run(*(s[:200] for s in spin_up.signals()))
    np.testing.assert_array_equal(a.lambda1_alpha, b.lambda1_alpha, strict=True)
    with pytest.raises(fado.ConfigError) as info:
        est.set_rs_hat(float("nan"))
    assert info.value.field == "rs_hat"
    assert est.machine.rs == 0.5


def test_step_result_containers() -> None:
    out = fado.Estimator("paper").step(1.0, 0.0, 2.0, 0.0)
    d = out.to_dict()
    assert list(d) == list(fado.OUTPUT_NAMES)
    assert d["theta"] == out.theta
    assert repr(out).startswith("StepResult(theta=")
    with pytest.raises(AttributeError):
        out.theta = 1.0  # type: ignore[misc]


def test_float32_estimator_steps_in_single_precision() -> None:
    est = fado.Estimator("paper", dtype="float32")
    assert est.dtype == "float32"
    out = est.step(1.0, 0.1, 2.0, 0.3)
    for name in ("theta", "lambda1_alpha", "lambda_r_beta"):
        value = getattr(out, name)
        assert float(np.float32(value)) == value, name  # exactly representable in f32
    wide = fado.Estimator("paper").step(1.0, 0.1, 2.0, 0.3)
    assert out.lambda1_alpha != wide.lambda1_alpha
    assert out.lambda1_alpha == pytest.approx(wide.lambda1_alpha, rel=1e-6)


def test_mode_names_match_the_native_codes() -> None:
    assert Mode.LIMITER == fado._fado.MODE_LIMITER
    assert Mode.DISTURBANCE_FEEDBACK == fado._fado.MODE_DISTURBANCE_FEEDBACK
    assert len(set(Mode)) == 2


def test_align_refuses_non_finite_arguments_naming_them() -> None:
    est = fado.Estimator("paper")
    before = est.last
    for kwargs, name in [
        ({"theta0": math.nan}, "theta0"),
        ({"theta0": 0.0, "i_alpha": math.inf}, "i_alpha"),
        ({"theta0": 0.0, "i_beta": -math.inf}, "i_beta"),
    ]:
        with pytest.raises(ValueError, match=name) as info:
            est.align(**kwargs)
        assert isinstance(info.value, fado.InputError) and info.value.argument == name
    assert est.last == before  # nothing was applied


def test_salient_machine_uses_its_ld_and_lq() -> None:
    """On an interior-magnet motor the start-up flux is λ̂a·e^{jθ0} + L̂q·i with the active
    flux λ̂a = λ̂f + (L̂d − L̂q)·i_d, and the rotor flux λ̂r = λ2 − L̂q·i: L̂q, not L̂d,
    multiplies the current vector; L̂d only sets the magnitude of λ̂r."""
    ipm = fado.Machine.preset("ipmsm-2k2")
    assert ipm.salient and ipm.ld != ipm.lq
    est = fado.Estimator(ipm, theta0=0.2)
    est.align(0.2, i_alpha=2.0, i_beta=-1.0)
    i_d = 2.0 * math.cos(0.2) - 1.0 * math.sin(0.2)
    active = ipm.flux_linkage + (ipm.ld - ipm.lq) * i_d
    assert est.last.lambda1_alpha == pytest.approx(active * math.cos(0.2) + ipm.lq * 2.0)
    assert est.last.lambda1_beta == pytest.approx(active * math.sin(0.2) - ipm.lq * 1.0)
    out = est.step(0.0, 0.0, 2.0, -1.0)
    assert out.lambda_r_alpha == pytest.approx(out.lambda2_alpha - ipm.lq * 2.0)
    assert out.lambda_r_beta == pytest.approx(out.lambda2_beta + ipm.lq * 1.0)
