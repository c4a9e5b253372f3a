#!/usr/bin/env bash
# Measures the CI gate's baseline for this machine class: one configs/ci.toml sweep on this
# machine, from the committed code, filed by `nbody-bench gate --save-baseline` as
# results/baseline/ci-<CPU signature>-<logical CPUs>cpu.json (the other classes' files stay).
# Run it on a quiet machine of a class CI runs on, after a change that is meant to alter the
# timings (or ci.toml), then commit the file. Takes about 20 s plus the build when the class has
# no baseline yet.
#
# A baseline never absorbs a regression silently: when the class already has a baseline, this
# build and the commit that baseline records are first measured side by side (A/B: the base
# revision is built in a git worktree, cached under target/gate-base/, then both builds are
# interleaved case by case; minutes), judged as every A/B gate run is. If a case regressed, the
# old file is kept, the script exits 1 and names each regressed case with its ratio and CI.
# A slowdown that is intended is accepted by naming every regressed case, with the reason:
#
#   scripts/refresh-baseline.sh --accept CASE... --reason "why it is slower"
#
# Every argument is passed on to `gate --save-baseline` (also --rounds, --threshold, --out,
# --record DIR). An acceptance is appended to results/history/<class>.gate.jsonl (or --record's
# DIR): commit it with the new baseline.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ -n "$(git status --porcelain --untracked-files=no 2>/dev/null)" ]; then
    echo "warning: uncommitted changes: the baseline will not describe a commit" >&2
fi
cargo build --release --quiet
bin=target/release/nbody-bench
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
# The lock keeps other timing runs on this machine from overlapping with the sweep.
lock=()
if command -v flock >/dev/null 2>&1; then
    lock=(flock /tmp/nbody-bench.lock)
fi
${lock[@]+"${lock[@]}"} "$bin" sweep --config configs/ci.toml --out "$out"
# Checked against itself (schema, machine, config), and A/B against the replaced baseline's
# commit, before it is filed; the A/B run measures too, so it holds the lock as well.
${lock[@]+"${lock[@]}"} "$bin" gate --baseline results/baseline --save-baseline "$out/ci/results.json" "$@"
echo "commit the new file of results/baseline/ (and, after --accept, results/history/)"
