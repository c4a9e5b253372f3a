#!/usr/bin/env python3
"""mycode: a direct-summation gravitational N-body program, the one that mycode.toml's
[[external]] entry runs (written by `nbody-bench init --external mycode --lang python`).
Standard library only.

It takes the bodies of --initial FILE (what `nbody-bench export --format text` writes: the sweep
exports the scenario's bodies into each case's work directory first, so this program starts from
the particles our kernels start from) or, without it, a seeded Plummer sphere of --n bodies;
integrates them --steps steps with leapfrog (kick-drift-kick, i.e. velocity Verlet); and prints

    bodies N steps S dt DT G G softening EPS from SOURCE
    energy initial E0 final E1 relative drift D
    time total SECONDS

`time total` is the timed loop alone (time.perf_counter around the steps, in `evolve`): the sweep
reads it with the entry's `time` regex and divides it by the entry's `steps`. The energy line is the sanity
check the entry's `check` looks for; the energies are computed outside the timed loop.

Measuring your own code: replace the body of `evolve` with your code's calls (the comment above
it does this for REBOUND) and keep the rest, the arguments, the timing and the printed lines, so that the
config needs no change. Run it alone first:

    python3 mycode.py --n 200 --steps 10

usage: mycode.py --n N --steps S [--seed SEED] [--initial FILE] [--dt DT]
Exit status: 0, or 2 for bad input (with a message saying what was wrong).
"""
import argparse
import math
import random
import sys
import time

# The `galaxy` scenario's law and step, used when no --initial file gives them.
G = 1.0
SOFTENING = 0.05
DT = 1e-3


class InputError(Exception):
    """Bad input: printed as the message, exit status 2."""


class Bodies:
    """Positions, velocities, inertial masses and gravitational masses (the export's `mass` and
    `strength` columns), one list per component: plain lists of floats are what pure Python
    indexes fastest."""

    def __init__(self):
        self.x, self.y, self.z = [], [], []
        self.vx, self.vy, self.vz = [], [], []
        self.mass, self.strength = [], []

    def add(self, pos, vel, mass, strength):
        for column, value in zip((self.x, self.y, self.z, self.vx, self.vy, self.vz),
                                 (*pos, *vel)):
            column.append(value)
        self.mass.append(mass)
        self.strength.append(strength)

    def __len__(self):
        return len(self.mass)


def plummer(n, seed):
    """A Plummer sphere of n equal masses (total 1, scale radius 1) in virial equilibrium
    (Aarseth, Henon and Wielen 1974), centred on its centre of mass."""
    rng = random.Random(seed)
    bodies = Bodies()
    for _ in range(n):
        # Radius from the enclosed mass fraction, cut at 0.999 (r ≈ 23) as usual.
        r = 1.0 / math.sqrt(rng.uniform(1e-12, 0.999) ** (-2.0 / 3.0) - 1.0)
        # Speed from the distribution function, by rejection: q = v / v_escape.
        while True:
            q, y = rng.random(), rng.uniform(0.0, 0.1)
            if y < q * q * (1.0 - q * q) ** 3.5:
                break
        v = q * math.sqrt(2.0) * (1.0 + r * r) ** -0.25
        bodies.add(isotropic(rng, r), isotropic(rng, v), 1.0 / n, 1.0 / n)
    for column in (bodies.x, bodies.y, bodies.z, bodies.vx, bodies.vy, bodies.vz):
        mean = sum(column) / n
        column[:] = [c - mean for c in column]
    return bodies


def isotropic(rng, length):
    """A vector of the given length in a uniformly random direction."""
    cos_t = rng.uniform(-1.0, 1.0)
    sin_t = math.sqrt(1.0 - cos_t * cos_t)
    phi = rng.uniform(0.0, 2.0 * math.pi)
    return (length * sin_t * math.cos(phi), length * sin_t * math.sin(phi), length * cos_t)


