#!/usr/bin/python3
"""Pictures of tresca runs (matplotlib from Debian's python3-matplotlib).

  /usr/bin/python3 perf/plot.py --run run.json [--csv contact.csv] [--scaling scaling.json] --out DIR

writes, for what it is given:
  DIR/residual.png  the Newton residual history |v| (log scale) with the
                    cumulative inner CG and outer CG or GMRES iterations (from tresca --json)
  DIR/contact.png   the contact face: separated / stick / slip, the contact
                    pressure lambda / nodal area, slip vectors (from --contact-csv)
  DIR/scaling.png   time and work per level against dofs, log-log, with the
                    ideal slope 1 (from scaling --json)
Exit status 0, or 2 with one line on stderr if an input is missing or malformed.
"""
import argparse
import csv
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def fail(msg):
    print("plot.py: error: " + msg, file=sys.stderr)
    sys.exit(2)


def load_json(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        fail(f"cannot read '{path}': {e}")


def residual(run, out):
    h = run.get("residual_history")
    if not h:
        fail("the run JSON has no residual_history")
    k = list(range(len(h)))
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.semilogy(k, h, "o-", label="|v| (Newton)")
    ax.axhline(run.get("eps", 1e-6), color="grey", ls="--", lw=0.8, label="eps")
    ax.set_xlabel("Newton iteration")
    ax.set_ylabel("|v|")
    inner, outer = run.get("inner_iterations_history"), run.get("outer_iterations_history")
    if inner and outer:
        ax2 = ax.twinx()
        ax2.plot(k, inner, "s:", color="tab:orange", label="inner MG-CG (cumulative)")
        ax2.plot(k, outer, "^:", color="tab:green", label="outer CG or GMRES (cumulative)")
        ax2.set_ylabel("Krylov iterations")
        lines = ax.get_legend_handles_labels()
        lines2 = ax2.get_legend_handles_labels()
        ax.legend(lines[0] + lines2[0], lines[1] + lines2[1], fontsize=8, loc="upper right")
    else:
        ax.legend(fontsize=8)
    dims = run.get("dims", ["?"] * 3)
    ax.set_title(f"mesh {dims[0]}x{dims[1]}x{dims[2]}: {run.get('reason', '?')} after {len(h) - 1} steps", fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "residual.png"), dpi=110)
    plt.close(fig)


def contact(path, out):
    try:
        with open(path) as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        fail(f"cannot read '{path}': {e}")
    need = {"x", "y", "ux", "uy", "lambda", "contact", "stick"}
    if not rows or not need <= set(rows[0]):
        fail(f"'{path}' is not a tresca contact CSV (columns {sorted(need)})")
    x = [float(r["x"]) for r in rows]
    y = [float(r["y"]) for r in rows]
    lam = [float(r["lambda"]) for r in rows]
    status = [0 if r["contact"] == "0" else (1 if r["stick"] == "1" else 2) for r in rows]
    # nodal area from the spacing (halved on the edges)
    xs, ys = sorted(set(x)), sorted(set(y))
    hx = xs[1] - xs[0] if len(xs) > 1 else 1.0
    hy = ys[1] - ys[0] if len(ys) > 1 else 1.0
    area = [hx * hy * (0.5 if xi == xs[-1] else 1) * (0.5 if yi in (ys[0], ys[-1]) else 1) for xi, yi in zip(x, y)]
    p = [l / a for l, a in zip(lam, area)]
    fig, axs = plt.subplots(1, 2, figsize=(11, 4))
    colors = {0: "lightgrey", 1: "tab:blue", 2: "tab:red"}
    names = {0: "separated", 1: "stick", 2: "slip"}
    for s in (0, 1, 2):
        sel = [i for i, v in enumerate(status) if v == s]
        axs[0].scatter([x[i] for i in sel], [y[i] for i in sel], s=8, c=colors[s], label=f"{names[s]} ({len(sel)})")
    slip = [i for i, v in enumerate(status) if v == 2]
    if slip:
        axs[0].quiver([x[i] for i in slip], [y[i] for i in slip], [float(rows[i]["ux"]) for i in slip],
                      [float(rows[i]["uy"]) for i in slip], color="k", width=0.002)
    axs[0].set_title("contact status, slip vectors (u_x, u_y)", fontsize=10)
    axs[0].legend(fontsize=8, loc="upper right")
    sc = axs[1].scatter(x, y, c=p, s=10, cmap="viridis")
    fig.colorbar(sc, ax=axs[1], label="contact pressure lambda / area [Pa]")
    axs[1].set_title("contact pressure", fontsize=10)
    for a in axs:
        a.set_aspect("equal")
        a.set_xlabel("x [m]")
        a.set_ylabel("y [m]")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "contact.png"), dpi=110)
    plt.close(fig)


def scaling(path, out):
    rows = load_json(path)
    if not isinstance(rows, list) or not rows:
        fail(f"'{path}' is not a scaling JSON (a list of runs)")
    try:
        dofs = [r["dofs"] for r in rows]
        t = [r["times"]["total"] for r in rows]
        fmv = [r["counts"]["fine_matvecs_total"] for r in rows]
    except (KeyError, TypeError) as e:
        fail(f"'{path}' lacks {e}")
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.loglog(dofs, t, "o-", label="time [s]")
    work = [f * d for f, d in zip(fmv, dofs)]  # fmv x dofs: work in dof-applications
    ax.loglog(dofs, [w / work[-1] * t[-1] for w in work], "s--", label="work (fmv x dofs), scaled to the time")
    ax.loglog(dofs, [d / dofs[-1] * t[-1] for d in dofs], ":", color="grey", label="ideal: slope 1")
    ax.set_xlabel("dofs")
    ax.set_ylabel("seconds")
    ax.legend(fontsize=8)
    ax.set_title("whole contact solves per level", fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "scaling.png"), dpi=110)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description="Pictures of tresca runs")
    ap.add_argument("--run", help="tresca --json output")
    ap.add_argument("--csv", help="tresca --contact-csv output")
    ap.add_argument("--scaling", help="scaling --json output")
    ap.add_argument("--out", required=True, help="directory for the PNGs")
    a = ap.parse_args()
    if not (a.run or a.csv or a.scaling):
        fail("give at least one of --run, --csv, --scaling")
    os.makedirs(a.out, exist_ok=True)
    if a.run:
        residual(load_json(a.run), a.out)
    if a.csv:
        contact(a.csv, a.out)
    if a.scaling:
        scaling(a.scaling, a.out)


if __name__ == "__main__":
    main()
