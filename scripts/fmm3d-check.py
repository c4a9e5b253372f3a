#!/usr/bin/env python3
"""Checks scripts/fmm3d-driver.py against our naive kernel, in seconds (scripts/test.sh runs it
after scripts/install-fmm3d.sh):

1. the forces it writes for the coulomb scenario (n = 2000, seed 1) agree with the naive forces
   of `nbody-bench validate --dump` to FMM3D's requested precision (eps 1e-3 and 1e-9: the
   relative l2 error of all forces and the median relative error per particle at most eps),
   which pins the conversion of FMM3D's potential gradient to our force convention;
2. its error line handles the quench: two charges moved closer than 1e-3, every particle
   sampled, the reported errors stay within eps and both are counted;
3. its output matches every regex of the `[[external]]` entries of configs/vs-fmm3d.toml;
4. bad arguments are usage errors (exit 2).

usage: fmm3d-check.py NBODY_BENCH   (run with the peers' venv: .peers/venv/bin/python)
"""
import os
import re
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
DRIVER = ROOT / "scripts" / "fmm3d-driver.py"
CONFIG = ROOT / "configs" / "vs-fmm3d.toml"
N = 2000
QUENCH = 1e-3


def run_driver(*args, expect=0):
    env = dict(os.environ, OMP_NUM_THREADS="1")
    p = subprocess.run([sys.executable, str(DRIVER), *map(str, args)], capture_output=True,
                       text=True, env=env, timeout=120)
    if p.returncode != expect:
        sys.exit(f"FAIL: fmm3d-driver.py {' '.join(map(str, args))} exited {p.returncode}, "
                 f"expected {expect}\n{p.stdout}{p.stderr}")
    return p.stdout + p.stderr


def run_bench(*args):
    p = subprocess.run(list(map(str, args)), capture_output=True, text=True, timeout=120)
    if p.returncode != 0:
        sys.exit(f"FAIL: {' '.join(map(str, args))} exited {p.returncode}\n{p.stdout}{p.stderr}")


def reported_errors(out):
    m = re.search(r"force error median ([0-9.eE+-]+) max ([0-9.eE+-]+)", out)
    if not m:
        sys.exit(f"FAIL: no force error line in\n{out}")
    return float(m.group(1)), float(m.group(2))


def check(ok, what):
    print(f"{'ok  ' if ok else 'FAIL'} {what}")
    return ok


def main():
    if len(sys.argv) != 2:
        print(__doc__.strip().splitlines()[-1], file=sys.stderr)
        sys.exit(2)
    bench = sys.argv[1]
    good = True
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        state, dump = tmp / "state.npy", tmp / "forces.txt"
        run_bench(bench, "export", "--scenario", "coulomb", "-n", N, "--seed", 1, "--format", "npy",
                  "--out", state)
        run_bench(bench, "validate", "--scenario", "coulomb", "-n", N, "--seed", 1, "--dump", dump)
        table = np.loadtxt(dump)
        columns = next(line for line in dump.read_text().splitlines()
                       if line.startswith("# columns:")).split()[2:]
        naive = table[:, [columns.index(f"f{d}_naive") for d in "xyz"]]
        pos = np.load(state)[:, 1:4]
        if not np.array_equal(pos, table[:, 1:4]):
            sys.exit("FAIL: the exported particles differ from validate's")
        gap = np.sqrt(min(np.sum((pos[i + 1:] - pos[i]) ** 2, axis=1).min() for i in range(N - 1)))
        if gap < QUENCH:
            sys.exit(f"FAIL: two particles are {gap:.2e} apart, closer than the quench: "
                     "FMM3D has none, choose another seed")

        # 1. The forces against the naive kernel's.
        for eps in (1e-3, 1e-9):
            out = tmp / f"fmm3d-{eps:g}.npy"
            text = run_driver(state, eps, 1, 64, "--forces", out)
            forces = np.load(out)
            l2 = np.linalg.norm(forces - naive) / np.linalg.norm(naive)
            rel = np.linalg.norm(forces - naive, axis=1) / np.linalg.norm(naive, axis=1)
            good &= check(l2 <= eps and np.median(rel) <= eps,
                          f"eps {eps:g}: forces vs naive, relative l2 {l2:.2e}, median "
                          f"{np.median(rel):.2e}, max {rel.max():.2e} (n = {N})")
            median, _ = reported_errors(text)
            good &= check(median <= eps, f"eps {eps:g}: the driver's median error {median:.2e}")

        # 2. Two charges closer than the quench: FMM3D's pair force is taken out before the
        # comparison, so the errors stay FMM3D's.
        near = np.load(state)
        near[1, 1:4] = near[0, 1:4] + [4e-4, 0.0, 0.0]
        np.save(tmp / "near.npy", near)
        text = run_driver(tmp / "near.npy", 1e-9, 1, N)
        median, largest = reported_errors(text)
        good &= check("quench 0.001: 2 of 2000" in text and largest <= 1e-6,
                      f"a pair 4e-4 apart: both counted, errors median {median:.2e} max "
                      f"{largest:.2e}")

        # 3. The config's regexes find the driver's lines.
        config = tomllib.loads(CONFIG.read_text())
        text = run_driver(state, 1e-3, 2)
        for ext in config["external"]:
            found = (re.search(ext["time"]["regex"], text) and re.search(ext["check"], text)
                     and re.search(ext["force_error"], text))
            good &= check(bool(found), f"{ext['name']}: time, check and force_error found")

        # 4. Usage errors.
        for args in [(), (state,), (state, "x", 1), (state, 1e-3, 0), (state, 0, 1),
                     (state, 1e-3, 1, -1), (tmp / "missing.npy", 1e-3, 1),
                     (state, 1e-3, 1, "--forces")]:
            err = run_driver(*args, expect=2)
            good &= check("usage: fmm3d-driver.py" in err, f"usage error for {list(map(str, args))}")
    if not good:
        sys.exit("fmm3d-check: FAILED")
    print("fmm3d-check: all passed")


if __name__ == "__main__":
    main()
