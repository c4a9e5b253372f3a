"""The atoms of a LAMMPS data file that `nbody-bench export --format lammps-data` wrote for the
3-D Lennard-Jones melt: what the peers' drivers (scripts/openmm-driver.py,
scripts/gromacs-driver.py) start from. Standard library only."""


class InputError(Exception):
    """Bad input: the drivers print it as the message and exit with status 2."""


def read(path):
    """`(lo, sides, positions, velocities)` of the data file (atom style atomic, one type of
    mass 1): the box's lower corner and side lengths, and each atom's position and velocity in
    the order of its id."""
    try:
        with open(path) as f:
            lines = f.read().splitlines()
    except OSError as e:
        raise InputError(f"cannot read {path}: {e.strerror}")
    bounds, section, atoms, velocities = {}, None, {}, {}
    for number, line in enumerate(lines[1:], 2):
        words = line.split("#")[0].split()
        if not words:
            continue
        try:
            if len(words) == 4 and words[2].endswith("lo") and words[3].endswith("hi"):
                bounds[words[2][0]] = (float(words[0]), float(words[1]))
            elif words[0] in ("Atoms", "Velocities", "Masses"):
                section = words[0]
            elif section == "Atoms" and len(words) >= 5:
                atoms[int(words[0])] = tuple(float(w) for w in words[2:5])
            elif section == "Velocities" and len(words) >= 4:
                velocities[int(words[0])] = tuple(float(w) for w in words[1:4])
            elif section == "Masses" and len(words) >= 2 and float(words[1]) != 1.0:
                raise InputError(f"{path}: atom mass {words[1]}; the drivers run LJ's unit mass")
        except ValueError as e:
            raise InputError(f"{path} line {number}: {e}; is this a file of `nbody-bench export "
                             "--format lammps-data`?")
    if sorted(bounds) != ["x", "y", "z"]:
        raise InputError(f"{path}: no 3-D box (xlo xhi, ylo yhi, zlo zhi); export a 3-D scenario")
    if not atoms or sorted(atoms) != sorted(velocities):
        raise InputError(f"{path}: every atom needs a position and a velocity")
    ids = sorted(atoms)
    lo = [bounds[a][0] for a in "xyz"]
    sides = [bounds[a][1] - bounds[a][0] for a in "xyz"]
    return lo, sides, [atoms[i] for i in ids], [velocities[i] for i in ids]
