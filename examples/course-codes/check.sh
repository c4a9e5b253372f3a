#!/usr/bin/env bash
# check.sh: builds the four course codes into a temporary directory (never into this folder),
# runs each at a tiny size and checks what the harness relies on. Exit 0 when everything holds,
# 1 with a message naming the failed check. A few seconds of CPU in all.
#
#   bash examples/course-codes/check.sh
#
# What is checked, and why the tolerances are what they are:
# (a) each run prints the header line and every phase, time and energy line, with the n, steps,
#     threads and ranks it was given, and its phases add up to its `time total` (at least 90%:
#     nothing large in the loop escapes the phases; at most 200%). On more than one rank the
#     phases are means over ranks and the total is the slowest rank's, so the two differ by how
#     unevenly the ranks leave the starting barrier and reach the end; on a machine whose ranks
#     share CPUs that is a scheduler slice or more (2 ms of a 5.6 ms run was seen in CI), as large
#     as these runs: on more than one rank only the upper bound is checked (the lower one is checked
#     on the serial and OpenMP codes);
# (b) energy conservation, relative to |E0|:
#     - LJ, 1e-3 over 100 steps of n = 200: velocity Verlet's error is bounded, and here it is set
#       by the hardest collisions (the r^-13 core; at dt = 1e-4 a fast pair closes 4% of sigma per
#       step) and by pairs crossing the cutoff, where the truncated force jumps. Over seeds 1-8 it
#       was at most 2e-4, so 1e-3 leaves a margin of 5; zeroed, halved or doubled initial
#       velocities (the assignment's bugs) change E by tens of percent;
#     - Coulomb, 1e-5 over 100 steps of n = 200 at seed 1: nothing collapses yet (measured
#       5e-7). The scenario itself does not conserve energy once an opposite pair falls together
#       (at n = 1000 seed 1 a pair does between steps 40 and 60; at n = 200 seed 2 does within
#       100), which is why this check uses a fixed, tiny case: the generator is ours, so the
#       initial state is the same on every machine;
# (c) the serial, OpenMP (1 and 2 threads) and MPI (1, 2, 3 ranks) LJ codes start from the same
#     state and agree on the final energy to 1e-6 relative: they differ only in the order of the
#     float32 force sums, which moves the 100-step energy by about 1e-9 relative, while 1e-6 is
#     still 100 times below the integrator's own error (a code that integrates differently shows);
#     the MPI codes give the same energy at every rank count (1e-12), as each particle's force
#     is summed in the same order whatever the blocks, and 3 ranks split n = 200 unevenly;
# and: -T sets the temperature (kinetic energy of n particles at T0 is n*T0, standard deviation
# sqrt(n)*T0; variance T0^2 or one velocity component would be far off), frames are written only
# with -o and have the NBView01 size, a bad option exits 2, a too-large time step stops the run.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
build=$(mktemp -d "${TMPDIR:-/tmp}/course-codes.XXXXXX")
trap 'rm -rf "$build"' EXIT

fail() {
    echo "check.sh: FAIL: $*" >&2
    exit 1
}
ok() { echo "ok   $*"; }

N=200
STEPS=100

# ------------------------------------------------------------------ build
if ! command -v mpicc >/dev/null 2>&1; then
    echo "mpicc not found: installing Open MPI with scripts/install-mpi.sh"
    bash "$repo/scripts/install-mpi.sh" || fail "no MPI: install Open MPI (libopenmpi-dev openmpi-bin)"
fi
compile() { # compiler, program, extra flags: any compiler output (a warning) is a failure
    local cc=$1 prog=$2
    shift 2
    local msg
    if ! msg=$("$cc" -O2 -Wall -Wextra "$@" "$here/$prog.c" -o "$build/$prog" -lm 2>&1); then
        fail "compiling $prog.c:"$'\n'"$msg"
    fi
    [ -z "$msg" ] || fail "$prog.c compiles with warnings:"$'\n'"$msg"
}
compile cc lj_serial -fopenmp
compile cc lj_omp -fopenmp
compile mpicc lj_mpi
compile mpicc coulomb_mpi
ok "built lj_serial, lj_omp (cc -fopenmp), lj_mpi, coulomb_mpi (mpicc) with no warnings"

mpirun_args=()
if mpirun --version 2>&1 | grep "Open MPI" >/dev/null; then
    mpirun_args=(--oversubscribe --bind-to none)
    [ "$(id -u)" = 0 ] && mpirun_args+=(--allow-run-as-root)
fi
on_ranks() { # ranks, program and arguments
    local r=$1
    shift
    mpirun "${mpirun_args[@]}" -n "$r" "$@"
}

