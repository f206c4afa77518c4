#!/usr/bin/env python3
"""The scenario-results table of crates/fado-sim/README.md, measured on the current code.

Runs `fado-sim run <scenario>` (release build) for fig8-fig12, switching-resolved and averaged,
default non-idealities and matched models, seed 1, and prints the Markdown table from each
run's metrics.json. Usage: python3 scripts/scenario-table.py [--out DIR]
"""

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCENARIOS = ["fig8", "fig9", "fig10", "fig11", "fig12"]


def run(binary: Path, scenario: str, averaged: bool, out: Path) -> dict:
    cmd = [str(binary), "run", scenario, "--out", str(out)]
    if averaged:
        cmd.append("--averaged")
    # Exit 1 = ran but failed its criteria: still a row.
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode not in (0, 1):
        sys.exit(f"{' '.join(cmd)} failed ({done.returncode}): {done.stderr.strip()}")
    return json.loads((out / "metrics.json").read_text())


def checks(m: dict) -> str:
    parts = []
    for c in m["checks"]:
        if c["name"] == "tripped":
            continue
        name = c["name"].replace("|", "\\|")
        fail = "" if c["passed"] else " **FAIL**"
        parts.append(f"{name} = {c['value']:.4g}{fail}")
    return "; ".join(parts)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, help="keep the runs' outputs here (default: a temporary directory)")
    args = ap.parse_args()
    subprocess.run(["cargo", "build", "--release", "-q", "-p", "fado-sim"], cwd=ROOT, check=True)
    binary = ROOT / "target" / "release" / "fado-sim"
    with tempfile.TemporaryDirectory() as tmp:
        base = args.out or Path(tmp)
        print("| scenario | inverter | passed | max err | rms err | max err near 0 | rms near 0 "
              "| max speed err | simulated | wall | checks |")
        print("|---|---|---|---|---|---|---|---|---|---|---|")
        for averaged in (False, True):
            for s in SCENARIOS:
                inv = "averaged" if averaged else "switching"
                m = run(binary, s, averaged, base / f"{s}-{inv}")
                print(f"| {s} | {inv} | {'yes' if m['passed'] else '**no**'} "
                      f"| {m['max_angle_error']:.3f} | {m['rms_angle_error']:.3f} "
                      f"| {m['max_angle_error_zero_speed']:.3f} | {m['rms_angle_error_zero_speed']:.3f} "
                      f"| {m['max_speed_error_rpm']:.1f} | {m['simulated_seconds']:.1f} "
                      f"| {m['wall_seconds']:.3f} | {checks(m)} |")


if __name__ == "__main__":
    main()
