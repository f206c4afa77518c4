#!/usr/bin/env bash
# Runs every cargo-fuzz target of fuzz/ for a bounded time and reports.
# Not part of CI: needs the nightly toolchain and cargo-fuzz (`cargo install cargo-fuzz`).
#
#   scripts/fuzz.sh [seconds-per-target] [target...]
#
# Defaults: 60 s for each of estimator_step, drive_step and baseline_step, one job each (the
# machine is shared). A crash leaves its input in fuzz/artifacts/<target>/; `cargo +nightly fuzz fmt
# <target> <file>` prints the decoded case; copy the file to fuzz/regressions/<target>/ and
# replay it as a test in crates/fado-core/tests/fuzz_regressions.rs. Every input already in
# fuzz/regressions/ is replayed first, so a fixed crash stays fixed.
set -euo pipefail
cd "$(dirname "$0")/../fuzz"
seconds="${1:-60}"
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
    targets=(estimator_step drive_step baseline_step)
fi
cargo +nightly fuzz build -O >/dev/null 2>&1
status=0
for t in "${targets[@]}"; do
    mkdir -p "corpus/$t" "regressions/$t"
    if compgen -G "regressions/$t/*" >/dev/null; then
        echo "== $t: replaying fuzz/regressions/$t"
        cargo +nightly fuzz run -O "$t" regressions/$t/* -- -runs=0 >/dev/null 2>&1 ||
            { echo "   a regression input fails again"; status=1; }
    fi
    echo "== $t: fuzzing for ${seconds} s"
    log="target/fuzz-$t.log"
    if cargo +nightly fuzz run -O "$t" "corpus/$t" -- \
        -max_total_time="$seconds" -max_len=4096 -print_final_stats=1 >"$log" 2>&1; then
        result=ok
    else
        result="CRASH (see $log and fuzz/artifacts/$t/)"
        status=1
    fi
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo '?')
    rate=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo '?')
    cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 || true)
    echo "   $result: $runs executions, $rate exec/s, ${cov:-cov: ?}, corpus $(ls "corpus/$t" | wc -l) inputs"
done
exit $status
