#!/usr/bin/env bash
# Runs the Cortex-M4F example (examples/cortex-m) under QEMU (mps2-an386, cortex-m4,
# semihosting) and fails unless the image exits with success: every scenario kept lock (both
# speeds, default and fixed R̂s, the paper's path, a salient IPMSM), and the paper's method alone
# (the image's two kernels) gave fado's paper's-path θ̂ within 1e-4 rad and the same mode in
# every sample. About 2 s after the build. CI runs it after scripts/check-firmware-symbols.sh.
# Without qemu-system-arm (Debian package of that name) or a Cortex-M toolchain it says so
# loudly and exits 0: the host no_std check and the symbol gate still run in CI.
set -euo pipefail
cd "$(dirname "$0")/.."

skip() {
    echo "######################################################################" >&2
    echo "# WARNING: $1" >&2
    echo "# The Cortex-M4F image DID NOT RUN under QEMU." >&2
    echo "######################################################################" >&2
    exit 0
}

if ! command -v qemu-system-arm >/dev/null; then
    if [[ "${CI:-}" == "true" ]] && command -v apt-get >/dev/null; then
        (apt-get install -y -qq qemu-system-arm >/dev/null 2>&1 ||
            { apt-get update -qq >/dev/null 2>&1 &&
                apt-get install -y -qq qemu-system-arm >/dev/null 2>&1; }) || true
    fi
    command -v qemu-system-arm >/dev/null ||
        skip "qemu-system-arm missing (apt-get install qemu-system-arm)"
fi
status=0
image=$(bash scripts/firmware-build.sh) || status=$?
if [[ $status -eq 2 ]]; then
    skip "no toolchain for thumbv7em-none-eabihf"
elif [[ $status -ne 0 ]]; then
    echo "FAIL: the Cortex-M4F example does not build" >&2
    exit 1
fi
echo "== $image under QEMU"
status=0
timeout 300 qemu-system-arm -machine mps2-an386 -cpu cortex-m4 -nographic \
    -semihosting-config enable=on,target=native -icount shift=2,sleep=off \
    -kernel "$image" || status=$?
if [[ $status -ne 0 ]]; then
    echo "FAIL: the Cortex-M4F image exited with status $status (a scenario lost lock, or a" \
        "kernel differs from fado's paper's path: see the lines marked above)" >&2
    exit 1
fi
echo "OK: every scenario of the Cortex-M4F image kept lock, and the kernels gave fado's angle"
