#!/usr/bin/env python3
"""A battery of machines nobody gave us: motors drawn at random (seeded) over the classes users
bring, each a self-consistent datasheet, run through the ratings-scaled scenarios.

    scripts/drawn-machines.py draw DIR [--count N] [--seed S]
    scripts/drawn-machines.py run DIR [--scenarios a,b] [--seeds 1,2] [--bin PATH] [--out OUT]

`draw` writes N motor files `DIR/drawn-XX-....toml`. Each machine is drawn as its designer
would size it:

- pole pairs 1–24 (log-uniform), rated power 20 W–200 kW (log-uniform), rated electrical
  frequency 30–800 Hz, DC link 12–800 V growing with the power (8·√P V, ×/÷ 2);
- per-unit magnetics at the rated current: surface magnets (Ld = Lq, L·I/λf 0.05–0.5) or
  interior magnets (Lq/Ld 1.2–3, Ld·I/λf 0.2–0.7), copper drop Rs·I/(ω·λf) falling with the
  power (0.25 at 20 W, 0.03 at 200 kW, ×/÷ 2);
- λf from the DC link: the rated point (MTPA at rated current and speed) uses 60–85 % of the
  linear range Vdc/√3; then I from the torque, Rs, Ld, Lq from the per-unit values;
- optional saturation (`[motor.saturation]`, the magnet as a d current i_f): q
  self-saturation (secant Lq 15–45 % below its zero-current value at rated q current),
  cross-saturation (0–30 % of the zero-current 1/Lq) and d self-saturation (0–20 % of
  1/Ld), with `ld`, `lq`, `flux_linkage` the zero-current values and the rated torque the
  model's MTPA torque at rated current;
- the PWM carrier 4–40 kHz, raised to the ratings' bounds (ω·Ts ≤ 0.2, L/R ≥ 2·Ts, ripple ≤
  0.6·I); a machine that needs more than 40 kHz is drawn again;
- the inertia from the rotor's size: volume = T / (10–40 kN·m/m³), length/diameter 0.8–2.5
  (0.15–0.6 above 8 pole pairs), iron at 6,200 kg/m³, times a coupled load of 1–5×.

`run` runs every scenario at every seed on every file of DIR (`fado-sim run SCENARIO --config
FILE --out OUT/...` with the
sensor-noise seed `[current_sensor] seed = N` appended to the file, one process at a time) and prints the table of results, the
worst |θ − θ̂| and what failed; `--out` keeps the runs (default: a temporary directory).
"""

import argparse
import json
import math
import pathlib
import random
import subprocess
import sys
import tempfile

IRON_DENSITY = 6200.0  # kg/m³, a rotor's iron and magnets with its holes
MAX_CARRIER = 40e3
MIN_CARRIER = 4e3


def loguniform(rng, lo, hi):
    return math.exp(rng.uniform(math.log(lo), math.log(hi)))


def mtpa_linear(l_d, l_q):
    """Per-unit MTPA: (torque / (1.5·p·λf·I), current angle β) with i_d = −I·sin β."""
    best = (0.0, 0.0)
    for k in range(0, 901):
        beta = math.radians(k * 0.1)
        tau = math.cos(beta) + (l_q - l_d) * math.sin(beta) * math.cos(beta)
        if tau > best[0]:
            best = (tau, beta)
    return best


class Saturated:
    """The algebraic model with the magnet as a d current, U = V = 0, S = 2, T = 4."""

    def __init__(self, ld, lq, flux, current, drop_q, cross, d_share):
        self.a_dq = 2.0 * cross / (lq * flux * flux)
        self.a_q0 = (1.0 - cross) / lq
        psi_q = current * lq * (1.0 - drop_q)
        self.a_qq = (1.0 / (lq * (1.0 - drop_q)) - 1.0 / lq) / psi_q**4
        self.a_dd = d_share / (3.0 * ld * flux * flux)
        self.a_d0 = (1.0 - d_share) / ld
        self.i_f = self.a_d0 * flux + self.a_dd * flux**3

    def current(self, pd, pq):
        idd = (self.a_d0 + self.a_dd * pd * pd + 0.5 * self.a_dq * pq * pq) * pd - self.i_f
        iq = (self.a_q0 + self.a_qq * pq**4 + 0.5 * self.a_dq * pd * pd) * pq
        return idd, iq

    def flux(self, i_d, i_q, guess):
        pd, pq = guess
        for _ in range(60):
            fd, fq = self.current(pd, pq)
            fd -= i_d
            fq -= i_q
            j11 = self.a_d0 + 3.0 * self.a_dd * pd * pd + 0.5 * self.a_dq * pq * pq
            j12 = self.a_dq * pd * pq
            j22 = self.a_q0 + 5.0 * self.a_qq * pq**4 + 0.5 * self.a_dq * pd * pd
            det = j11 * j22 - j12 * j12
            dd = (j22 * fd - j12 * fq) / det
            dq = (j11 * fq - j12 * fd) / det
            pd -= dd
            pq -= dq
            if abs(dd) + abs(dq) < 1e-13 * (abs(pd) + abs(pq)):
                break
        return pd, pq

    def mtpa_torque(self, pole_pairs, current, flux, lq):
        best = 0.0
        for k in range(0, 451):
            beta = math.radians(k * 0.2)
            i_d, i_q = -current * math.sin(beta), current * math.cos(beta)
            pd, pq = self.flux(i_d, i_q, (flux, lq * i_q))
            best = max(best, 1.5 * pole_pairs * (pd * i_q - pq * i_d))
        return best

    def table(self):
        return {
            "a_d0": self.a_d0, "a_dd": self.a_dd, "s": 2.0,
            "a_q0": self.a_q0, "a_qq": self.a_qq, "t": 4.0,
            "a_dq": self.a_dq, "u": 0.0, "v": 0.0, "psi_f": 0.0, "i_f": self.i_f,
        }


