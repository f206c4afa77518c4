#!/usr/bin/env bash
# Regenerates the operating-envelope figure of the fig11 reversal, R̂s error × load torque:
#   1. `fado-sim sweep fig11` over rs_error (= R̂s/(Rs+r_on) − 1) −30…+30 % in 2 % steps and,
#      zoomed, −6…+6 % in 0.25 % steps, each × load torque 0…11.5 N·m (rated) in 0.5 N·m
#      steps: 31×24 + 49×24 = 1920 runs, switching-resolved inverter unless --averaged;
#   2. docs/envelope-NAME.png (two heatmaps, fado.plot.envelope) and the two CSVs beside it.
# Sweeps are resumable: an interrupted run picks up where it stopped (out/envelope-NAME-*).
# Usage: scripts/envelope.sh [--name NAME] [fado-sim sweep options...]
#   e.g. scripts/envelope.sh --name fig11-rs-load-adaptive --config rs-adaptation.toml
#   Options after --name go to `fado-sim sweep` as they are (--config FILE, --averaged,
#   --threads N, --fresh, or a one-value --axis section.key=value to fix a setting).
# Needs: cargo; a Python with fado[plot,pandas] installed (PYTHON, default .venv/bin/python).
set -euo pipefail
cd "$(dirname "$0")/.."

name=fig11-rs-load
if [[ "${1:-}" == "--name" ]]; then
    name=$2
    shift 2
fi
python=${PYTHON:-.venv/bin/python}
[[ -x "$python" ]] || python=python3

cargo build --release -p fado-sim --bin fado-sim
target=${CARGO_TARGET_DIR:-target}
sim="$target/release/fado-sim"
loads="--axis load_torque=0:11.5:24"
"$sim" sweep fig11 --axis rs_error=-0.3:0.3:31 $loads --out "out/envelope-$name-wide" "$@"
"$sim" sweep fig11 --axis rs_error=-0.06:0.06:49 $loads --out "out/envelope-$name-zoom" "$@"

mkdir -p docs
cp "out/envelope-$name-wide/sweep.csv" "docs/envelope-$name-wide.csv"
cp "out/envelope-$name-zoom/sweep.csv" "docs/envelope-$name-zoom.csv"
"$python" - "$name" "$*" <<'PY'
import sys

import pandas as pd

import fado.plot

name, options = sys.argv[1], sys.argv[2]
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

fig = Figure(figsize=(13.0, 5.0), layout="constrained")
FigureCanvasAgg(fig)
axes = fig.subplots(1, 2)
for ax, part, title in [
    (axes[0], "wide", "R̂s error −30…+30 % (2 % steps)"),
    (axes[1], "zoom", "zoom: −6…+6 % (0.25 % steps)"),
]:
    df = pd.read_csv(f"docs/envelope-{name}-{part}.csv")
    df["rs_error_percent"] = (100 * df["rs_error"]).round(6)
    fado.plot.envelope(df, "rs_error_percent", "load_torque", ax=ax, vmax=1.0)
    ax.set_xlabel("R̂s error, R̂s/(Rs + r_on) − 1 (%)")
    ax.set_ylabel("load torque after the ramp (N·m)")
    n, ok = len(df), int(df["passed"].sum())
    ax.set_title(f"{title}: {ok} of {n} points pass", fontsize=9)
inverter = "averaged" if "--averaged" in options else "switching-resolved"
fig.suptitle(
    f"fig11 reversal (−90 → +90 r/min in 2 s under load), {inverter} inverter"
    + (f", options: {options}" if options.strip() else "")
    + "\ncolour: max |θ − θ̂| after 2 s (rad, capped at 1); hatched: fails the fig11 criteria"
    " (|θ − θ̂| ≤ 0.25 rad near zero speed, speed error ≤ 30 r/min, no trip);"
    " red line: pass boundary",
    fontsize=9,
)
fig.savefig(f"docs/envelope-{name}.png", dpi=110)
print(f"wrote docs/envelope-{name}.png")
PY
