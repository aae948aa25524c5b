#!/usr/bin/env bash
# Build vehsim's FMI 2.0 co-simulation FMU: bash fmu/build.sh [OUT] (default target/vehsim.fmu).
# Builds the fmu/ crate into the project's target/ (reusing the dependencies `cargo test
# --release` compiled there), then packages it with fmu/package.py (python3, standard library).
set -euo pipefail
cd "$(dirname "$0")/.."
OUT="${1:-target/vehsim.fmu}"
cargo build --release --locked -p vehsim-fmu
"${PYTHON:-python3}" fmu/package.py --lib target/release/libvehsim_fmu.so --out "$OUT"
