#!/usr/bin/env python3
"""The per-preset table of the whole operating range (docs/range.md), measured on the current
code.

Runs `fado-sim run fullrange` and `fado-sim run regen-stop` (release build, switching-resolved,
default non-idealities) for every preset of motors/ and motors/saturated/ and the current-sensor
seeds 1-4, and prints
the Markdown table: the top speed and the power held against the model's limits (`fullrange`
computes them, fado_sim::range), the largest angle error over the seeds, and which runs pass.
Usage: python3 scripts/range-table.py [--seeds 1 2 3 4] [--out DIR | --keep]
"""

import argparse
import json
import re
import subprocess
import sys
from pathlib import Path

from run_directory import add_arguments, run_directory

ROOT = Path(__file__).resolve().parent.parent
SCENARIOS = ["fullrange", "regen-stop"]


def run(binary: Path, scenario: str, config: Path, out: Path) -> dict:
    cmd = [str(binary), "run", scenario, "--config", str(config), "--out", str(out)]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode not in (0, 1):  # 1 = ran but missed a criterion: still a row
        sys.exit(f"{' '.join(cmd)} failed ({done.returncode}): {done.stderr.strip()}")
    return json.loads((out / "metrics.json").read_text())


def with_seed(preset: Path, seed: int) -> Path:
    """The preset with `[current_sensor] seed` set (merged into its own table if it has one),
    written beside the preset so that a flux map it names by a relative path resolves."""
    text = preset.read_text(encoding="utf-8")
    if re.search(r"^\[current_sensor\]", text, flags=re.M):
        text = re.sub(r"^\[current_sensor\]\n", f"[current_sensor]\nseed = {seed}\n", text,
                      count=1, flags=re.M)
    else:
        text += f"\n[current_sensor]\nseed = {seed}\n"
    path = preset.parent / f".range-table-{preset.stem}-seed{seed}.toml"
    path.write_text(text, encoding="utf-8")
    return path


def check(m: dict, prefix: str) -> dict | None:
    return next((c for c in m["checks"] if c["name"].startswith(prefix)), None)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4])
    add_arguments(ap)
    args = ap.parse_args()
    subprocess.run(["cargo", "build", "--release", "--quiet", "-p", "fado-sim", "--bin",
                    "fado-sim"], cwd=ROOT, check=True)
    binary = ROOT / "target" / "release" / "fado-sim"
    with run_directory(args.out, args.keep, "fado-range-") as work:
        table(binary, args.seeds, work)


def table(binary: Path, seeds: list[int], work: Path) -> None:
    """Runs every preset's range scenarios in `work` and prints the table."""
    print("| preset | top speed: model → reached (r/min) | power at the top: limit / held (W) "
          "| max \\|θ − θ̂\\| fullrange (rad) | fullrange passes | max \\|θ − θ̂\\| regen-stop (rad) "
          "| regen-stop passes | failed criteria |")
    print("|---|---|---|---|---|---|---|---|")
    presets = sorted((ROOT / "motors").glob("*.toml")) + sorted(
        (ROOT / "motors" / "saturated").glob("*.toml"))
    for preset in presets:
        row = {s: [] for s in SCENARIOS}
        for seed in seeds:
            cfg = with_seed(preset, seed)
            try:
                for s in SCENARIOS:
                    row[s].append(run(binary, s, cfg, work / f"{preset.stem}-{s}-seed{seed}"))
            finally:
                cfg.unlink()
        fr = row["fullrange"]
        top = check(fr[0], "mean speed at the top")
        power = check(fr[0], "power held at the top")
        model_top = re.search(r"model: (\d+)", top["name"]).group(1) if top else "?"
        limits = re.search(r"limit (\d+), rated (\d+)", power["name"]) if power else None
        reached = min(check(m, "mean speed at the top")["value"] for m in fr) if top else float("nan")
        held = min(check(m, "power held at the top")["value"] for m in fr) if power else float("nan")
        failed = sorted({f"{s}: {c['name']}" for s in SCENARIOS for m in row[s]
                         for c in m["checks"] if not c["passed"]})
        passes = {s: sum(m["passed"] for m in row[s]) for s in SCENARIOS}
        angle = {s: max(m["max_angle_error"] for m in row[s]) for s in SCENARIOS}
        n = len(seeds)
        failed_text = "; ".join(failed).replace("|", "\\|") or "—"
        name = preset.relative_to(ROOT / "motors").with_suffix("").as_posix()
        print(f"| {name} | {model_top} → {reached:.0f} | "
              f"{limits.group(1) if limits else '?'} / {held:.0f} (rated {limits.group(2) if limits else '?'}) | "
              f"{angle['fullrange']:.3f} | {passes['fullrange']}/{n} | {angle['regen-stop']:.3f} | "
              f"{passes['regen-stop']}/{n} | {failed_text} |")


if __name__ == "__main__":
    main()