def read_initial(path):
    """The bodies of an exported state (`# nbody-bench initial state v1`, `#` header lines, then
    `id x y z vx vy vz mass strength` a body) and the law and step its header names."""
    params = {"G": G, "softening": SOFTENING, "dt": DT}
    columns, rows = None, {}
    try:
        lines = open(path, encoding="utf-8").read().splitlines()
    except OSError as e:
        raise InputError(f"--initial {path}: cannot read it ({e.strerror}); write it with "
                         "`nbody-bench export --format text --out FILE`")
    for number, line in enumerate(lines, 1):
        words = line.split()
        where = f"initial state {path} line {number}"
        if not words:
            continue
        if words[0] == "#":
            words = words[1:]
            if words[:1] == ["columns:"]:
                columns = words[1:]
                if columns != "id x y z vx vy vz mass strength".split():
                    raise InputError(f"{where}: columns {' '.join(columns)}: this program "
                                     "simulates 3-D bodies (a scenario of dimension 3)")
            elif words[:1] == ["law"]:
                if words[1:2] != ["gravity"]:
                    raise InputError(f"{where}: law {' '.join(words[1:2])}: this program "
                                     "computes gravity; export the `galaxy` scenario")
                params.update(named_numbers(words, ("G", "softening"), where))
            elif words[:1] == ["scenario"]:
                params.update(named_numbers(words, ("dt",), where))
            continue
        if columns is None:
            raise InputError(f"{where}: a body before the `# columns:` line; is this a file of "
                             "`nbody-bench export --format text`?")
        values = numbers(words, where)
        if len(values) != len(columns):
            raise InputError(f"{where}: {len(values)} values, expected {len(columns)} "
                             f"({' '.join(columns)})")
        rows[int(values[0])] = values[1:]
    if not rows:
        raise InputError(f"initial state {path}: no bodies")
    if sorted(rows) != list(range(len(rows))):
        raise InputError(f"initial state {path}: ids are not 0..{len(rows) - 1}, each once")
    bodies = Bodies()
    for i in range(len(rows)):
        r = rows[i]
        bodies.add(r[0:3], r[3:6], r[6], r[7])
    return bodies, params


def named_numbers(words, names, where):
    """The numbers that follow the given names in a header line (`G 1 softening 0.05`), each at
    its first place: the law's formula later in the line names G again."""
    found = {}
    for i, word in enumerate(words[:-1]):
        if word in names and word not in found:
            found[word] = numbers([words[i + 1]], where)[0]
    return found


def numbers(words, where):
    try:
        values = [float(w) for w in words]
    except ValueError as e:
        raise InputError(f"{where}: {e}")
    if not all(math.isfinite(v) for v in values):
        raise InputError(f"{where}: every value must be a finite number")
    return values


def accelerations(b, g, eps2, ax, ay, az):
    """Overwrites ax, ay, az with every body's acceleration: each pair once (Newton's third
    law), Plummer-softened, a_i = G s_i / m_i * sum_j s_j (x_j - x_i) / (r^2 + eps^2)^1.5."""
    x, y, z, s = b.x, b.y, b.z, b.strength
    n = len(x)
    for i in range(n):
        ax[i] = ay[i] = az[i] = 0.0
    for i in range(n):
        xi, yi, zi, si = x[i], y[i], z[i], s[i]
        fx = fy = fz = 0.0
        for j in range(i + 1, n):
            dx, dy, dz = x[j] - xi, y[j] - yi, z[j] - zi
            r2 = dx * dx + dy * dy + dz * dz + eps2
            w = 1.0 / (r2 * math.sqrt(r2))
            sj = s[j] * w
            fx += sj * dx
            fy += sj * dy
            fz += sj * dz
            si_w = si * w
            ax[j] -= si_w * dx
            ay[j] -= si_w * dy
            az[j] -= si_w * dz
        ax[i] += fx
        ay[i] += fy
        az[i] += fz
    for i in range(n):
        k = g * s[i] / b.mass[i]
        ax[i] *= k
        ay[i] *= k
        az[i] *= k


def energy(b, g, eps2):
    """Kinetic plus potential energy (the potential of the softened law, -G s_i s_j / sqrt(r^2 +
    eps^2) a pair)."""
    n = len(b)
    kinetic = 0.5 * sum(b.mass[i] * (b.vx[i] ** 2 + b.vy[i] ** 2 + b.vz[i] ** 2)
                        for i in range(n))
    potential = 0.0
    for i in range(n):
        for j in range(i + 1, n):
            r2 = (b.x[j] - b.x[i]) ** 2 + (b.y[j] - b.y[i]) ** 2 + (b.z[j] - b.z[i]) ** 2
            potential -= b.strength[i] * b.strength[j] / math.sqrt(r2 + eps2)
    return kinetic + g * potential


