#!/usr/bin/env bash
# Build the vehsim wheel and run the Python package's tests in a fresh virtual environment.
# Needs python3 (>= 3.9, with venv and pip) and the Rust toolchain; installs the pinned tools of
# python/requirements-test.txt from PyPI. Run from anywhere; called by .ci/run.
set -euo pipefail
cd "$(dirname "$0")/.."
PY="${PYTHON:-python3}"
VENV=python/target/venv
rm -rf "$VENV" python/target/wheels
"$PY" -m venv "$VENV"
"$VENV/bin/python" -m pip install --quiet --disable-pip-version-check -r python/requirements-test.txt
# The CLI binary the tests compare against (already built by `cargo test --release`).
cargo build --release --bin vehsim
# The FMI 2.0 co-simulation FMU the FMPy tests import (fmu/: built into ./target, packaged into
# target/vehsim.fmu with the venv's Python).
PYTHON="$VENV/bin/python" bash fmu/build.sh target/vehsim.fmu
# python/ is a member of the project's workspace: the root Cargo.lock pins its crates and the build
# goes into the project's target/, reusing what the Rust suite compiled where features agree.
"$VENV/bin/maturin" build --release --locked --manifest-path python/Cargo.toml \
    --interpreter "$VENV/bin/python" --out python/target/wheels
"$VENV/bin/python" -m pip install --quiet --disable-pip-version-check --no-deps python/target/wheels/vehsim-*.whl
# From the project root, where no folder shadows the installed wheel. VEHSIM_REQUIRE_SLURM=1:
# python/tests/test_slurm.py starts a single-node Slurm (scripts/slurm_single_node.sh installs
# slurm-wlm and munge with apt-get when missing, which needs root) and fails, not skips, when it
# cannot.
VEHSIM_BIN="$PWD/target/release/vehsim" VEHSIM_FMU="$PWD/target/vehsim.fmu" VEHSIM_REQUIRE_CLI=1 VEHSIM_REQUIRE_SLURM=1 \
    "$VENV/bin/python" -m pytest -p no:cacheprovider -rs python/tests
