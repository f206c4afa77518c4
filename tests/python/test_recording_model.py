"""`fado.estimate` checks a recording against its machine's voltage equation before the replay
(crates/fado-py/src/recording_model.rs): a recording whose currents have the wrong sign or whose
voltage and current columns are exchanged is named with that slip; a valid one, whatever it
does (forward, backward, reversing, salient, in the simulated drive's closed loop), is not."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import fado
from conftest import ramp_then_hold, synthetic_recording
from test_estimate import ipmsm_recording

IPM = fado.Machine.preset("ipmsm-2k2")
SLIPS = {
    "currents negated": (lambda v_a, v_b, i_a, i_b: (v_a, v_b, -i_a, -i_b), "sign reversed"),
    "columns exchanged": (lambda v_a, v_b, i_a, i_b: (i_a, i_b, v_a, v_b), "columns exchanged"),
}


def _quiet(signals, machine, ts=1e-4) -> fado.EstimateResult:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return fado.estimate(*signals, machine=machine, ts=ts)


def _cases() -> list[tuple[str, tuple[np.ndarray, ...], str | fado.Machine]]:
    paper = synthetic_recording(ramp_then_hold(20_000, 20.0, 0.3))
    backwards = synthetic_recording(-ramp_then_hold(20_000, 20.0, 0.3), i_q=-10.0)
    return [
        ("paper spin-up", paper.signals(), "paper"),
        ("paper backwards", backwards.signals(), "paper"),
        ("ipmsm i_d = 0", ipmsm_recording(IPM, 0.0).signals(), "ipmsm-2k2"),
        ("ipmsm i_d = -0.5", ipmsm_recording(IPM, -0.5).signals(), "ipmsm-2k2"),
    ]


def _drive_replay() -> tuple[np.ndarray, ...]:
    """The estimator's inputs of the simulated drive's Fig. 9 (−300 r/min throughout, averaged
    inverter), one sample of computational delay as in test_simulate.py."""
    result = fado.simulate("fig9", {"simulation": {"decimation": 1}}, averaged=True)
    tr = result.traces

    def delayed(x: np.ndarray) -> np.ndarray:
        return np.ascontiguousarray(np.concatenate(([0.0, 0.0], x[:-2])))

    return (
        delayed(tr["v_alpha_ref"]),
        delayed(tr["v_beta_ref"]),
        np.ascontiguousarray(tr["i_alpha"]),
        np.ascontiguousarray(tr["i_beta"]),
    )


@pytest.mark.parametrize("case", range(4))
@pytest.mark.parametrize("slip", sorted(SLIPS))
def test_a_slipped_recording_is_named_and_a_valid_one_is_not(case: int, slip: str) -> None:
    name, signals, machine = _cases()[case]
    _quiet(signals, machine)
    change, match = SLIPS[slip]
    with pytest.warns(UserWarning, match=match):
        fado.estimate(*change(*signals), machine=machine, ts=1e-4)


def test_the_drive_replay_of_fig9_is_valid_and_its_slips_are_named() -> None:
    signals = _drive_replay()
    _quiet(signals, "paper")
    for change, match in SLIPS.values():
        with pytest.warns(UserWarning, match=match):
            fado.estimate(*change(*signals), machine="paper", ts=1e-4)


def test_alpha_and_beta_swapped_are_a_motor_turning_the_other_way() -> None:
    """Conjugating every signal maps the machine's equations onto themselves with θ → −θ: the
    swapped recording is a valid recording of the motor turning backwards, and its estimate runs
    backwards (no check on the recording alone can tell; the module documentation says why)."""
    rec = synthetic_recording(ramp_then_hold(20_000, 20.0, 0.3))
    swapped = (rec.v_beta, rec.v_alpha, rec.i_beta, rec.i_alpha)
    forward = _quiet(rec.signals(), "paper")
    backward = _quiet(swapped, "paper")
    assert np.mean(forward.omega[-5000:]) > 0.0 > np.mean(backward.omega[-5000:])


def test_one_pair_of_columns_swapped_is_named() -> None:
    """The currents' α and β exchanged with the voltages as given (or the reverse) break the
    voltage equation, which the swap undone restores."""
    rec = synthetic_recording(ramp_then_hold(20_000, 20.0, 0.3))
    _quiet(rec.signals(), "paper")
    for signals, match in [
        ((rec.v_alpha, rec.v_beta, rec.i_beta, rec.i_alpha), "`i_alpha` and `i_beta` exchanged"),
        ((rec.v_beta, rec.v_alpha, rec.i_alpha, rec.i_beta), "`v_alpha` and `v_beta` exchanged"),
    ]:
        with pytest.warns(UserWarning, match=match):
            fado.estimate(*signals, machine="paper", ts=1e-4)


def test_another_machines_recording_is_named() -> None:
    """The IPMSM's recording replayed on the paper's motor misfits every reading: the warning
    says the recording contradicts the machine it is replayed on."""
    signals = ipmsm_recording(IPM, 0.0).signals()
    with pytest.warns(UserWarning, match="nor with its columns' sign or order changed"):
        fado.estimate(*signals, machine="paper", ts=1e-4)