def carrier_needed(omega_e, ld, lq, rs, dc, current):
    """The ratings' bounds on the carrier (fado_core::ratings): ω·Ts ≤ 0.2 with Ts = 1/(2f),
    L/R ≥ 2·Ts, ripple Vdc/(6·L·f) ≤ 0.6·I."""
    lmin = min(ld, lq)
    return max(omega_e / (2 * 0.2), rs / lmin, dc / (6 * lmin * 0.6 * current))


def time_constant_plausible(power, ld, lq, rs, current, flux, omega_e):
    """The windings' time constant min(L)/R inside the band of real machines of that power
    (fado_core::machine_checks::scale, with a 10 % margin): at most 10 ms·(P/1 kW)^0.75, and
    where (L·I/λf)·(ω·L/R) exceeds 3 at least 0.25 ms·(P/1 kW)^0.75."""
    size = (power / 1e3) ** 0.75
    tau = min(ld, lq) / rs
    product = max(ld, lq) * current / flux * omega_e * min(ld, lq) / rs
    return tau <= 0.9 * 10e-3 * size and (product <= 3 or tau >= 1.1 * 0.25e-3 * size)


def draw_one(rng):
    """One machine as a dict of keys, or None when it needs a carrier above 40 kHz."""
    power = loguniform(rng, 20.0, 2e5)
    pole_pairs = max(1, min(24, int(round(loguniform(rng, 1.0, 24.0)))))
    f_e = loguniform(rng, 30.0, 800.0)
    omega_e = 2 * math.pi * f_e
    omega_m = omega_e / pole_pairs
    torque = power / omega_m
    dc = min(800.0, max(12.0, 8.0 * math.sqrt(power) * loguniform(rng, 0.5, 2.0)))
    interior = rng.random() < 0.55
    if interior:
        ratio = rng.uniform(1.2, 3.0)
        l_d = loguniform(rng, 0.2, 0.7)
        l_q = min(1.5, ratio * l_d)
    else:
        l_d = l_q = loguniform(rng, 0.05, 0.5)
    r = 0.25 * (power / 20.0) ** -0.22 * loguniform(rng, 0.5, 2.0)
    use = rng.uniform(0.6, 0.85)
    tau, beta = mtpa_linear(l_d, l_q)
    v_pu = math.hypot(1.0 - l_d * math.sin(beta), l_q * math.cos(beta)) + r
    flux = use * dc / math.sqrt(3) / (omega_e * v_pu)
    current = torque / (1.5 * pole_pairs * flux * tau)
    rs = r * omega_e * flux / current
    ld = l_d * flux / current
    lq = l_q * flux / current
    saturation = None
    if rng.random() < (0.45 if interior else 0.15):
        sat = Saturated(
            ld, lq, flux, current,
            drop_q=rng.uniform(0.15, 0.45) if interior else rng.uniform(0.05, 0.2),
            cross=rng.uniform(0.0, 0.3) if interior else rng.uniform(0.0, 0.1),
            d_share=rng.uniform(0.0, 0.2),
        )
        torque = sat.mtpa_torque(pole_pairs, current, flux, lq)
        saturation = sat.table()
    carrier = loguniform(rng, MIN_CARRIER, MAX_CARRIER)
    need = carrier_needed(omega_e, ld, lq, rs, dc, current)
    if need > MAX_CARRIER or not time_constant_plausible(power, ld, lq, rs, current, flux, omega_e):
        return None
    carrier = math.ceil(max(carrier, need) / 1000.0) * 1000.0
    trv = loguniform(rng, 10e3, 40e3)
    aspect = loguniform(rng, 0.15, 0.6) if pole_pairs > 8 else loguniform(rng, 0.8, 2.5)
    volume = torque / trv
    radius = (volume / (2 * math.pi * aspect)) ** (1 / 3)
    length = 2 * radius * aspect
    inertia = 0.5 * IRON_DENSITY * math.pi * radius**4 * length * loguniform(rng, 1.0, 5.0)
    return {
        "class": ("ipm" if interior else "spm") + ("-sat" if saturation else ""),
        "power": power, "use": use,
        "motor": {
            "rs": rs, "ld": ld, "lq": lq, "flux_linkage": flux, "pole_pairs": pole_pairs,
            "inertia": inertia, "rated_current": current,
            "rated_speed_rpm": omega_m * 60 / (2 * math.pi), "rated_torque": torque,
        },
        "saturation": saturation,
        "inverter": {"dc_voltage": round(dc, 1), "switching_frequency": carrier},
    }


