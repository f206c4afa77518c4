#!/usr/bin/env bash
# Closed loop on the machines of scripts/motulator-machines.py (crates/fado-sim/tests/data/
# motulator/*.toml: the plant motulator's algebraic model under [motor.saturation], the drive's
# model its flux map), switching-resolved with the default non-idealities, current-sensor seeds
# 1-4: `reversal`, `stops` and `rated-reversal` (a) with the true map as the drive's model and
# (b) with the model `fado-sim commission` identifies from the datasheet's (zero-current)
# values in [motor]. Prints a Markdown table: pass/FAIL and the angle error (near zero speed for
# the reversals, over the run for `stops`) per seed.
# Usage: bash scripts/motulator-closed-loop.sh [OUT_DIR]   (FADO_SIM, SEEDS, MACHINES override)
set -euo pipefail
bin=${FADO_SIM:-target/release/fado-sim}
out=${1:-out/motulator-closed-loop}
seeds=${SEEDS:-1 2 3 4}
dir=crates/fado-sim/tests/data/motulator
machines=${MACHINES:-mot-ipm-1k1 mot-pmsyrm-4k mot-spm-dsat mot-ipm-60k mot-syrm-2k2}
mkdir -p "$out"
cell() {
  python3 - "$1" "$2" <<'PY'
import json, sys
try:
    m = json.load(open(sys.argv[1] + "/metrics.json"))
except FileNotFoundError:
    print("—"); sys.exit()
e = m.get("max_angle_error" if sys.argv[2] == "stops" else "max_angle_error_zero_speed")
print(f"{'pass' if m['passed'] else 'FAIL'} {'n/a' if e is None else f'{e:.3f}'}")
PY
}
echo "| machine | model | seed | reversal | stops | rated-reversal |"
echo "|---|---|---:|---|---|---|"
for name in $machines; do
  for seed in $seeds; do
    true_cfg="$out/$name-true-$seed.toml"
    sed "s|^flux_map = \"|flux_map = \"$PWD/$dir/|" "$dir/$name.toml" > "$true_cfg"
    printf '\n[current_sensor]\nseed = %s\n' "$seed" >> "$true_cfg"
    if ! "$bin" run reversal --config "$true_cfg" --out "$out/$name-true-$seed-reversal" \
        > /dev/null 2> "$out/$name-true-$seed.err"; then
      if [[ ! -f "$out/$name-true-$seed-reversal/metrics.json" ]]; then
        echo "| $name | true map | $seed | refused: $(head -c 300 "$out/$name-true-$seed.err" | tr '\n' ' ') | | |"
        continue
      fi
    fi
    row="| $name | true map | $seed | $(cell "$out/$name-true-$seed-reversal" reversal)"
    for sc in stops rated-reversal; do
      "$bin" run "$sc" --config "$true_cfg" --out "$out/$name-true-$seed-$sc" > /dev/null 2>&1 || true
      row+=" | $(cell "$out/$name-true-$seed-$sc" "$sc")"
    done
    echo "$row |"
    d="$out/$name-commissioned-$seed"
    # The plant without the drive's [model]: commissioning writes the model it identifies.
    grep -v -e '^\[model\]$' -e '^flux_map = ' "$true_cfg" > "$out/$name-plant-$seed.toml"
    "$bin" commission --config "$out/$name-plant-$seed.toml" --seed "$seed" --out "$d" \
      > "$d.log" 2>&1 || true
    if [[ ! -f "$d/identified.toml" ]]; then
      echo "| $name | commissioned | $seed | not identified: $(head -1 "$d.log") | | |"
      continue
    fi
    row="| $name | commissioned | $seed"
    for sc in reversal stops rated-reversal; do
      "$bin" run "$sc" --config "$d/identified.toml" --out "$d/$sc" > /dev/null 2>&1 || true
      row+=" | $(cell "$d/$sc" "$sc")"
    done
    echo "$row |"
  done
done
