#!/usr/bin/env python3
"""The start-up under a load arriving during it: a step load's arrival swept through the
start-up (offsets, angle finding, gain calibration, hold, the first moments after ready) at
0.5 and 1.0 × the rated torque, on every motor file given.

    scripts/calibration-load-sweep.py --bin BIN [--seeds 1] [--loads 0.5,1.0] FILE|DIR ...

Each machine first runs unloaded (`custom`: standstill, then a ramp to 6 % of its rated speed
from 0.3 s after its unloaded start-up ends, as `loaded-start`'s brake lead, over 1 s, held
0.8 s; the rotor at a seeded angle; the acceleration feed-forward of `fullrange`); the
start-up's span [0, ready] gives the arrival times (shares 0.05–0.97 of it and 10 ms after
it), each labelled with the phase the unloaded run is in then: `offsets` before any current,
`current` while the angle search or the gain calibration applies current, `ready` after. A run passes when |θ − θ̂| stays below
0.25 rad over the whole run (as `fullrange` judges), the rotor runs back at most 0.5 rad
electrical from the load's arrival (before it the start-up's alignment turns the unloaded
rotor), and the speed is within 2 % of the rated speed of its reference at the end.
Prints one line per failure and the pass counts per phase.
"""

import argparse
import csv
import json
import math
import pathlib
import re
import subprocess
import sys
import tempfile

SHARES = [0.05, 0.25, 0.5, 0.75, 0.9, 0.97]


def motor_text(path):
    text = path.read_text()
    return re.sub(
        r'(flux_map\s*=\s*")([^"/][^"]*)"',
        lambda m: f'{m.group(1)}{(path.parent / m.group(2)).resolve()}"',
        text,
    )


def value(text, key):
    m = re.search(rf"^{key}\s*=\s*([0-9.eE+-]+)", text, re.M)
    return float(m.group(1)) if m else None


def run(binary, text, out):
    cfg = out.with_suffix(".toml")
    cfg.write_text(text)
    d = subprocess.run(
        [binary, "run", "custom", "--config", str(cfg), "--out", str(out)],
        capture_output=True,
        text=True,
    )
    if d.returncode not in (0, 1):
        return None, d.stderr.strip()[:300]
    m = json.loads((out / "metrics.json").read_text())
    rows = list(csv.DictReader(open(out / "traces.csv")))
    return (m, rows), None


def judge(rows, rated_rpm, pole_pairs, at=0.0):
    err = max(abs(float(r["angle_error"])) for r in rows)
    travel, low, last = 0.0, 0.0, None
    for r in rows:
        if float(r["time"]) < at:
            continue
        th = float(r["theta"])
        if last is not None:
            d = (th - last + math.pi) % (2 * math.pi) - math.pi
            travel += d
            low = min(low, travel)
        last = th
    end = rows[-1]
    speed_err = abs(float(end["speed_rpm"]) - float(end["speed_ref_rpm"]))
    ok = err < 0.25 and -low < 0.5 and speed_err < 0.02 * rated_rpm
    return ok, err, -low, speed_err


def phase_at(rows, t, ready):
    """The unloaded run's phase at `t`: offsets (no current yet), current (the angle finding
    or the gain calibration: a current reference), or ready."""
    if t >= ready:
        return "ready"
    seen_current = False
    for r in rows:
        if abs(float(r["i_d_ref"])) + abs(float(r["i_q_ref"])) > 1e-6 or abs(float(r["i_d"])) > 0.05 * 1:
            seen_current = True
        if float(r["time"]) >= t:
            break
    return "current" if seen_current else "offsets"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--seeds", default="1")
    ap.add_argument("--loads", default="0.5,1.0")
    ap.add_argument("--extra", default="")
    ap.add_argument("paths", nargs="+")
    a = ap.parse_args()
    files = []
    for p in map(pathlib.Path, a.paths):
        files += sorted(p.glob("*.toml")) if p.is_dir() else [p]
    loads = [float(x) for x in a.loads.split(",")]
    total, passed, per_phase = 0, 0, {}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        for f in files:
            base = motor_text(f)
            rated = value(base, "rated_torque")
            rpm = value(base, "rated_speed_rpm")
            pp = value(base, "pole_pairs") or 1
            if rated is None or rpm is None:
                continue
            for seed in [int(s) for s in a.seeds.split(",")]:
                angle = (seed * 2.399963) % (2 * math.pi) - math.pi
                common = (
                    f"\n[current_sensor]\nseed = {seed}\n"
                    if not re.search(r"^\[current_sensor\]", base, re.M)
                    else ""
                )

                def config(load_pts, ramp_at):
                    n = 0.06 * rpm
                    return (
                        base
                        + common
                        + f"\n[simulation]\ninitial_angle = {angle:.4f}\nduration = {ramp_at + 1.8:.3f}\n"
                        + "eval_start = 0.0\ndecimation = 5\n"
                        + f"[speed_reference]\npoints = [[0.0, 0.0], [{ramp_at:.3f}, 0.0], [{ramp_at + 1.0:.3f}, {n}]]\n"
                        + f"[load.torque]\npoints = {load_pts}\n"
                        + "[controller.tracker_feedforward]\nenabled = true\n"
                        + a.extra
                        + "\n"
                    )

                r0, e = run(a.bin, config("[[0.0, 0.0]]", 1.2), tmp / f"{f.stem}-{seed}-u")
                if r0 is None:
                    print(f"{f.stem} seed {seed}: ERROR {e}")
                    continue
                m0, rows0 = r0
                ready = m0["startup"].get("ready_time") or float("nan")
                if not math.isfinite(ready):
                    print(f"{f.stem} seed {seed}: never ready unloaded")
                    continue
                ramp_at = ready + 0.3
                ok0 = judge(rows0, rpm, pp)
                if not ok0[0]:
                    print(f"{f.stem} seed {seed}: unloaded fails {ok0}")
                arrivals = [s * ready for s in SHARES] + [ready + 0.01]
                for share in loads:
                    torque = share * rated
                    for at in arrivals:
                        ph = phase_at(rows0, at, ready)
                        pts = f"[[0.0, 0.0], [{at - 1e-4:.6f}, 0.0], [{at:.6f}, {torque}]]"
                        r, e = run(a.bin, config(pts, ramp_at), tmp / f"{f.stem}-{seed}-{share}-{at:.4f}")
                        total += 1
                        key = ph
                        per_phase.setdefault(key, [0, 0])
                        per_phase[key][1] += 1
                        if r is None:
                            print(f"{f.stem} s{seed} load {share} at {at:.3f} ({ph}): ERROR {e}")
                            continue
                        m, rows = r
                        ok, err, back, serr = judge(rows, rpm, pp, at)
                        st = m["startup"]
                        if ok:
                            passed += 1
                            per_phase[key][0] += 1
                        else:
                            print(
                                f"FAIL {f.parent.name}/{f.stem} s{seed} load {share} at {at:.3f} s ({ph}, ready {ready:.3f}): "
                                f"err {err:.3f} back {back:.3f} speed_err {serr:.1f} "
                                f"[{st.get('gain_calibration')} ready {st.get('ready_time')}, moved {st.get('motion_before_ready', 0):.3f}]",
                                flush=True,
                            )
    print(f"passed {passed}/{total}")
    for k, (p, n) in per_phase.items():
        print(f"  {k}: {p}/{n}")
    return 0 if passed == total else 1


if __name__ == "__main__":
    sys.exit(main())
