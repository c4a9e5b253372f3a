#!/usr/bin/env python3
"""OpenMM's CPU platform on LAMMPS's in.lj, from the atoms our kernels start from.

usage: openmm-driver.py STATE.data STEPS THREADS

STATE.data is what `nbody-bench export --format lammps-data` writes for a 3-D Lennard-Jones
scenario (lj-melt): a periodic box, one atom type of mass 1, positions and velocities in LJ
reduced units. The run is the physics of configs/lammps/in.melt: 12-6 Lennard-Jones with
epsilon = sigma = 1 cut (not shifted) at 2.5 sigma, no long-range dispersion correction, the
minimum image in the periodic box, NVE with OpenMM's Verlet integrator (leapfrog, started half a
step back so that its trajectory is velocity Verlet's) at dt = 0.005 tau. Reduced units
map one to one onto OpenMM's: sigma = 1 nm, epsilon = 1 kJ/mol and m = 1 Da make tau = 1 ps.

OpenMM is run as its users run it for this physics: NonbondedForce with CutoffPeriodic (its
vectorized CPU kernel and its own neighbour list), the CPU platform on THREADS threads. The
timed loop is `integrator.step(STEPS)` alone; the context's creation (the first neighbour list)
and the energies around it are outside it, as LAMMPS's "Loop time" leaves out its setup.

Prints
    openmm VERSION platform CPU threads T atoms N steps S
    energy initial E0 final E1 relative drift D
    time total SECONDS
    openmm done
Exit status: 0, or 2 for bad input (with a message saying what was wrong).
"""
import sys
import time

CUTOFF = 2.5
DT = 0.005


class InputError(Exception):
    """Bad input: printed as the message, exit status 2."""


def read_lammps_data(path):
    """The box sides, positions and velocities of a LAMMPS data file (atom style atomic)."""
    try:
        with open(path) as f:
            lines = f.read().splitlines()
    except OSError as e:
        raise InputError(f"cannot read {path}: {e.strerror}")
    sides, section, atoms, velocities = {}, None, {}, {}
    for line in lines[1:]:
        words = line.split("#")[0].split()
        if not words:
            continue
        if len(words) == 4 and words[2].endswith("lo") and words[3].endswith("hi"):
            sides[words[2][0]] = float(words[1]) - float(words[0])
        elif words[0] in ("Atoms", "Velocities", "Masses"):
            section = words[0]
        elif section == "Atoms" and len(words) >= 5:
            atoms[int(words[0])] = tuple(float(w) for w in words[2:5])
        elif section == "Velocities" and len(words) >= 4:
            velocities[int(words[0])] = tuple(float(w) for w in words[1:4])
        elif section == "Masses" and len(words) >= 2 and float(words[1]) != 1.0:
            raise InputError(f"{path}: atom mass {words[1]}; this driver runs LJ's unit mass")
    if sorted(sides) != ["x", "y", "z"]:
        raise InputError(f"{path}: no 3-D box (xlo xhi, ylo yhi, zlo zhi); export a 3-D scenario")
    if not atoms or sorted(atoms) != sorted(velocities):
        raise InputError(f"{path}: every atom needs a position and a velocity")
    ids = sorted(atoms)
    return [sides[a] for a in "xyz"], [atoms[i] for i in ids], [velocities[i] for i in ids]


def build(sides, count):
    """The LJ system of `count` unit-mass atoms in the periodic box of `sides`."""
    import openmm
    system = openmm.System()
    system.setDefaultPeriodicBoxVectors(
        openmm.Vec3(sides[0], 0, 0), openmm.Vec3(0, sides[1], 0), openmm.Vec3(0, 0, sides[2]))
    lj = openmm.NonbondedForce()
    lj.setNonbondedMethod(openmm.NonbondedForce.CutoffPeriodic)
    lj.setCutoffDistance(CUTOFF)
    lj.setUseDispersionCorrection(False)
    lj.setUseSwitchingFunction(False)
    for _ in range(count):
        system.addParticle(1.0)
        lj.addParticle(0.0, 1.0, 1.0)
    system.addForce(lj)
    return system


def main(argv):
    if len(argv) != 4:
        raise InputError("usage: openmm-driver.py STATE.data STEPS THREADS")
    path = argv[1]
    try:
        steps, threads = int(argv[2]), int(argv[3])
    except ValueError:
        raise InputError(f"STEPS and THREADS are positive integers (got {argv[2]!r}, {argv[3]!r})")
    if steps < 1 or threads < 1:
        raise InputError(f"STEPS and THREADS are positive integers (got {steps}, {threads})")
    sides, positions, velocities = read_lammps_data(path)
    if min(sides) < 2 * CUTOFF:
        raise InputError(f"{path}: a box side of {min(sides)} is under twice the cutoff {CUTOFF}")
    try:
        import openmm
    except ImportError:
        raise InputError("OpenMM is not installed: run scripts/install-peers.sh (.peers/openmm)")
    system = build(sides, len(positions))
    integrator = openmm.VerletIntegrator(DT)
    platform = openmm.Platform.getPlatformByName("CPU")
    context = openmm.Context(system, integrator, platform, {"Threads": str(threads)})
    context.setPositions(positions)
    # OpenMM's Verlet is leapfrog, its velocities half a step behind its positions: half a kick
    # back from the exported velocities gives velocity Verlet's trajectory, LAMMPS's and ours.
    forces = context.getState(getForces=True).getForces(asNumpy=True)._value
    context.setVelocities([tuple(v[d] - 0.5 * DT * f[d] for d in range(3))
                           for v, f in zip(velocities, forces)])

    def energy():
        state = context.getState(getEnergy=True)
        return (state.getKineticEnergy() + state.getPotentialEnergy()).value_in_unit(
            openmm.unit.kilojoule_per_mole)

    e0 = energy()
    clock = time.perf_counter()
    integrator.step(steps)
    # getState waits for the platform to finish; on the CPU platform step() already has.
    context.getState(getPositions=False)
    elapsed = time.perf_counter() - clock
    e1 = energy()
    used = platform.getPropertyValue(context, "Threads")
    print(f"openmm {openmm.__version__} platform CPU threads {used} atoms {len(positions)} "
          f"steps {steps}")
    print(f"energy initial {e0:.9e} final {e1:.9e} relative drift {(e1 - e0) / abs(e0):.3e}")
    print(f"time total {elapsed:.9f}")
    print("openmm done")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv))
    except InputError as e:
        print(f"openmm-driver.py: {e}", file=sys.stderr)
        sys.exit(2)
