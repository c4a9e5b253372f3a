#!/usr/bin/env bash
# The established codes the vs-*.toml configs measure next to ours: LAMMPS (Debian/Ubuntu
# package `lammps`, with apt when missing and this runs as root; otherwise it stops with the
# command to run) and a Python venv at .peers/venv with pytreegrav, numba and numpy.
# Idempotent: what is there already is left as it is.
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/install-lammps.sh

venv=.peers/venv
if ! "$venv/bin/python" -c "import pytreegrav, numba, numpy" >/dev/null 2>&1; then
    echo "creating $venv with pytreegrav, numba, numpy"
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet --upgrade pip
    "$venv/bin/pip" install --quiet pytreegrav numba numpy
fi
echo "peers ready: $(lmp -h 2>/dev/null | awk 'NF && !done { print; done = 1 }'); pytreegrav in $venv"
