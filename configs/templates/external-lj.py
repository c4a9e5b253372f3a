#!/usr/bin/env python3
"""mycode: a Lennard-Jones molecular-dynamics program in a periodic box, the one that
mycode.toml's [[external]] entry runs (written by `nbody-bench init --external mycode --lang
python --physics lj`). Standard library only.

It takes the atoms of --initial FILE, what `nbody-bench export --format lammps-data` writes for
the 3-D melt (the sweep exports the scenario's atoms into each case's work directory first, so
this program starts from the atoms our kernels start from): a periodic box, positions and
velocities in LJ reduced units (sigma, epsilon and the mass are 1), the cutoff and the time step
in its first line. It integrates them --steps steps with velocity Verlet, the force 12-6
Lennard-Jones truncated at the cutoff, each pair at its nearest image, and prints

    atoms N steps S dt DT cutoff RC threads T from FILE
    energy initial E0 final E1 relative drift D
    time total SECONDS

`time total` is the timed loop alone (time.perf_counter around the steps, in `evolve`): the sweep
reads it with the entry's `time` regex and divides it by the entry's `steps`. The energy (the
pair energy shifted to zero at the cutoff, as our kernels report it) is the sanity check the
entry's `check` looks for; it is computed outside the timed loop.

Measuring your own code (OpenMM, HOOMD, ASE...): replace the body of `evolve` with your code's
calls (the comment above it does this for OpenMM's CPU platform) and keep the rest, the
arguments, the timing and the printed lines, so that the config needs no change. --threads is
the sweep's thread count, for your code to use; this pure-Python loop runs one thread whatever
it is told. Run it alone first:

    nbody-bench export --scenario lj-melt -n 4000 --format lammps-data --out state.data
    python3 mycode.py --initial state.data --steps 2 --threads 1

usage: mycode.py --initial FILE --steps S [--threads T] [--dt DT]
Exit status: 0, or 2 for bad input (with a message saying what was wrong).
"""
import argparse
import math
import re
import sys
import time


class InputError(Exception):
    """Bad input: printed as the message, exit status 2."""


class Atoms:
    """Positions and velocities, one list per component (plain lists of floats are what pure
    Python indexes fastest), and the periodic box's sides."""

    def __init__(self, sides):
        self.sides = sides
        self.x, self.y, self.z = [], [], []
        self.vx, self.vy, self.vz = [], [], []

    def __len__(self):
        return len(self.x)


def read_state(path):
    """The atoms of a LAMMPS data file from `nbody-bench export --format lammps-data` and the
    cutoff and time step its first line names (the step in reduced units: the export's dt over
    its sigma, the time unit when epsilon and the mass are 1)."""
    try:
        lines = open(path, encoding="utf-8").read().splitlines()
    except OSError as e:
        raise InputError(f"--initial {path}: cannot read it ({e.strerror}); write it with "
                         "`nbody-bench export --scenario lj-melt --format lammps-data --out FILE`")
    head = lines[0] if lines else ""
    found = {key: re.search(pattern, head) for key, pattern in (
        ("dim", r"\bdim (\d+)"), ("dt", r"\bdt ([0-9.eE+-]+)"),
        ("sigma", r"sigma = ([0-9.eE+-]+)"), ("cutoff", r"cutoff ([0-9.eE+-]+) sigma"))}
    missing = [key for key, match in found.items() if match is None]
    if missing:
        raise InputError(f"--initial {path}: its first line names no {', '.join(missing)}; is "
                         "this a file of `nbody-bench export --format lammps-data`?")
    if found["dim"].group(1) != "3":
        raise InputError(f"--initial {path}: a {found['dim'].group(1)}-D state; this program "
                         "simulates the periodic 3-D melt: export the `lj-melt` scenario")
    params = {"cutoff": float(found["cutoff"].group(1)),
              "dt": float(found["dt"].group(1)) / float(found["sigma"].group(1))}
    sides, section, rows = {}, None, {"Atoms": {}, "Velocities": {}}
    for number, line in enumerate(lines[1:], 2):
        words = line.split("#")[0].split()
        if not words:
            continue
        where = f"--initial {path} line {number}"
        if len(words) == 4 and words[2][1:] == "lo" and words[3][1:] == "hi":
            lo, hi = numbers(words[:2], where)
            sides[words[2][0]] = hi - lo
        elif words[0] in ("Masses", "Atoms", "Velocities"):
            section = words[0]
        elif section == "Masses" and numbers(words[1:2], where) != [1.0]:
            raise InputError(f"{where}: mass {words[1]}: this program runs LJ's unit mass")
        elif section == "Atoms":
            rows[section][atom_id(words, 5, where)] = numbers(words[2:5], where)
        elif section == "Velocities":
            rows[section][atom_id(words, 4, where)] = numbers(words[1:4], where)
    if sorted(sides) != ["x", "y", "z"]:
        raise InputError(f"--initial {path}: no box (xlo xhi, ylo yhi, zlo zhi lines)")
    atoms = Atoms([sides["x"], sides["y"], sides["z"]])
    if not rows["Atoms"] or sorted(rows["Atoms"]) != sorted(rows["Velocities"]):
        raise InputError(f"--initial {path}: every atom needs a position and a velocity")
    for i in sorted(rows["Atoms"]):
        p, v = rows["Atoms"][i], rows["Velocities"][i]
        for column, value in zip((atoms.x, atoms.y, atoms.z, atoms.vx, atoms.vy, atoms.vz),
                                 (*p, *v)):
            column.append(value)
    if min(atoms.sides) < 2.0 * params["cutoff"]:
        raise InputError(f"--initial {path}: a box side of {min(atoms.sides):g} is under twice "
                         f"the cutoff {params['cutoff']:g}: an atom would meet two images of "
                         "another; export more atoms")
    return atoms, params


