"""`fado.estimate` and `Estimator.run` against `Estimator.step`, and against the motor."""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest
from conftest import Recording, ramp_then_hold, synthetic_recording

import fado
from fado import Mode


def wrap(x: np.ndarray) -> np.ndarray:
    return np.angle(np.exp(1j * x))


def stepped(est: fado.Estimator, *signals: np.ndarray) -> dict[str, np.ndarray]:
    """Steps sample by sample from Python and stacks the results like `estimate` does."""
    rows = [est.step(*map(float, sample)) for sample in zip(*signals)]
    float_dtype = np.float32 if est.dtype == "float32" else np.float64
    out = {}
    for name in fado.OUTPUT_NAMES:
        values = [getattr(r, name) for r in rows]
        if name in ("mode", "lock"):
            out[name] = np.array(values, dtype=np.int8)
        elif isinstance(values[0], bool):
            out[name] = np.array(values, dtype=bool)
        else:
            out[name] = np.array(values, dtype=float_dtype)
    return out


def assert_identical(result: fado.EstimateResult, expected: dict[str, np.ndarray]) -> None:
    assert result.keys() == list(fado.OUTPUT_NAMES)
    for name in fado.OUTPUT_NAMES:
        got = result[name]
        assert got.dtype == expected[name].dtype, name
        # Bit for bit, NaN-free by construction: array_equal, not allclose.
        np.testing.assert_array_equal(got, expected[name], err_msg=name, strict=True)


def with_faults(rec: Recording) -> tuple[np.ndarray, ...]:
    """The recording's signals with a few non-finite samples, as a glitching ADC would give."""
    v_alpha, v_beta, i_alpha, i_beta = (s.copy() for s in rec.signals())
    v_alpha[1234] = np.nan
    i_beta[5678] = np.inf
    v_beta[15000] = -np.inf
    return v_alpha, v_beta, i_alpha, i_beta


@pytest.mark.parametrize("dtype", ["float64", "float32"])
def test_estimate_equals_stepping_sample_by_sample(spin_up: Recording, dtype: str) -> None:
    signals = with_faults(spin_up)
    result = fado.estimate(*signals, machine="paper", theta0=spin_up.theta0, dtype=dtype)
    est = fado.Estimator("paper", dtype=dtype)
    est.align(spin_up.theta0, float(signals[2][0]), float(signals[3][0]))
    assert_identical(result, stepped(est, *signals))
    # The recording really exercises both feedbacks and the fault path.
    assert set(np.unique(result.mode)) == {Mode.LIMITER, Mode.DISTURBANCE_FEEDBACK}
    assert np.count_nonzero(result.input_fault) == 3
    assert result.dtype == dtype and len(result) == len(signals[0])


def test_run_in_chunks_equals_one_run(spin_up: Recording) -> None:
    whole = fado.Estimator("paper")
    once = whole.run(*spin_up.signals())
    chunked = fado.Estimator("paper")
    bounds = [0, 1, 700, 701, 9000, 20_000]
    parts = [
        chunked.run(*(s[a:b] for s in spin_up.signals())) for a, b in zip(bounds, bounds[1:])
    ]
    for name in fado.OUTPUT_NAMES:
        np.testing.assert_array_equal(
            once[name], np.concatenate([p[name] for p in parts]), strict=True
        )
    assert whole.last == chunked.last


def test_estimate_defaults_equal_a_fresh_estimator(spin_up: Recording) -> None:
    n = 3000
    signals = [s[:n] for s in spin_up.signals()]
    machine = fado.Machine.paper().replace(rs=0.3)
    cfg = fado.EstimatorConfig(disturbance_feedback={"k_df": 0.7})
    by_function = fado.estimate(*signals, machine=machine, config=cfg)
    by_object = fado.Estimator(machine, cfg).run(*signals)
    for name in fado.OUTPUT_NAMES:
        np.testing.assert_array_equal(by_function[name], by_object[name], strict=True)


def test_ts_argument(spin_up: Recording) -> None:
    n = 2000
    signals = [s[:n] for s in spin_up.signals()]
    machine = fado.Machine.paper().replace(rs=0.3)
    by_function = fado.estimate(*signals, machine=machine, ts=50e-6)
    by_object = fado.Estimator(machine, ts=50e-6).run(*signals)
    np.testing.assert_array_equal(by_function.theta, by_object.theta, strict=True)
    assert by_function.ts == 50e-6
    np.testing.assert_allclose(by_function.time[:3], [0.0, 50e-6, 100e-6])
    different = fado.estimate(*signals, machine=machine)
    assert not np.array_equal(by_function.lambda1_alpha, different.lambda1_alpha)


