#!/usr/bin/env bash
# End to end: every motor preset (motors/*.toml), sensor seeds 1-4: `fado-sim commission`, then
# the preset's `reversal` and `stops` scenarios with the identified [model], R̂s adaptation on
# and off; and the same scenarios with the true model (the preset file as is) for reference.
# Prints a markdown table (docs/commissioning.md, "End to end").
set -euo pipefail
bin=${FADO_SIM:-target/release/fado-sim}
out=${1:-out/commission-e2e}
seeds=${SEEDS:-1 2 3 4}
mkdir -p "$out"
no_adapt=$'\n[estimator.rs_adaptation]\nenabled = false\n'
for cfg in motors/*.toml; do
  name=$(basename "$cfg" .toml)
  # The true model: the preset as is ([model] = [motor]).
  cp "$cfg" "$out/$name-true-on.toml"
  { cat "$cfg"; printf '%s' "$no_adapt"; } > "$out/$name-true-off.toml"
  for adapt in on off; do
    for sc in reversal stops; do
      "$bin" run "$sc" --config "$out/$name-true-$adapt.toml" --out "$out/$name-true-$adapt-$sc" > /dev/null || true
    done
  done
  for seed in $seeds; do
    d="$out/$name-$seed"
    "$bin" commission --motor "$name" --seed "$seed" --out "$d" > /dev/null 2> "$d.err" || true
    [[ -f "$d/identified.toml" ]] || continue
    cp "$d/identified.toml" "$d/id-on.toml"
    { cat "$d/identified.toml"; printf '%s' "$no_adapt"; } > "$d/id-off.toml"
    for adapt in on off; do
      for sc in reversal stops; do
        "$bin" run "$sc" --config "$d/id-$adapt.toml" --out "$d/$adapt-$sc" > /dev/null || true
      done
    done
  done
done
python3 - "$out" "$seeds" <<'PY'
import json, os, sys
out, seeds = sys.argv[1], sys.argv[2].split()
def cell(path):
    try:
        m = json.load(open(os.path.join(path, "metrics.json")))
    except FileNotFoundError:
        return "—"
    e = m.get("max_angle_error_zero_speed")
    e = "n/a" if e is None else f"{e:.3f}"
    return f"{'pass' if m['passed'] else 'FAIL'} {e}"
motors = sorted(os.path.basename(f)[:-5] for f in os.listdir("motors") if f.endswith(".toml"))
cols = [(a, s) for a in ("on", "off") for s in ("reversal", "stops")]
head = " | ".join(f"{s}, R̂s adapt. {a}" for a, s in cols)
print(f"| motor | model | {head} |")
print("|---|---|" + "---|" * len(cols))
for name in motors:
    row = [cell(os.path.join(out, f"{name}-true-{a}-{s}")) for a, s in cols]
    print(f"| {name} | true | " + " | ".join(row) + " |")
    for seed in seeds:
        d = os.path.join(out, f"{name}-{seed}")
        if not os.path.isfile(os.path.join(d, "identified.toml")):
            # Refused before it ran (its preconditions: no metrics.json, the key named in the
            # error) or aborted (metrics.json with its status).
            try:
                why = json.load(open(os.path.join(d, "metrics.json")))["status"]
            except FileNotFoundError:
                err = open(d + ".err").read().strip().splitlines()
                key = err[-1].split(": ")[1].strip("`") if err and err[-1].count(": ") > 1 else "?"
                why = f"refused ({key})"
            print(f"| {name} | identified, seed {seed} | commissioning {why} | | | |")
            continue
        row = [cell(os.path.join(d, f"{a}-{s}")) for a, s in cols]
        print(f"| {name} | identified, seed {seed} | " + " | ".join(row) + " |")
PY
