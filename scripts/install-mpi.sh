#!/usr/bin/env bash
# Open MPI and libclang (for the bindings generator of mpi-sys), installed with apt when missing
# and this runs as root; otherwise it stops with the command to run. Idempotent.
set -euo pipefail

# libclang and its headers, which the bindings generator of mpi-sys needs at build time.
have_libclang() {
    if command -v dpkg >/dev/null 2>&1; then
        dpkg -s libclang-dev >/dev/null 2>&1
    else
        # Not grep -q: under pipefail an early exit of grep can fail the pipe (SIGPIPE).
        ldconfig -p 2>/dev/null | grep libclang >/dev/null
    fi
}

have_mpi() {
    command -v mpirun >/dev/null 2>&1 &&
        { pkg-config --exists ompi 2>/dev/null || pkg-config --exists mpich 2>/dev/null; } &&
        have_libclang
}

if have_mpi; then
    exit 0
fi
packages="libopenmpi-dev openmpi-bin libclang-dev"
if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    echo "installing $packages"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $packages >/dev/null
else
    echo "MPI is not installed. Install it, e.g.: sudo apt-get install -y $packages" >&2
    exit 2
fi
if ! have_mpi; then
    echo "MPI or libclang still missing after installing $packages" >&2
    exit 1
fi
