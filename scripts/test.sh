#!/usr/bin/env bash
# Runs every check of the project: formatting, lints, unit and integration tests, the benches
# (once each), the force validation of every scenario, the MPI tests and the performance gate.
# Works on a fresh machine with a Rust toolchain (the MPI tests install Open MPI with apt when
# run as root).
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v cargo >/dev/null 2>&1; then
    echo "cargo not found: install Rust from https://rustup.rs" >&2
    exit 2
fi
rustup component add rustfmt clippy >/dev/null 2>&1 || true

cargo fmt --all -- --check
cargo clippy --all-targets --release -- -D warnings
cargo test --release
# The criterion benches, each benchmark run once (criterion's test mode), so they cannot rot.
cargo test --release --benches
cargo run --release --quiet -- validate --threads 2
# The performance gate (a fresh configs/ci.toml sweep against results/baseline/ci.json) runs
# before the MPI tests: it measures the default build, the one its baseline comes from.
scripts/ci-gate.sh
# The MPI drivers under mpirun (installs Open MPI with apt when missing and run as root).
scripts/mpi-tests.sh
