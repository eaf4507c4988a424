#!/usr/bin/env bash
# Targeted mutation testing (cargo-mutants 27): each named module against the
# tests that guard it. Not part of CI. Results and the missed mutants:
# firmware/docs/mutants.md.
#
#   hil-tests/mutants.sh                   # every target below, in order
#   hil-tests/mutants.sh detector wheel    # some targets by name
#   hil-tests/mutants.sh --list            # the targets and their mutant counts
#   hil-tests/mutants.sh --iterate detector
#       # again, skipping the mutants the last run caught or found unviable
#       # (after adding tests, or to finish an interrupted run)
#
# It mutates the checkout it lives in (`--in-place`) and restores each file
# after each mutant, so run it in a clone you are not editing meanwhile:
#
#   git clone --branch BRANCH REPO CLONE && CLONE/hil-tests/mutants.sh
#
# Give the clone a target directory no other checkout builds in meanwhile:
# cargo names a workspace member's build by its path inside the workspace,
# so two checkouts of the project sharing one target directory share their
# builds, and the other checkout may test a mutant's.
#
# Speed: copying the tree and building it cold cost 789 s before the first
# mutant. In place, with a warm target directory (CARGO_TARGET_DIR if set,
# else the clone's own target/), each mutant rebuilds only the mutated crate
# and the test binaries named for its target. Incremental builds of the
# mutated crate (a few hundred MB of cache, the dependencies are never
# incremental), no debug info and opt-level 1 for that crate alone make a
# rebuild a few seconds and its property tests twice as fast as at opt-level
# 0. Figures: firmware/docs/mutants.md.
#
# Needs `cargo install cargo-mutants --locked`. Output goes to
# mutants.out/<target>/mutants.out/ (git-ignored): outcomes.json and the
# caught/missed/unviable/timeout lists.
set -euo pipefail
cd "$(dirname "$0")/.."

export CARGO_PROFILE_DEV_DEBUG=0 CARGO_INCREMENTAL=1
# A mutant's failures are no regressions of the code: keep proptest from
# writing them into the committed regression files.
export PROPTEST_DISABLE_FAILURE_PERSISTENCE=1
# Longest a mutant's tests may run, s: the slowest target's baseline is
# under 15 s even on a loaded machine, so a mutant past this has made
# something loop.
timeout_s="${MUTANTS_TIMEOUT_S:-60}"

# name | package | file | name filters (comma-separated) | test targets (built and run)
#   [| test name filter (the tests run of those targets)]
targets=(
  "detector|wobble-core|firmware/core/src/detector/machine.rs|analyse|--test detector_machine --test detector_props --test sampler_detector"
  "loss-accounting|wobble-core|firmware/core/src/logger/mod.rs|.|--lib --test logger_card"
  "nmea-lines|wobble-core|firmware/core/src/gps/line.rs|.|--lib --test gps_properties --test gps_captures"
  "edge-time|wobble-core|firmware/core/src/wheel_capture.rs|.|--lib --test wheel_capture_props"
  "queue|wobble-core|firmware/core/src/channels.rs|RecordQueue|--lib"
  "episode-fit|wobblog|host-tools/src/analysis/episodes.rs|measure,neighbours|--test analysis_corpus --test analysis_residual --test censored_episodes --test streaming_analysis --test close_episodes"
  "episode-search|wobblog|host-tools/src/analysis/search.rs|EpisodeSearch::analyse|--test streaming_analysis --test censored_episodes"
  "wheel|wobble-core|firmware/core/src/wheel.rs|.|--lib --test wheel_sensor"
  "sdcard|wobble-core|firmware/core/src/drivers/sdcard.rs|.|--test sd_init --test sd_init_no_card --test sd_operation --test sd_reidentify"
  "gnss-bringup|wobble-core|firmware/core/src/drivers/gnss_bringup.rs|.|--test gnss_bringup --test gnss_setup --test gps_setup_runner"
  "selftest|wobble-core|firmware/core/src/selftest.rs|.|--lib --test selftest_card"
  "resample|wobblog|host-tools/src/resample.rs|.|--lib --test csv_checks"
  "decimator|wobblog|host-tools/src/plot/mod.rs|Decimator|--lib --test plot_figures"
  "csv-lines|wobblog|host-tools/src/export/text.rs|.|--lib --test roundtrip"
  "line-writer|wobblog|host-tools/src/export/lines.rs|.|--lib --test broken_pipe"
  "event-order|wobblog|host-tools/src/events.rs|TimeOrder|--lib --test events_config"
  "gpx-track|wobblog|host-tools/src/cmd/gpx.rs|.|--test gpx_track --test log_semantics --test broken_pipe"
  "naming|wobble-model|host-tools/bicycle-model/src/naming.rs|speeds,sway_like,classify|--test naming_grid --test rigid_rider --test sway_mode --test wobble_model --test whipple_benchmark --test bicycleparameters_bicycles"
  "critical|wobble-model|host-tools/bicycle-model/src/critical.rs|sign,by_newton|--lib"
  "critical-newton|wobble-model|host-tools/bicycle-model/src/critical/newton.rs|.|--lib"
  "margin-regression|wobblog|host-tools/src/analysis/margin/[!t]*.rs|.|--lib|analysis::margin::"
  "decay-trend|wobble-core|firmware/core/src/detector/trend.rs|.|--lib --test detector_machine --test detector_props"
  "margin-warning|wobble-core|firmware/core/src/detector/margin.rs|MarginWarning,fieller,estimate,robust_line,weighted_line,between_kick_variance,median,t_975|--lib|detector::margin::"
)

