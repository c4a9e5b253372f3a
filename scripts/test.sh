#!/usr/bin/env bash
# Runs every check of the project: formatting, lints, unit and integration tests, the benches
# (once each), the force validation of every scenario, and the performance gate. Works on a
# fresh machine with a Rust toolchain.
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v cargo >/dev/null 2>&1; then
    echo "cargo not found: install Rust from https://rustup.rs" >&2
    exit 2
fi
rustup component add rustfmt clippy >/dev/null 2>&1 || true

cargo fmt --all -- --check
cargo clippy --all-targets --release -- -D warnings
cargo test --release
# The criterion benches, each benchmark run once (criterion's test mode), so they cannot rot.
cargo test --release --benches
cargo run --release --quiet -- validate --threads 2
# The performance gate: a fresh configs/ci.toml sweep against results/baseline/ci.json.
scripts/ci-gate.sh
