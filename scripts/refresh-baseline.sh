#!/usr/bin/env bash
# Re-measures the CI gate's baseline, results/baseline/ci.json: one configs/ci.toml sweep on
# this machine, from the committed code. Run it on a quiet machine of the CI machine class
# (the CPU model and signature CI reports), after a change that is meant to alter the timings
# (or ci.toml), then commit the file. Takes about 20 s plus the build.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ -n "$(git status --porcelain --untracked-files=no 2>/dev/null)" ]; then
    echo "warning: uncommitted changes: the baseline will not describe a commit" >&2
fi
cargo build --release --quiet
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
# The lock keeps other timing runs on this machine from overlapping with the sweep.
lock=()
if command -v flock >/dev/null 2>&1; then
    lock=(flock /tmp/nbody-bench.lock)
fi
${lock[@]+"${lock[@]}"} cargo run --release --quiet -- sweep --config configs/ci.toml --out "$out"
mkdir -p results/baseline
cp "$out/ci/results.json" results/baseline/.ci.json.tmp
mv results/baseline/.ci.json.tmp results/baseline/ci.json
# The new baseline must pass against itself (schema, machine, config).
cargo run --release --quiet -- gate --baseline results/baseline/ci.json \
    --current results/baseline/ci.json >/dev/null
echo "results/baseline/ci.json refreshed; commit it"
