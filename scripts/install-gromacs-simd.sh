#!/usr/bin/env bash
# GROMACS built for this machine's SIMD, in .peers/gromacs-simd (its `gmx` at
# .peers/gromacs-simd/bin/gmx), for configs/vs-lammps-melt.toml's `gromacs-simd` runs.
#
# Debian's `gromacs` package is compiled for SSE4.1, so that it runs on every amd64 CPU; its
# rules say to build with the SIMD detected for local use, which is what GROMACS's own install
# guide asks for speed. This builds the same release (Debian's source package, 2022.5) that way:
# GMX_SIMD chosen by GROMACS's CMake for this CPU (AVX_512 or AVX2_256), OpenMP, no MPI or GPU,
# GROMACS's own FFT (the melt has no PME). About a quarter of an hour of both cores the first
# time; never in CI. As root it installs cmake and enables Debian's source lists with apt when
# missing.
# Idempotent: a `gmx` that runs here is left as it is. A machine of another SIMD level needs a
# new build: `--rebuild`.
set -euo pipefail
cd "$(dirname "$0")/.."

prefix=$PWD/.peers/gromacs-simd
if [[ "${1:-}" == "--rebuild" ]]; then
    rm -rf "$prefix"
elif [[ -n "${1:-}" ]]; then
    echo "usage: scripts/install-gromacs-simd.sh [--rebuild]" >&2
    exit 2
fi
# A build for a SIMD level this CPU lacks stops with a fatal error: it does not count as there.
ready() {
    echo "GROMACS for this machine's SIMD is ready:" \
         "$("$prefix/bin/gmx" --version 2>/dev/null | grep 'SIMD instructions')"
}
if "$prefix/bin/gmx" --version >/dev/null 2>&1; then
    ready
    exit 0
fi

if ! command -v cmake >/dev/null 2>&1 || ! command -v g++ >/dev/null 2>&1; then
    if [[ $(id -u) -ne 0 ]]; then
        echo "cmake and g++ are needed: sudo apt-get install -y cmake g++" >&2
        exit 2
    fi
    DEBIAN_FRONTEND=noninteractive apt-get install -y -q cmake g++ >/dev/null
fi

work=.peers/gromacs-src
mkdir -p "$work"
if ! compgen -G "$work/gromacs_*.orig.tar.gz" >/dev/null; then
    if [[ $(id -u) -ne 0 ]]; then
        echo "Debian's GROMACS source is fetched with apt as root (apt-get source gromacs); run" \
             "this as root, or put gromacs_*.orig.tar.gz in $work" >&2
        exit 2
    fi
    sources=/etc/apt/sources.list.d/nbody-bench-src.sources
    if ! apt-get source --print-uris gromacs >/dev/null 2>&1; then
        codename=$(. /etc/os-release && echo "$VERSION_CODENAME")
        printf '%s\n' "Types: deb-src" "URIs: http://deb.debian.org/debian" "Suites: $codename" \
            "Components: main" "Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg" \
            >"$sources"
        apt-get update -q >/dev/null
    fi
    (cd "$work" && apt-get source -q --download-only gromacs >/dev/null 2>&1)
fi
tarball=$(compgen -G "$work/gromacs_*.orig.tar.gz" | grep -v regressiontests | head -n 1)
version=$(basename "$tarball" | sed 's/^gromacs_\(.*\)\.orig\.tar\.gz$/\1/')
rm -rf "$work/gromacs-$version" "$work/build"
tar -xzf "$tarball" -C "$work"

echo "building GROMACS $version for this machine's SIMD into $prefix (about a quarter of an hour)"
cmake -S "$work/gromacs-$version" -B "$work/build" -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_INSTALL_PREFIX="$prefix" -DGMX_OPENMP=ON -DGMX_MPI=OFF -DGMX_GPU=OFF \
    -DGMX_FFT_LIBRARY=fftpack -DGMX_HWLOC=OFF -DGMXAPI=OFF -DGMX_INSTALL_LEGACY_API=OFF \
    -DBUILD_TESTING=OFF -DGMX_BUILD_HELP=OFF -DGMX_USE_MUPARSER=INTERNAL \
    -DGMX_VERSION_STRING_OF_FORK="simd-build" >"$work/cmake.log" 2>&1 ||
    { tail -n 30 "$work/cmake.log" >&2; exit 1; }
cmake --build "$work/build" --target install -j "$(nproc)" >"$work/build.log" 2>&1 ||
    { tail -n 30 "$work/build.log" >&2; exit 1; }
rm -rf "$work/build" "$work/gromacs-$version"
ready
