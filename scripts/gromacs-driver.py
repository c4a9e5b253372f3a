#!/usr/bin/env python3
"""GROMACS's mdrun on LAMMPS's in.lj, from the atoms our kernels start from.

usage: gromacs-driver.py STATE.data STEPS THREADS [GMX]

STATE.data is what `nbody-bench export --format lammps-data` writes for the 3-D Lennard-Jones melt
(lj-melt): a periodic box, one atom type of mass 1, positions and velocities in LJ reduced units.
GMX is the `gmx` program to run (default: `gmx` on the PATH, Debian's package). The run is the
physics of configs/lammps/in.melt: 12-6 Lennard-Jones with epsilon = sigma = 1 cut (not shifted:
vdw-modifier None) at 2.5 sigma, no dispersion correction, periodic in x, y and z, NVE (no
thermostat; the centre of mass's drift, zero in the export, removed every 100 steps) at
dt = 0.005 tau, the pair list built to rc + skin = 2.8 sigma every 20 steps without a check
(in.lj's own rule; GROMACS prunes it between builds). Reduced units map one to one onto
GROMACS's: sigma = 1 nm, epsilon = 1 kJ/mol and m = 1 u make tau = 1 ps.

GROMACS is run as its users run it on one node: one thread-MPI rank with THREADS OpenMP threads,
the nonbonded work on the CPU, its own cluster pair list and SIMD kernels. The time is mdrun's
wall time over the second half of the steps (-resethway: the start-up, the first list and the
load balancing fall in the first half), doubled to stand for STEPS steps.

Prints
    gromacs VERSION simd SIMD threads T atoms N steps S (timed S/2)
    time total SECONDS
    gromacs done
Exit status: 0, 1 when gmx fails (its log's last lines on stderr), or 2 for bad input.
"""
import os
import re
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "lib"))
from lammps_data import InputError, read as read_lammps_data  # noqa: E402

CUTOFF = 2.5
SKIN = 0.3
DT = 0.005
NSTLIST = 20


def write_inputs(directory, sides, positions, velocities, steps):
    """conf.gro (positions and velocities at 8 decimals: GROMACS reads the precision from the
    first line's layout), topol.top (one atom type, sigma = epsilon = 1) and grompp.mdp."""
    with open(os.path.join(directory, "conf.gro"), "w") as f:
        f.write("lj-melt from nbody-bench export\n")
        f.write(f"{len(positions)}\n")
        for i, (p, v) in enumerate(zip(positions, velocities)):
            f.write(f"{(i + 1) % 100000:5d}{'LJ':<5}{'LJ':>5}{(i + 1) % 100000:5d}"
                    + "".join(f"{c:17.8f}" for c in p) + "".join(f"{c:17.8f}" for c in v) + "\n")
        f.write("".join(f"{s:17.8f}" for s in sides) + "\n")
    with open(os.path.join(directory, "topol.top"), "w") as f:
        f.write("[ defaults ]\n; nbfunc comb-rule gen-pairs\n1 2 no 1.0 1.0\n\n"
                "[ atomtypes ]\n; name mass charge ptype sigma epsilon\nLJ 1.0 0.0 A 1.0 1.0\n\n"
                "[ moleculetype ]\nLJ 1\n\n[ atoms ]\n1 LJ 1 LJ LJ 1 0.0 1.0\n\n"
                f"[ system ]\nlj-melt\n\n[ molecules ]\nLJ {len(positions)}\n")
    with open(os.path.join(directory, "grompp.mdp"), "w") as f:
        f.write(f"""integrator = md
dt = {DT}
nsteps = {steps}
cutoff-scheme = Verlet
verlet-buffer-tolerance = -1
nstlist = {NSTLIST}
rlist = {CUTOFF + SKIN}
vdwtype = Cut-off
vdw-modifier = None
rvdw = {CUTOFF}
coulombtype = Cut-off
rcoulomb = {CUTOFF}
DispCorr = no
pbc = xyz
tcoupl = no
pcoupl = no
comm-mode = Linear
nstcomm = 100
continuation = yes
gen-vel = no
nstcalcenergy = 100
nstenergy = 0
nstlog = 0
nstxout = 0
nstvout = 0
nstfout = 0
""")


def run(command, directory):
    """Runs a gmx command in `directory`; its output, or exit 1 with its last lines."""
    env = dict(os.environ, GMX_MAXBACKUP="-1")
    try:
        done = subprocess.run(command, cwd=directory, env=env, capture_output=True, text=True)
    except FileNotFoundError:
        raise InputError(f"{command[0]} not found: install GROMACS (apt install gromacs) or name "
                         "the gmx program as the fourth argument")
    if done.returncode != 0:
        tail = "\n".join((done.stdout + done.stderr).splitlines()[-25:])
        print(f"gromacs-driver.py: {' '.join(command)} failed:\n{tail}", file=sys.stderr)
        sys.exit(1)
    return done.stdout + done.stderr


def main(argv):
    if len(argv) not in (4, 5):
        raise InputError("usage: gromacs-driver.py STATE.data STEPS THREADS [GMX]")
    path, gmx = argv[1], argv[4] if len(argv) == 5 else "gmx"
    try:
        steps, threads = int(argv[2]), int(argv[3])
    except ValueError:
        raise InputError(f"STEPS and THREADS are integers (got {argv[2]!r}, {argv[3]!r})")
    if steps < 2 or threads < 1:
        raise InputError(f"STEPS is at least 2 and THREADS at least 1 (got {steps}, {threads})")
    lo, sides, positions, velocities = read_lammps_data(path)
    # A .gro box starts at the origin.
    positions = [tuple(p[d] - lo[d] for d in range(3)) for p in positions]
    if min(sides) < 2 * (CUTOFF + SKIN):
        raise InputError(f"{path}: a box side of {min(sides)} is under twice the list radius "
                         f"{CUTOFF + SKIN}")
    with tempfile.TemporaryDirectory(prefix="gromacs-", dir=os.path.dirname(path) or ".") as d:
        write_inputs(d, sides, positions, velocities, steps)
        run([gmx, "grompp", "-f", "grompp.mdp", "-c", "conf.gro", "-p", "topol.top",
             "-o", "topol.tpr", "-maxwarn", "0"], d)
        run([gmx, "mdrun", "-s", "topol.tpr", "-ntmpi", "1", "-ntomp", str(threads), "-nb", "cpu",
             "-resethway", "-noconfout", "-g", "md.log"], d)
        with open(os.path.join(d, "md.log")) as f:
            log = f.read()
    wall = re.search(r"^\s*Time:\s+([0-9.eE+-]+)\s+([0-9.eE+-]+)", log, re.M)
    version = re.search(r"GROMACS version:\s+(\S+)", log)
    simd = re.search(r"SIMD instructions:\s+(\S+)", log)
    if wall is None:
        print("gromacs-driver.py: no `Time:` line in mdrun's log", file=sys.stderr)
        return 1
    timed = steps - steps // 2
    named = [f"gromacs {version.group(1)}" if version else "gromacs (its log names no version)",
             f"simd {simd.group(1)}" if simd else "simd (not in its log)"]
    print(f"{' '.join(named)} threads {threads} atoms {len(positions)} steps {steps} "
          f"(timed {timed})")
    print(f"time total {float(wall.group(2)) * steps / timed:.9f}")
    print("gromacs done")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv))
    except InputError as e:
        print(f"gromacs-driver.py: {e}", file=sys.stderr)
        sys.exit(2)
