#!/usr/bin/env bash
# Firmware proof for fado-core:
#  1. builds tests/embedded, a freestanding #![no_std] #![no_main] image that links the f32
#     estimator with no standard library, no C runtime and no allocator (release, panic=abort),
#     prints its size, and runs it for a few thousand steps where the host can (x86-64 Linux);
#  2. asserts that fado-core's normal dependency tree enables no `std` feature anywhere.
# Usage: bash scripts/check-no-std.sh [--build-only]   (--build-only prints just the image path)
set -euo pipefail
cd "$(dirname "$0")/.."

target=x86_64-unknown-linux-gnu
target_dir="$PWD/target/embedded"
image="$target_dir/$target/release/fado-embedded-check"

# These flags are for the image only; --target keeps them off build scripts and proc-macros.
RUSTFLAGS="-C link-arg=-nostartfiles -C link-arg=-nostdlib -C link-arg=-static -C relocation-model=static" \
    cargo build --release --quiet \
    --manifest-path tests/embedded/Cargo.toml \
    --target "$target" --target-dir "$target_dir"

if [[ "${1:-}" == "--build-only" ]]; then
    echo "$image"
    exit 0
fi

echo "== freestanding image: $image"
size "$image"
text=$(size "$image" | awk 'NR == 2 { print $1 }')
echo "text size: $text bytes (whole image: estimator, libm, core)"

if [[ "$(uname -s)-$(uname -m)" == "Linux-x86_64" ]]; then
    "$image" 5000
    echo "ran 5000 estimator steps in the freestanding image: exit 0"
fi

echo "== fado-core dependency features (normal edges)"
tree=$(cargo tree -p fado-core -e normal -e features --color never)
echo "$tree"
if grep -E 'feature "std"' <<<"$tree"; then
    echo "FAIL: a dependency of fado-core enables its std feature" >&2
    exit 1
fi
echo "OK: no std feature in fado-core's dependencies; freestanding image links and runs"
