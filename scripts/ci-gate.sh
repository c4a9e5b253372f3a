#!/usr/bin/env bash
# The CI performance gate: `nbody-bench gate`, which judges this build on whatever machine CI
# runs on. Exit 1 when a case regressed (always, in every format), else 2 when it cannot judge
# (bad input, missing cases, a base revision that is missing or does not build), else 0 — it
# never passes without judging.
#
# - results/baseline/ holds one baseline per machine class (CPU model, CPU signature, logical
#   CPUs). If one was measured on this machine class, this build reproduces it, and the
#   machine's calibrated FMA rate is within 12 % of the baseline's, the gate sweeps the config
#   stored in it with this build and compares with it (the fast path, about 15 s).
# - Otherwise (another class, a stale baseline, or the machine running faster or slower than
#   when its baseline was measured) it builds the baseline's commit in a git worktree (cached in
#   target/gate-base/) and measures both builds here case by case, round by round, both at
#   the same moment on a CPU each where two are free, else in turns (A/B).
#   scripts/refresh-baseline.sh on such a machine adds its class's file.
# The thresholds and the rule are docs/explanation/gate.md's, measured by `nbody-bench
# gate-study` on each machine class.
#
# NBODY_BENCH_GATE_AGAINST=REV always runs A/B against REV: a pull-request job sets it to the
# pull request's base commit (for example NBODY_BENCH_GATE_AGAINST="$GITHUB_BASE_SHA" after a
# checkout with fetch-depth: 0, so the commit is present). NBODY_BENCH_GATE_THRESHOLD overrides
# the threshold. With GITHUB_STEP_SUMMARY set, the Markdown table is appended to the job
# summary. What the gate measured is kept under results/runs/gate/.
#
# NBODY_BENCH_GATE_BASELINE=PATH takes another baseline file or folder than results/baseline;
# NBODY_BENCH_GATE_CURRENT=RESULTS judges a sweep already measured (a results.json, a run
# directory or a config name) instead of measuring this build.
#
# NBODY_BENCH_BIN=PATH judges that binary (scripts/test.sh passes the one its test build made:
# a `cargo build` would compile the crate again, since the tests' dev-dependencies change the
# features of shared dependencies); without it, this builds one.
set -euo pipefail
cd "$(dirname "$0")/.."

bin=${NBODY_BENCH_BIN:-}
if [ -z "$bin" ]; then
    cargo build --release --quiet
    bin=target/release/nbody-bench
fi
args=(--baseline "${NBODY_BENCH_GATE_BASELINE:-results/baseline}")
if [ -n "${NBODY_BENCH_GATE_CURRENT:-}" ]; then
    args+=(--current "$NBODY_BENCH_GATE_CURRENT")
fi
if [ -n "${NBODY_BENCH_GATE_THRESHOLD:-}" ]; then
    args+=(--threshold "$NBODY_BENCH_GATE_THRESHOLD")
fi
if [ -n "${NBODY_BENCH_GATE_AGAINST:-}" ]; then
    args+=(--against "$NBODY_BENCH_GATE_AGAINST")
fi
# The lock keeps other timing runs on this machine from overlapping with the gate's.
lock=()
if command -v flock >/dev/null 2>&1; then
    lock=(flock /tmp/nbody-bench.lock)
fi
if [ -n "${GITHUB_STEP_SUMMARY:-}" ]; then
    status=0
    ${lock[@]+"${lock[@]}"} "$bin" gate "${args[@]}" --format markdown \
        | tee -a "$GITHUB_STEP_SUMMARY" || status=$?
    exit "$status"
fi
exec ${lock[@]+"${lock[@]}"} "$bin" gate "${args[@]}"
