#!/usr/bin/env bash
# Long run: one simulated hour with the averaged plant and the f32 drive, (a) at
# 300 r/min under 7.5 N·m and (b) at 0 r/min under 7.5 N·m. Runs the ignored tests of
# crates/fado-sim/tests/long_run.rs in release and prints their per-minute tables (angle-error
# statistics, magnitudes of λ1, D̂, the trackers' speed errors, the PI integrals, flag counts)
# and the drift verdicts; the full output is also kept in target/long-run.txt.
# Usage: bash scripts/long-run.sh [seconds]     (default 3600; e.g. 120 for a smoke run)
#        FADO_LONG_RUN_PRECISION=f64 bash scripts/long-run.sh   (the f64 drive, for comparison)
# Exit status: that of the tests (non-zero if a drift criterion fails).
set -uo pipefail
cd "$(dirname "$0")/.."
export FADO_LONG_RUN_SECONDS="${1:-3600}"
mkdir -p target
echo "== long run: ${FADO_LONG_RUN_SECONDS} s simulated per case, $(nproc) cores"
cargo test --release -p fado-sim --test long_run -- --ignored --nocapture --test-threads 2 \
    2>&1 | tee target/long-run.txt | grep -E '^(###|\||ok  |FAIL|test |[0-9] r/min|300 r/min|0 r/min)'
status=${PIPESTATUS[0]}
echo "== full output: target/long-run.txt (exit status $status)"
exit "$status"
