#!/usr/bin/env bash
# Runs every check and test of the project on a fresh machine: installs what
# it needs first (idempotent), then formatting, lints on the host and on the
# MCU target, the host test suite, the firmware build, and the Python
# package's build and tests.
set -euo pipefail
cd "$(dirname "$0")/.."

TARGET=thumbv7em-none-eabihf

step() { printf '\n==> %s\n' "$*"; }

step "toolchain components, the $TARGET target, QEMU and dosfstools (installed only when missing)"
rustup component add rustfmt clippy >/dev/null 2>&1 || true
source hil-tests/install-tools.sh

step "cargo fmt --check"
cargo fmt --all -- --check

step "clippy, host crates (all targets)"
# Without --workspace: the default members, i.e. every crate that builds for the host.
cargo clippy --all-targets -- -D warnings

step "clippy and build, core crate for $TARGET"
cargo clippy -p wobble-core --target "$TARGET" -- -D warnings
cargo build -p wobble-core --target "$TARGET" --release

step "firmware for the STM32F405 board: release build, clippy, size budget"
# Built from the crate's directory, as a user flashing it does: its
# `.cargo/config.toml` selects the MCU target and the size-optimised profile.
(cd firmware/stm32f405 && cargo build --release)
cargo clippy -p wobble-stm32f405 --target "$TARGET" -- -D warnings
# One build, one image: a release build from anywhere but the crate's
# directory would not get its size profile, and is refused by build.rs.
root_build_err=$(mktemp)
if cargo check -q --release -p wobble-stm32f405 --target "$TARGET" 2>"$root_build_err"; then
    echo "a release build from the workspace root was not refused" >&2
    exit 1
fi
grep -q "cd firmware/stm32f405 && cargo build --release" "$root_build_err"
# Nor does an opt-level given in the environment make it the same image.
if CARGO_PROFILE_RELEASE_OPT_LEVEL=z cargo check -q --release -p wobble-stm32f405 \
    --target "$TARGET" 2>"$root_build_err"; then
    echo "a release build from the root with CARGO_PROFILE_RELEASE_OPT_LEVEL=z was not refused" >&2
    exit 1
fi
grep -q "cd firmware/stm32f405 && cargo build --release" "$root_build_err"
rm -f "$root_build_err"
# The memory plan (firmware/docs/board.md): fails when flash > 384 KiB (the
# active slot of the field-update layout) or CCM > 64 KiB.
cargo run -q -p wobble-size-budget -- "${CARGO_TARGET_DIR:-target}/$TARGET/release/wobble-stm32f405"
# A worst-case stack bound of the image (llvm-objdump, a few seconds), which
# must fit the stack the image reserves, and with the static SRAM at most
# 120 KiB (the memory plan); its resolution of indirect calls and the plan's
# check are unit-tested on crafted images first (firmware/docs/board.md).
python3 firmware/size-budget/test_stack_bound.py
python3 firmware/size-budget/stack_bound.py --check "${CARGO_TARGET_DIR:-target}/$TARGET/release/wobble-stm32f405"

step "on-target tests (hil-tests/on-target): build and clippy; they run on a board with a probe"
cargo build -p wobble-on-target --tests --target "$TARGET"
cargo clippy -p wobble-on-target --tests --target "$TARGET" -- -D warnings

step "QEMU image (netduinoplus2): clippy and release build, run by the tests"
cargo clippy -p wobble-qemu-image --target "$TARGET" -- -D warnings
(cd hil-tests/qemu-image && cargo build --release)

# Property tests draw their cases from the fixed seed in .cargo/config.toml
# (the environment's PROPTEST_RNG_SEED wins): every run of one tree runs the
# same cases. Fresh seeds and more cases: hil-tests/proptest-fresh.sh
# (host-tools/docs/robustness.md, "Property tests").
step "tests (PROPTEST_RNG_SEED=${PROPTEST_RNG_SEED:-from .cargo/config.toml})"
cargo test

step "Python package (host-tools/python): clippy, build into a virtual environment, pytest"
hil-tests/python-tests.sh
