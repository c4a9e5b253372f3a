#!/usr/bin/env python3
"""FMM3D (fmm3dpy's lfmm3d, the Laplace kernel in f64) on the particles of `nbody-bench export
--format npy` (columns id x y z vx vy vz mass strength), for configs/vs-fmm3d.toml: computes
every particle's Coulomb force from the charges (the strength column) STEPS times (forces only:
no integration), after one untimed evaluation, prints the time, then the median and largest
relative force error of the last evaluation against a direct sum on a seeded sample of
particles, in our convention.

FMM3D's potential is u_i = sum_j q_j / (4 pi r_ij) and its gradient grad_i; our Coulomb force on
i is q_i sum_j q_j (x_i - x_j) / r_ij^3 = -4 pi q_i grad_i. The coulomb scenario zeroes pairs
closer than its quench (1e-3); FMM3D has no quench (it leaves out only a particle's own
charge). The direct sum skips those pairs, and the error is taken after removing them from
FMM3D's force on the sampled particles too (untimed; the near field of an FMM is a direct sum,
so that is the force FMM3D would give with a quench): what is left is FMM3D's approximation
error. Such pairs are rare (about 2e-9 n^2: none at n = 1e4, a few dozen at 1e5); a line says
how many sampled particles had one.

usage: fmm3d-driver.py STATE.npy EPS STEPS [SAMPLE] [--forces OUT.npy]
  EPS     FMM3D's requested precision (> 0, < 1)
  STEPS   timed force evaluations (>= 1)
  SAMPLE  particles whose force is checked against the direct sum [default: 256; 0 = none]
  --forces OUT.npy  also write the last evaluation's forces (n x 3, float64, our convention)
"""
import sys
import time

import numpy as np

# The coulomb scenario's quench (crates/engine/src/scenario/mod.rs, COULOMB_QUENCH): pairs closer than this
# exert no force.
QUENCH = 1e-3
USAGE = "usage: fmm3d-driver.py STATE.npy EPS STEPS [SAMPLE] [--forces OUT.npy]"


def usage_error(message):
    print(f"fmm3d-driver.py: {message}\n{USAGE}", file=sys.stderr)
    sys.exit(2)


def parse(argv):
    args = list(argv)
    forces_out = None
    if "--forces" in args:
        i = args.index("--forces")
        if i + 1 >= len(args):
            usage_error("--forces needs a file name")
        forces_out = args[i + 1]
        del args[i:i + 2]
    if len(args) not in (3, 4):
        usage_error(f"expected 3 or 4 arguments, got {len(args)}")
    path = args[0]
    try:
        eps = float(args[1])
    except ValueError:
        usage_error(f"EPS must be a number, got `{args[1]}`")
    if not 0.0 < eps < 1.0:
        usage_error(f"EPS must be > 0 and < 1, got {args[1]}")
    try:
        steps = int(args[2])
        sample = int(args[3]) if len(args) > 3 else 256
    except ValueError:
        usage_error(f"STEPS and SAMPLE must be whole numbers, got {args[2:]}")
    if steps < 1:
        usage_error(f"STEPS must be at least 1, got {steps}")
    if sample < 0:
        usage_error(f"SAMPLE must be at least 0, got {sample}")
    return path, eps, steps, sample, forces_out


def load(path):
    try:
        state = np.load(path)
    except (OSError, ValueError) as e:
        usage_error(f"cannot read {path} as a .npy array: {e}")
    if state.ndim != 2 or state.shape[1] != 9 or state.shape[0] < 2:
        usage_error(f"{path} has shape {state.shape}; expected (n >= 2, 9) from "
                    "`nbody-bench export --format npy` (id x y z vx vy vz mass strength)")
    return state


def coulomb_forces(fmm3dpy, pos_t, q, eps):
    """Our Coulomb forces (n x 3) from one FMM3D evaluation; pos_t is 3 x n, Fortran order."""
    out = fmm3dpy.lfmm3d(eps=eps, sources=pos_t, charges=q, pg=2)
    return (-4.0 * np.pi) * q[:, None] * out.grad.T


def direct(pos, q, idx):
    """Our Coulomb force on the particles idx by direct summation, and the part of the
    unquenched sum that comes from pairs closer than the quench (both len(idx) x 3)."""
    exact = np.zeros((len(idx), 3))
    near = np.zeros((len(idx), 3))
    chunk = max(1, 2_000_000 // len(q))
    for start in range(0, len(idx), chunk):
        rows = idx[start:start + chunk]
        d = pos[rows][:, None, :] - pos[None, :, :]
        r2 = np.einsum("tjk,tjk->tj", d, d)
        r2[np.arange(len(rows)), rows] = np.inf  # not itself
        w = q[None, :] / (r2 * np.sqrt(r2))
        close = r2 < QUENCH * QUENCH
        near[start:start + len(rows)] = np.einsum("tj,tjk->tk", np.where(close, w, 0.0), d)
        exact[start:start + len(rows)] = np.einsum("tj,tjk->tk", np.where(close, 0.0, w), d)
    return q[idx, None] * exact, q[idx, None] * near


def main():
    path, eps, steps, sample, forces_out = parse(sys.argv[1:])
    state = load(path)
    import fmm3dpy

    pos = np.ascontiguousarray(state[:, 1:4])
    pos_t = pos.T  # 3 x n in Fortran order, as lfmm3d takes it: no copy per call
    q = np.ascontiguousarray(state[:, 8])
    n = len(q)
    coulomb_forces(fmm3dpy, pos_t, q, eps)  # untimed: first-call costs stay out of the time
    start = time.perf_counter()
    for _ in range(steps):
        forces = coulomb_forces(fmm3dpy, pos_t, q, eps)
    elapsed = time.perf_counter() - start
    print(f"force time {elapsed:.9e} s for {steps} evaluations of {n} particles (eps {eps:g})")
    if forces_out is not None:
        np.save(forces_out, forces)
    if sample > 0:
        rng = np.random.default_rng(0x5EED)
        idx = rng.choice(n, size=min(sample, n), replace=False)
        exact, near = direct(pos, q, idx)
        err = (np.linalg.norm(forces[idx] - near - exact, axis=1)
               / np.linalg.norm(exact, axis=1))
        quenched = int(np.count_nonzero(np.any(near != 0.0, axis=1)))
        print(f"sampled particles with a pair closer than the quench {QUENCH:g}: {quenched} "
              f"of {len(idx)}")
        print(f"force error median {np.median(err):.6e} max {np.max(err):.6e}")
    print("fmm3d done")


if __name__ == "__main__":
    main()
