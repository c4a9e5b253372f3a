#!/usr/bin/env bash
# Measures every sweep REPORT.md uses into the committed reference results (results/<name>/,
# the only place besides an explicit --out that sweeps write to; a user's sweeps go to
# results/runs/), then regenerates the report from results/.
#
#   scripts/report.sh            measure what is missing or unfinished (resumes with this build), then report
#   scripts/report.sh --fresh    measure everything again (old results kept as .bak copies)
#   scripts/report.sh --report   only regenerate REPORT.md from the committed results
#
# About 35 minutes on a 2-vCPU Intel Xeon (2026-12-02), 9 of them the pytreegrav comparison
# (numba compiles in every run), plus about 25 for the MPI sweeps (scripts/mpi-report.sh). Run it on a quiet machine: the sweeps record the background
# load they saw, and the report shows it.
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=scripts/lib/sweep.sh
source scripts/lib/sweep.sh

CONFIGS=(complexity complexity-large strong strong-long-range weak weak-time octree-accuracy
    vs-lammps vs-lammps-liquid lammps-skin lammps-skin-liquid vs-pytreegrav vs-fmm3d
    seeds seeds-weak seeds-weak-time course-codes)
mode="${1:-}"
cargo build --release --quiet
bin=target/release/nbody-bench
if [[ "$mode" != "--report" ]]; then
    # The vs-*.toml sweeps run LAMMPS and pytreegrav next to our kernels; course-codes compiles
    # the course's C codes with mpicc.
    scripts/install-peers.sh
    scripts/install-mpi.sh
fi

if [[ "$mode" != "--report" ]]; then
    for name in "${CONFIGS[@]}"; do
        sweep_into_results "$bin" "$name" "$mode"
    done
    # The MPI sweeps and their mpi-bench files (rebuilds the binary with the mpi feature).
    scripts/mpi-report.sh "$mode"
fi
"$bin" report --results results --out REPORT.md
