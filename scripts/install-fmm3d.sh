#!/usr/bin/env bash
# FMM3D's Python interface (PyPI `fmm3dpy`, a wheel with the compiled library) and numpy in the
# peers' venv .peers/venv, for scripts/fmm3d-driver.py (configs/vs-fmm3d.toml) and the check
# scripts/test.sh runs (scripts/fmm3d-check.py); and pandas, with which the suite reads
# `export-results` tables back (tests/suite/export_results.rs). The venv is created when
# missing. Idempotent: nothing is done when all three import. About 10 s on a fresh machine
# (a few wheels).
set -euo pipefail
cd "$(dirname "$0")/.."

venv=.peers/venv
if "$venv/bin/python" -c "import fmm3dpy, numpy, pandas" >/dev/null 2>&1; then
    exit 0
fi
if [ ! -x "$venv/bin/python" ]; then
    echo "creating $venv"
    python3 -m venv "$venv"
fi
echo "installing fmm3dpy, numpy and pandas in $venv"
# The version measured in results/vs-fmm3d; numpy and pandas as pip resolves them (pytreegrav
# shares numpy).
"$venv/bin/pip" install --quiet "fmm3dpy==2.1.0" numpy pandas
