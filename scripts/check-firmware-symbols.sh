#!/usr/bin/env bash
# CI gate for the firmware build: builds examples/cortex-m for thumbv7em-none-eabihf
# (Cortex-M4F, single-precision FPU) and fails when any software double-precision routine
# (__aeabi_d*, __muldf3, __adddf3, __divdf3, ...) or any panic or formatting function is
# reachable from the 10 kHz interrupt (SysTick) of the f32 build, or from `drive_step` (the
# f32 SensorlessDrive's step, which the image runs once). Reachability is the call graph of
# the disassembly (scripts/firmware_cost.py graph).
# Without a Cortex-M toolchain (no rustup target, no Debian rustc-web) or binutils it says so
# loudly and runs the host no_std check (scripts/check-no-std.sh) instead.
set -euo pipefail
cd "$(dirname "$0")/.."

fallback() {
    echo "######################################################################" >&2
    echo "# WARNING: $1" >&2
    echo "# The Cortex-M4F symbol check DID NOT RUN; running the host no_std check only." >&2
    echo "######################################################################" >&2
    bash scripts/check-no-std.sh
    exit 0
}

if ! command -v arm-none-eabi-objdump >/dev/null; then
    if [[ "${CI:-}" == "true" ]] && command -v apt-get >/dev/null; then
        (apt-get install -y -qq binutils-arm-none-eabi >/dev/null 2>&1 ||
            { apt-get update -qq >/dev/null 2>&1 &&
                apt-get install -y -qq binutils-arm-none-eabi >/dev/null 2>&1; }) || true
    fi
    command -v arm-none-eabi-objdump >/dev/null ||
        fallback "arm-none-eabi-objdump missing (apt-get install binutils-arm-none-eabi)"
fi
status=0
image=$(bash scripts/firmware-build.sh) || status=$?
if [[ $status -eq 2 ]]; then
    fallback "no toolchain for thumbv7em-none-eabihf"
elif [[ $status -ne 0 ]]; then
    echo "FAIL: the Cortex-M4F example does not build" >&2
    exit 1
fi
echo "== symbols reachable from the interrupt of $image"
status=0
python3 scripts/firmware_cost.py graph "$image" SysTick || status=1
echo "== symbols reachable from the drive's step (drive_step)"
python3 scripts/firmware_cost.py graph "$image" drive_step || status=1
exit $status