# Measuring a library instead: replace the body of `evolve` with its calls, and copy its
# bodies back into `b` at the end so that the energy line checks its result. REBOUND, for
# example (`pip install rebound`; `sim.step()` is one leapfrog step of its own):
#
#     import rebound
#     sim = rebound.Simulation()
#     sim.G, sim.softening, sim.dt, sim.integrator = g, math.sqrt(eps2), dt, "leapfrog"
#     for i in range(len(b)):
#         sim.add(m=b.mass[i], x=b.x[i], y=b.y[i], z=b.z[i], vx=b.vx[i], vy=b.vy[i], vz=b.vz[i])
#     start = time.perf_counter()          # the setting-up above is left out of the time
#     for _ in range(steps):
#         sim.step()
#     elapsed = time.perf_counter() - start
#     for i, p in enumerate(sim.particles):
#         b.x[i], b.y[i], b.z[i], b.vx[i], b.vy[i], b.vz[i] = p.x, p.y, p.z, p.vx, p.vy, p.vz
#     return elapsed
#
# A library that runs threads (REBOUND built with OpenMP, NumPy's BLAS) is told their number by
# the sweep: see `threads` and `env` in the config.
def evolve(b, steps, dt, g, eps2):
    """Advances the bodies `steps` leapfrog steps; returns the seconds this took, the time that
    the sweep measures (set-up before the clock starts is not counted)."""
    n = len(b)
    ax, ay, az = [0.0] * n, [0.0] * n, [0.0] * n
    half = 0.5 * dt
    # The first forces are set-up: each timed step then evaluates them once, as our kernels' do.
    accelerations(b, g, eps2, ax, ay, az)
    start = time.perf_counter()
    for _ in range(steps):
        for v, a in ((b.vx, ax), (b.vy, ay), (b.vz, az)):
            for i in range(n):
                v[i] += half * a[i]
        for p, v in ((b.x, b.vx), (b.y, b.vy), (b.z, b.vz)):
            for i in range(n):
                p[i] += dt * v[i]
        accelerations(b, g, eps2, ax, ay, az)
        for v, a in ((b.vx, ax), (b.vy, ay), (b.vz, az)):
            for i in range(n):
                v[i] += half * a[i]
    return time.perf_counter() - start


def arguments(argv):
    p = argparse.ArgumentParser(description="Direct-summation gravitational N-body, leapfrog.")
    p.add_argument("--n", type=int, required=True, help="number of bodies (the file's, with "
                   "--initial)")
    p.add_argument("--steps", type=int, required=True, help="time steps of the timed loop")
    p.add_argument("--seed", type=int, default=1, help="seed of the Plummer sphere")
    p.add_argument("--initial", metavar="FILE", help="bodies, law and step from "
                   "`nbody-bench export --format text` output instead of the Plummer sphere")
    p.add_argument("--dt", type=float, help="time step [default: the file's, else 0.001]")
    args = p.parse_args(argv)
    if args.n < 2 or args.steps < 1:
        p.error("--n must be at least 2 and --steps at least 1")
    if args.dt is not None and not (math.isfinite(args.dt) and args.dt > 0):
        p.error("--dt must be a finite number above 0")
    return args


def main(argv):
    args = arguments(argv)
    if args.initial:
        bodies, params = read_initial(args.initial)
        if len(bodies) != args.n:
            raise InputError(f"--n {args.n}, but {args.initial} holds {len(bodies)} bodies")
        source = args.initial
    else:
        bodies, params = plummer(args.n, args.seed), {"G": G, "softening": SOFTENING, "dt": DT}
        source = f"a Plummer sphere, seed {args.seed}"
    g, eps2 = params["G"], params["softening"] ** 2
    dt = args.dt if args.dt is not None else params["dt"]
    print(f"bodies {len(bodies)} steps {args.steps} dt {dt:g} G {g:g} softening "
          f"{params['softening']:g} from {source}")
    before = energy(bodies, g, eps2)
    elapsed = evolve(bodies, args.steps, dt, g, eps2)
    after = energy(bodies, g, eps2)
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
