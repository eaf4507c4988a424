#!/usr/bin/env bash
# Checks that the main job (`hil-tests/demo.sh`) left every result it
# promises in its output folder (default out/demo), each non-empty.
# Exit 1, naming what is missing, otherwise.
set -euo pipefail
cd "$(dirname "$0")/.."

OUT="${1:-out/demo}"
missing=0
for f in card.img RUN00001.WBL ride.csv summary.txt summary.json ride.png report.html; do
    if [ ! -s "$OUT/$f" ]; then
        echo "check-demo: $OUT/$f is missing or empty" >&2
        missing=1
    fi
done
# The decoded ride has the interface's header and 30 s of 100 Hz frames.
if [ -s "$OUT/ride.csv" ]; then
    head -n1 "$OUT/ride.csv" | grep -q '^t_s,ax_g,ay_g,az_g,gx_dps,gy_dps,gz_dps,steer_deg,speed_mps,gps_lat_deg,gps_lon_deg,gps_speed_mps,gps_fix' \
        || { echo "check-demo: $OUT/ride.csv: unexpected header" >&2; missing=1; }
    rows=$(($(wc -l < "$OUT/ride.csv") - 1))
    [ "$rows" -ge 2900 ] || { echo "check-demo: $OUT/ride.csv: only $rows frames" >&2; missing=1; }
fi
# The PNG is a PNG.
if [ -s "$OUT/ride.png" ] && ! head -c 8 "$OUT/ride.png" | od -An -tx1 | grep -q '89 50 4e 47'; then
    echo "check-demo: $OUT/ride.png is not a PNG" >&2
    missing=1
fi
# The report is a whole page with the ride view's spectrogram.
if [ -s "$OUT/report.html" ] && ! { head -c 15 "$OUT/report.html" | grep -q '<!DOCTYPE html>' &&
    tail -c 20 "$OUT/report.html" | grep -q '</html>' &&
    grep -q 'data-section="spectrogram"' "$OUT/report.html"; }; then
    echo "check-demo: $OUT/report.html is not a whole report" >&2
    missing=1
fi
[ "$missing" -eq 0 ] && echo "check-demo: every result of the main job is in $OUT/"
exit "$missing"
