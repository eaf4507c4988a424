#!/usr/bin/env bash
# Targeted mutation testing (cargo-mutants 27): each named module against the
# tests that guard it. Not part of CI: a full pass takes tens of minutes on
# two cores. Results and the missed mutants: firmware/docs/mutants.md.
#
#   hil-tests/mutants.sh            # every target below
#   hil-tests/mutants.sh queue      # one target by name
#
# Needs `cargo install cargo-mutants --locked`. Output goes to
# mutants.out/<target>/ (git-ignored).
set -euo pipefail
cd "$(dirname "$0")/.."

# name | package | file | name filter | test arguments
targets=(
  "queue|wobble-core|firmware/core/src/channels.rs|RecordQueue|--lib"
  "edge-time|wobble-core|firmware/core/src/wheel_capture.rs|.|--lib --test wheel_capture_props"
  "detector|wobble-core|firmware/core/src/detector/machine.rs|analyse|--test detector_machine --test detector_props --test sampler_detector"
  "wheel|wobble-core|firmware/core/src/wheel.rs|.|--lib --test wheel_sensor"
  "nmea-lines|wobble-core|firmware/core/src/gps/line.rs|.|--lib --test gps_properties --test gps_captures"
  "loss-accounting|wobble-core|firmware/core/src/logger/mod.rs|.|--lib --test logger_card"
  "episode-fit|wobblog|host-tools/src/analysis/episodes.rs|measure|--test analysis_corpus --test analysis_residual"
)

want="${1:-}"
for t in "${targets[@]}"; do
  IFS='|' read -r name package file filter tests <<<"$t"
  [[ -n "$want" && "$want" != "$name" ]] && continue
  echo "== $name: $file ($filter)"
  mkdir -p "mutants.out/$name"
  # shellcheck disable=SC2086 # the test arguments are words
  cargo mutants -j 1 --no-shuffle -p "$package" -f "$file" -F "$filter" \
    --output "mutants.out/$name" -- $tests || true
  grep -h . "mutants.out/$name/mutants.out/missed.txt" 2>/dev/null | sed 's/^/  missed: /' || true
done