@pytest.mark.parametrize(("dtype", "tolerance"), [("float64", 1e-3), ("float32", 1e-3)])
def test_tracks_the_rotor_angle_of_a_consistent_recording(
    spin_up: Recording, dtype: str, tolerance: float
) -> None:
    """Matched R̂s, L̂q: after the spin-up the angle error is small and the modes are right."""
    result = fado.estimate(*spin_up.signals(), machine="paper", theta0=spin_up.theta0, dtype=dtype)
    settled = slice(15_000, None)  # the last 0.5 s, 1.2 s after the ramp ended
    error = wrap(result.theta[settled] - spin_up.theta[settled])
    assert np.max(np.abs(error)) < tolerance
    np.testing.assert_allclose(result.omega_control[settled], spin_up.omega[settled], rtol=0.01)
    assert np.all(result.mode[settled] == Mode.DISTURBANCE_FEEDBACK)
    assert result.mode[0] == Mode.LIMITER
    np.testing.assert_array_equal(result.flag_limit, result.mode == Mode.LIMITER)
    # The paper's identities hold on the arrays: λ2 = λ1 − D̂ (eq. 20), λ̂r = λ2 − L̂q·i (eq. 5).
    np.testing.assert_allclose(
        result.lambda2_alpha, result.lambda1_alpha - result.disturbance_alpha, atol=1e-6
    )
    lq = fado.Machine.paper().lq
    np.testing.assert_allclose(
        result.lambda_r_beta, result.lambda2_beta - lq * spin_up.i_beta, atol=1e-6
    )


def test_float32_inputs_in_float64_mode_are_widened_exactly(spin_up: Recording) -> None:
    n = 3000
    narrow = [s[:n].astype(np.float32) for s in spin_up.signals()]
    widened = [s.astype(np.float64) for s in narrow]
    a = fado.estimate(*narrow, machine="paper")
    b = fado.estimate(*widened, machine="paper")
    assert a.theta.dtype == np.float64
    np.testing.assert_array_equal(a.theta, b.theta, strict=True)


def test_float32_mode_rounds_float64_inputs_like_a_cast(spin_up: Recording) -> None:
    n = 3000
    wide = [s[:n] for s in spin_up.signals()]
    a = fado.estimate(*wide, machine="paper", dtype="float32")
    b = fado.estimate(*(s.astype(np.float32) for s in wide), machine="paper", dtype=np.float32)
    assert a.theta.dtype == np.float32
    np.testing.assert_array_equal(a.theta, b.theta, strict=True)


def test_float32_and_float64_agree_to_single_precision(spin_up: Recording) -> None:
    r64 = fado.estimate(*spin_up.signals(), machine="paper", theta0=spin_up.theta0)
    r32 = fado.estimate(
        *spin_up.signals(), machine="paper", theta0=spin_up.theta0, dtype="float32"
    )
    assert not np.array_equal(r64.theta.astype(np.float32), r32.theta)
    np.testing.assert_allclose(wrap(r32.theta - r64.theta), 0.0, atol=5e-3)


def test_theta0_aligns_with_the_first_current_sample() -> None:
    rec = synthetic_recording(np.full(500, 2 * np.pi * 10.0), theta0=-2.0)
    result = fado.estimate(*rec.signals(), machine="paper", theta0=rec.theta0)
    est = fado.Estimator("paper")
    est.align(rec.theta0, float(rec.i_alpha[0]), float(rec.i_beta[0]))
    first = est.step(*(float(s[0]) for s in rec.signals()))
    assert result.theta[0] == first.theta
    assert result.lambda1_alpha[0] == first.lambda1_alpha
    unaligned = fado.estimate(*rec.signals(), machine="paper")
    assert unaligned.lambda1_alpha[0] != first.lambda1_alpha


def test_empty_recording_gives_empty_arrays() -> None:
    empty = np.empty(0)
    result = fado.estimate(empty, empty, empty, empty, machine="paper", theta0=1.0)
    assert len(result) == 0
    for name in fado.OUTPUT_NAMES:
        assert result[name].shape == (0,)


def test_result_containers(spin_up: Recording) -> None:
    n = 100
    result = fado.estimate(*(s[:n] for s in spin_up.signals()), machine="paper")
    as_dict = result.to_dict()
    assert list(as_dict) == list(fado.OUTPUT_NAMES)
    assert as_dict["theta"] is result.theta  # shared, not copied
    assert result.mode.dtype == np.int8
    assert result.flag_limit.dtype == np.bool_
    assert result.time.dtype == np.float64 and result.time[-1] == pytest.approx((n - 1) * 1e-4)
    with pytest.raises(KeyError):
        result["no_such_output"]
    assert "samples=100" in repr(result)