# ------------------------------------------------------------------ helpers
# run NAME command...: runs, keeps stdout in $build/NAME.out, fails on a non-zero exit.
run() {
    local name=$1
    shift
    if ! "$@" >"$build/$name.out" 2>"$build/$name.err"; then
        fail "$name exited with an error:"$'\n'"$(tail -5 "$build/$name.err")"
    fi
}
value() { # name, line prefix (e.g. "phase force"): the number after it
    awk -v p="$2" 'index($0, p " ") == 1 { print $(NF) }' "$build/$1.out"
}
e0() { awk '/^energy initial/ { print $3 }' "$build/$1.out"; }
e1() { awk '/^energy initial/ { print $5 }' "$build/$1.out"; }
# rel a b: |a - b| / |b|
rel() { awk -v a="$1" -v b="$2" 'BEGIN { d = a - b; if (d < 0) d = -d; if (b < 0) b = -b; print d / b }'; }
below() { awk -v x="$1" -v t="$2" 'BEGIN { exit !(x <= t) }'; }

num='[0-9]+\.[0-9]{9}'
sci='-?[0-9]\.[0-9]{10}e[-+][0-9]{2,3}'
# (a): the lines, the header's fields and the phases against the total.
check_lines() { # name, program, n, steps, threads, ranks
    local f="$build/$1.out"
    grep -Eq "^course-code: $2 n=$3 steps=$4 threads=$5 ranks=$6\$" "$f" ||
        fail "$1: no line 'course-code: $2 n=$3 steps=$4 threads=$5 ranks=$6' in:"$'\n'"$(cat "$f")"
    for phase in force reduce integrate comm output; do
        grep -Eq "^phase $phase $num\$" "$f" || fail "$1: no 'phase $phase <seconds>' line"
    done
    grep -Eq "^time total $num\$" "$f" || fail "$1: no 'time total <seconds>' line"
    grep -Eq "^energy initial $sci final $sci\$" "$f" || fail "$1: no 'energy initial E0 final E1' line"
    [ "$(wc -l <"$f")" -eq 8 ] || fail "$1: expected 8 lines on stdout, got $(wc -l <"$f")"
    local sum total
    sum=$(awk '/^phase / { s += $3 } END { printf "%.9f", s }' "$f")
    total=$(value "$1" "time total")
    local lower=0.9
    [ "$6" -gt 1 ] && lower=0
    awk -v s="$sum" -v t="$total" -v l="$lower" 'BEGIN { exit !(s >= l * t && s <= 2.0 * t + 1e-4) }' ||
        fail "$1: phases add up to $sum s but time total is $total s"
}
check_drift() { # name, tolerance
    local d
    d=$(rel "$(e1 "$1")" "$(e0 "$1")")
    below "$d" "$2" || fail "$1: energy drift $d is above $2 (E0 $(e0 "$1"), E1 $(e1 "$1"))"
    echo "$d"
}

# ------------------------------------------------------------------ LJ codes
run lj_serial "$build/lj_serial" -n $N -F 1 -f $STEPS
check_lines lj_serial lj_serial $N $STEPS 1 1
d=$(check_drift lj_serial 1e-3) # an assignment, so that a failure inside stops the script
ok "lj_serial n=$N: all lines; energy drift $d (tolerance 1e-3)"
ref=$(e1 lj_serial)

for t in 1 2; do
    run lj_omp_$t env OMP_NUM_THREADS=$t "$build/lj_omp" -n $N -F 1 -f $STEPS
    check_lines lj_omp_$t lj_omp $N $STEPS $t 1
    d=$(check_drift lj_omp_$t 1e-3)
    x=$(rel "$(e1 lj_omp_$t)" "$ref")
    below "$x" 1e-6 || fail "lj_omp on $t threads ends at E $(e1 lj_omp_$t), lj_serial at $ref (relative $x > 1e-6)"
    ok "lj_omp $t thread(s): all lines; drift $d; final energy vs lj_serial $x (tolerance 1e-6)"
done

for r in 1 2 3; do
    run lj_mpi_$r on_ranks $r "$build/lj_mpi" -n $N -F 1 -f $STEPS
    check_lines lj_mpi_$r lj_mpi $N $STEPS 1 $r
    d=$(check_drift lj_mpi_$r 1e-3)
    x=$(rel "$(e1 lj_mpi_$r)" "$ref")
    below "$x" 1e-6 || fail "lj_mpi on $r ranks ends at E $(e1 lj_mpi_$r), lj_serial at $ref (relative $x > 1e-6)"
    [ "$(e0 lj_mpi_$r)" = "$(e0 lj_serial)" ] || fail "lj_mpi on $r ranks starts from another state (E0 $(e0 lj_mpi_$r))"
    y=$(rel "$(e1 lj_mpi_$r)" "$(e1 lj_mpi_1)")
    below "$y" 1e-12 || fail "lj_mpi: the final energy depends on the rank count ($r ranks: relative $y)"
    ok "lj_mpi $r rank(s): all lines; drift $d; final energy vs lj_serial $x, vs 1 rank $y"
