#!/usr/bin/env bash
# The main job: runs the logger firmware under QEMU (STM32F405, netduinoplus2)
# on the bundled ride like the seed paper's Figure 6 (a 6.4 Hz wobble growing
# over a 0.65 Hz weave at about 4 m/s) with a real 5 Hz NMEA capture, shows
# the alert as it happens, then decodes the card.
#
# Results in out/demo/ (or the folder given as $1): card.img (the FAT32 SD
# card image), RUN00001.WBL (the log), ride.csv (decoded frames), summary.txt
# and summary.json (`wobblog info`), ride.png (`wobblog plot`), report.html
# (`wobblog report`).
# Installs what it needs first, once: the ARM target, qemu-system-arm and
# dosfstools.
set -euo pipefail
cd "$(dirname "$0")/.."

OUT="${1:-out/demo}"

source hil-tests/install-tools.sh

# Only a folder that an earlier demo made (it holds the marker) is replaced:
# a folder given by mistake that holds real logs is never touched.
MARKER=.wobble-demo
if [ -e "$OUT" ] && [ ! -e "$OUT/$MARKER" ] && [ -n "$(ls -A "$OUT")" ]; then
    echo "demo.sh: $OUT exists and was not made by the demo; choose another folder" >&2
    exit 1
fi
# Two builds: `--bin` narrows every package a command selects.
cargo build -q --release -p wobble-hil --bin qemu-demo
cargo build -q --release -p wobblog --bin wobblog
BIN="${CARGO_TARGET_DIR:-target}/release"

rm -rf "$OUT"
mkdir -p "$OUT"
touch "$OUT/$MARKER"
"$BIN/qemu-demo" "$OUT"

LOG="$OUT/RUN00001.WBL"
"$BIN/wobblog" decode "$LOG" -o "$OUT/ride.csv"
"$BIN/wobblog" info "$LOG" | tee "$OUT/summary.txt"
"$BIN/wobblog" info "$LOG" --json > "$OUT/summary.json"
"$BIN/wobblog" plot "$LOG" -o "$OUT/ride.png"
"$BIN/wobblog" report "$LOG" -o "$OUT/report.html"
echo
echo "results in $OUT/:"
ls -1 "$OUT"