def fmt(v):
    return str(int(v)) if isinstance(v, int) else f"{v:.6g}" if abs(v) < 1e5 else f"{v:.6e}"


def toml_text(name, m, seed):
    mo = m["motor"]
    lines = [
        f"# {name}: a drawn {m['class']} machine, {m['power']:.4g} W, {mo['pole_pairs']} pole pairs,",
        f"# {m['inverter']['dc_voltage']} V link (scripts/drawn-machines.py draw, seed {seed}); the",
        f"# rated point uses {100 * m['use']:.0f} % of the link's linear range (constant inductances).",
        "[motor]",
    ]
    lines += [f"{k} = {fmt(float(v)) if k != 'pole_pairs' else v}" for k, v in mo.items()]
    if m["saturation"]:
        lines += ["", "[motor.saturation]"]
        lines += [f"{k} = {fmt(v)}" for k, v in m["saturation"].items()]
    lines += ["", "[inverter]"]
    lines += [f"{k} = {fmt(v)}" for k, v in m["inverter"].items()]
    return "\n".join(lines) + "\n"


def draw(args):
    out = pathlib.Path(args.dir)
    out.mkdir(parents=True, exist_ok=True)
    rng = random.Random(args.seed)
    k = 0
    while k < args.count:
        m = draw_one(rng)
        if m is None:
            continue
        k += 1
        mo = m["motor"]
        name = (f"drawn-{k:02d}-{m['class']}-{mo['pole_pairs']}p-"
                f"{m['inverter']['dc_voltage']:.0f}v-{m['power']:.0f}w")
        (out / f"{name}.toml").write_text(toml_text(name, m, args.seed))
        print(name)


def verdict(metrics):
    """(passed, worst angle error, what failed) from a metrics.json."""
    passed = bool(metrics.get("passed", False))
    worst = None
    for key in ("max_angle_error_zero_speed", "max_angle_error"):
        if isinstance(metrics.get(key), (int, float)):
            worst = max(worst or 0.0, metrics[key])
    failed = [f"{c.get('name', '?')} = {c.get('value', float('nan')):.3g}"
              for c in metrics.get("checks", []) if not c.get("passed", True)]
    status = metrics.get("startup", {}).get("status")
    if status and status != "ready":
        failed.append(f"start-up {status}")
    return passed, worst, failed


def run(args):
    files = sorted(pathlib.Path(args.dir).glob("*.toml"))
    root = pathlib.Path(args.out or tempfile.mkdtemp(prefix="drawn-"))
    rows = []
    for f in files:
        for scenario in args.scenarios.split(","):
            for seed in args.seeds.split(","):
                out = root / f.stem / f"{scenario}-{seed}"
                out.mkdir(parents=True, exist_ok=True)
                cfg = out / "config.toml"
                cfg.write_text(f.read_text() + f"\n[current_sensor]\nseed = {seed}\n")
                p = subprocess.run(
                    [args.bin, "run", scenario, "--config", str(cfg), "--out", str(out)],
                    capture_output=True, text=True)
                mpath = out / "metrics.json"
                if not mpath.exists():
                    err = (p.stderr.strip().splitlines() or ["?"])[-1]
                    rows.append((f.stem, scenario, seed, "REFUSED", "", err[:160]))
                else:
                    ok, worst, failed = verdict(json.loads(mpath.read_text()))
                    w = f"{worst:.3f}" if worst is not None else ""
                    rows.append((f.stem, scenario, seed, "pass" if ok else "FAIL", w,
                                 "; ".join(failed)))
                print("\t".join(rows[-1]), flush=True)
    bad = sum(r[3] != "pass" for r in rows)
    print(f"{len(rows) - bad} of {len(rows)} runs pass; runs in {root}")
    return 1 if bad else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    d = sub.add_parser("draw")
    d.add_argument("dir")
    d.add_argument("--count", type=int, default=24)
    d.add_argument("--seed", type=int, default=1)
    r = sub.add_parser("run")
    r.add_argument("dir")
    r.add_argument("--scenarios", default="loaded-start,reversal,stops,rated-reversal")
    r.add_argument("--seeds", default="1,2")
    r.add_argument("--bin", default="target/release/fado-sim")
    r.add_argument("--out")
    args = ap.parse_args()
    sys.exit(draw(args) if args.cmd == "draw" else run(args))


if __name__ == "__main__":
    main()
