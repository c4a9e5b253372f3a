# Sourced by scripts/report.sh and scripts/mpi-report.sh: sweep_into_results BIN NAME MODE sweeps
# configs/NAME.toml into the committed results/NAME/: from scratch with MODE --fresh (the old
# file kept as .bak), resuming an unfinished one otherwise. Every sweep's cases are appended to
# the performance history of the machine class (results/history/, `nbody-bench history`).
sweep_into_results() {
    local bin=$1 name=$2 mode=$3
    echo "== sweep configs/$name.toml"
    if [[ "$mode" == "--fresh" ]]; then
        "$bin" sweep --config "configs/$name.toml" --out results --fresh --record
    elif [[ -f "results/$name/results.json" ]]; then
        "$bin" sweep --config "configs/$name.toml" --out results --resume --force --record
    else
        "$bin" sweep --config "configs/$name.toml" --out results --record
    fi
}
