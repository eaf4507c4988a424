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
