#!/usr/bin/env bash
# Speed of the switching-resolved closed loop (plant + drive, one core) on a saturating machine
# against the same machine with constant inductances: simulated seconds per CPU second of the
# process (user + system time, so that other load on the machine does not count), best of N.
# The default scenario is `stops`, which every preset passes: a run that trips stops switching
# and simulates its remaining seconds cheaply, so its figure would not be the drive's.
# Usage: bash scripts/saturated-speed.sh [N]      (env SCENARIO=stops)
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:-3}
scenario=${SCENARIO:-stops}
cargo build --release --quiet -p fado-sim
bin=target/release/fado-sim
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
printf '| motor | magnetics | simulated (s) | CPU (s), best of %s | × real time |\n|---|---|---:|---:|---:|\n' "$n"
for pair in "motors/ipmsm-2k2.toml:constant inductances" \
    "motors/saturated/ipmsm-2k2-qsat.toml:algebraic saturation" \
    "motors/saturated/pmsyrm-baldor-5k6.toml:algebraic saturation with rib" \
    "motors/saturated/pmsyrm-baldor-5k6-measured.toml:measured 21 × 27 flux map" \
    "motors/saturated/pmsm-gem-1k1-measured.toml:measured 12 × 25 flux map"; do
    file=${pair%%:*}
    kind=${pair#*:}
    best=
    for _ in $(seq "$n"); do
        /usr/bin/time -f '%U %S' -o "$tmp/t" "$bin" run "$scenario" --config "$file" --out "$tmp/out" >/dev/null 2>&1 || true
        cpu=$(tail -n 1 "$tmp/t" | awk '{print $1 + $2}')
        if [[ -z "$best" ]] || awk -v a="$cpu" -v b="$best" 'BEGIN{exit !(a < b)}'; then best=$cpu; fi
    done
    sim=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['simulated_seconds'])" "$tmp/out/metrics.json")
    python3 -c "import sys; s, c = float(sys.argv[1]), float(sys.argv[2]); print(f'| {sys.argv[3]} | {sys.argv[4]} | {s:.2f} | {c:.3f} | {s / max(c, 1e-3):.0f} |')" \
        "$sim" "$best" "$(basename "$file" .toml)" "$kind"
done
