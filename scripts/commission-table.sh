#!/usr/bin/env bash
# Accuracy table of `fado-sim commission`: every motor preset (motors/*.toml), then the minimal
# motor files of other classes (crates/fado-sim/tests/data/classes/*.toml: circuit and ratings
# only, every other key derived), sensor seeds 1-4, identified vs truth (switching-resolved
# inverter, default non-idealities); k is the current sensors' gain ratio (1 + g_a)/(1 + g_b)
# the DC test measures (true 1.005 by default). Prints the two tables, a blank line between.
set -euo pipefail
bin=${FADO_SIM:-target/release/fado-sim}
out=${1:-out/commission-table}
mkdir -p "$out/presets" "$out/classes"
# commission SOURCE NAME DIR: seeds 1-4 into DIR/NAME-SEED. A refused set-up (commission's
# preconditions) writes no metrics.json: its message is kept in DIR/NAME-SEED.err.
commission() {
  for seed in 1 2 3 4; do
    mkdir -p "$3/$2-$seed"
    "$bin" commission $1 --seed "$seed" --out "$3/$2-$seed" > /dev/null 2> "$3/$2-$seed.err" || true
  done
}
for cfg in motors/*.toml; do
  name=$(basename "$cfg" .toml)
  commission "--motor $name" "$name" "$out/presets"
done
for cfg in crates/fado-sim/tests/data/classes/*.toml; do
  commission "--config $cfg" "$(basename "$cfg" .toml)" "$out/classes"
done
python3 - "$out" <<'PY'
import json, sys, glob, os
out = sys.argv[1]
def table(where):
    print("| motor | seed | Rs | Ld | Lq | λf | J | B (N·m·s/rad) | V_th error (V) | k | time (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for d in sorted(glob.glob(os.path.join(where, "*-[1-4]"))):
        name, seed = os.path.basename(d).rsplit("-", 1)
        if not os.path.exists(os.path.join(d, "metrics.json")):
            err = open(d + ".err").read().strip().splitlines()
            why = err[-1].split(": ")[1].strip("`") if err and err[-1].count(": ") > 1 else "no output"
            print(f"| {name} | {seed} | refused ({why}) | | | | | | | | |")
            continue
        m = json.load(open(os.path.join(d, "metrics.json")))
        if not m["passed"]:
            print(f"| {name} | {seed} | {m['status']} | | | | | | | | {m['simulated_seconds']:.2f} |")
            continue
        p = {r["parameter"]: r for r in m["parameters"]}
        pc = lambda k: f"{100*p[k]['error']:+.2f} %"
        b = p["viscous_friction"]
        # k not measured (the rotor's swing too slow for the DC levels' hold): 1, σ infinite.
        k = pc("current_gain_ratio") + ("" if p["current_gain_ratio"]["confidence"] is not None
                                         else " (not measured)")
        print(f"| {name} | {seed} | {pc('rs')} | {pc('ld')} | {pc('lq')} | {pc('flux_linkage')} | {pc('inertia')} "
              f"| {b['identified']:.2e} (true {b['truth']:.1e}) | {p['threshold_voltage']['error']:+.3f} "
              f"| {k} | {m['simulated_seconds']:.2f} |")
table(os.path.join(out, "presets"))
print()
table(os.path.join(out, "classes"))
PY
