#!/usr/bin/env python3
"""pytreegrav on the particles of `nbody-bench export --format npy` (columns id x y z vx vy vz
mass strength), for configs/vs-pytreegrav.toml: builds the tree and computes every particle's
acceleration STEPS times (forces only: no integration), prints the time, then the median and
largest relative force error of the last evaluation against pytreegrav's direct sum on a seeded
sample of particles. ORDER is the expansion of pytreegrav's accepted nodes: `monopole` (its
default) or `quadrupole` (its `quadrupole=True`).

usage: pytreegrav-driver.py STATE.npy THETA STEPS [SOFTENING] [SAMPLE] [ORDER]
"""
import sys
import time

import numpy as np
import pytreegrav


def main():
    path, theta, steps = sys.argv[1], float(sys.argv[2]), int(sys.argv[3])
    softening = float(sys.argv[4]) if len(sys.argv) > 4 else 0.05
    sample = int(sys.argv[5]) if len(sys.argv) > 5 else 256
    order = sys.argv[6] if len(sys.argv) > 6 else "monopole"
    if order not in ("monopole", "quadrupole"):
        sys.exit(f"pytreegrav-driver.py: ORDER must be monopole or quadrupole, not {order!r}")
    quadrupole = order == "quadrupole"
    state = np.load(path)
    pos = np.ascontiguousarray(state[:, 1:4])
    m = np.ascontiguousarray(state[:, 7])
    h = np.full(len(m), softening)
    # numba compiles on the first calls (the direct sum of small sets, the tree of large
    # ones): one whole evaluation first, untimed.
    pytreegrav.Accel(pos, m, h, theta=theta, quadrupole=quadrupole)
    start = time.perf_counter()
    for _ in range(steps):
        acc = pytreegrav.Accel(pos, m, h, theta=theta, quadrupole=quadrupole)
    elapsed = time.perf_counter() - start
    print(f"force time {elapsed:.9e} s for {steps} evaluations of {len(m)} particles")
    rng = np.random.default_rng(0x5EED)
    idx = rng.choice(len(m), size=min(sample, len(m)), replace=False)
    exact = pytreegrav.AccelTarget(pos[idx], pos, m, softening_target=h[idx], softening_source=h,
                                   method="bruteforce")
    err = np.linalg.norm(acc[idx] - exact, axis=1) / np.linalg.norm(exact, axis=1)
    print(f"force error median {np.median(err):.6e} max {np.max(err):.6e}")
    print("pytreegrav done")


if __name__ == "__main__":
    main()
