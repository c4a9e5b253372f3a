#!/usr/bin/env bash
# The Slurm path against a real Slurm (the one-node Slurm of scripts/slurm-local.sh, started
# here unless SLURM_CONF already points at one):
#   - the suite's Slurm tests (tests/suite/slurm.rs: a sweep through Slurm against one without,
#     an MPI case under srun in its job, a failing job, a job over its time limit, a sweep
#     killed while its job is queued and resumed);
#   - scripts/weak-mpi-job.sh under `sbatch -n 2 --wait`, checked for its results.
# Both at once: the time-limit test waits more than a minute for Slurm to stop its job.
#
#   scripts/slurm-tests.sh [CARGO TEST ARGS...]     e.g. --features mpi
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -z "${SLURM_CONF:-}" ]; then
    SLURM_LOCAL_CPUS=${SLURM_LOCAL_CPUS:-4} exec scripts/slurm-local.sh -- "$0" "$@"
fi
bin=${NBODY_BENCH_BIN:-target/release/nbody-bench}

cargo test --release "$@" --test suite -- --ignored slurm:: &
tests=$!

out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
status=0
OUT="$out" BASE_N=2000 STEPS=20 WARMUP=2 sbatch --wait --parsable -n 2 \
    --output="$out/job.out" scripts/weak-mpi-job.sh >/dev/null || status=$?
results=$(find "$out" -name results.json -path '*weak-mpi-*' | head -n 1)
if [ "$status" != 0 ] || [ -z "$results" ] || [ ! -s "$(dirname "$results")/mpi-bench.json" ]; then
    echo "scripts/weak-mpi-job.sh under sbatch failed (status $status); its output:" >&2
    cat "$out/job.out" >&2 || true
    wait "$tests" || true
    exit 1
fi
cases=$(python3 -c 'import json, sys; print(len(json.load(open(sys.argv[1]))["cases"]))' "$results")
echo "weak-mpi-job.sh under sbatch -n 2: $cases cases measured, mpi-bench.json written"
wait "$tests"
