#!/usr/bin/env bash
# Installs, once, what building and running the firmware under QEMU needs:
# the ARM target, qemu-system-arm and dosfstools (mkfs.fat, fsck.fat).
# Sourced by demo.sh and test-all.sh; does nothing when all is there.
TARGET=thumbv7em-none-eabihf
rustup target list --installed | grep -qx "$TARGET" || rustup target add "$TARGET"
missing=()
command -v qemu-system-arm >/dev/null || missing+=(qemu-system-arm)
{ command -v mkfs.fat && command -v fsck.fat; } >/dev/null || missing+=(dosfstools)
if ((${#missing[@]})); then
    SUDO=""
    [ "$(id -u)" -eq 0 ] || SUDO=sudo
    $SUDO apt-get update
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y "${missing[@]}"
fi
# DuckDB's Python wheel: the dataset test queries `wobblog export` output
# with a real engine (the duckdb crate's bundled C++ build would cost CI
# minutes). A user install; Debian's Python refuses pip without the flag.
if ! python3 -c 'import duckdb' 2>/dev/null; then
    python3 -m pip --version >/dev/null 2>&1 || {
        SUDO=""
        [ "$(id -u)" -eq 0 ] || SUDO=sudo
        $SUDO apt-get update
        DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y python3-pip
    }
    python3 -m pip install --user --quiet duckdb 2>/dev/null ||
        python3 -m pip install --user --quiet --break-system-packages duckdb
fi
