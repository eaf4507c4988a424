#!/usr/bin/env bash
# The property tests and fuzz harnesses with fresh random seeds and more
# cases: what the test command (`hil-tests/test-all.sh`, a fixed seed from
# `.cargo/config.toml`, the same cases on every run) never draws. Not part
# of CI: a failure here is a new case to keep, not a broken landing.
#
#   hil-tests/proptest-fresh.sh                       # 3 rounds of the whole suite
#   ROUNDS=10 hil-tests/proptest-fresh.sh -p wobblog  # cargo test arguments pass through
#
# Each round draws a new seed and prints it first; tests whose config leaves
# the number of cases to proptest run PROPTEST_CASES (default 2048) of them,
# the fuzz harnesses WOBBLOG_FUZZ_SECONDS (default 60) each. On a failure
# the round's seed is printed again: rerun with
#
#   PROPTEST_RNG_SEED=SEED cargo test ... TEST_NAME
#
# and keep the case: proptest writes it to the test's
# `*.proptest-regressions` file (commit it), or write it out as a plain
# test with its values, as `tests/kick_episodes.rs` does.
set -euo pipefail
cd "$(dirname "$0")/.."

rounds=${ROUNDS:-3}
export PROPTEST_CASES=${PROPTEST_CASES:-2048}
export WOBBLOG_FUZZ_SECONDS=${WOBBLOG_FUZZ_SECONDS:-60}

for round in $(seq 1 "$rounds"); do
    seed=$(od -An -N8 -tu8 /dev/urandom | tr -d ' ')
    printf '\n==> round %s of %s: PROPTEST_RNG_SEED=%s\n' "$round" "$rounds" "$seed"
    if ! PROPTEST_RNG_SEED=$seed cargo test "$@"; then
        printf '\nfailed with PROPTEST_RNG_SEED=%s\n' "$seed" >&2
        exit 1
    fi
done