def atom_id(words, fields, where):
    """The id that starts a line of at least `fields` words of the Atoms or Velocities
    section."""
    if len(words) < fields or not words[0].isdigit():
        raise InputError(f"{where}: expected an atom id and {fields - 1} values, got "
                         f"{' '.join(words)!r}")
    return int(words[0])


def numbers(words, where):
    try:
        values = [float(w) for w in words]
    except ValueError as e:
        raise InputError(f"{where}: {e}")
    if not all(math.isfinite(v) for v in values):
        raise InputError(f"{where}: every value must be a finite number")
    return values


def pairs(atoms, rc):
    """Every pair (i, j) closer than the cutoff candidates: from a cell list of cells at least
    rc wide, each cell against itself and half of its 26 neighbours, or all pairs in a box
    too small for three cells a side."""
    n = len(atoms)
    counts = [max(1, int(side // rc)) for side in atoms.sides]
    if min(counts) < 3:
        for i in range(n):
            for j in range(i + 1, n):
                yield i, j
        return
    cx, cy, cz = counts
    cells = {}
    for i in range(n):
        key = tuple(int(p[i] % s / s * c) % c for p, s, c in
                    zip((atoms.x, atoms.y, atoms.z), atoms.sides, counts))
        cells.setdefault(key, []).append(i)
    half = [(dx, dy, dz) for dx in (-1, 0, 1) for dy in (-1, 0, 1) for dz in (-1, 0, 1)
            if (dx, dy, dz) > (0, 0, 0)]
    for (a, b, c), members in cells.items():
        for k, i in enumerate(members):
            for j in members[k + 1:]:
                yield i, j
        for dx, dy, dz in half:
            for j in cells.get(((a + dx) % cx, (b + dy) % cy, (c + dz) % cz), ()):
                for i in members:
                    yield i, j


def forces(atoms, rc, fx, fy, fz):
    """Overwrites fx, fy, fz with every atom's force; returns the shifted pair energy."""
    x, y, z = atoms.x, atoms.y, atoms.z
    lx, ly, lz = atoms.sides
    rc2 = rc * rc
    shift = 4.0 * (rc2 ** -6 - rc2 ** -3)
    for f in (fx, fy, fz):
        f[:] = [0.0] * len(f)
    energy = 0.0
    for i, j in pairs(atoms, rc):
        dx, dy, dz = x[i] - x[j], y[i] - y[j], z[i] - z[j]
        dx -= lx * round(dx / lx)
        dy -= ly * round(dy / ly)
        dz -= lz * round(dz / lz)
        r2 = dx * dx + dy * dy + dz * dz
        if r2 >= rc2:
            continue
        inv6 = 1.0 / (r2 * r2 * r2)
        energy += 4.0 * inv6 * (inv6 - 1.0) - shift
        w = 24.0 * inv6 * (2.0 * inv6 - 1.0) / r2
        fx[i] += w * dx
        fy[i] += w * dy
        fz[i] += w * dz
        fx[j] -= w * dx
        fy[j] -= w * dy
        fz[j] -= w * dz
    return energy


def energy(atoms, rc):
    """Kinetic plus potential energy."""
    n = len(atoms)
    kinetic = 0.5 * sum(atoms.vx[i] ** 2 + atoms.vy[i] ** 2 + atoms.vz[i] ** 2 for i in range(n))
    zero = [0.0] * n
    return kinetic + forces(atoms, rc, list(zero), list(zero), list(zero))


# Measuring a library instead: replace the body of `evolve` with its calls, and copy its atoms
# back into `atoms` at the end so that the energy line checks its result. OpenMM's CPU platform,
# for example (`pip install openmm`; reduced units map one to one onto OpenMM's: sigma = 1 nm,
# epsilon = 1 kJ/mol, mass 1 Da, tau = 1 ps):
#
#     import openmm
#     system = openmm.System()
#     system.setDefaultPeriodicBoxVectors(*(openmm.Vec3(*(s if k == d else 0 for k in range(3)))
#                                           for d, s in enumerate(atoms.sides)))
#     lj = openmm.NonbondedForce()
#     lj.setNonbondedMethod(openmm.NonbondedForce.CutoffPeriodic)
#     lj.setCutoffDistance(rc)
#     lj.setUseDispersionCorrection(False)
#     for _ in range(len(atoms)):
#         system.addParticle(1.0)
#         lj.addParticle(0.0, 1.0, 1.0)
#     system.addForce(lj)
#     integrator = openmm.VerletIntegrator(dt)
#     context = openmm.Context(system, integrator, openmm.Platform.getPlatformByName("CPU"),
#                              {"Threads": str(threads)})
#     context.setPositions(list(zip(atoms.x, atoms.y, atoms.z)))
#     # OpenMM's Verlet is leapfrog, its velocities half a step behind its positions: half a
#     # kick back from ours (and forward at the end) gives velocity Verlet's trajectory.
#     f = context.getState(getForces=True).getForces(asNumpy=True)._value
#     context.setVelocities([(atoms.vx[i] - 0.5 * dt * f[i][0], atoms.vy[i] - 0.5 * dt * f[i][1],
#                             atoms.vz[i] - 0.5 * dt * f[i][2]) for i in range(len(atoms))])
#     start = time.perf_counter()
#     integrator.step(steps)
#     elapsed = time.perf_counter() - start
#     state = context.getState(getPositions=True, getVelocities=True, getForces=True)
#     p, v, f = (q(asNumpy=True)._value for q in (state.getPositions, state.getVelocities,
#                                                 state.getForces))
#     for i in range(len(atoms)):
#         atoms.x[i], atoms.y[i], atoms.z[i] = p[i]
#         atoms.vx[i], atoms.vy[i], atoms.vz[i] = v[i] + 0.5 * dt * f[i]
#     return elapsed
def evolve(atoms, steps, dt, rc, threads):
    """Advances the atoms `steps` velocity-Verlet steps; returns the seconds this took, the time
    that the sweep measures (set-up before the clock starts is not counted). `threads` is the
    sweep's thread count: this loop runs one."""
    n = len(atoms)
    fx, fy, fz = [0.0] * n, [0.0] * n, [0.0] * n
    half = 0.5 * dt
    # The first forces are set-up: each timed step then evaluates them once, as our kernels' do.
    forces(atoms, rc, fx, fy, fz)
    start = time.perf_counter()
    for _ in range(steps):
        for v, f in ((atoms.vx, fx), (atoms.vy, fy), (atoms.vz, fz)):
            for i in range(n):
                v[i] += half * f[i]
        for p, v, side in ((atoms.x, atoms.vx, atoms.sides[0]), (atoms.y, atoms.vy, atoms.sides[1]),
                           (atoms.z, atoms.vz, atoms.sides[2])):
            for i in range(n):
                p[i] = (p[i] + dt * v[i]) % side
        forces(atoms, rc, fx, fy, fz)
        for v, f in ((atoms.vx, fx), (atoms.vy, fy), (atoms.vz, fz)):
            for i in range(n):
                v[i] += half * f[i]
    return time.perf_counter() - start


def arguments(argv):
    p = argparse.ArgumentParser(description="Lennard-Jones molecular dynamics in a periodic "
                                "box, velocity Verlet.")
    p.add_argument("--initial", metavar="FILE", required=True, help="atoms, box, cutoff and "
                   "step from `nbody-bench export --format lammps-data` (the lj-melt scenario)")
    p.add_argument("--steps", type=int, required=True, help="time steps of the timed loop")
    p.add_argument("--threads", type=int, default=1, help="threads for your code to use (this "
                   "pure-Python loop runs one)")
    p.add_argument("--dt", type=float, help="time step in reduced units [default: the file's]")
    args = p.parse_args(argv)
    if args.steps < 1 or args.threads < 1:
        p.error("--steps and --threads must be at least 1")
    if args.dt is not None and not (math.isfinite(args.dt) and args.dt > 0):
        p.error("--dt must be a finite number above 0")
    return args


def main(argv):
    args = arguments(argv)
    atoms, params = read_state(args.initial)
    rc = params["cutoff"]
    dt = args.dt if args.dt is not None else params["dt"]
    print(f"atoms {len(atoms)} steps {args.steps} dt {dt:g} cutoff {rc:g} threads {args.threads} "
          f"from {args.initial}")
    before = energy(atoms, rc)
    elapsed = evolve(atoms, args.steps, dt, rc, args.threads)
    after = energy(atoms, rc)
    # |ΔE/E|, never negative: a NaN or infinite energy prints `nan` or `inf`, which the
    # config's check (`relative drift [0-9]`) refuses as a failed run.
    drift = abs((after - before) / before) if before != 0 else abs(after - before)
    print(f"energy initial {before:.9e} final {after:.9e} relative drift {drift:.3e}")
    print(f"time total {elapsed:.9e}")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except InputError as e:
        print(f"{sys.argv[0]}: {e}", file=sys.stderr)
        sys.exit(2)
