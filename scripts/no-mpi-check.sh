#!/usr/bin/env bash
# A build without the `mpi` feature refuses every MPI entry point with exit 2 and the rebuild
# hint, and writes nothing. The same check as tests/suite/mpi_cli.rs runs without the feature;
# CI builds its tests with the feature, so it checks the default binary here instead.
#   scripts/no-mpi-check.sh target/release/nbody-bench
set -euo pipefail
bin="$1"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
printf 'name = "m"\nstudy = "cartesian"\nscenarios = ["lj-box"]\nkernels = ["naive"]\nn = [100]\n[mpi]\nranks = [1]\n' \
    >"$tmp/c.toml"
hint='built without the `mpi` feature; rebuild with `--features mpi`'
refused() {
    local out status=0
    out=$("$bin" "$@" 2>&1 </dev/null) || status=$?
    if [ "$status" != 2 ] || ! grep -qF -- "$hint" <<<"$out"; then
        echo "no-MPI check FAILED: $* exited with $status:" >&2
        echo "$out" >&2
        exit 1
    fi
}
refused run --scenario lj-box --kernel cell-list --decomp domain
refused mpi-bench --out "$tmp/b.json"
refused mpi-check --scenario coulomb --kernel naive --decomp allgather
refused sweep --config "$tmp/c.toml" --out "$tmp"
if [ -e "$tmp/b.json" ] || [ -e "$tmp/m" ]; then
    echo "no-MPI check FAILED: a refused command left a file" >&2
    exit 1
fi
echo "no-MPI check passed: every MPI entry point refused with the rebuild hint"