done

# -T: the initial kinetic energy is the difference of E0 at T0 and at rest (same positions).
run lj_T0 "$build/lj_serial" -n $N -F 1 -f 1 -T 0
run lj_T2 "$build/lj_serial" -n $N -F 1 -f 1 -T 2
kin=$(awk -v a="$(e0 lj_T2)" -v b="$(e0 lj_T0)" 'BEGIN { print a - b }')
awk -v k="$kin" -v n=$N 'BEGIN { m = 2 * n; s = 2 * sqrt(n); exit !(k > m - 5 * s && k < m + 5 * s) }' ||
    fail "-T 2: initial kinetic energy $kin, expected $((2 * N)) (n*T0) within 5 standard deviations"
ok "-T 2: initial kinetic energy $kin (n*T0 = $((2 * N)), sd $(awk -v n=$N 'BEGIN { printf "%.0f", 2 * sqrt(n) }'))"

# Output: none without -o, NBView01 frames with it (header 9 + 8 bytes, 8 bytes per particle).
[ "$(value lj_serial "phase output")" = "0.000000000" ] || fail "lj_serial wrote output without -o"
frames_size=$((17 + 3 * N * 8)) # the initial frame and one after each of F = 2 frames
run lj_out "$build/lj_serial" -n $N -F 2 -f 10 -o "$build/serial.nbv"
run lj_mpi_out on_ranks 2 "$build/lj_mpi" -n $N -F 2 -f 10 -o "$build/mpi.nbv"
run coulomb_out on_ranks 2 "$build/coulomb_mpi" -n $N -s 20 -f 10 -o "$build/coulomb.nbv"
for f in serial mpi coulomb; do
    [ "$(head -c 9 "$build/$f.nbv")" = "NBView01" ] || fail "$f.nbv does not start with NBView01"
    size=$(wc -c <"$build/$f.nbv")
    [ "$size" -eq $frames_size ] || fail "$f.nbv has $size bytes, expected $frames_size"
done
cmp -s "$build/serial.nbv" "$build/mpi.nbv" && same="identical" || same="not identical"
ok "-o writes NBView01 frames of the expected size (lj_serial and lj_mpi files $same)"

# ------------------------------------------------------------------ Coulomb
for r in 1 2 3; do
    run coulomb_$r on_ranks $r "$build/coulomb_mpi" -n $N -s $STEPS
    check_lines coulomb_$r coulomb_mpi $N $STEPS 1 $r
    d=$(check_drift coulomb_$r 1e-5)
    y=$(rel "$(e1 coulomb_$r)" "$(e1 coulomb_1)")
    below "$y" 1e-12 || fail "coulomb_mpi: the final energy depends on the rank count ($r ranks: relative $y)"
    ok "coulomb_mpi $r rank(s): all lines; energy drift $d (tolerance 1e-5); vs 1 rank $y"
done

# ------------------------------------------------------------------ command line and failures
for prog in lj_serial lj_omp; do
    "$build/$prog" -h | grep "^usage:" >/dev/null || fail "$prog -h prints no usage"
    set +e
    "$build/$prog" -n 0 >/dev/null 2>&1
    st=$?
    set -e
    [ $st -eq 2 ] || fail "$prog -n 0 exits $st, expected 2"
done
for prog in lj_mpi coulomb_mpi; do
    on_ranks 2 "$build/$prog" -h | grep -c "^usage:" | grep -qx 1 || fail "$prog -h: not one usage text"
    set +e
    on_ranks 2 "$build/$prog" -x >/dev/null 2>&1
    st=$?
    set -e
    [ $st -ne 0 ] || fail "$prog -x (an unknown option) exits 0"
done
set +e
"$build/lj_serial" -n $N -F 1 -f $STEPS -t 0.05 >/dev/null 2>"$build/big_dt.err"
st=$?
set -e
[ $st -eq 1 ] && grep -q "reduce -t" "$build/big_dt.err" || fail "-t 0.05 did not stop at the walls"
ok "-h prints the usage (once under MPI), bad options fail, -t 0.05 stops with 'reduce -t'"

echo "check.sh: all checks passed"
