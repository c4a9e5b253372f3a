#!/usr/bin/env bash
# The CI performance gate: a fresh configs/ci.toml sweep (about 20 s), compared with the
# committed baseline results/baseline/ci.json. Exit 0 when no case regressed, 1 when one did,
# 2 for bad input. The threshold comes from the noise study in the README (CI section);
# NBODY_BENCH_GATE_THRESHOLD overrides it. With GITHUB_STEP_SUMMARY set, the Markdown table is
# appended to the job summary too.
#
# A baseline from another machine class (CPU model or logical CPU count) cannot judge this
# machine's timings: the gate then says so and this script passes without gating, unless
# NBODY_BENCH_GATE_STRICT_MACHINE=1. Refresh the baseline on the CI machine class with
# scripts/refresh-baseline.sh.
set -euo pipefail
cd "$(dirname "$0")/.."

threshold="${NBODY_BENCH_GATE_THRESHOLD:-0.25}"
baseline=results/baseline/ci.json
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT

cargo build --release --quiet
lock=()
if command -v flock >/dev/null 2>&1; then
    lock=(flock /tmp/nbody-bench.lock)
fi
echo "performance gate: sweeping configs/ci.toml (about 20 s)" >&2
if ! "${lock[@]}" cargo run --release --quiet -- sweep --config configs/ci.toml --out "$out" \
    >"$out/sweep.log" 2>&1; then
    cat "$out/sweep.log" >&2
    exit 2
fi
current="$out/ci/results.json"

status=0
cargo run --release --quiet -- gate --baseline "$baseline" --current "$current" \
    --threshold "$threshold" 2>"$out/gate.err" || status=$?
cat "$out/gate.err" >&2
if [ "$status" = 2 ] && grep -q "comes from another machine" "$out/gate.err" \
    && [ "${NBODY_BENCH_GATE_STRICT_MACHINE:-0}" != 1 ]; then
    echo "performance gate skipped: $baseline was measured on another machine class" >&2
    exit 0
fi
if [ -n "${GITHUB_STEP_SUMMARY:-}" ]; then
    cargo run --release --quiet -- gate --baseline "$baseline" --current "$current" \
        --threshold "$threshold" --format markdown >>"$GITHUB_STEP_SUMMARY" 2>/dev/null || true
fi
exit "$status"
