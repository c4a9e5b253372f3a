#!/usr/bin/env bash
# LAMMPS (`lmp`, the Debian/Ubuntu package `lammps`), installed with apt when missing and this
# runs as root; otherwise it stops with the command to run (exit 2). Idempotent.
set -euo pipefail

if command -v lmp >/dev/null 2>&1; then
    exit 0
fi
if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    echo "installing lammps"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq lammps >/dev/null
else
    echo "LAMMPS (lmp) is missing; install it with: sudo apt-get install -y lammps" >&2
    exit 2
fi
