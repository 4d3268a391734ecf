#!/usr/bin/env python3
"""Random valid contact problems, each solved by `tresca --problem`: how many converge.

A demanding user's cases are not the seed benchmark: plates and blocks of any
proportions, elements up to hundreds of times longer than wide (a tenth over
50:1), auxetic to nearly incompressible materials, Tresca bounds from a
thousandth to a hundred times the mean contact force, Coulomb F up to 3,
plane, sphere and cylinder obstacles with and without a gap, loads that
press, shear and lift. This draws such problems (small meshes: a second or
less each; --refine K: the same problems on meshes K times finer per axis),
solves each and tallies the outcome by reason. A run that ends without an answer must say
so (exit 1 with its reason); exit 2 (bad input) means this generator made an
invalid problem, and anything else is a defect.

  python3 perf/robustness_sweep.py [--seed S] [--count N] [--refine K] [--bin build/bin/tresca]
                                   [--jobs J] [--keep DIR] [--compare OTHER_BIN]

--compare runs every problem with a second binary as well (an A/B of a
change) and lists the problems whose outcome differs. perf/RESULTS.md §0zq
has the figures.
"""
import argparse
import concurrent.futures as cf
import json
import math
import os
import random
import subprocess
import sys
import tempfile
import time
from collections import Counter


def draw(rng, refine=1):
    """One valid problem file's contents (drivers/cases/README.md schema); refine
    K > 1: the same problem (the same draws) on a mesh K times finer per axis,
    its Tresca bound per contact node scaled so that the bound per area stays."""
    def log_uniform(a, b):
        return 10 ** rng.uniform(math.log10(a), math.log10(b))
    while True:
        ex, ey, ez = rng.randint(2, 40), rng.randint(1, 24), rng.randint(1, 12)
        if ex * ey * ez <= 30000:
            break
    LX, LY, LZ = log_uniform(0.2, 5), log_uniform(0.1, 3), log_uniform(0.02, 2)
    E = log_uniform(1e6, 1e12)
    nu = rng.uniform(-0.9, 0.49) if rng.random() < 1 / 3 else rng.uniform(0, 0.49)
    s = 1e-3 * E  # tractions of strains about 1e-3
    top = [rng.uniform(-1, 1) * 0.3 * s, rng.uniform(-1, 1) * 0.1 * s, -rng.uniform(-0.3, 1) * s]
    traction = {"z1": top}
    if rng.random() < 0.7:
        traction["x1"] = [rng.uniform(-1, 1) * s, rng.uniform(-1, 1) * 0.2 * s, rng.uniform(-1, 1) * 0.2 * s]
    if rng.random() < 0.3:
        traction["y0"] = [rng.uniform(-1, 1) * 0.2 * s for _ in range(3)]
    loads = {"traction": traction}
    if rng.random() < 0.3:
        loads["body_force"] = [0, 0, -rng.uniform(0, 1) * s / LZ]
    mean_force = abs(top[2]) * LX * LY / (ex * (ey + 1)) + 1e-30  # per contact node
    if rng.random() < 0.6:
        per_area = ex * (ey + 1) / (refine * ex * (refine * ey + 1))
        friction = {"tresca": mean_force * log_uniform(1e-3, 1e2) * per_area}
    else:
        friction = {"coulomb": rng.uniform(0, 1) if rng.random() < 0.5 else log_uniform(1e-3, 3)}
    kind = rng.random()
    if kind < 0.5:
        obstacle = {"kind": "plane", "gap": rng.choice([0, LZ * log_uniform(1e-8, 1e-2)]),
                    "slope": [rng.uniform(0, 1e-3), rng.uniform(0, 1e-3)]}
    elif kind < 0.75:
        obstacle = {"kind": "sphere", "radius": LX * log_uniform(0.5, 20),
                    "center": [rng.uniform(0, LX), rng.uniform(0, LY)], "gap": rng.choice([0, LZ * log_uniform(1e-8, 1e-3)])}
    else:
        obstacle = {"kind": "cylinder", "radius": LY * log_uniform(0.5, 20), "y": rng.uniform(0, LY),
                    "gap": rng.choice([0, LZ * log_uniform(1e-8, 1e-3)])}
    return {"mesh": {"dims": [refine * ex, refine * ey, refine * ez]}, "box": {"lengths": [LX, LY, LZ], "origin": [0, 0, 0]},
            "material": {"E": E, "nu": nu}, "loads": loads, "friction": friction, "obstacle": obstacle}


