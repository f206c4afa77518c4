"""Shared fixtures: a synthetic PMSM recording consistent with the estimator's model.

The recording is generated from the motor equations, not from fado: a rotor turning at a
prescribed electrical speed with a constant d-q current, flux λ = e^{jθ}·(λf + Ld·i_d + j·Lq·i_q)
(= λf·e^{jθ} + L·i for surface magnets, Ld = Lq = L) and the voltage that the discrete
integrator of docs/method/estimator.md (section 1) would need, v[k] = (λ[k] − λ[k−1])/Ts + R·(i[k] + i[k−1])/2. With a
matched machine model the estimator should recover θ; with any data the bindings must
reproduce the Rust estimator bit for bit. The default motor is the paper's
(``fado.Machine.paper()``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import pytest

TS = 100e-6
RS = 0.327
LQ = 2.63e-3
FLUX = 0.088


@dataclass(frozen=True)
class Recording:
    """Voltages applied over each interval, sampled currents and the true rotor angle."""

    v_alpha: npt.NDArray[np.float64]
    v_beta: npt.NDArray[np.float64]
    i_alpha: npt.NDArray[np.float64]
    i_beta: npt.NDArray[np.float64]
    theta: npt.NDArray[np.float64]
    omega: npt.NDArray[np.float64]
    theta0: float

    def signals(self) -> tuple[npt.NDArray[np.float64], ...]:
        return self.v_alpha, self.v_beta, self.i_alpha, self.i_beta


def synthetic_recording(
    omega: npt.NDArray[np.float64],
    i_d: float = 0.0,
    i_q: float = 10.0,
    theta0: float = 0.3,
    *,
    rs: float = RS,
    ld: float = LQ,
    lq: float = LQ,
    flux: float = FLUX,
) -> Recording:
    """The signals for electrical speed `omega[k]` (rad/s) at every sample k, on a motor with
    `rs`, `ld`, `lq`, `flux` (default: the paper's)."""
    theta_ext = theta0 + TS * np.concatenate(([0.0], np.cumsum(omega)))  # θ[-1], θ[0], ...
    rotor = np.exp(1j * theta_ext)
    i_ext = (i_d + 1j * i_q) * rotor
    flux_ext = (flux + ld * i_d + 1j * lq * i_q) * rotor
    i_now, i_prev = i_ext[1:], i_ext[:-1]
    v = np.diff(flux_ext) / TS + rs * 0.5 * (i_now + i_prev)
    # The estimator has no remembered current on its first sample and uses i[0] alone.
    v[0] += rs * 0.5 * (i_now[0] - i_prev[0])
    return Recording(
        v_alpha=np.ascontiguousarray(v.real),
        v_beta=np.ascontiguousarray(v.imag),
        i_alpha=np.ascontiguousarray(i_now.real),
        i_beta=np.ascontiguousarray(i_now.imag),
        theta=np.angle(np.exp(1j * theta_ext[1:])),
        omega=omega,
        theta0=float(theta_ext[0]),
    )


def ramp_then_hold(n: int, f_final_hz: float, ramp_s: float) -> npt.NDArray[np.float64]:
    """Electrical speed ramping from 0 to `f_final_hz` in `ramp_s`, then constant."""
    t = np.arange(n) * TS
    return 2.0 * np.pi * f_final_hz * np.minimum(t / ramp_s, 1.0)


@pytest.fixture(scope="session")
def spin_up() -> Recording:
    """2 s: 0 → 20 Hz electrical in 0.3 s under 10 A of q current (crosses both modes)."""
    return synthetic_recording(ramp_then_hold(20_000, 20.0, 0.3))
