#!/usr/bin/env bash
# Installs, once, what building and running the firmware under QEMU needs:
# the ARM target, qemu-system-arm, dosfstools (mkfs.fat, fsck.fat), exfatprogs
# (mkfs.exfat), llvm
# (llvm-objdump, for the stack bound), chromium (headless, for the report's
# browser test), and
# the Python packages the host tests read outputs with.
# Sourced by demo.sh and test-all.sh; does nothing when all is there.
TARGET=thumbv7em-none-eabihf
rustup target list --installed | grep -qx "$TARGET" || rustup target add "$TARGET"
missing=()
command -v qemu-system-arm >/dev/null || missing+=(qemu-system-arm)
{ command -v mkfs.fat && command -v fsck.fat; } >/dev/null || missing+=(dosfstools)
command -v mkfs.exfat >/dev/null || missing+=(exfatprogs)  # the card-format tests
command -v llvm-objdump >/dev/null || missing+=(llvm)  # the stack bound
command -v chromium >/dev/null || missing+=(chromium)  # the report's browser test
if ((${#missing[@]})); then
    SUDO=""
    [ "$(id -u)" -eq 0 ] || SUDO=sudo
    $SUDO apt-get update
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y "${missing[@]}"
fi
# Python packages the tests read outputs back with, as researchers do:
# DuckDB, Polars, pyarrow and pandas (datasets, Parquet, CSV, JSON lines) and
# gpxpy (GPX). Wheels, no C++ builds; a user install, as Debian's Python
# refuses pip without the flag. Only what is missing is installed.
PY_PACKAGES=(duckdb polars pyarrow pandas gpxpy)
py_missing=()
for pkg in "${PY_PACKAGES[@]}"; do
    python3 -c "import $pkg" 2>/dev/null || py_missing+=("$pkg")
done
if ((${#py_missing[@]})); then
    python3 -m pip --version >/dev/null 2>&1 || {
        SUDO=""
        [ "$(id -u)" -eq 0 ] || SUDO=sudo
        $SUDO apt-get update
        DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y python3-pip
    }
    python3 -m pip install --user --quiet "${py_missing[@]}" 2>/dev/null ||
        python3 -m pip install --user --quiet --break-system-packages "${py_missing[@]}"
fi
