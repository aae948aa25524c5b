#!/usr/bin/env bash
# Every check and test, Rust and Python: README's test command, and what `.ci/run` runs.
# Style first (cheap, and a failure there should not wait for the suites): formatting, clippy
# with warnings as errors on every target, the API docs with warnings as errors; then the Rust
# suite and the Python package's (python/test.sh). The slow suites are in scripts/test-long.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo fmt --check
cargo clippy --release --all-targets --locked -- -D warnings
RUSTDOCFLAGS="-D warnings" cargo doc --release --no-deps --locked
cargo test --release --locked
bash python/test.sh
