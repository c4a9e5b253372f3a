#!/usr/bin/env bash
# Measures the CI gate's baseline for this machine class: one configs/ci.toml sweep on this
# machine, from the committed code, filed by `nbody-bench gate --save-baseline` as
# results/baseline/ci-<CPU signature>-<logical CPUs>cpu.json (replacing this class's earlier
# file; the other classes' files stay). Run it on a quiet machine of a class CI runs on, after a
# change that is meant to alter the timings (or ci.toml), then commit the file. Takes about 20 s
# plus the build.
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
# Checked against itself (schema, machine, config) before it is filed.
"$bin" gate --baseline results/baseline --save-baseline "$out/ci/results.json"
echo "commit the new file of results/baseline/"
