#!/usr/bin/env python3
"""Consistency check of the motor presets in motors/*.toml (standard library only, Python 3.11+).

For every preset it checks the schema (exact key set, first line "# <name>: <source>") and
the physics that unit slips break, then prints one table row:

  T_model   torque the linear model gives at rated current: 1.5·p·λf·I for Ld = Lq; for a
            salient rotor the MTPA torque 1.5·p·(λf·iq + (Ld − Lq)·id·iq) with
            id = (λf − √(λf² + 8·(Lq − Ld)²·I²)) / (4·(Lq − Ld)), iq = √(I² − id²).
            Check: 0.7 ≤ T_rated / T_model ≤ 1.5.
  E/Vmax    back-EMF at rated speed ω·λf over the largest phase voltage of the DC link,
            Vdc/√3 (space-vector modulation). Check: < 1.
  |v|/Vmax  steady-state voltage at rated speed and current (MTPA currents, R and L drops)
            over Vdc/√3; reported, flagged with '!' above 1 (field weakening would be needed).
  L/R       electrical time constants Ld/R and Lq/R (ms) and Lq/R in samples of Ts.
  ω·Ts      rated electrical speed times the sampling period Ts = 1/(2·f_sw) (the drive
            samples at twice the switching frequency). Check: ≤ 0.3.

Usage: python3 scripts/check_motor_presets.py [motors-dir]   (exit status 1 on any failure)
"""

from __future__ import annotations

import math
import sys
import tomllib
from pathlib import Path

MOTOR_KEYS = {
    "rs",
    "ld",
    "lq",
    "flux_linkage",
    "pole_pairs",
    "inertia",
    "viscous_friction",
    "rated_current",
    "rated_speed_rpm",
    "rated_torque",
}
INVERTER_KEYS = {"dc_voltage", "switching_frequency"}

TORQUE_RATIO = (0.7, 1.5)
MAX_OMEGA_TS = 0.3


def mtpa_currents(m: dict, i: float) -> tuple[float, float]:
    """(id, iq) of the maximum-torque-per-ampere point at current magnitude i (A peak)."""
    dl = m["lq"] - m["ld"]
    lam = m["flux_linkage"]
    if abs(dl) < 1e-12 * max(m["ld"], m["lq"]):
        return 0.0, i
    i_d = (lam - math.sqrt(lam * lam + 8.0 * dl * dl * i * i)) / (4.0 * dl)
    return i_d, math.sqrt(max(i * i - i_d * i_d, 0.0))


INVERTER_OPTIONAL_KEYS = {"dead_time", "threshold_voltage", "current_band"}
# A saturated machine (motors/saturated/) adds its magnetic model: `[motor.saturation]` or
# `flux_map`; its ld, lq, flux_linkage are the model's zero-current values, which the rows
# below evaluate (docs/method/saturation.md).
MOTOR_MAGNETICS_KEYS = {"saturation", "flux_map"}


def torque(m: dict, i_d: float, i_q: float) -> float:
    """Electromagnetic torque (amplitude-invariant dq): 1.5·p·(λf·iq + (Ld − Lq)·id·iq)."""
    p = m["pole_pairs"]
    return 1.5 * p * (m["flux_linkage"] * i_q + (m["ld"] - m["lq"]) * i_d * i_q)


