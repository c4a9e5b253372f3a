#!/usr/bin/env bash
# FMM3D built from source the way its authors recommend, into its own venv .peers/fmm3d-native,
# for the `fmm3d-native-*` entries of configs/vs-fmm3d.toml (scripts/fmm3d-driver.py run with
# that venv's python). PyPI's `fmm3dpy` wheel (scripts/install-fmm3d.sh, .peers/venv) is the
# plain run beside it: a generic x86-64 build (SSE2, no AVX/FMA), without OpenMP and with the
# plain Fortran near-field kernels.
#
# What is built: the sdist of the same version as the wheel (fmm3dpy 2.1.0, the whole FMM3D
# source tree), its library lib-static/libfmm3d.a made with FMM3D's own makefile, then the
# Python extension modules (f2py, through the sdist's meson build) linked against that library,
# as FMM3D's `make python` does (python/setup.py upstream links ../lib-static/libfmm3d.a with
# FMM_FLIBS = '$(LIBS) $(OMPFLAGS)'). The sdist's meson build alone would compile the library
# itself at plain -O3, without -march=native, OpenMP or the vectorized kernels: it is patched
# here to link the makefile's library instead.
#
# The flags are the makefile's defaults for Linux/gcc (FMM3D's recommended build), spelt out
# below so that they are on record:
#   FFLAGS   = -fPIC -O3 -march=native -funroll-loops -std=legacy -w   (gfortran)
#   CXXFLAGS = -std=c++11 -DSCTL_PROFILE=-1 -fPIC -O3 -march=native -funroll-loops
#   FAST_KER=ON: the near field (the direct sums between neighbouring boxes, l3ddirect*,
#     h3ddirect*) through vec-kernels/, C++ kernels written with the SCTL SIMD library, which
#     -march=native lets use the machine's widest vectors (AVX2/AVX-512 with FMA); the makefile
#     turns OMP on with it.
#   OMP=ON: -fopenmp; the library's loops run on OMP_NUM_THREADS threads.
# -march=native makes the build fit this machine only: it is made where it runs, never copied.
#
# Optional: scripts/install-peers.sh calls it; CI does not (it takes a few minutes: the library
# is ~45 Fortran files at -O3 plus the C++ kernels). Needs gfortran, g++ and make (apt-get
# installs them when missing and this runs as root). Idempotent: nothing is done when the venv
# imports fmm3dpy and records this build (.peers/fmm3d-native/fmm3d-native-build.txt). The
# sources and objects stay in .peers/fmm3d-native/src, so a build cut short goes on from there.
set -euo pipefail
cd "$(dirname "$0")/.."

version=2.1.0
venv=.peers/fmm3d-native
record="$venv/fmm3d-native-build.txt"
if [ -f "$record" ] && "$venv/bin/python" -c "import fmm3dpy, numpy" >/dev/null 2>&1; then
    exit 0
fi

missing=()
for tool in gfortran g++ make; do
    command -v "$tool" >/dev/null 2>&1 || missing+=("$tool")
done
if [ ${#missing[@]} -gt 0 ]; then
    if [ "$(id -u)" -eq 0 ] && command -v apt-get >/dev/null 2>&1; then
        echo "installing ${missing[*]} with apt-get"
        apt-get update -qq
        apt-get install -y -qq gfortran g++ make >/dev/null
    else
        echo "install-fmm3d-native.sh: missing ${missing[*]}; run: apt-get install -y gfortran g++ make" >&2
        exit 1
    fi
fi

start=$(date +%s)
if [ ! -x "$venv/bin/python" ]; then
    echo "creating $venv"
    python3 -m venv "$venv"
fi
# The build tools in the venv itself: meson-python and numpy (whose f2py writes the wrappers and
# which the modules are built against), meson and ninja. The build runs without isolation so
# that it uses them, hence the venv's bin first on PATH (meson-python looks for `meson` there).
"$venv/bin/pip" install --quiet "numpy>=2" meson-python meson ninja
export PATH="$PWD/$venv/bin:$PATH"

src="$venv/src"
tree="$src/fmm3dpy-$version"
if [ ! -f "$tree/makefile" ]; then
    mkdir -p "$src"
    echo "downloading the fmm3dpy $version sdist"
    pip download --quiet --no-binary fmm3dpy --no-deps --no-build-isolation \
        "fmm3dpy==$version" -d "$src"
    tar -xzf "$src/fmm3dpy-$version.tar.gz" -C "$src"
fi

flags_f='-fPIC -O3 -march=native -funroll-loops -std=legacy -w'
flags_cxx='-std=c++11 -DSCTL_PROFILE=-1 -fPIC -O3 -march=native -funroll-loops'
# make.inc is how FMM3D's makefile takes local flags (it is read before the makefile adds
# -fopenmp for OMP=ON, which flags given on make's command line would override).
printf 'FFLAGS = %s\nCXXFLAGS = %s\n' "$flags_f" "$flags_cxx" >"$tree/make.inc"
echo "building libfmm3d.a (FAST_KER=ON, OMP=ON; FFLAGS $flags_f -fopenmp)"
# `libfmm3d.a` is the makefile's target for the static library (it moves it to lib-static/).
make -C "$tree" -j"$(nproc)" FAST_KER=ON OMP=ON libfmm3d.a >"$src/make.log" 2>&1 ||
    { tail -30 "$src/make.log" >&2; exit 1; }

# The sdist's meson build, made to link lib-static/libfmm3d.a (with libgomp for OpenMP and
# libstdc++ for the C++ kernels) instead of compiling the library itself.
"$venv/bin/python" - "$tree/meson.build" <<'EOF'
import sys
path = sys.argv[1]
text = open(path).read()
start = text.find("fmm3d_lib = static_library(")
if start >= 0:  # not patched yet
    old_lib = text[start:text.index(")\n", start) + 2]
    new_lib = ("fmm3d_lib = declare_dependency(link_args: [meson.project_source_root() / "
               "'lib-static/libfmm3d.a', '-fopenmp', '-lgomp', '-lstdc++', '-lm'])\n")
    text = text.replace(old_lib, new_lib)
    text = text.replace("dependencies: [f2py_dep],\n    link_with: [fmm3d_lib],",
                        "dependencies: [f2py_dep, fmm3d_lib],")
    assert "link_with: [fmm3d_lib]" not in text, "meson.build not as expected"
    open(path, "w").write(text)
EOF
echo "building and installing fmm3dpy against it"
pip install --quiet --no-build-isolation --no-deps --force-reinstall "./$tree" \
    || { echo "install-fmm3d-native.sh: pip install of the patched sdist failed" >&2; exit 1; }

"$venv/bin/python" -c "import fmm3dpy, numpy"
so=$("$venv/bin/python" -c "import fmm3dpy.lfmm3d_fortran as m; print(m.__file__)")
ldd "$so" | grep libgomp >/dev/null ||
    { echo "install-fmm3d-native.sh: $so is not linked with OpenMP" >&2; exit 1; }
{
    echo "fmm3dpy $version from its sdist, libfmm3d.a by FMM3D's makefile"
    echo "make FAST_KER=ON OMP=ON libfmm3d.a"
    echo "FFLAGS=$flags_f -fopenmp"
    echo "CXXFLAGS=$flags_cxx"
    echo "$(gfortran --version | head -1)"
    echo "built on $(uname -m), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2-) in $(($(date +%s) - start)) s"
} >"$record"
echo "fmm3dpy $version built natively in $venv ($(($(date +%s) - start)) s)"