def solve(binary, problem, out, timeout):
    """(exit status, reason, Newton steps, fine matvecs, seconds, residual floor) of one run."""
    env = dict(os.environ, OMP_NUM_THREADS=os.environ.get("OMP_NUM_THREADS", "1"))
    t = time.time()
    try:
        rc = subprocess.run([binary, "--problem", problem, "--quiet", "--json", out], env=env,
                            capture_output=True, timeout=timeout).returncode
    except subprocess.TimeoutExpired:
        return 124, "timeout", -1, 0.0, time.time() - t, 0.0
    t = time.time() - t
    try:
        j = json.load(open(out))
        return (rc, j["reason"], j["newton_iterations"], j["counts"]["fine_matvecs_total"], t,
                j.get("residual_floor", 0.0))
    except (OSError, ValueError, KeyError):
        return rc, "-", -1, 0.0, t, 0.0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--count", type=int, default=100)
    ap.add_argument("--refine", type=int, default=1,
                    help="the same problems on meshes K times finer per axis (K^3 the elements)")
    ap.add_argument("--bin", default="build/bin/tresca")
    ap.add_argument("--compare", help="a second tresca binary, run on the same problems")
    ap.add_argument("--jobs", type=int, default=2, help="runs at a time (each on OMP_NUM_THREADS, default 1)")
    ap.add_argument("--timeout", type=float, default=300)
    ap.add_argument("--keep", help="write the problems and results here (default: a temporary folder)")
    a = ap.parse_args()
    if a.refine < 1 or a.count < 1:
        sys.exit("robustness_sweep: --refine and --count must be at least 1")
    binaries = [a.bin] + ([a.compare] if a.compare else [])
    for b in binaries:
        if not os.access(b, os.X_OK):
            sys.exit(f"robustness_sweep: {b} is not an executable (build first, or give --bin)")
    folder = a.keep or tempfile.mkdtemp(prefix="tresca_sweep_")
    os.makedirs(folder, exist_ok=True)
    rng = random.Random(a.seed)
    names = []
    for k in range(a.count):
        name = os.path.join(folder, f"s{a.seed}_{k:03d}")
        with open(name + ".json", "w") as f:
            json.dump(draw(rng, a.refine), f, indent=1)
        names.append(name)
    results = []
    for i, b in enumerate(binaries):
        with cf.ThreadPoolExecutor(a.jobs) as ex:
            results.append(list(ex.map(lambda n: solve(b, n + ".json", f"{n}.out{i}.json", a.timeout), names)))
    print(f"# {a.count} problems, seed {a.seed}, refine {a.refine}, in {folder}; OMP_NUM_THREADS={os.environ.get('OMP_NUM_THREADS', '1')}")
    for i, b in enumerate(binaries):
        rows = results[i]
        tally = Counter(r[1] if r[0] in (0, 1) else f"exit {r[0]}" for r in rows)
        ok = sum(1 for r in rows if r[0] == 0)
        odd = [os.path.basename(n) for n, r in zip(names, rows) if r[0] not in (0, 1)]
        print(f"{b}: {ok} of {a.count} converged ({100.0 * ok / a.count:.0f} %); by reason: "
              + ", ".join(f"{k} {v}" for k, v in tally.most_common())
              + f"; median {sorted(r[4] for r in rows)[len(rows) // 2]:.2f} s a run")
        floor = sum(1 for r in rows if r[0] == 0 and r[5] > 0)
        if floor:
            print(f"  {floor} of them converged to the level that r = S u - b~ resolves, above eps (residual_floor)")
        if odd:
            print(f"  neither converged nor an honest failure (exit status not 0 or 1): {' '.join(odd)}")
    if a.compare:
        print("problems whose outcome differs (reason, Newton steps, fine matvecs):")
        for n, r0, r1 in zip(names, *results):
            if (r0[0] == 0) != (r1[0] == 0):
                print(f"  {os.path.basename(n)}: {r0[1]} {r0[2]} {r0[3]:.0f} | {r1[1]} {r1[2]} {r1[3]:.0f}")
    bad = sum(1 for rows in results for r in rows if r[0] not in (0, 1))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