def check(path: Path) -> tuple[dict, list[str]]:
    errors: list[str] = []
    text = path.read_text(encoding="utf-8")
    first = text.splitlines()[0] if text else ""
    name = path.stem
    if not first.startswith(f"# {name}: ") or len(first) <= len(f"# {name}: ") + 10:
        errors.append(f"first line must be '# {name}: <source ...>'")
    doc = tomllib.loads(text)
    if set(doc) != {"motor", "inverter"}:
        errors.append(f"sections {sorted(doc)} != ['inverter', 'motor']")
    m = doc.get("motor", {})
    inv = doc.get("inverter", {})
    for section, got, want in (("motor", m, MOTOR_KEYS), ("inverter", inv, INVERTER_KEYS)):
        # A MOSFET inverter may state its own dead time and knee voltage (the 24/48 V presets).
        optional = INVERTER_OPTIONAL_KEYS if section == "inverter" else MOTOR_MAGNETICS_KEYS
        if not want <= set(got) <= want | optional:
            missing, extra = sorted(want - set(got)), sorted(set(got) - want - optional)
            errors.append(f"[{section}] missing {missing} extra {extra}")
    if errors:
        return {"name": name}, errors
    for key, value in {**m, **inv}.items():
        if key in MOTOR_MAGNETICS_KEYS:
            continue
        if key == "viscous_friction":
            ok = value >= 0
        elif key == "pole_pairs":
            ok = isinstance(value, int) and value >= 1
        else:
            ok = isinstance(value, (int, float)) and math.isfinite(value) and value > 0
        if not ok:
            errors.append(f"{key} = {value!r} out of range")
    if errors:
        return {"name": name}, errors

    p = m["pole_pairs"]
    i_rated = m["rated_current"]
    w_mech = m["rated_speed_rpm"] * 2.0 * math.pi / 60.0
    w_el = p * w_mech
    ts = 0.5 / inv["switching_frequency"]
    v_max = inv["dc_voltage"] / math.sqrt(3.0)

    i_d, i_q = mtpa_currents(m, i_rated)
    t_model = torque(m, i_d, i_q)
    ratio = m["rated_torque"] / t_model
    emf = w_el * m["flux_linkage"]
    v_d = m["rs"] * i_d - w_el * m["lq"] * i_q
    v_q = m["rs"] * i_q + w_el * (m["ld"] * i_d + m["flux_linkage"])
    v_mag = math.hypot(v_d, v_q)
    tau_d, tau_q = m["ld"] / m["rs"], m["lq"] / m["rs"]
    w_ts = w_el * ts

    if not TORQUE_RATIO[0] <= ratio <= TORQUE_RATIO[1]:
        errors.append(f"rated torque / model torque = {ratio:.2f} outside {TORQUE_RATIO}")
    if emf >= v_max:
        errors.append(f"back-EMF {emf:.1f} V at rated speed >= Vdc/√3 = {v_max:.1f} V")
    if w_ts > MAX_OMEGA_TS:
        errors.append(f"ω_rated·Ts = {w_ts:.3f} > {MAX_OMEGA_TS}")

    row = {
        "name": name,
        "p": p,
        "lq_ld": m["lq"] / m["ld"],
        "id": i_d,
        "t_model": t_model,
        "t_rated": m["rated_torque"],
        "ratio": ratio,
        "emf": emf,
        "emf_ratio": emf / v_max,
        "v_ratio": v_mag / v_max,
        "tau_d_ms": tau_d * 1e3,
        "tau_q_ms": tau_q * 1e3,
        "tau_q_ts": tau_q / ts,
        "f_el": w_el / (2.0 * math.pi),
        "w_ts": w_ts,
        "vdc": inv["dc_voltage"],
    }
    return row, errors


def main() -> int:
    root = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parent.parent / "motors"
    files = sorted(root.glob("*.toml"))
    if not files:
        print(f"no presets in {root}", file=sys.stderr)
        return 1
    header = (
        f"{'preset':<22} {'p':>2} {'Lq/Ld':>5} {'Vdc':>5} {'id_MTPA':>7} {'T_model':>7} "
        f"{'T_rated':>7} {'ratio':>5} {'E_rated':>7} {'E/Vmax':>6} {'|v|/Vmax':>8} "
        f"{'Ld/R ms':>7} {'Lq/R ms':>7} {'Lq/R/Ts':>7} {'f_el Hz':>7} {'w*Ts':>6}  ok"
    )
    print(header)
    print("-" * len(header))
    failed = False
    for path in files:
        row, errors = check(path)
        if "t_model" in row:
            flag = "!" if row["v_ratio"] > 1.0 else " "
            print(
                f"{row['name']:<22} {row['p']:>2} {row['lq_ld']:>5.2f} {row['vdc']:>5.0f} "
                f"{row['id']:>7.2f} {row['t_model']:>7.2f} {row['t_rated']:>7.2f} "
                f"{row['ratio']:>5.2f} {row['emf']:>7.1f} {row['emf_ratio']:>6.2f} "
                f"{row['v_ratio']:>7.2f}{flag} {row['tau_d_ms']:>7.2f} {row['tau_q_ms']:>7.2f} "
                f"{row['tau_q_ts']:>7.1f} {row['f_el']:>7.1f} {row['w_ts']:>6.3f}  "
                f"{'yes' if not errors else 'NO'}"
            )
        else:
            print(f"{row['name']:<22} (not evaluated)  NO")
        for e in errors:
            print(f"    {path.name}: {e}")
        failed |= bool(errors)
    print(
        "\nT_model: linear-model torque at rated current (MTPA if Lq != Ld); "
        "ratio = T_rated/T_model in [0.7, 1.5]; E/Vmax = ω·λf/(Vdc/√3) < 1; "
        "|v|/Vmax: rated point incl. R, L drops ('!' > 1); w*Ts = ω_rated/(2·f_sw) <= 0.3"
    )
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
