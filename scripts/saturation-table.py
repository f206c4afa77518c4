#!/usr/bin/env python3
"""The per-preset table of the saturated machines in closed loop (docs/results/saturation.md),
measured on the current code.

Runs `fado-sim run` for `reversal`, `stops` and `rated-reversal` (release build,
switching-resolved, default non-idealities) on every preset of motors/saturated/ for the
current-sensor seeds 1-4, the drive given the plant's own magnetic model (`[model]` inherits
`[motor.saturation]`), and prints the Markdown table: per preset and scenario the largest angle
error over the seeds (near zero speed for the reversals, over the run for `stops`), the largest
speed error, and how many seeds pass.
Usage: python3 scripts/saturation-table.py [--seeds 1 2 3 4] [--out DIR | --keep]
"""

import argparse
import json
import re
import subprocess
import sys
from pathlib import Path

from run_directory import add_arguments, run_directory

ROOT = Path(__file__).resolve().parent.parent
SCENARIOS = ["reversal", "stops", "rated-reversal"]


def run(binary: Path, scenario: str, config: Path, out: Path) -> dict:
    cmd = [str(binary), "run", scenario, "--config", str(config), "--out", str(out)]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode not in (0, 1):  # 1 = ran but missed a criterion: still a row
        sys.exit(f"{' '.join(cmd)} failed ({done.returncode}): {done.stderr.strip()}")
    return json.loads((out / "metrics.json").read_text())


def with_seed(preset: Path, seed: int, directory: Path) -> Path:
    """The preset with `[current_sensor] seed` set, written beside the preset's own directory
    name so that a relative `flux_map` path still resolves."""
    text = preset.read_text(encoding="utf-8")
    if re.search(r"^\[current_sensor\]", text, flags=re.M):
        text = re.sub(r"^\[current_sensor\]\n", f"[current_sensor]\nseed = {seed}\n", text,
                      count=1, flags=re.M)
    else:
        text += f"\n[current_sensor]\nseed = {seed}\n"
    text = re.sub(r'^(flux_map\s*=\s*")([^"/][^"]*)"',
                  lambda m: f'{m.group(1)}{(preset.parent / m.group(2)).resolve()}"', text,
                  flags=re.M)
    path = directory / f"{preset.stem}-seed{seed}.toml"
    path.write_text(text, encoding="utf-8")
    return path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4])
    add_arguments(ap)
    args = ap.parse_args()
    subprocess.run(["cargo", "build", "--release", "--quiet", "-p", "fado-sim", "--bin",
                    "fado-sim"], cwd=ROOT, check=True)
    binary = ROOT / "target" / "release" / "fado-sim"
    with run_directory(args.out, args.keep, "fado-saturation-") as work:
        table(binary, args.seeds, work)


def table(binary: Path, seeds: list[int], work: Path) -> None:
    """Runs every saturated preset's scenarios in `work` and prints the table."""
    print("| preset | scenario | max \\|θ − θ̂\\| (rad) | max speed error (r/min) | "
          f"seeds passing (of {len(seeds)}) |")
    print("|---|---|---|---|---|")
    for preset in sorted((ROOT / "motors" / "saturated").glob("*.toml")):
        for scenario in SCENARIOS:
            angles, speeds, passed = [], [], 0
            for seed in seeds:
                config = with_seed(preset, seed, work)
                m = run(binary, scenario, config, work / f"{preset.stem}-{scenario}-{seed}")
                key = "max_angle_error" if scenario == "stops" else "max_angle_error_zero_speed"
                trip = m["tripped"]
                angles.append(float("inf") if trip else m[key])
                speeds.append(m["max_speed_error_rpm"])
                passed += bool(m["passed"])
            worst = max(angles)
            angle = "trip" if worst == float("inf") else f"{worst:.3f}"
            print(f"| {preset.stem} | {scenario} | {angle} | {max(speeds):.1f} | {passed} |")


if __name__ == "__main__":
    main()