list=false
iterate=()
wanted=()
for a in "$@"; do
  case "$a" in
    --list) list=true ;;
    --iterate) iterate=(--iterate) ;;
    *) wanted+=("$a") ;;
  esac
done

# In place means a mutated file is briefly in the work tree: refuse a tree
# with uncommitted changes, so `git diff` afterwards shows exactly what a
# run left behind (nothing, unless it was killed mid-mutant).
if ! $list && ! git diff --quiet HEAD; then
  echo "mutants.sh: uncommitted changes in $(pwd); run it in a clean clone" >&2
  exit 2
fi

for t in "${targets[@]}"; do
  IFS='|' read -r name package file filter tests test_filter <<<"$t"
  if ((${#wanted[@]})) && [[ ! " ${wanted[*]} " =~ " $name " ]]; then
    continue
  fi
  # The test targets go to every cargo call, so the build before each mutant
  # builds only these binaries, not all of the package's tests.
  cargo_args=(--cargo-arg="--config=profile.dev.package.$package.opt-level=1")
  for w in $tests; do
    [[ "$w" == --test ]] && continue
    if [[ "$w" == --lib ]]; then cargo_args+=(--cargo-arg=--lib); else cargo_args+=(--cargo-arg="--test=$w"); fi
  done
  filters=(-p "$package" -f "$file")
  for re in ${filter//,/ }; do filters+=(-F "$re"); done
  if $list; then
    echo "$name: $(cargo mutants --list "${filters[@]}" | wc -l) mutants ($file, $filter; $tests $test_filter)"
    continue
  fi
  echo "== $name: $file ($filter), tests $tests $test_filter"
  out="mutants.out/$name"
  mkdir -p "$out"
  start=$(date +%s)
  # In place runs one mutant at a time (no `-j`). Exit status 2 (missed
  # mutants) or 3 (timeouts) is the result; anything else is a failed run.
  status=0
  cargo mutants --no-shuffle --in-place --timeout "$timeout_s" "${filters[@]}" \
    "${cargo_args[@]}" "${iterate[@]}" --output "$out" -- ${test_filter:+"$test_filter"} || status=$?
  if ((status != 0 && status != 2 && status != 3)); then
    echo "mutants.sh: cargo mutants failed on $name (status $status)" >&2
    exit 1
  fi
  r="$out/mutants.out"
  count() { if [[ -s "$r/$1.txt" ]]; then grep -c . "$r/$1.txt"; else echo 0; fi; }
  echo "== $name: $(count caught) caught, $(count missed) missed, $(count unviable) unviable," \
    "$(count timeout) timeouts in $(($(date +%s) - start)) s" \
    "$( ((${#iterate[@]})) && echo "($(count previously_caught) caught or unviable before)")"
  sed 's/^/  missed: /' "$r/missed.txt" 2>/dev/null || true
  if ! git diff --quiet HEAD; then
    echo "mutants.sh: the run left $(git diff --name-only HEAD) changed; restore it with git checkout" >&2
    exit 1
  fi
done
