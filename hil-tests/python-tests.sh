#!/usr/bin/env bash
# Builds the Python package (host-tools/python) into a virtual environment
# and runs its tests (pytest), which compare it with the CLI built here.
# Run by test-all.sh; idempotent: the environment and the Cargo target
# directory are kept, so a second run only rebuilds what changed.
set -euo pipefail
cd "$(dirname "$0")/.."

TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target}"
VENV="$TARGET_DIR/python-venv"
# The test dependencies: the build backend, the runner, the libraries the
# package's Arrow tables are read with, and the MCAP reader with its ROS 2
# decoder (the CLI's MCAP files are read with them): `name` or
# `name:module` where the module is named otherwise.
PY_PACKAGES=(maturin pytest polars pyarrow pandas duckdb mcap mcap-ros2-support:mcap_ros2)

if [ ! -x "$VENV/bin/python" ]; then
    # Debian's Python has no venv module (ensurepip) without python3-venv.
    if ! python3 -c "import ensurepip, venv" 2>/dev/null; then
        SUDO=""
        [ "$(id -u)" -eq 0 ] || SUDO=sudo
        $SUDO apt-get update
        DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y python3-venv
    fi
    rm -rf "$VENV"
    python3 -m venv "$VENV"
fi
missing=()
for entry in "${PY_PACKAGES[@]}"; do
    "$VENV/bin/python" -c "import ${entry#*:}" 2>/dev/null || missing+=("${entry%%:*}")
done
if ((${#missing[@]})); then
    "$VENV/bin/python" -m pip install --quiet "${missing[@]}"
fi

cargo clippy -p wobblog-python --all-targets -- -D warnings
# The CLI whose outputs the tests compare with (already built by demo.sh).
cargo build -q --release -p wobblog --bin wobblog
# The package as a user installs it (`pip install ./host-tools/python`),
# with the environment's maturin instead of a fresh one per build; the
# extension is built once, in the shared target directory.
PATH="$VENV/bin:$PATH" CARGO_TARGET_DIR="$TARGET_DIR" "$VENV/bin/python" -m pip install --quiet \
    --no-build-isolation --force-reinstall --no-deps ./host-tools/python
WOBBLOG_CLI="$TARGET_DIR/release/wobblog" "$VENV/bin/python" -m pytest -q host-tools/python/tests
