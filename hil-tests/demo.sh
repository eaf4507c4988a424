#!/usr/bin/env bash
# The main job: runs the logger firmware under QEMU (STM32F405, netduinoplus2)
# on the bundled ride like the seed paper's Figure 6 (a 6.4 Hz wobble growing
# over a 0.65 Hz weave at about 4 m/s) with a real 5 Hz NMEA capture, shows
# the alert as it happens, then decodes the card.
#
# Results in out/demo/ (or the folder given as $1): card.img (the FAT32 SD
# card image), RUN00001.WBL (the log), ride.csv (decoded frames), summary.txt
# and summary.json (`wobblog info`), ride.png (`wobblog plot`, when present).
# Installs what it needs first, once: the ARM target, qemu-system-arm and
# dosfstools.
set -euo pipefail
cd "$(dirname "$0")/.."

OUT="${1:-out/demo}"

source hil-tests/install-tools.sh

rm -rf "$OUT"
mkdir -p "$OUT"
cargo build -q --release -p wobble-hil --bin qemu-demo -p wobblog
BIN="${CARGO_TARGET_DIR:-target}/release"
"$BIN/qemu-demo" "$OUT"

LOG="$OUT/RUN00001.WBL"
"$BIN/wobblog" decode "$LOG" -o "$OUT/ride.csv"
"$BIN/wobblog" info "$LOG" | tee "$OUT/summary.txt"
"$BIN/wobblog" info "$LOG" --json > "$OUT/summary.json"
if "$BIN/wobblog" plot --help >/dev/null 2>&1; then
    "$BIN/wobblog" plot "$LOG" -o "$OUT/ride.png"
fi
echo
echo "results in $OUT/:"
ls -1 "$OUT"
