#!/usr/bin/env bash
# Instructions per SensorlessEstimator::step, counted by callgrind (deterministic, unlike
# wall-clock timings on a shared machine). Each count runs the program for N1 and for N2 steps
# and divides the difference by N2 - N1, so that start-up and warm-up cancel.
#  - host build (dev/src/bin/estimator-step-workload.rs), f32 and f64: the whole program, and
#    only the instructions inside the out-of-line `isr_step` call (--toggle-collect);
#  - the freestanding firmware image of tests/embedded (f32, libm maths, LTO), whole program
#    (its loop adds ~15 instructions of input generation per step);
#  - f32 inside the step for fado with fixed R̂s, on the paper's path, the paper's method alone
#    (the Cortex-M image's kernel) and the Ortega baseline (dev/src/bin/estimator-step-workload.rs: FIXED_RS,
#    PAPER_PATH, ESTIMATOR=paper-kernel, ESTIMATOR=ortega).
# Usage: bash scripts/callgrind.sh   (N1, N2 from the environment; defaults 20000 and 40000)
set -euo pipefail
cd "$(dirname "$0")/.."

n1=${N1:-20000}
n2=${N2:-40000}
if ! command -v valgrind >/dev/null; then
    echo "valgrind not found (apt-get install valgrind)" >&2
    exit 1
fi

# Ir of one callgrind run; extra valgrind options first, then the program and its arguments.
instructions() {
    local out
    out=$(mktemp)
    valgrind --tool=callgrind --callgrind-out-file=/dev/null "$@" >/dev/null 2>"$out"
    sed -n 's/.*I *refs: *//p' "$out" | tr -d ','
    rm -f "$out"
}

per_step() { # label, then the command (valgrind options, program, args without N)
    local label=$1
    shift
    local a b
    a=$(instructions "$@" "$n1")
    b=$(instructions "$@" "$n2")
    awk -v l="$label" -v a="$a" -v b="$b" -v n1="$n1" -v n2="$n2" \
        'BEGIN { printf "%-48s %8.1f instructions/step\n", l, (b - a) / (n2 - n1) }'
}

cargo build --release --quiet -p fado-dev --bin estimator-step-workload
driver=target/release/estimator-step-workload
image=$(bash scripts/check-no-std.sh --build-only)

echo "callgrind, (Ir(N2) - Ir(N1)) / (N2 - N1) with N1 = $n1, N2 = $n2"
for p in f32 f64; do
    per_step "host $p, whole program" "$driver" "$p"
    per_step "host $p, inside isr_step only" --toggle-collect='*isr_step*' "$driver" "$p"
done
per_step "firmware image f32 (libm, LTO), whole program" "$image"
# The host ratio, f32 inside the step: fado's variants against the Ortega baseline (which
# shares fado's trackers and atan2, so the ratio is the cost of what each method adds).
echo "f32 inside isr_step, fado's variants and the Ortega baseline"
for v in "default (R̂s adaptation)=" "default, step_lean (firmware's call)=LEAN=1" \
    "fixed R̂s=FIXED_RS=1" "paper's path=PAPER_PATH=1" \
    "the paper's method alone=ESTIMATOR=paper-kernel" "Ortega baseline=ESTIMATOR=ortega"; do
    (
        [[ -n ${v#*=} ]] && export "${v#*=}"
        per_step "host f32, ${v%%=*}" --toggle-collect='*isr_step*' "$driver" f32
    )
done
