#!/usr/bin/env bash
# The λ̂f × load envelope of the fig11 reversal, with and without the λ̂f law:
#   1. `fado-sim sweep fig11` over flux_linkage_error (= λ̂f/λf − 1) −10…+10 % in 2.5 % steps ×
#      load torque 0…7.5 N·m in 1.25 N·m steps (63 runs), switching-resolved, once with the
#      defaults and once with `[estimator.flux_linkage_adaptation] rate = 0` (law off);
#   2. docs/envelope-fig11-lf-load-{law-off,default}.csv, and docs/envelope-fig11-lf-load.png
#      drawn from them (with the per-sample law at 5 s⁻¹,
#      docs/envelope-fig11-lf-load-after-lf5.csv, as the middle panel);
#   3. the two markdown tables of the envelope on stdout (docs/results/envelopes.md).
# Usage: bash scripts/envelope-lf.sh [fado-sim sweep options, e.g. --threads 1]
# Needs: cargo; a python3 with numpy and matplotlib (PYTHON, default python3).
set -euo pipefail
cd "$(dirname "$0")/.."
python=${PYTHON:-python3}
cargo build --release --quiet -p fado-sim --bin fado-sim
target=${CARGO_TARGET_DIR:-target}
sim="$target/release/fado-sim"
axes=(--axis flux_linkage_error=-0.1:0.1:9 --axis load_torque=0:7.5:7)
off=$(mktemp /tmp/fado-lf-off.XXXXXX.toml)
trap 'rm -f "$off"' EXIT
printf '[estimator.flux_linkage_adaptation]\nrate = 0.0\n' >"$off"
"$sim" sweep fig11 "${axes[@]}" --fresh --out out/envelope-lf-load-default "$@" >/dev/null
"$sim" sweep fig11 "${axes[@]}" --config "$off" --fresh --out out/envelope-lf-load-law-off "$@" >/dev/null
cp out/envelope-lf-load-default/sweep.csv docs/envelope-fig11-lf-load-default.csv
cp out/envelope-lf-load-law-off/sweep.csv docs/envelope-fig11-lf-load-law-off.csv
"$python" - <<'PY'
import csv

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure


def grid(name):
    rows = list(csv.DictReader(open(f"docs/envelope-fig11-lf-load-{name}.csv")))
    lf = sorted({float(r["flux_linkage_error"]) for r in rows})
    load = sorted({float(r["load_torque"]) for r in rows})
    value = np.full((len(load), len(lf)), np.nan)
    ok = np.zeros_like(value, dtype=bool)
    for r in rows:
        i, j = load.index(float(r["load_torque"])), lf.index(float(r["flux_linkage_error"]))
        value[i, j] = float(r["max_angle_error_zero_speed"] or "nan")
        ok[i, j] = r["passed"] == "true"
    return lf, load, value, ok


panels = [
    ("law-off", "λ̂f law off (flux_linkage_adaptation_rate = 0)"),
    ("after-lf5", "per-sample λ̂f law, 5 s⁻¹"),
    ("default", "defaults: revolution-mean λ̂f law (dead zone 1 %, following beyond 2 %)"),
]
fig = Figure(figsize=(16.5, 5.0), layout="constrained")
FigureCanvasAgg(fig)
axes = fig.subplots(1, 3)
for ax, (name, title) in zip(axes, panels):
    lf, load, value, ok = grid(name)
    im = ax.imshow(np.minimum(value, 1.0), origin="lower", vmin=0, vmax=1, cmap="viridis",
                   aspect="auto")
    for i in range(len(load)):
        for j in range(len(lf)):
            v = value[i, j]
            ax.text(j, i, f"{v:.2f}" + ("" if ok[i, j] else "✗"), ha="center", va="center",
                    fontsize=7, color="white" if v < 0.6 else "black")
    ax.set_xticks(range(len(lf)), [f"{100 * x:+.1f}" for x in lf])
    ax.set_yticks(range(len(load)), [f"{x:.2f}" for x in load])
    ax.set_xlabel("λ̂f error, λ̂f/λf − 1 (%)")
    ax.set_ylabel("load torque (N·m)")
    ax.set_title(f"{title}: {int(ok.sum())} of {ok.size} pass", fontsize=9)
fig.colorbar(im, ax=axes, label="max |θ − θ̂| near zero speed (rad, clipped at 1)")
fig.suptitle("fig11 reversal (−90 → +90 r/min under load), switching-resolved, "
             "λ̂f error × load (✗ = fails)")
fig.savefig("docs/envelope-fig11-lf-load.png", dpi=100)
for name, title in panels[::2]:
    lf, load, value, ok = grid(name)
    print(f"\n{title}:\n")
    print("| λ̂f error \\ load (N·m) | " + " | ".join(f"{x:g}" for x in load) + " |")
    print("|---|" + "---|" * len(load))
    for j, x in enumerate(lf):
        cells = [f"{value[i, j]:.2f}" + ("" if ok[i, j] else " ✗") for i in range(len(load))]
        print(f"| {100 * x:+.1f} % | " + " | ".join(cells) + " |")
    print(f"\n{int(ok.sum())} of {ok.size} pass")
PY
