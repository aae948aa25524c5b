#!/usr/bin/env bash
# vehsim against a public peer: the same 10 s sine steer on mu 0.15 ice in vehsim (`vehsim bench`)
# and in CommonRoad's single-track drift model (commonroad-vehicle-models from PyPI, classic RK4
# at 1 ms in Python), timed in interleaved pairs; prints both runs' peak yaw rate and the median
# ratio of the pairs. The case and how each side is set up: scripts/bench_commonroad.py.
#
#   scripts/bench_commonroad.sh [PAIRS] [VEHSIM_RUNS] [CR_STEP_S]   (defaults 5, 50 and 0.001)
#
# Builds target/release/vehsim if needed; installs the pinned CommonRoad package into a throwaway
# virtual environment in a temporary folder, removed at the end with the run's files. Needs
# python3 with venv and pip, and network access to PyPI. Takes about PAIRS x 1.5 s plus the install.
set -euo pipefail
cd "$(dirname "$0")/.."
PAIRS=${1:-5}
RUNS=${2:-50}
STEP=${3:-0.001}
COMMONROAD=commonroad-vehicle-models==3.0.2
cargo build --release --quiet --bin vehsim
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"${PYTHON:-python3}" -m venv "$tmp/venv"
"$tmp/venv/bin/python" -m pip install --quiet --disable-pip-version-check "$COMMONROAD"
TMPDIR=$tmp "$tmp/venv/bin/python" scripts/bench_commonroad.py --vehsim target/release/vehsim \
    --spec maneuvers/sine_steer.toml --tir vehicles/tyres/srtt_p225_60r16.tir --pairs "$PAIRS" --vehsim-runs "$RUNS" --step "$STEP"
