#!/usr/bin/env bash
# Builds the board example examples/b-g431b-esc1 (fado's drive in the PWM interrupt of ST's
# B-G431B-ESC1, STM32G431CB, stm32g4xx-hal) for thumbv7em-none-eabihf and prints its size.
# The image is built, not run (it needs the board). Without the rustup target it says so loudly
# and exits 0, as scripts/check-firmware-symbols.sh does; CI's log then shows the skip.
set -euo pipefail
cd "$(dirname "$0")/.."

target=thumbv7em-none-eabihf
target_dir="$PWD/target/board"
if ! command -v rustup >/dev/null ||
    ! { rustup target list --installed 2>/dev/null | grep -qx "$target" ||
        timeout 120 rustup target add "$target" >&2; }; then
    echo "NO $target TARGET: the B-G431B-ESC1 example was not built" >&2
    exit 0
fi
cargo fmt --check --manifest-path examples/b-g431b-esc1/Cargo.toml
(cd examples/b-g431b-esc1 && cargo build --release --quiet --locked --target-dir "$target_dir")
image="$target_dir/$target/release/fado-b-g431b-esc1"
if command -v arm-none-eabi-size >/dev/null; then
    arm-none-eabi-size "$image"
else
    ls -l "$image"
fi
