#!/usr/bin/env bash
# The MPI tests, run for real: builds with `--features mpi` and checks under `mpirun -n 1..4`
# that distributed runs end in the state of the serial run (to rounding) with every particle
# present once, for the replicated and the spatial decomposition (the cell list and the Verlet
# list on the spatial one), that the distributed trees give forces within validate's bound,
# uneven particle counts, ranks left without particles, particles migrating beyond the
# neighbouring regions and rebalancing; then the error paths, the JSON outputs, `mpi-bench` and
# a sweep under the launcher.
#
# Open MPI and libclang (for the bindings) are installed by scripts/install-mpi.sh. Everything
# MPI-free (regions, statistics, byte counts, the wire format, the state comparison) is in
# `crate::decomp` and tested by `cargo test` without the feature. It never skips a test.
set -euo pipefail
cd "$(dirname "$0")/.."

fail() {
    echo "MPI TESTS FAILED: $*" >&2
    exit 1
}

scripts/install-mpi.sh
# scripts/test.sh passes the binary it built with the feature (NBODY_BENCH_BIN). Run alone,
# this builds it.
if [ -n "${NBODY_BENCH_BIN:-}" ]; then
    BIN=$NBODY_BENCH_BIN
else
    cargo build --release --features mpi
    BIN=target/release/nbody-bench
fi
MPIRUN=(mpirun --oversubscribe --bind-to none)
if [ "$(id -u)" = 0 ]; then
    MPIRUN+=(--allow-run-as-root)
fi
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT

# mpirun -n RANKS nbody-bench mpi-check ARGS..., which exits 1 on a mismatch.
check() {
    local ranks=$1
    shift
    echo "--- $ranks rank(s): mpi-check $*"
    # pipefail: mpi-check's status survives the tail.
    "${MPIRUN[@]}" -n "$ranks" "$BIN" mpi-check "$@" </dev/null | tail -n 5 ||
        fail "mpi-check $* on $ranks ranks"
}

# mpirun -n RANKS nbody-bench ARGS... must exit 2 and print MESSAGE.
refuses() {
    local ranks=$1 message=$2
    shift 2
    echo "--- $ranks rank(s): $* must be refused with: $message"
    local out status=0
    out=$("${MPIRUN[@]}" -n "$ranks" "$BIN" "$@" 2>&1 </dev/null) || status=$?
    [ "$status" = 2 ] || fail "$* exited with $status, not 2:
$out"
    grep -qF -- "$message" <<<"$out" || fail "$* did not say '$message':
$out"
}

for ranks in 1 2 3 4; do
    migration=()
    if [ "$ranks" -gt 1 ]; then migration=(--expect-migration); fi
    # Replicated data, uneven n (301 and 2001 divide by none of 2..4): naive (targets) and
    # symmetric (pair shares + Allreduce), on both laws.
    check "$ranks" --scenario coulomb --kernel naive --decomp allgather -n 301 --steps 10
    check "$ranks" --scenario coulomb --kernel symmetric --decomp allgather -n 301 --steps 10
    check "$ranks" --scenario lj-box --kernel naive --decomp allgather -n 2001 --steps 20
    check "$ranks" --scenario lj-box --kernel symmetric --decomp allgather -n 2001 --steps 20
    # Spatial decomposition: particles cross rank borders during the run.
    check "$ranks" --scenario lj-box --kernel cell-list --decomp domain -n 3001 --steps 60 ${migration[@]+"${migration[@]}"}
    # The Verlet list: full lists of the block's targets kept between steps (allgather), and
    # the owned particles' half list rebuilt as particles migrate (domain); 60 steps cross
    # many rebuilds.
    check "$ranks" --scenario lj-box --kernel verlet --decomp allgather -n 2001 --steps 60
    check "$ranks" --scenario lj-box --kernel verlet --decomp domain -n 3001 --steps 60 ${migration[@]+"${migration[@]}"}
done

# The distributed Barnes-Hut trees: forces within validate's bound at θ = 0.5 and energy drift
# of the order of the serial run's (a few hundred steps), for gravity and for Coulomb's two
# trees, with bodies crossing domains; the source's octants (8^k domains; other counts get
# balanced runs of cells) and the locally essential trees over a rebalanced bisection.
for ranks in 1 2 3 4; do
    # Bodies cross between ranks' domains within 30 steps; the 150 let the energy drift the
    # check compares with the serial run's build up. One rank has no domains to cross.
    migration=() steps=30
    if [ "$ranks" -gt 1 ]; then migration=(--expect-migration) steps=150; fi
    for decomp in octants tree; do
        check "$ranks" --scenario galaxy --kernel octree --decomp "$decomp" -n 2001 --steps "$steps" ${migration[@]+"${migration[@]}"}
        # (The plasma's charges barely leave their octants in 30 steps: the galaxy tests migration.)
        check "$ranks" --scenario coulomb --kernel octree --decomp "$decomp" -n 1501 --steps 30
    done
