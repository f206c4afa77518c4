#!/usr/bin/env bash
# Builds examples/cortex-m for thumbv7em-none-eabihf (Cortex-M4F) and prints the image path.
# Route 1: rustup's prebuilt target. Route 2 (no rustup download possible): Debian's rustc-web
# with its core sources, `-Zbuild-std` (apt-get install rustc-web cargo-web rust-web-src
# rust-web-llvm lld-22). Exit status 2 when neither route is available.
set -euo pipefail
cd "$(dirname "$0")/.."

target=thumbv7em-none-eabihf
target_dir="$PWD/target/cortex-m"
image="$target_dir/$target/release/fado-cortex-m"

if command -v rustup >/dev/null &&
    { rustup target list --installed 2>/dev/null | grep -qx "$target" ||
        timeout 120 rustup target add "$target" >&2; }; then
    (cd examples/cortex-m && cargo build --release --quiet --target-dir "$target_dir") >&2
elif [[ -x /usr/bin/cargo && -x /usr/bin/rustc ]] && /usr/bin/rustc --version >/dev/null 2>&1; then
    # Debian's rustc-web/cargo-web install /usr/bin/rustc and /usr/bin/cargo; rust-web-src the
    # core sources that -Zbuild-std compiles; lld-22 the linker (this route is written to the
    # issue's recipe but was not exercised where rustup worked).
    echo "rustup target unavailable: building with Debian's $(/usr/bin/rustc --version) and -Zbuild-std" >&2
    linker=$(command -v ld.lld-22 || command -v ld.lld || echo rust-lld)
    (cd examples/cortex-m && RUSTC=/usr/bin/rustc RUSTC_BOOTSTRAP=1 \
        CARGO_TARGET_THUMBV7EM_NONE_EABIHF_LINKER="$linker" /usr/bin/cargo build --release --quiet \
        --target-dir "$target_dir" -Zbuild-std=core,compiler_builtins \
        -Zbuild-std-features=compiler-builtins-mem) >&2
else
    echo "NO CORTEX-M TOOLCHAIN: neither 'rustup target add $target' nor Debian's rustc-web" >&2
    exit 2
fi
echo "$image"
