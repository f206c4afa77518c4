#!/usr/bin/env python3
"""Saturated machines of motulator's own magnetic models, simulated by motulator and replayed
through `fado.estimate`.

motulator (Aalto-Electric-Drives/motulator 0.18, MIT licence, `pip install motulator==0.18.*`,
Python >= 3.12) models a saturated synchronous machine by its current map i(ψ): the algebraic
models `SaturationModelSyRM` (Hinkkanen et al., IEEE TIA 53(3) 2017) and
`SaturationModelPMSyRM` (the magnet as the Norton source ψn of a saturating rib, Lelli et al.,
ICEM 2024). The machines below are none of fado's presets or test machines, each of another
class: a small high-saliency IPMSM (1 kW), a PM-SyRM with other coefficients than the Baldor
preset's, an SPMSM whose d axis alone saturates, a large traction IPMSM (60 kW), and a SyRM
without a magnet. Every coefficient is made up (tuned only to give each class's inductances and
ratings); the model forms and their code are motulator's.

`maps DIR` writes each machine's flux map ψ(i) as fado's CSV (`i_d,i_q,psi_d,psi_q`, rotor
frame, d on the magnet; each node the exact inverse of motulator's i(ψ) by a root solve) on a
13 × 17 grid over i_d ∈ [−2, 1] × rated, i_q ∈ [−2, 2] × rated, and its fado-sim TOML (the
plant's model under `[motor.saturation]`, the same coefficients). motulator's SyRM puts d on
its high-permeance axis; fado puts d where a magnet goes, so its axes are swapped.

`replay` simulates each machine in motulator (`model.Drive`: its machine model integrating ψ
with i = i(ψ), a ZOH-averaged inverter, one sample of computational delay; a sensored
`CurrentVectorController` with motulator's own MTPA reference generator and current
controller, 100 µs sampling) through fado-sim's ratings-scaled `reversal` (0 → −6 % of rated
speed, the load to a share of rated torque over [1.2 s, 1.7 s], the reversal to +6 % at 6 % of
rated speed per second), the no-load injection of fado's drive added to the current reference
(|i_d| raised to √(I_min² − i_q²), I_min 18.4 % of rated current, along +d), and replays the
realized voltage and the measured current through `fado.estimate` with the machine's flux map
and the default tuning (R̂s adaptation on). It prints max |θ − θ̂| where |n| < 2 % of rated
speed after 2 s, and R̂s/Rs's range after 1 s; `--out DIR` keeps each run's signals
(`NAME-LOAD.npz`), `--reuse` replays them again.

`coupling` prints each magnet machine's frame coupling |s|/κ on its MTPA curve
(`fado_core::active_flux`'s formula from motulator's model).

Usage: python3 scripts/motulator-machines.py maps DIR
       python3 scripts/motulator-machines.py coupling [--load 0.3 0.65 1.0]
       python3 scripts/motulator-machines.py replay [--machine NAME ...] [--load 0 0.3 ...]
                                            [--out DIR [--reuse]]
(`replay` needs motulator and the `fado` package in one Python >= 3.12 environment.)
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import flux_map_csv  # noqa: E402

TS = 1e-4
I_MIN_RATIO = 0.1836521739130435  # fado's drive: I_min of eq. (23), a share of rated current


@dataclass
class Machine:
    """A machine of motulator's algebraic models: `kind` "pmsyrm" (SaturationModelPMSyRM) or
    "syrm" (SaturationModelSyRM, axes swapped into fado's frame), its coefficients in
    motulator's names, and its ratings (A peak, r/min, N·m)."""

    name: str
    title: str
    kind: str
    coef: dict
    rs: float
    pole_pairs: int
    rated_current: float
    rated_speed_rpm: float
    rated_torque: float
    dc_voltage: float
    inertia: float

    def model(self):
        from motulator.drive.utils import SaturationModelPMSyRM, SaturationModelSyRM

        cls = SaturationModelPMSyRM if self.kind == "pmsyrm" else SaturationModelSyRM
        return cls(**self.coef)

    def current(self, psi: complex) -> complex:
        """i(ψ) in fado's frame (d on the magnet or on the low-permeance axis)."""
        if self.kind == "syrm":
            i = complex(self.model()(psi.imag + 1j * psi.real))
            return i.imag + 1j * i.real
        return complex(self.model()(psi))

    def current_map(self, psi):
        """motulator's i(ψ) in fado's frame (d on the magnet or on the low-permeance axis),
        scalars or arrays of ψd + jψq."""
        model = self.model()
        if self.kind == "syrm":
            psi = np.asarray(psi)
            i = np.asarray(model(psi.imag + 1j * psi.real))
            return i.imag + 1j * i.real
        return np.asarray(model(psi))

    def current(self, psi_d: float, psi_q: float) -> tuple[float, float]:
        """i(ψ) as (i_d, i_q) (the plant's hot path)."""
        i = complex(self.current_map(psi_d + 1j * psi_q))
        return i.real, i.imag

    def flux_array(self, i) -> np.ndarray:
        """ψ(i) in fado's frame, element-wise: Newton's method on motulator's i(ψ) (numerical
        Jacobian, steps limited to 0.02 Vs + 30 %), followed from zero current along 32 steps
        of i, to 1e-9 of rated current."""
        i = np.atleast_1d(np.asarray(i, complex))
        psi = np.full(i.shape, self._zero_flux(), complex)
        for step in range(1, 33):
            goal = i * step / 32
            for _ in range(60):
                f = self.current_map(psi) - goal
                if np.max(np.abs(f)) < 1e-9 * self.rated_current:
                    break
                h = 1e-7 * (1e-3 + np.abs(psi))
                fd = (self.current_map(psi + h) - goal - f) / h
                fq = (self.current_map(psi + 1j * h) - goal - f) / h
                det = fd.real * fq.imag - fq.real * fd.imag
                sd = (fq.imag * f.real - fq.real * f.imag) / det
                sq = (-fd.imag * f.real + fd.real * f.imag) / det
                size = np.abs(sd) + np.abs(sq)
                scale = np.minimum(1.0, (0.02 + 0.3 * np.abs(psi)) / (1e-30 + size))
                psi = psi - scale * (sd + 1j * sq)
            else:
                raise RuntimeError(f"{self.name}: ψ(i) did not converge")
        return psi

    def flux(self, i_d, i_q=None):
        """ψ(i): `flux(i)` with i = i_d + j·i_q a complex scalar gives a complex ψ;
        `flux(i_d, i_q)` with arrays gives (ψd, ψq) (the interface of
        scripts/saturated-replay.py's machines)."""
        if i_q is None:
            return complex(self.flux_array(i_d)[0])
        i_d, i_q = np.broadcast_arrays(np.asarray(i_d, float), np.asarray(i_q, float))
        psi = self.flux_array((i_d + 1j * i_q).ravel()).reshape(i_d.shape)
        return psi.real, psi.imag

    def torque(self, i_d, i_q):
        pd, pq = self.flux(i_d, i_q)
        return 1.5 * self.pole_pairs * (pd * i_q - pq * i_d)

    def _zero_flux(self) -> float:
        """ψd where i(ψd, 0) = 0 (the magnet's flux; 0 without a magnet)."""
        if self.current(0.0, 0.0)[0] == 0.0:
            return 0.0
        lo, hi = 0.0, 10.0
        for _ in range(100):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if self.current(mid, 0.0)[0] < 0.0 else (lo, mid)
        return 0.5 * (lo + hi)

    def zero_current(self) -> tuple[float, float, float]:
        """λ = ψd(0, 0), the incremental L_d and L_q at zero current."""
        h = 1e-4 * self.rated_current
        lam = self.flux(0j).real
        ld = (self.flux(h).real - self.flux(-h).real) / (2 * h)
        lq = (self.flux(1j * h).imag - self.flux(-1j * h).imag) / (2 * h)
        return lam, ld, lq

    def axes(self, nd: int = 13, nq: int = 17) -> tuple[np.ndarray, np.ndarray]:
        r = self.rated_current
        return np.linspace(-2 * r, r, nd), np.linspace(-2 * r, 2 * r, nq)

    def tabulate(self, nd: int = 13, nq: int = 17) -> tuple[np.ndarray, ...]:
        """ψ(i) on the grid: the d axis, the q axis, ψd and ψq (axis 0 along i_d)."""
        d_axis, q_axis = self.axes(nd, nq)
        pd, pq = self.flux(d_axis[:, None], q_axis[None, :])
        return d_axis, q_axis, pd, pq


HINKKANEN = ("Hinkkanen, Pescetto, Mölsä, Saarakkala, Pellegrino, Bojoi, IEEE TIA 53(3) 2017, "
             "https://doi.org/10.1109/TIA.2016.2644624")
LELLI = ("Lelli, Hinkkanen, Giulii Capponi, Proc. ICEM 2024, "
         "https://doi.org/10.1109/ICEM60801.2024.10700403")

MACHINES = [
    Machine("mot-ipm-1k1", "a made-up 1.1 kW 6-pole high-saliency IPMSM (L_q/L_d 3.2)",
            "pmsyrm", dict(a_d0=22.0, a_dd=40.0, S=4, a_q0=9.0, a_qq=250.0, T=4, a_dq=30.0,
                           U=1, V=1, psi_n=1.8693899589478546, a_b=6.0, a_bp=1.0, W=2, k_q=0.1),
            rs=2.4, pole_pairs=3, rated_current=4.0, rated_speed_rpm=1500.0, rated_torque=6.0,
            dc_voltage=540.0, inertia=3e-3),
    Machine("mot-pmsyrm-4k", "a made-up 4 kW 4-pole ferrite PM-SyRM (L_q/L_d 3.6, weak magnet)",
            "pmsyrm", dict(a_d0=6.0, a_dd=40.0, S=5, a_q0=3.5, a_qq=5.0, T=5, a_dq=40.0, U=1,
                           V=0, psi_n=0.5323338858228551, a_b=40.0, a_bp=2.0, W=2, k_q=0.2),
            rs=0.9, pole_pairs=2, rated_current=10.0, rated_speed_rpm=1500.0,
            rated_torque=16.0, dc_voltage=540.0, inertia=0.03),
    Machine("mot-spm-dsat", "a made-up 1.1 kW 8-pole SPMSM whose d axis alone saturates",
            "pmsyrm", dict(a_d0=200.0, a_dd=8e5, S=4, a_q0=400.0, a_qq=0.0, T=1, a_dq=0.0, U=1,
                           V=1, psi_n=0.24, a_b=200.0, a_bp=0.0, W=0, k_q=0.0),
            rs=0.6, pole_pairs=4, rated_current=6.0, rated_speed_rpm=3000.0, rated_torque=3.4,
            dc_voltage=320.0, inertia=4e-4),
    Machine("mot-ipm-60k", "a made-up 60 kW 8-pole traction IPMSM",
            "pmsyrm", dict(a_d0=1 / 0.14e-3 * 0.8, a_dd=1e7, S=4, a_q0=1 / 0.40e-3, a_qq=5e7,
                           T=4, a_dq=2e8, U=1, V=1, psi_n=0.46414300303748174, a_b=1e4, a_bp=2.0, W=2, k_q=0.1),
            rs=0.01, pole_pairs=4, rated_current=400.0, rated_speed_rpm=3000.0,
            rated_torque=190.0, dc_voltage=400.0, inertia=0.1),
    Machine("mot-syrm-2k2", "a made-up 2.2 kW 4-pole SyRM without a magnet", "syrm",
            dict(a_d0=25.0, a_dd=200.0, S=5, a_q0=150.0, a_qq=300.0, T=1, a_dq=500.0, U=1, V=0),
            rs=1.5, pole_pairs=2, rated_current=10.0, rated_speed_rpm=1500.0,
            rated_torque=4.5, dc_voltage=540.0, inertia=0.01),
]


def by_name(name: str) -> Machine:
    return next(m for m in MACHINES if m.name == name)


def mtpa_torque(m: Machine, current: float) -> float:
    """The largest torque at |i| = `current` (1.5·p·(ψd·i_q − ψq·i_d), 0.5° steps)."""
    beta = np.radians(np.arange(0.0, 89.0, 0.5))
    return float(np.max(m.torque(-current * np.sin(beta), current * np.cos(beta))))


def toml_text(m: Machine, csv_name: str) -> str:
    """fado-sim's TOML of the machine: the plant's model under [motor.saturation] (the same
    coefficients; for the SyRM the swapped axes), the drive's model the flux map."""
    lam, ld, lq = m.zero_current()
    c = dict(m.coef)
    if m.kind == "syrm":  # d ↔ q with their exponents (the cross term's U ↔ V)
        c = dict(a_d0=c["a_q0"], a_dd=c["a_qq"], S=c["T"], a_q0=c["a_d0"], a_qq=c["a_dd"],
                 T=c["S"], a_dq=c["a_dq"], U=c["V"], V=c["U"])
    sat = dict(a_d0=c["a_d0"], a_dd=c["a_dd"], s=c["S"], a_q0=c["a_q0"], a_qq=c["a_qq"],
               t=c["T"], a_dq=c["a_dq"], u=c["U"], v=c["V"], psi_f=0.0,
               psi_n=c.get("psi_n", 0.0), a_b=c.get("a_b", 0.0), a_bp=c.get("a_bp", 0.0),
               w=c.get("W", 2.0), k_q=c.get("k_q", 0.0))
    i_q = m.rated_current
    lqs = m.flux(1j * i_q).imag / i_q
    form = "SaturationModelSyRM, axes swapped" if m.kind == "syrm" else "SaturationModelPMSyRM"
    lines = [
        f"# {m.name}: {m.title}, {m.rated_torque:g} N·m, {m.rated_speed_rpm:g} r/min, "
        f"{m.dc_voltage:g} V",
        "#",
        "# A test machine, not a product: generated by scripts/motulator-machines.py from",
        f"# motulator 0.18's {form} (model of "
        + (HINKKANEN if m.kind == "syrm" else LELLI) + ")",
        "# with made-up coefficients (motulator's names: "
        + ", ".join(f"{k}={v:g}" for k, v in m.coef.items()) + ").",
        f"# At zero current ψd = {lam:.4f} Vs, incremental Ld = {ld * 1e3:.4g} mH, "
        f"Lq = {lq * 1e3:.4g} mH; the secant Lq at rated i_q is {lqs * 1e3:.4g} mH;",
        f"# the MTPA torque at rated current is {mtpa_torque(m, m.rated_current):.3g} N·m.",
        f"# [model] flux_map: the exact inverse of motulator's i(ψ) on a 13 × 17 grid "
        f"({csv_name}).",
        "[motor]",
        f"rs = {m.rs:g}",
        f"ld = {ld:.6g}",
        f"lq = {lq:.6g}",
        f"flux_linkage = {lam:.6g}",
        f"pole_pairs = {m.pole_pairs}",
        f"inertia = {m.inertia:g}",
        f"rated_current = {m.rated_current:g}",
        f"rated_speed_rpm = {m.rated_speed_rpm:g}",
        f"rated_torque = {m.rated_torque:g}",
        "",
        "[motor.saturation]",
        *(f"{k} = {float(v)!r}" for k, v in sat.items()),
        "",
        "[model]",
        f'flux_map = "{csv_name}"',
        "",
        "[inverter]",
        f"dc_voltage = {m.dc_voltage:g}",
        "switching_frequency = 10000.0",
        "",
    ]
    return "\n".join(lines)


def write_maps(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    for m in MACHINES:
        d_axis, q_axis, pd, pq = m.tabulate()
        csv = out / f"{m.name}.csv"
        flux_map_csv.write(csv, [f"{m.name}: {m.title}; motulator 0.18 "
                                 f"{'SaturationModelSyRM (axes swapped)' if m.kind == 'syrm' else 'SaturationModelPMSyRM'}"
                                 f" {m.coef}",
                                 "Written by scripts/motulator-machines.py maps: each node the "
                                 "root of motulator's i(psi) = i."], d_axis, q_axis, pd, pq)
        (out / f"{m.name}.toml").write_text(toml_text(m, csv.name), encoding="utf-8")
        print(f"wrote {csv} and {m.name}.toml")


def frame_coupling(m: Machine, load: float) -> tuple[complex, float]:
    """The MTPA current of `load` × rated torque and the frame coupling |s|/κ there, with the
    formula of `fado_core::active_flux::ActiveFlux::frame_coupling` (s = (L_q,s − L_dd)·i_q +
    L_dq·i_d, κ = λa + L_qd·i_q − (L_qq − L_q,s)·i_d, L_q,s = ψq/i_q the secant, λa = ψd −
    L_q,s·i_d) from motulator's model."""
    betas = np.radians(np.arange(0.0, 89.0, 0.5))
    for a in np.linspace(0.05, 1.5, 60) * m.rated_current:
        tau = m.torque(-a * np.sin(betas), a * np.cos(betas))
        k = int(np.argmax(tau))
        if tau[k] >= load * m.rated_torque:
            break
    i = complex(-a * np.sin(betas[k]), a * np.cos(betas[k]))
    h = 1e-4 * m.rated_current
    psi, psi_d, psi_q = m.flux(i), m.flux(i + h), m.flux(i + 1j * h)
    l_dd, l_qd = (psi_d.real - psi.real) / h, (psi_d.imag - psi.imag) / h
    l_dq, l_qq = (psi_q.real - psi.real) / h, (psi_q.imag - psi.imag) / h
    l_qs = psi.imag / i.imag
    s = (l_qs - l_dd) * i.imag + l_dq * i.real
    kappa = psi.real - l_qs * i.real + l_qd * i.imag - (l_qq - l_qs) * i.real
    return i, abs(s) / kappa


def profile(points: list[tuple[float, float]], t: float) -> float:
    xs, ys = zip(*points)
    return float(np.interp(t, xs, ys))


def simulate_motulator(m: Machine, load: float,
                       duration: float = 5.5) -> dict[str, np.ndarray]:
    """motulator's drive, sensored, through fado-sim's ratings-scaled `reversal` under
    `load` × rated torque: t, v_a, v_b (the realized voltage over [n − 1, n]), i_a, i_b (at n),
    θ and ω (electrical, true) at the 100 µs samples."""
    import motulator.drive.control.sm as control
    from motulator.drive import model
    from motulator.drive.utils import MagneticModel

    d_axis, q_axis, pd, pq = m.tabulate(25, 33)
    swap = m.kind == "syrm"
    # motulator's frame (its SyRM: d on the high-permeance axis), for its plant and control.
    if swap:
        d_axis, q_axis, pd, pq = q_axis, d_axis, pq.T, pd.T
    grid_i = d_axis[:, None] + 1j * q_axis[None, :]
    flux_map = MagneticModel(i_s_dq=grid_i, psi_s_dq=pd + 1j * pq, type="flux_map")
    plant_par = model.SaturatedSynchronousMachinePars(n_p=m.pole_pairs, R_s=m.rs,
                                                      i_s_dq_fcn=m.model())
    mdl = model.Drive(model.SynchronousMachine(plant_par),
                      model.MechanicalSystem(J=m.inertia),
                      model.VoltageSourceConverter(u_dc=m.dc_voltage))
    est_par = control.SaturatedSynchronousMachinePars(n_p=m.pole_pairs, R_s=m.rs,
                                                      psi_s_dq_fcn=flux_map)
    psi_min = 0.5 * abs(m.flux(0.3 * m.rated_current + 0j)) if swap else None
    cfg = control.CurrentVectorControllerCfg(i_s_max=2 * m.rated_current, sensorless=False,
                                             T_s=TS, psi_s_min=psi_min)
    vc = control.CurrentVectorController(est_par, cfg)
    i_min = I_MIN_RATIO * m.rated_current
    plain = vc.reference_gen.compute_current_ref

    def with_injection(tau: float) -> complex:
        # fado's drive's eq. (23): |i_d| raised to √(I_min² − i_q²) along +d (fado's frame).
        i = complex(plain(tau))
        if swap:
            extra = math.sqrt(max(i_min * i_min - i.real * i.real, 0.0))
            return i.real + 1j * (i.imag + extra)
        extra = math.sqrt(max(i_min * i_min - i.imag * i.imag, 0.0))
        return i.real + extra + 1j * i.imag

    vc.reference_gen.compute_current_ref = with_injection
    ctrl = _Recording(vc, control.SpeedController(J=m.inertia, alpha_s=2 * math.pi * 4))
    w_rated_m = m.rated_speed_rpm * 2 * math.pi / 60
    n_rev = 0.06 * w_rated_m
    speed_ref = [(0.0, 0.0), (0.2, 0.0), (1.2, -n_rev), (2.5, -n_rev), (4.5, n_rev),
                 (9.9, n_rev)]
    load_ref = [(0.0, 0.0), (1.2, 0.0), (1.7, load * m.rated_torque), (9.9, load * m.rated_torque)]
    ctrl.set_speed_ref(lambda t: profile(speed_ref, t))
    mdl.mechanics.set_external_load_torque(lambda t: profile(load_ref, t))
    model.Simulation(mdl, ctrl, show_progress=False).simulate(t_stop=duration)
    rec = {k: np.array(v) for k, v in ctrl.rec.items()}
    if swap:  # back to fado's frame: θ_fado = θ_motulator + π/2 (d_fado on motulator's q)
        rec["theta"] = np.angle(np.exp(1j * (rec["theta"] + math.pi / 2)))
    # The realized voltage of the period [n, n + 1] recorded at n is fado's v over [n − 1, n]
    # at n + 1.
    for k in ("v_a", "v_b"):
        rec[k] = np.concatenate(([rec[k][0]], rec[k][:-1]))
    return rec


def simulate(m: Machine, load: float, duration: float = 5.5) -> dict[str, np.ndarray]:
    """The plant and the sensored drive of scripts/saturated-replay.py (RK4, 4 sub-steps per
    sample, fado's drive's MTPA and injection) with motulator's i(ψ) as the machine."""
    import importlib.util

    path = Path(__file__).resolve().parent / "saturated-replay.py"
    spec = importlib.util.spec_from_file_location("saturated_replay", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules["saturated_replay"] = module
    spec.loader.exec_module(module)
    return module.simulate(m, load, duration=duration)


def _recording_class():
    import motulator.drive.control.sm as control

    class Recording(control.VectorControlSystem):
        """motulator's vector control system, recording the truth at each sample."""

        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            self.rec = {k: [] for k in ("t", "v_a", "v_b", "i_a", "i_b", "theta", "omega")}
            self._mdl = None

        def get_measurement(self, mdl):
            self._mdl = mdl
            return super().get_measurement(mdl)

        def get_feedback(self, meas):
            fbk = super().get_feedback(meas)
            mdl = self._mdl
            u = complex(np.exp(1j * fbk.theta_c) * fbk.u_s_zoh)
            r = self.rec
            r["t"].append(self.t)
            r["v_a"].append(u.real)
            r["v_b"].append(u.imag)
            r["i_a"].append(meas.i_c_ab.real)
            r["i_b"].append(meas.i_c_ab.imag)
            r["theta"].append(float(np.angle(np.exp(1j * mdl.machine.state.theta_m.real))))
            r["omega"].append(mdl.machine.par.n_p * mdl.mechanics.meas_speed())
            return fbk

    return Recording


def _Recording(*args, **kwargs):
    return _recording_class()(*args, **kwargs)


def replay(fado, m: Machine, rec: dict[str, np.ndarray]) -> tuple[float, float, float]:
    """max |θ − θ̂| near zero speed after 2 s, and the range of R̂s/Rs after 1 s."""
    lam, ld, lq = m.zero_current()
    machine = fado.Machine(rs=m.rs, ld=ld, lq=lq, flux_linkage=lam, pole_pairs=m.pole_pairs,
                           inertia=m.inertia, rated_current=m.rated_current,
                           rated_speed_rpm=m.rated_speed_rpm, rated_torque=m.rated_torque,
                           dc_voltage=m.dc_voltage,
                           flux_map=tuple(np.ascontiguousarray(c.ravel()) for c in
                                          _nodes(*m.tabulate())))
    r = fado.estimate(rec["v_a"], rec["v_b"], rec["i_a"], rec["i_b"], machine=machine, ts=TS,
                      theta0=float(rec["theta"][0]))
    err = np.abs(np.angle(np.exp(1j * (rec["theta"] - np.asarray(r.theta)))))
    w_rated = m.rated_speed_rpm * 2 * math.pi / 60 * m.pole_pairs
    near = (np.abs(rec["omega"]) < 0.02 * w_rated) & (rec["t"] > 2.0)
    rs = np.asarray(r.rs_hat)[rec["t"] > 1.0] / m.rs
    return float(err[near].max()), float(rs.min()), float(rs.max())


def _nodes(d_axis, q_axis, pd, pq):
    d, q = np.meshgrid(d_axis, q_axis, indexing="ij")
    return d, q, pd, pq


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    mp = sub.add_parser("maps", help="write each machine's flux-map CSV and fado-sim TOML")
    mp.add_argument("out", type=Path)
    cp = sub.add_parser("coupling", help="the frame coupling on the MTPA curve")
    cp.add_argument("--load", nargs="*", type=float, default=[0.3, 0.65, 1.0])
    rp = sub.add_parser("replay", help="simulate in motulator, replay through fado.estimate")
    rp.add_argument("--machine", nargs="*", help="machine names (substring match)")
    rp.add_argument("--load", nargs="*", type=float, default=[0.0, 0.3, 0.65, 1.0])
    rp.add_argument("--out", type=Path, help="keep each run's signals as DIR/NAME-LOAD.npz")
    rp.add_argument("--reuse", action="store_true", help="replay the signals kept in --out")
    rp.add_argument("--plant", choices=["rk4", "motulator"], default="rk4",
                    help="rk4: saturated-replay.py's plant and drive with motulator's i(ψ); "
                         "motulator: motulator's own simulation and controller (slow)")
    rp.add_argument("--duration", type=float, default=5.5, help="seconds of `reversal`")
    rp.add_argument("--simulate-only", action="store_true",
                    help="only write the signals to --out (no fado needed)")
    args = ap.parse_args()
    if args.cmd == "maps":
        write_maps(args.out)
        return
    if args.cmd == "coupling":
        for m in MACHINES[:4]:
            cells = [f"{load:.0%} {frame_coupling(m, load)[1]:.2f}" for load in args.load]
            print(f"{m.name}: |s|/κ " + ", ".join(cells))
        return
    if args.simulate_only and args.out is None:
        sys.exit("--simulate-only writes to --out DIR")
    fado = None if args.simulate_only else __import__("fado")
    print("| machine | load | max |θ − θ̂| near zero speed (rad) | R̂s/Rs |")
    print("|---|---:|---:|---|")
    worst = 0.0
    for m in MACHINES:
        if args.machine and not any(s in m.name for s in args.machine):
            continue
        for load in args.load:
            slug = f"{m.name}-{round(load * 100)}" + ("-mot" if args.plant == "motulator" else "")
            saved = args.out / f"{slug}.npz" if args.out else None
            if saved is not None and saved.exists() and args.reuse:
                rec = dict(np.load(saved))
            else:
                run = simulate if args.plant == "rk4" else simulate_motulator
                rec = run(m, load, duration=args.duration)
                if saved is not None:
                    args.out.mkdir(parents=True, exist_ok=True)
                    np.savez(saved, **rec)
            if fado is None:
                print(f"| {m.name} | {load:.0%} | simulated: {saved} | |", flush=True)
                continue
            try:
                err, lo, hi = replay(fado, m, rec)
            except ValueError as e:
                print(f"| {m.name} | {load:.0%} | refused: {e} | |", flush=True)
                continue
            worst = max(worst, err)
            print(f"| {m.name} | {load:.0%} | {err:.3f} | {lo:.3f}–{hi:.3f} |", flush=True)
    print(f"worst {worst:.3f} rad")
    sys.exit(0 if worst < 0.25 else 1)


if __name__ == "__main__":
    main()
