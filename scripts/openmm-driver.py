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
import os
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "lib"))
from lammps_data import InputError, read as read_lammps_data  # noqa: E402

CUTOFF = 2.5
DT = 0.005


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
    _, sides, positions, velocities = read_lammps_data(path)
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