done
# Ranks without bodies, the quadrupole order, and rebalancing of the bisection.
check 4 --scenario galaxy --kernel octree --decomp octants -n 3 --steps 20 --expect-empty-rank
check 4 --scenario galaxy --kernel octree --decomp tree -n 3 --steps 20 --no-rebalance --expect-empty-rank
check 3 --scenario galaxy --kernel octree --decomp tree -n 3000 --steps 50 --multipole quadrupole --theta 0.7
check 3 --scenario galaxy --kernel octree --decomp octants -n 3000 --steps 50 --multipole quadrupole --theta 0.7
check 4 --scenario galaxy --kernel octree --decomp tree -n 2001 --steps 60 --rebalance-above 1.01 --expect-rebalance

# More kernels and shapes.
check 3 --scenario galaxy --kernel octree --decomp allgather -n 600 --steps 5
check 2 --scenario coulomb --kernel per-thread --decomp allgather -n 1500 --steps 5 --threads 2
check 3 --scenario lj-box --kernel cell-list --decomp allgather -n 2001 --steps 20
check 4 --scenario lj-box --kernel cell-list --decomp domain -n 3001 --steps 60 --rank-grid 2x2 --precision f64 --expect-migration
check 4 --scenario lj-liquid --kernel cell-list --decomp domain -n 4000 --steps 30 --precision f64 --expect-migration
check 4 --scenario lj-liquid --kernel verlet --decomp domain -n 4000 --steps 30 --precision f64 --expect-migration
# The liquid in f64: in f32 its rounding differences grow to near the tolerance in 30 steps.
check 3 --scenario lj-liquid --kernel verlet --decomp allgather -n 3000 --steps 30 --skin 0.005 --precision f64
# A list long enough to be split over the threads of each rank.
check 2 --scenario lj-liquid --kernel verlet --decomp domain -n 8000 --steps 30 --threads 2 --precision f64 --expect-migration
# Ranks with no particle at all.
check 4 --scenario lj-box --kernel cell-list --decomp domain -n 3 --steps 20 --no-rebalance --expect-empty-rank
check 4 --scenario lj-box --kernel symmetric --decomp allgather -n 3 --steps 20 --expect-empty-rank
# Particles that jump over a whole region in one step (a dilute gas, thin slabs, a long step):
# sent to their new owner through an all-to-all.
check 4 --scenario lj-box --kernel cell-list --decomp domain -n 40 --density 1 --dt 0.5 --steps 8 --rank-grid 1x4 --no-rebalance --precision f64 --expect-far-migration
# The boundaries move when the load drifts (a low threshold makes it happen early).
check 4 --scenario lj-box --kernel cell-list --decomp domain -n 400 --steps 100 --rank-grid 4x1 --rebalance-above 1.01 --expect-rebalance

# Errors: clear message, exit 2, every rank stops.
refuses 2 "needs --kernel cell-list or verlet" run --decomp domain --scenario lj-box --kernel naive -n 100
refuses 2 "--decomp tree distributes the Barnes-Hut tree and needs --kernel octree" run --decomp tree --scenario galaxy --kernel naive -n 100
refuses 2 "--decomp octants distributes the Barnes-Hut tree and needs --kernel octree" run --decomp octants --scenario galaxy --kernel cell-list -n 100
refuses 2 "--rank-grid applies to --decomp domain only" run --decomp tree --scenario galaxy --kernel octree -n 100 --rank-grid 2x1
refuses 2 "--skin applies to the verlet and cluster-pair kernels only" run --decomp allgather --scenario lj-box --kernel cell-list -n 100 --skin 0.003
refuses 1 "needs at least 2 ranks" mpi-bench --out "$TMP/bench.json"
refuses 3 "still outside the box after one reflection" \
    run --decomp domain --scenario lj-box --kernel cell-list -n 60 --density 20 --dt 0.1 --steps 20
refuses 2 "not of the form AxB" run --decomp domain --scenario lj-box --kernel cell-list -n 100 --rank-grid 2y1
[ ! -e "$TMP/bench.json" ] || fail "a refused mpi-bench left a file"

# Ranks started with different jobs (mpirun's MPMD form `-n 1 A : -n 1 B`): MPI starts, rank 0
# broadcasts the digest of its job, and every rank stops with exit 2 before any other
# collective: rank 0 names the ranks that differ, and they say what they ran. Each rank runs
# under a wrapper that records its own exit status; a timeout catches a hang.
cat >"$TMP/rank.sh" <<'WRAPPER'
#!/bin/sh
"$@"
status=$?
echo "$status" >"$RANK_STATUS.${OMPI_COMM_WORLD_RANK:-x}"
exit "$status"
WRAPPER
chmod +x "$TMP/rank.sh"
# mismatched DIFFERING_RANK APP [: APP ...], each APP `-n K SUBCOMMAND ARGS...`: mpirun must exit
# with 2, every rank must exit with 2 by itself, and the messages must name DIFFERING_RANK.
mismatched() {
    local differing=$1
    shift
    local apps=() word prev="" in_app=0 ranks=0
    for word in "$@"; do
        case "$word" in
        run | mpi-check)
            apps+=("$TMP/rank.sh" "$BIN" "$word")
            in_app=1
            ;;
        :)
            apps+=(:)
            in_app=0
            ;;
        *)
            apps+=("$word")
            if [ "$in_app" = 0 ] && [ "$prev" = -n ]; then ranks=$((ranks + word)); fi
            ;;
        esac
        prev=$word
    done
    echo "--- ranks started with different jobs: $*"
    local out status=0
    out=$(RANK_STATUS="$TMP/status" timeout 60 "${MPIRUN[@]}" -x RANK_STATUS "${apps[@]}" 2>&1 </dev/null) ||
        status=$?
    [ "$status" != 124 ] || fail "ranks started with different jobs hung: $*
