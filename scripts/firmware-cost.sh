#!/usr/bin/env bash
# Cost of fado's f32 estimator step on a Cortex-M4F, measured on the firmware image itself:
# builds examples/cortex-m (scripts/firmware-build.sh), runs it in QEMU (mps2-an386,
# cortex-m4, semihosting) and reports, per scenario (low and high electrical speed, with and
# without the R̂s adaptation): the instructions and the Cortex-M4 cycle estimate per step (an
# instruction trace weighted by the TRM's cycle timings, see scripts/firmware_cost.py and
# docs/results/firmware-cost.md), the .text reachable from the step and from the ISR, the deepest stack
# (painted stack, measured in the image) and size_of the estimator's state and parameters
# (EstimatorState, EstimatorParams, in f32 and f64) and of their owner SensorlessEstimator.
# Scenarios 4 and 5 run fado's paper's path and, beside it on the same samples, the paper's
# estimator alone (paper_kernel_step, examples/cortex-m/src/paper_kernel.rs): both are traced
# in the same run and reported apart (docs/results/firmware-cost.md); scenarios 6 and 7 the
# same with the observer's gains held as fado's default holds them (paper_kernel_held_step),
# 8 and 9 the default step on a salient IPMSM, 10 and 11 the same IPMSM saturating, its model a
# 16 × 16 flux map in flash as a uniform-grid table (MachineMagnetics::Uniform), stepped by
# estimator_step_table (EstimatorState::step_lean_in: the step compiled for the table named
# by its type) with estimator_step (the machine record's model, matched at run time) beside
# it on the same samples, scenario 12 the whole drive (drive_step) around a simulated motor
# (docs/results/firmware-cost.md); scenario 13 that flux map alone
# (examples/cortex-m/src/flux_lookup.rs): one lookup ψ(i) (flux_map_lookup) and its inverse
# i(ψ) by Newton from a warm start (flux_map_inverse), and the same lookup in the uniform-grid
# table (uniform_table_lookup: UniformFluxTable::flux) and as the estimator's steps make it
# (step_map_lookup: the machine record's MachineMagnetics::flux_warm, as step_lean inlines it;
# step_table_lookup: FluxLookup::flux_warm on the table named by its type, as step_lean_in
# inlines it).
# Needs qemu-system-arm and binutils-arm-none-eabi (Debian packages of those names).
# Writes docs/results/firmware-cost.md whole from what it prints (scripts/firmware_cost_page.py).
# Usage: bash scripts/firmware-cost.sh [STEPS_MEASURED_PER_SCENARIO (default 300)]
set -euo pipefail
cd "$(dirname "$0")/.."
tail_steps="${1:-300}"

# Everything measured, printed (the page below is generated from this output).
measure() {

for tool in qemu-system-arm arm-none-eabi-objdump; do
    command -v "$tool" >/dev/null || {
        echo "missing $tool: apt-get install qemu-system-arm binutils-arm-none-eabi" >&2
        exit 2
    }
done
image=$(bash scripts/firmware-build.sh)
qemu=(qemu-system-arm -machine mps2-an386 -cpu cortex-m4 -nographic
    -semihosting-config enable=on,target=native -icount shift=2,sleep=off -kernel "$image")

echo "== image: $image"
arm-none-eabi-size "$image"
echo "== run (semihosting output of the image)"
run_log=$(mktemp /tmp/fado-firmware-run.XXXXXX)
trap 'rm -f "$run_log"' EXIT
timeout 300 "${qemu[@]}" | tee "$run_log"
echo "== state and parameters (size_of, printed by the image)"
grep -o 'EstimatorState<f32> = .*' "$run_log" | tr ',' '\n' | sed 's/^ */    /' || true
grep -o 'deepest stack: .*' "$run_log" | sed 's/^/    /' || true

echo "== code reachable from the step and from the interrupt"
for root in estimator_step paper_kernel_step paper_kernel_held_step SysTick drive_step \
    flux_map_lookup flux_map_inverse uniform_table_lookup step_map_lookup estimator_step_table \
    step_table_lookup; do
    { python3 scripts/firmware_cost.py graph "$image" "$root" || true; } |
        grep -E '^(\.text reachable|OK:|FORBIDDEN)' || true
done

echo "== instruction trace (QEMU -d exec,nochain -singlestep, filtered to the step's code)"
log=$(mktemp /tmp/fado-firmware-trace.XXXXXX)
trap 'rm -f "$log" "$run_log"' EXIT
filter=$(python3 scripts/firmware_cost.py ranges "$image" \
    estimator_step,paper_kernel_step,paper_kernel_held_step,drive_step,flux_map_lookup,flux_map_inverse,uniform_table_lookup,step_map_lookup,estimator_step_table,step_table_lookup \
    scenario_marker)
timeout 900 "${qemu[@]}" -singlestep -d exec,nochain -dfilter "$filter" -D "$log" >/dev/null
roots=(estimator_step paper_kernel_step paper_kernel_held_step drive_step flux_map_lookup
    flux_map_inverse uniform_table_lookup step_map_lookup estimator_step_table step_table_lookup)
titles=(
    "fado's step (estimator_step: scenarios 0-1 default, 2-3 fixed R̂s, 4-5 the paper's path, 6-7 the paper's path with the gains held over fado's default period, 8-9 a salient IPMSM, 10-11 the same saturating with a 16 × 16 uniform flux table in flash, the machine record's model matched at run time)"
    "the paper's estimator alone (paper_kernel_step, beside fado's paper's path: scenarios 4-5)"
    "the same with the gains held (paper_kernel_held_step, beside scenarios 6-7)"
    "the whole drive (drive_step: SensorlessDrive<f32>::step, fado's estimator inside; scenario 12)"
    "one lookup ψ(i) in a 16 × 16 flux map in flash (flux_map_lookup: FluxMap::flux; scenario 13)"
    "its inverse i(ψ) by Newton from the last current (flux_map_inverse: FluxMap::current_from; scenario 13)"
    "the same lookup in the uniform-grid table (uniform_table_lookup: UniformFluxTable::flux; scenario 13)"
    "the same lookup as the estimator's step makes it (step_map_lookup: MachineMagnetics::flux_warm; scenario 13)"
    "the step compiled for the table (estimator_step_table: EstimatorState::step_lean_in with the 16 × 16 table named by its type; scenarios 10-11)"
    "the same lookup as the step compiled for the table makes it (step_table_lookup: FluxLookup::flux_warm; scenario 13)"
)
# Each root's steps end at the entry of any other root traced in the same run.
for k in "${!roots[@]}"; do
    echo "-- ${titles[$k]}"
    python3 scripts/firmware_cost.py trace "$image" "${roots[$k]}" "$log" "$tail_steps" \
        "${roots[@]:0:$k}" "${roots[@]:$((k + 1))}"
done
}

page_log=$(mktemp /tmp/fado-firmware-page.XXXXXX)
trap 'rm -f "$page_log"' EXIT
measure | tee "$page_log"
python3 scripts/firmware_cost_page.py "$page_log" docs/results/firmware-cost.md
