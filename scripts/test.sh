#!/usr/bin/env bash
# Runs every check of the project: formatting, lints, unit and integration tests, the benches
# (once each), the force validation of every scenario, the performance gate and the MPI tests.
# Works on a fresh machine with a Rust toolchain (Open MPI and libclang are installed with apt
# when missing and this runs as root).
#
# Compile time is most of the run, so the tests are built once, with one feature set: the
# default build (what users run) is built and checked first, and judged by the gate; then,
# with MPI installed, one `cargo test --features mpi --all-targets` builds the unit tests, the
# integration suite (one binary), the benches and the MPI binary together.
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v cargo >/dev/null 2>&1; then
    echo "cargo not found: install Rust from https://rustup.rs" >&2
    exit 2
fi
rustup component add rustfmt clippy >/dev/null 2>&1 || true
step() {
    echo "== $* ($(date -u +%H:%M:%S))" >&2
}

step "format and lints of the default build"
cargo fmt --all -- --check
cargo clippy --all-targets --release -- -D warnings

step "the default build: validation, the entry points that need MPI, the performance gate"
cargo build --release
target/release/nbody-bench validate --threads 2
scripts/no-mpi-check.sh target/release/nbody-bench
# The gate measures timings: nothing else runs meanwhile.
scripts/ci-gate.sh

step "Open MPI, lints and every test with the mpi feature"
scripts/install-mpi.sh
# The suite runs one small LAMMPS case through the harness (tests/suite/peers.rs), which fails
# without `lmp`: install it when missing (as root, with apt).
if ! command -v lmp >/dev/null 2>&1; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        echo "installing lammps"
        apt-get update -qq
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq lammps >/dev/null
    else
        echo "LAMMPS (lmp) is missing and this is not root: sudo apt-get install -y lammps" >&2
        exit 2
    fi
fi
cargo clippy --all-targets --release --features mpi -- -D warnings
# One build of every test target (unit tests, the integration suite, the benches in test
# mode, the examples, the binary), then the runs: the unit tests; the suite but its timing
# tests; those alone on one test thread (tests/suite/main.rs); each bench once (criterion's
# test mode, so that they cannot rot).
features=(--release --features mpi)
cargo test "${features[@]}" --all-targets --no-run
cargo test "${features[@]}" --lib --bins
cargo test "${features[@]}" --test suite -- --skip gate:: --skip dry_run::
cargo test "${features[@]}" --test suite -- --test-threads=1 gate:: dry_run::
cargo test "${features[@]}" --benches

step "the MPI drivers under mpirun"
NBODY_BENCH_BIN=target/release/nbody-bench scripts/mpi-tests.sh
step "all checks passed"
