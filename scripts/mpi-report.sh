#!/usr/bin/env bash
# Measures the MPI sweeps REPORT.md uses, with the mpi-bench files that predict them, into
# results/<name>/ (called by scripts/report.sh; takes the same --fresh):
#
# - configs/weak-mpi.toml (the LJ gas: replicated data and the spatial decomposition) with
#   mpi-bench on 2 and 4 ranks;
# - configs/weak-mpi-tree.toml (the galaxy: allgather, octants, tree) with mpi-bench on 2 ranks;
# - configs/weak-mpi-tree-tcp.toml, the same over TCP on loopback, with mpi-bench on 2 ranks
#   under `--mca btl tcp,self`;
# - configs/seeds-mpi-strong.toml, the Barnes-Hut report's strong scaling over MPI processes at
#   2000 bodies.
#
# About 25 minutes on a 2-vCPU machine. Installs Open MPI when missing (scripts/install-mpi.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=scripts/lib/sweep.sh
source scripts/lib/sweep.sh

mode="${1:-}"
scripts/install-mpi.sh
cargo build --release --quiet --features mpi
bin=target/release/nbody-bench
mpirun=(mpirun --oversubscribe --bind-to none)
if [ "$(id -u)" = 0 ]; then
    mpirun+=(--allow-run-as-root)
fi
lock=()
if command -v flock >/dev/null 2>&1; then
    lock=(flock /tmp/nbody-bench.lock)
fi

bench() { # DIR RANKS FILE [MPIRUN ARGS...]
    local dir=$1 ranks=$2 file=$3
    shift 3
    mkdir -p "results/$dir"
    echo "== mpi-bench on $ranks ranks $* -> results/$dir/$file"
    ${lock[@]+"${lock[@]}"} "${mpirun[@]}" "$@" -n "$ranks" "$bin" mpi-bench --out "results/$dir/$file"
}

sweep() { # NAME
    sweep_into_results "$bin" "$1" "$mode"
}

bench weak-mpi 2 mpi-bench-2.json
bench weak-mpi 4 mpi-bench-4.json
sweep weak-mpi
bench weak-mpi-tree 2 mpi-bench-2.json
sweep weak-mpi-tree
bench weak-mpi-tree-tcp 2 mpi-bench-tcp-2.json --mca btl tcp,self
sweep weak-mpi-tree-tcp
sweep seeds-mpi-strong
