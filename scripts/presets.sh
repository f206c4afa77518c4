#!/usr/bin/env bash
# Runs every motor preset of motors/ through the ratings-scaled scenarios (default: reversal and
# stops) for sensor-noise seeds 1-4, switching-resolved, default non-idealities, and prints a
# markdown table of the worst |θ − θ̂| (near zero speed for the reversals) and the verdicts.
# Usage: bash scripts/presets.sh [scenario ...]     (env SEEDS="1 2 3 4", EXTRA=toml snippet,
#        MOTORS='motors/saturated/*.toml' for another set of motor files)
set -euo pipefail
cd "$(dirname "$0")/.."
scenarios=("$@")
[[ ${#scenarios[@]} -gt 0 ]] || scenarios=(reversal stops)
seeds=${SEEDS:-1 2 3 4}
cargo build --release --quiet -p fado-sim
bin=target/release/fado-sim
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
metric() { # key file
    python3 -c "import json,sys; print(json.load(open(sys.argv[2]))[sys.argv[1]])" "$1" "$2"
}
printf '| preset | scenario |'
for s in $seeds; do printf ' seed %s |' "$s"; done
printf ' passed |\n|---|---|'
for _ in $seeds; do printf -- '---:|'; done
printf -- '---|\n'
for file in ${MOTORS:-motors/*.toml}; do
    name=$(basename "$file" .toml)
    for sc in "${scenarios[@]}"; do
        printf '| %s | %s |' "$name" "$sc"
        pass=0 total=0
        for s in $seeds; do
            cfg="$tmp/$name-$sc-$s.toml"
            # A flux map named relative to the motor file is given by its absolute path.
            dir=$(cd "$(dirname "$file")" && pwd)
            { sed "s|^flux_map = \"\([^/\"][^\"]*\)\"|flux_map = \"$dir/\1\"|" "$file"; printf '\n[current_sensor]\nseed = %s\n' "$s"; printf '%b' "${EXTRA:-}"; } >"$cfg"
            out="$tmp/out-$name-$sc-$s"
            if "$bin" run "$sc" --config "$cfg" --out "$out" >/dev/null 2>&1; then ok=1; else ok=0; fi
            if [[ -f "$out/metrics.json" ]]; then
                case "$sc" in
                    reversal | rated-reversal) key=max_angle_error_zero_speed ;;
                    *) key=max_angle_error ;;
                esac
                v=$(metric "$key" "$out/metrics.json")
                passed=$(metric passed "$out/metrics.json")
                [[ "$passed" == "True" ]] && pass=$((pass + 1))
                printf ' %.3f%s |' "$v" "$([[ "$passed" == "True" ]] || echo ' ✗')"
            else
                printf ' error |'
            fi
            total=$((total + 1))
        done
        printf ' %d/%d |\n' "$pass" "$total"
    done
done
