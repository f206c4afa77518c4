#!/usr/bin/env python3
"""The release hold at a loaded start: figure and table.

Runs `fado-sim run loaded-start` on ipmsm-2k2 (seed 1) with `[controller.release_hold]` on
and off and plots, around the brake's release, the rotor's travel from its angle at the
release and the torque demand (docs/release-hold.png); then runs `loaded-start` on every
preset of motors/ for seeds 1-4 and prints a Markdown table of the backward travel after the
release, the largest |θ − θ̂| from the release on and the verdict.

Usage: python3 scripts/release-hold-figure.py [--bin target/release/fado-sim] [--out docs]
       [--no-table]
"""

import argparse
import csv
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def run(binary, config_text, out_dir):
    """Runs loaded-start with `config_text`; returns (stdout, traces rows)."""
    cfg = Path(out_dir) / "config.toml"
    cfg.write_text(config_text)
    res = subprocess.run(
        [binary, "run", "loaded-start", "--config", str(cfg), "--out", str(Path(out_dir) / "run")],
        capture_output=True, text=True, check=False,
    )
    if res.returncode not in (0, 1):
        sys.exit(f"fado-sim failed ({res.returncode}): {res.stderr}")
    with open(Path(out_dir) / "run" / "traces.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    return res.stdout, rows


def check(stdout, name):
    m = re.search(re.escape(name) + r"\s+(\S+)\s+≤", stdout)
    return float(m.group(1)) if m else float("nan")


def figure(binary, out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    motor = (ROOT / "motors" / "ipmsm-2k2.toml").read_text()
    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(7, 5))
    for enabled, style in ((False, "--"), (True, "-")):
        text = motor + f"\n[controller.release_hold]\nenabled = {str(enabled).lower()}\n"
        with tempfile.TemporaryDirectory() as tmp:
            _, rows = run(binary, text, tmp)
        t = [float(r["time"]) for r in rows]
        theta = [float(r["theta"]) for r in rows]
        # The release: the first sample the rotor moves.
        k0 = next(i for i in range(1, len(theta)) if theta[i] != theta[0])
        t0 = t[k0 - 1]
        sel = [i for i in range(len(t)) if t0 - 0.01 <= t[i] <= t0 + 0.25]
        travel, unwrapped = [], 0.0
        for i in sel:
            step = theta[i] - theta[i - 1]
            step = (step + 3.141592653589793) % 6.283185307179586 - 3.141592653589793
            unwrapped += step if t[i] > t0 else 0.0
            travel.append(unwrapped)
        label = "release hold" if enabled else "without"
        ax1.plot([t[i] - t0 for i in sel], travel, style, label=label)
        ax2.plot([t[i] - t0 for i in sel], [float(rows[i]["i_q_ref"]) for i in sel], style, label=label)
    ax1.axhline(-0.5, color="grey", lw=0.8)
    ax1.set_ylabel("rotor travel (rad, electrical)")
    ax1.set_ylim(-3, 0.5)
    ax1.legend()
    ax2.set_ylabel("i_q* (A)")
    ax2.set_xlabel("time from the release (s)")
    fig.suptitle("ipmsm-2k2, loaded-start (seed 1): the rated torque from the release on")
    fig.tight_layout()
    path = Path(out) / "release-hold.png"
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


def table(binary):
    print("| preset | seed | backward travel (rad) | max abs(θ − θ̂) (rad) | passed |")
    print("|---|---|---|---|---|")
    for motor in sorted((ROOT / "motors").glob("*.toml")):
        for seed in (1, 2, 3, 4):
            text = motor.read_text() + f"\n[current_sensor]\nseed = {seed}\n"
            with tempfile.TemporaryDirectory() as tmp:
                stdout, _ = run(binary, text, tmp)
            back = check(stdout, "backward travel from t = 0 (rad)")
            err = check(stdout, "max |θ − θ̂| from ready on (rad)")
            passed = "PASSED              true" in stdout
            print(f"| {motor.stem} | {seed} | {back:.3f} | {err:.3f} | {passed} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bin", default=str(ROOT / "target" / "release" / "fado-sim"))
    ap.add_argument("--out", default=str(ROOT / "docs"))
    ap.add_argument("--no-table", action="store_true")
    args = ap.parse_args()
    figure(args.bin, args.out)
    if not args.no_table:
        table(args.bin)


if __name__ == "__main__":
    main()