$out"
    [ "$status" = 2 ] || fail "ranks started with different jobs: mpirun exited with $status, not 2: $*
$out"
    # Again with orte_abort_on_non_zero_status 0: mpirun then lets every rank end by itself
    # after the first exits with an error (and exits 0 itself), so each rank's own status and
    # message are seen.
    rm -f "$TMP"/status.*
    status=0
    out=$(RANK_STATUS="$TMP/status" timeout 60 "${MPIRUN[@]}" --mca orte_abort_on_non_zero_status 0 \
        -x RANK_STATUS "${apps[@]}" 2>&1 </dev/null) || status=$?
    [ "$status" != 124 ] || fail "ranks started with different jobs hung: $*
$out"
    local rank
    for ((rank = 0; rank < ranks; rank++)); do
        [ -e "$TMP/status.$rank" ] || fail "rank $rank reported no exit status: $*
$out"
        [ "$(cat "$TMP/status.$rank")" = 2 ] ||
            fail "rank $rank exited with $(cat "$TMP/status.$rank"), not 2: $*
$out"
    done
    grep -qF "the MPI ranks were not started with the same job: rank $differing (different arguments)" <<<"$out" ||
        fail "rank 0 did not name rank $differing: $*
$out"
    grep -qF "rank $differing was not started with rank 0's job (different arguments): it ran" <<<"$out" ||
        fail "rank $differing did not say what it ran: $*
$out"
}
JOB=(--decomp domain --scenario lj-box --kernel cell-list -n 500 --steps 3 --yes)
mismatched 1 -n 1 run "${JOB[@]}" : -n 1 run "${JOB[@]/3/30}"
mismatched 1 -n 1 run "${JOB[@]}" : -n 1 run "${JOB[@]/domain/allgather}"
mismatched 1 -n 1 run "${JOB[@]}" : -n 1 run "${JOB[@]/500/600}"
mismatched 1 -n 1 run "${JOB[@]}" --seed 1 : -n 1 run "${JOB[@]}" --seed 2
JOB_CHECK=(--decomp domain --scenario lj-box --kernel cell-list -n 500 --steps 3)
mismatched 1 -n 1 mpi-check "${JOB_CHECK[@]}" : -n 1 run "${JOB_CHECK[@]}"
mismatched 2 -n 2 run "${JOB[@]}" : -n 1 run "${JOB[@]/3/4}"

# Outputs.
echo "--- one rank without mpirun: run --decomp domain --json"
"$BIN" run --decomp domain --scenario lj-box --kernel cell-list -n 500 --steps 5 \
    --json "$TMP/single.json" </dev/null >/dev/null || fail "a single rank without mpirun"
for field in '"ranks": 1' '"decomposition": "domain"'; do
    grep -qF "$field" "$TMP/single.json" || fail "run --json of a single rank lacks $field"
done
python3 -c 'import json, sys; assert len(json.load(open(sys.argv[1]))["mpi"]["step_ns"]) == 5' \
    "$TMP/single.json" || fail "a single rank's run --json does not time its 5 steps"
echo "--- run --decomp domain --json"
"${MPIRUN[@]}" -n 2 "$BIN" run --decomp domain --scenario lj-box --kernel cell-list -n 4000 --steps 20 \
    --json "$TMP/run.json" </dev/null >/dev/null || fail "run --decomp domain"
for field in '"decomposition": "domain"' '"ranks": 2' '"comm_s"' '"wait_s"' '"bytes_sent"' \
    '"master_summary"' '"interactions"' '"per_rank"'; do
    grep -qF "$field" "$TMP/run.json" || fail "run --json lacks $field"
done
echo "--- mpi-bench"
"${MPIRUN[@]}" -n 2 "$BIN" mpi-bench --max-bytes 4096 --reps 20 --out "$TMP/bench.json" </dev/null >/dev/null ||
    fail "mpi-bench"
grep -qF '"schema": "nbody-bench/mpi-bench/v1"' "$TMP/bench.json" || fail "mpi-bench schema"
echo "--- sweep under mpirun"
"$BIN" sweep --config tests/configs/good/mpi-tiny.toml --out "$TMP" --no-calibration \
    >"$TMP/sweep.log" 2>&1 || fail "sweep under the MPI launcher: $(tail -n 20 "$TMP/sweep.log")"
grep -qF '"decomposition": "domain"' "$TMP/mpi-tiny/results.json" || fail "sweep results lack MPI rounds"

echo "MPI tests passed"
