#!/usr/bin/env python3
"""The start-up under a load arriving during it: a step load's arrival swept through the
start-up (offsets, angle finding, gain calibration, hold, the first moments after ready) at
0.5 and 1.0 × the rated torque, on every motor file given.

    scripts/calibration-load-sweep.py --bin BIN [--seeds 1] [--loads 0.5,1.0] [--extra TOML]
                                      FILE|DIR ...
    scripts/calibration-load-sweep.py --bin BIN --page docs/results/calibration-load.md FILE|DIR ...

`--page` runs the sweep twice, with the default drive and with the release hold armed at the
start-up's end (`[controller.release_hold] at_start = true`), and writes the Markdown page of
the pass counts per machine and phase.

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
        if abs(float(r["i_d_ref"])) + abs(float(r["i_q_ref"])) > 1e-6 or abs(float(r["i_d"])) > 0.05:
            seen_current = True
        if float(r["time"]) >= t:
            break
    return "current" if seen_current else "offsets"


def sweep(binary, files, seeds, loads, extra, log=print):
    """Runs the sweep; returns {file: {phase: [passed, total]}} and the failure lines."""
    results, failures = {}, []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        for f in files:
            base = motor_text(f)
            rated = value(base, "rated_torque")
            rpm = value(base, "rated_speed_rpm")
            pp = value(base, "pole_pairs") or 1
            if rated is None or rpm is None:
                continue
            per_phase = results.setdefault(f, {})
            for seed in seeds:
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
                        + extra
                        + "\n"
                    )

                r0, e = run(binary, config("[[0.0, 0.0]]", 1.2), tmp / f"{f.stem}-{seed}-u")
                if r0 is None:
                    log(f"{f.stem} seed {seed}: ERROR {e}")
                    continue
                m0, rows0 = r0
                ready = m0["startup"].get("ready_time") or float("nan")
                if not math.isfinite(ready):
                    log(f"{f.stem} seed {seed}: never ready unloaded")
                    continue
                ramp_at = ready + 0.3
                ok0 = judge(rows0, rpm, pp)
                if not ok0[0]:
                    log(f"{f.stem} seed {seed}: unloaded fails {ok0}")
                arrivals = [s * ready for s in SHARES] + [ready + 0.01]
                for share in loads:
                    torque = share * rated
                    for at in arrivals:
                        ph = phase_at(rows0, at, ready)
                        pts = f"[[0.0, 0.0], [{at - 1e-4:.6f}, 0.0], [{at:.6f}, {torque}]]"
                        r, e = run(binary, config(pts, ramp_at), tmp / f"{f.stem}-{seed}-{share}-{at:.4f}")
                        per_phase.setdefault(ph, [0, 0])
                        per_phase[ph][1] += 1
                        if r is None:
                            log(f"{f.stem} s{seed} load {share} at {at:.3f} ({ph}): ERROR {e}")
                            continue
                        m, rows = r
                        ok, err, back, serr = judge(rows, rpm, pp, at)
                        st = m["startup"]
                        if ok:
                            per_phase[ph][0] += 1
                        else:
                            line = (
                                f"FAIL {f.parent.name}/{f.stem} s{seed} load {share} at {at:.3f} s ({ph}, ready {ready:.3f}): "
                                f"err {err:.3f} back {back:.3f} speed_err {serr:.1f} "
                                f"[{st.get('gain_calibration')} ready {st.get('ready_time')}, moved {st.get('motion_before_ready', 0):.3f}]"
                            )
                            failures.append(line)
                            log(line)
    return results, failures


PHASES = ["offsets", "current", "ready"]


def counts(results):
    """{phase: [passed, total]} over every file, and the overall [passed, total]."""
    out = {ph: [0, 0] for ph in PHASES}
    for per_phase in results.values():
        for ph, (p, n) in per_phase.items():
            out[ph][0] += p
            out[ph][1] += n
    return out, [sum(v[0] for v in out.values()), sum(v[1] for v in out.values())]


def page(path, runs, seeds, loads):
    """Writes the Markdown page of `runs` [(label, results)]."""
    def cell(pn):
        return f"{pn[0]}/{pn[1]}" if pn[1] else "–"

    head = " | ".join(f"{label}: {ph}" for label, _ in runs for ph in PHASES)
    lines = [
        "| motor | " + head + " |",
        "|---|" + "---|" * (len(runs) * len(PHASES)),
    ]
    files = list(runs[0][1].keys())
    for f in files:
        cells = [cell(r.get(f, {}).get(ph, [0, 0])) for _, r in runs for ph in PHASES]
        lines.append(f"| {f.parent.name}/{f.stem} | " + " | ".join(cells) + " |")
    totals = []
    for label, r in runs:
        per, all_ = counts(r)
        totals.append(
            f"- {label}: **{all_[0]} of {all_[1]}** (before any current {cell(per['offsets'])}, "
            f"while the start-up drives current {cell(per['current'])}, 10 ms after ready "
            f"{cell(per['ready'])})"
        )
    text = f"""# A load arriving during the start-up