def test_to_pandas(spin_up: Recording) -> None:
    pd = pytest.importorskip("pandas")
    result = fado.estimate(*(s[:50] for s in spin_up.signals()), machine="paper")
    frame = result.to_pandas()
    assert isinstance(frame, pd.DataFrame)
    assert list(frame.columns) == list(fado.OUTPUT_NAMES)
    assert frame.index.name == "time_s"
    np.testing.assert_array_equal(frame["theta"].to_numpy(), result.theta)


def test_estimate_releases_the_gil() -> None:
    """While `estimate` runs in one thread, another keeps running Python code.

    With the GIL held the main loop would stall for the whole call; released, its longest
    pause is a scheduling quantum, far shorter than the call.
    """
    n = 2_000_000
    rng = np.random.default_rng(1)
    signals = [rng.normal(size=n) for _ in range(4)]
    done = threading.Event()
    span: list[float] = []

    def worker() -> None:
        start = time.perf_counter()
        fado.estimate(*signals, machine="paper")
        span.extend([start, time.perf_counter()])
        done.set()

    thread = threading.Thread(target=worker)
    last = time.perf_counter()
    longest = 0.0
    thread.start()
    while not done.is_set():
        now = time.perf_counter()
        longest = max(longest, now - last)
        last = now
    thread.join()
    duration = span[1] - span[0]
    assert longest < 0.5 * duration, (longest, duration)


IPMSM_SPIN_UP = ramp_then_hold(30_000, 20.0, 0.5)  # 0 → 20 Hz (27 % of rated) in 0.5 s


def ipmsm_recording(ipm: fado.Machine, i_d_ratio: float) -> Recording:
    """The 2.2 kW IPMSM preset under 65 % of its rated current in q, `i_d_ratio` of it in d."""
    return synthetic_recording(
        IPMSM_SPIN_UP,
        i_d=i_d_ratio * ipm.rated_current,
        i_q=0.65 * ipm.rated_current,
        rs=ipm.rs,
        ld=ipm.ld,
        lq=ipm.lq,
        flux=ipm.flux_linkage,
    )


def settled_error(result: fado.EstimateResult, rec: Recording) -> float:
    return float(np.max(np.abs(wrap(result.theta[20_000:] - rec.theta[20_000:]))))


@pytest.mark.parametrize(
    ("i_d_ratio", "rs_adaptation", "bound"),
    [
        (0.0, True, 1e-3),  # measured 4.4e-5 rad
        (0.0, False, 1e-3),  # measured 2.6e-5 rad
        (-0.15, False, 1e-3),  # measured 1.2e-4 rad
        (-0.5, False, 2e-3),  # measured 4.1e-4 rad
    ],
)
def test_ipmsm_preset_replayed_through_estimate(
    i_d_ratio: float, rs_adaptation: bool, bound: float
) -> None:
    """A salient motor (Ld 36 mH, Lq 51 mH) recorded from its own equations: with its preset as
    the machine, the estimator (rotor flux λ2 − L̂q·i, the active flux) tracks the angle for
    any i_d; with the paper's motor as the model it does not."""
    ipm = fado.Machine.preset("ipmsm-2k2")
    assert ipm.salient
    rec = ipmsm_recording(ipm, i_d_ratio)
    config = fado.EstimatorConfig(rs_adaptation={"enabled": rs_adaptation})
    result = fado.estimate(*rec.signals(), machine="ipmsm-2k2", config=config, theta0=rec.theta0)
    assert settled_error(result, rec) < bound
    np.testing.assert_allclose(result.omega_control[20_000:], rec.omega[20_000:], rtol=0.01)
    wrong = fado.estimate(*rec.signals(), machine="paper", config=config, theta0=rec.theta0)
    assert settled_error(wrong, rec) > 0.2  # measured 0.30–0.46 rad


@pytest.mark.parametrize("i_d_ratio", [-0.15, -0.5])
def test_ipmsm_rs_adaptation_is_unbiased_under_negative_i_d(i_d_ratio: float) -> None:
    """The R̂s laws compare |λ̂r| with the active flux λ̂f + (L̂d − L̂q)·î_d
    (before: R̂s 3.93 Ω for 3.6 Ω at i_d = −0.15·rated, 4.73 Ω at −0.5·rated)."""
    ipm = fado.Machine.preset("ipmsm-2k2")
    rec = ipmsm_recording(ipm, i_d_ratio)
    result = fado.estimate(*rec.signals(), machine=ipm, theta0=rec.theta0)
    assert abs(result.rs_hat[-1] / ipm.rs - 1.0) < 0.02
    assert settled_error(result, rec) < 2e-3
