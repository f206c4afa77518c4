#!/usr/bin/env bash
# The fig11-like loss-of-lock envelope of docs/method/lock.md on another motor ("Other
# motors"): the ratings-scaled `reversal` scenario (fig11 on the paper's motor) of a preset of
# motors/, with the same design as scripts/lock-sweeps.sh: R̂s error ±10 %, λ̂f error ±10 %,
# L̂q error ±30 %, final load 0 … the preset's rated torque (fig11's 0 … 11.5 N·m is 0 … rated on
# the paper's motor); N random points (default 400), seed SEED (default 7).
# EXTRA: TOML text appended to each variant's configuration (printf escapes, e.g.
# EXTRA='\n[controller.stall]\nfollow_min_current_ratio = 0.3\n'), to try a setting.
# usage: [SEED=N] [N=400] [SCENARIO=reversal] [VARIANTS="fixed-rs adaptive"] [EXTRA=...] \
#        scripts/lock-sweeps-preset.sh PRESET OUT_DIR      (then scripts/lock-eval.py)
set -euo pipefail
preset=${1:?usage: scripts/lock-sweeps-preset.sh PRESET OUT_DIR}
out=${2:?usage: scripts/lock-sweeps-preset.sh PRESET OUT_DIR}
cd "$(dirname "$0")/.."
file=motors/$preset.toml
[[ -f $file ]] || { echo "no preset $file" >&2; exit 2; }
cargo build --release -q -p fado-sim --bin fado-sim
seed=${SEED:-7}
n=${N:-400}
scenario=${SCENARIO:-reversal}
variants=${VARIANTS:-fixed-rs adaptive}
rated=$(python3 -c "import sys,tomllib; print(tomllib.load(open(sys.argv[1],'rb'))['motor']['rated_torque'])" "$file")
mkdir -p "$out"
for variant in $variants; do
    case $variant in fixed-rs*) adapt=false ;; *) adapt=true ;; esac
    case $variant in *clamping) clamp=true ;; *) clamp=false ;; esac
    { cat "$file"; printf '\n[estimator.rs_adaptation]\nenabled = %s\n[estimator.lock]\nlimiter_clamping = %s\n' "$adapt" "$clamp"
      printf "${EXTRA:-}"; } \
        >"$out/$variant.toml"
    rm -rf "${out:?}/$variant"
    nice -n 10 target/release/fado-sim sweep "$scenario" --config "$out/$variant.toml" \
        --random "$n" --seed "$seed" \
        --axis rs_error=-0.1..0.1 --axis flux_linkage_error=-0.1..0.1 \
        --axis lq_error=-0.3..0.3 --axis "load_torque=0..$rated" \
        --threads 2 --out "$out/$variant"
done