Generated by `python3 scripts/calibration-load-sweep.py --bin target/release/fado-sim --page
docs/results/calibration-load.md motors motors/saturated` (switching-resolved inverter,
sensor seeds {", ".join(map(str, seeds))}). Each motor first starts without a load, at a seeded
rotor angle, and ramps to 6 % of its rated speed from 0.3 s after it is ready; then a step load
of {" and ".join(f"{x:g}" for x in loads)} × its rated torque arrives at 5, 25, 50, 75, 90 and 97 %
of that unloaded start-up's duration, and 10 ms after ready. Each arrival is counted in the
phase the unloaded start-up is in then: before any current (the gates-off offset
calibration), while the start-up drives current (the angle finding, the gain calibration), or
after ready. A run passes when |θ − θ̂| stays below 0.25 rad over the whole run, the rotor runs
back at most 0.5 rad electrical from the load's arrival, and the end speed is within 2 % of the
rated speed of its reference. The drive is the default one, and the same drive with the
release hold armed at the start-up's end (`[controller.release_hold] at_start = true`; see
[the start-up](../method/startup.md) and its tuning docs for why it is off by default).

""" + "\n".join(totals) + "\n\n" + "\n".join(lines) + "\n"
    tmp = pathlib.Path(str(path) + ".tmp")
    tmp.write_text(text)
    tmp.replace(path)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--seeds", default="1")
    ap.add_argument("--loads", default="0.5,1.0")
    ap.add_argument("--extra", default="")
    ap.add_argument("--page", type=pathlib.Path)
    ap.add_argument("paths", nargs="+")
    a = ap.parse_args()
    files = []
    for p in map(pathlib.Path, a.paths):
        files += sorted(p.glob("*.toml")) if p.is_dir() else [p]
    loads = [float(x) for x in a.loads.split(",")]
    seeds = [int(s) for s in a.seeds.split(",")]
    if a.page:
        runs = []
        for label, extra in [
            ("default", a.extra),
            ("at_start", a.extra + "\n[controller.release_hold]\nat_start = true\n"),
        ]:
            results, _ = sweep(a.bin, files, seeds, loads, extra, log=lambda _: None)
            runs.append((label, results))
            _, all_ = counts(results)
            print(f"{label}: passed {all_[0]}/{all_[1]}", flush=True)
        page(a.page, runs, seeds, loads)
        print(f"wrote {a.page}")
        return 0
    results, _ = sweep(a.bin, files, seeds, loads, a.extra)
    per, all_ = counts(results)
    print(f"passed {all_[0]}/{all_[1]}")
    for k, (p, n) in per.items():
        print(f"  {k}: {p}/{n}")
    return 0 if all_[0] == all_[1] else 1

if __name__ == "__main__":
    sys.exit(main())
