#!/usr/bin/env python3
"""Two runs of the same problem (e.g. 1 and 2 MPI ranks) give the same
solution: contact CSV values within a relative tolerance of each column's
largest magnitude, the same contact and stick sets, and the same Newton
iteration count in the JSON summaries.

With "mixed": the case must have separated, sticking and sliding nodes.
With "krylov": the same Krylov iterations too (all of the Newton steps' CG
and all of the inner K_ii CG).

usage: compare_runs.py A.csv A.json B.csv B.json RTOL [mixed] [krylov]"""
import csv
import json
import sys


def main():
    a_csv, a_json, b_csv, b_json, rtol = sys.argv[1:6]
    rtol = float(rtol)
    a = list(csv.DictReader(open(a_csv)))
    b = list(csv.DictReader(open(b_csv)))
    ok = True
    if len(a) != len(b) or not a:
        print(f"row counts differ or empty: {len(a)} vs {len(b)}")
        return 1
    for col in ("ux", "uy", "uz", "lambda"):
        va = [float(r[col]) for r in a]
        vb = [float(r[col]) for r in b]
        scale = max(abs(x) for x in va) or 1.0
        diff = max(abs(x - y) for x, y in zip(va, vb)) / scale
        print(f"{col}: largest difference {diff:.3e} of max |{col}| (tolerance {rtol:g})")
        ok = ok and diff <= rtol
    for col in ("contact", "stick"):
        same = all(x[col] == y[col] for x, y in zip(a, b))
        print(f"{col} sets equal: {same}")
        ok = ok and same
    flags = sys.argv[6:]
    if "mixed" in flags:
        sep = sum(r["contact"] == "0" for r in a)
        stick = sum(r["contact"] == "1" and r["stick"] == "1" for r in a)
        slip = sum(r["contact"] == "1" and r["stick"] == "0" for r in a)
        print(f"states: {sep} separated, {stick} stick, {slip} slip")
        ok = ok and sep > 0 and stick > 0 and slip > 0
    ja, jb = json.load(open(a_json)), json.load(open(b_json))
    print(f"Newton iterations {ja['newton_iterations']} vs {jb['newton_iterations']}, "
          f"ranks {ja.get('ranks')} vs {jb.get('ranks')}, converged {ja['converged']} / {jb['converged']}")
    ok = ok and ja["newton_iterations"] == jb["newton_iterations"] and ja["converged"] and jb["converged"]
    krylov = ("outer_iterations", "inner_iterations")  # the Newton steps' CG, and the K_ii solves'
    ka, kb = [tuple(j["counts"][k] for k in krylov) for j in (ja, jb)]
    print(f"Krylov iterations (Newton-step CG, inner K_ii CG) {ka} vs {kb}")
    if "krylov" in flags:
        ok = ok and ka == kb
    print("same solution" if ok else "DIFFERENT")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
