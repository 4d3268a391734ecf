#!/usr/bin/env python3
"""Reads the driver's VTU files with VTK itself (ParaView's reader library,
Debian python3-vtk9) and checks them against the run's contact CSV and JSON:

  check_vtu.py --vtu B.vtu --csv C.csv --json J.json [--ascii A.vtu --min-ratio R]
  check_vtu.py --pvd P.pvd --steps N
  check_vtu.py --pvd P.pvd --json J.json      (a --vtk-every-iteration run)
  check_vtu.py --pvtu P.pvtu --vtu B.vtu --rtol R   (several ranks against one)
  check_vtu.py --vtu U.vtu --json J.json --patch P --beyond X --rtol R   (patch test)

- the body: (ex+1)(ey+1)(ez+1) points, ex*ey*ez hexahedra of positive volume
  (every cell is checked in vectorised form), its bottom plane's displacement
  equal to the contact file's;
- the fields: cell stress and von Mises equal to those recomputed here from
  the points and the displacement alone (isoparametric gradient at each
  hexahedron's centre, Hooke's law with the run's E, nu), contact_pressure
  times each node's share of the face equal to the normal contact force;
- --patch P: the uniform-pressure patch test (tests/cases/uniform_pressure.json):
  beyond x = X the contact pressure is P, the stress (0, 0, -P, 0, 0, 0) and
  von Mises P, to R relative;
- the contact file: displacement and lambda of every contact node equal to
  the CSV's (printed with 17 digits, so equal to the last bit up to one
  rounding), contact_status equal to the CSV's contact/stick columns;
- --ascii: the same run written as text holds the same arrays (to its 12
  digits), and the binary files are at least R times smaller;
- --pvd: a collection of N steps, the body (.vtu, or .pvtu and its pieces)
  and its contact face each, all files read by VTK;
- --pvtu: ParaView's parallel file of a run on several ranks, read whole by
  VTK's parallel reader: as many hexahedra as the one-rank file B.vtu, each
  point's displacement, contact force and status equal to B's at the same
  coordinates (displacements within R of the largest), and the contact
  files of both runs equal to R.
Exits 1 with the first failed check on stderr."""
import argparse
import csv
import json
import os
import sys

import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy


def fail(msg):
    print("check_vtu: FAILED: " + msg, file=sys.stderr)
    sys.exit(1)


def read(path):
    # a .pvtu (the pieces of a run on several ranks) with VTK's parallel reader
    r = vtk.vtkXMLPUnstructuredGridReader() if path.endswith(".pvtu") else vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    g = r.GetOutput()
    if r.GetErrorCode() != 0 or g is None or g.GetNumberOfPoints() == 0:
        fail(path + ": VTK could not read it")
    return g


def arrays(g):
    out = {"points": vtk_to_numpy(g.GetPoints().GetData()),
           "connectivity": vtk_to_numpy(g.GetCells().GetConnectivityArray()),
           "types": vtk_to_numpy(g.GetCellTypesArray())}
    for data in (g.GetPointData(), g.GetCellData()):
        for i in range(data.GetNumberOfArrays()):
            out[data.GetArrayName(i)] = vtk_to_numpy(data.GetArray(i))
    return out


def centre_stress(body, E, nu):
    """Cauchy stress at every hexahedron's centre from its corners' points and
    displacements alone (VTK node order, the isoparametric map: grad u =
    du/dxi J^-1 at xi = 0), in VTK's order xx yy zz xy yz xz."""
    conn = body["connectivity"].reshape(-1, 8)
    q, u = body["points"][conn], body["displacement"][conn]  # cells x 8 x 3

    def d_dxi(f):  # derivatives along the three reference axes at the centre
        return np.stack([(f[:, 1] - f[:, 0] + f[:, 2] - f[:, 3] + f[:, 5] - f[:, 4] + f[:, 6] - f[:, 7]) / 4,
                         (f[:, 3] - f[:, 0] + f[:, 2] - f[:, 1] + f[:, 7] - f[:, 4] + f[:, 6] - f[:, 5]) / 4,
                         (f[:, 4] - f[:, 0] + f[:, 5] - f[:, 1] + f[:, 6] - f[:, 2] + f[:, 7] - f[:, 3]) / 4], axis=1)

    J, G = d_dxi(q), d_dxi(u)  # J[c, i, :] = dx/dxi_i, G[c, i, :] = du/dxi_i
    grad = np.linalg.solve(J, G).transpose(0, 2, 1)  # grad[c, a, d] = du_a/dx_d
    eps = 0.5 * (grad + grad.transpose(0, 2, 1))
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    s = 2 * mu * eps + lam * np.trace(eps, axis1=1, axis2=2)[:, None, None] * np.eye(3)
    return np.stack([s[:, 0, 0], s[:, 1, 1], s[:, 2, 2], s[:, 0, 1], s[:, 1, 2], s[:, 0, 2]], axis=1)


def von_mises(s):
    return np.sqrt(0.5 * ((s[:, 0] - s[:, 1]) ** 2 + (s[:, 1] - s[:, 2]) ** 2 + (s[:, 2] - s[:, 0]) ** 2)
                   + 3 * (s[:, 3] ** 2 + s[:, 4] ** 2 + s[:, 5] ** 2))


def nodal_area(points, ex, ey):
    """each face node's share of the face: a quarter of every quad it is a corner of"""
    x, y = points[:, 0], points[:, 1]
    hx, hy = (x.max() - x.min()) / ex, (y.max() - y.min()) / ey
    wx = np.where(np.isclose(x, x.min()) | np.isclose(x, x.max()), 0.5, 1.0)
    wy = np.where(np.isclose(y, y.min()) | np.isclose(y, y.max()), 0.5, 1.0)
    return wx * wy * hx * hy


def check_fields(run, body, face):
    """stress, von Mises and contact pressure against their definitions,
    recomputed here from the points, the displacement and the contact force"""
    E, nu = run["problem"]["material"]["E"], run["problem"]["material"]["nu"]
    s = centre_stress(body, E, nu)
    scale = max(np.abs(s).max(), 1e-300)
    # (written in single precision: to float rounding of the largest)
    if body["stress"].shape != s.shape or np.abs(body["stress"] - s).max() > 1e-6 * scale:
        fail("cell stress differs from the recomputed one by %.3e of its largest" %
             (np.abs(body["stress"] - s).max() / scale))
    if np.abs(body["von_mises"] - von_mises(s)).max() > 1e-6 * scale:
        fail("von_mises differs from the recomputed one")
    ex, ey, _ = run["dims"]
    area = nodal_area(face["points"], ex, ey)
    lam = face["contact_force"][:, 2]
    fscale = max(np.abs(lam).max(), 1e-300)
    if np.abs(face["contact_pressure"] * area - lam).max() > 1e-12 * fscale:
        fail("contact_pressure x nodal area differs from the normal contact force")
    m = len(face["points"])
    if not np.array_equal(body["contact_pressure"][:m], face["contact_pressure"]):
        fail("the body's contact_pressure differs from the contact file's")
    return "stress, von Mises and contact pressure agree with their recomputation"


def check_patch(args):
    """the uniform-pressure patch test (tests/cases/uniform_pressure.json): beyond
    x = --beyond, contact pressure = p, stress zz = -p, the rest 0, von Mises = p"""
    with open(args.json) as f:
        run = json.load(f)
    body, face = arrays(read(args.vtu)), arrays(read(companion(args.vtu)))
    p = args.patch
    far = face["points"][:, 0] > args.beyond
    dp = np.abs(face["contact_pressure"][far] - p).max() / p
    conn = body["connectivity"].reshape(-1, 8)
    centre = body["points"][conn].mean(axis=1)
    cells = centre[:, 0] > args.beyond
    uniform = np.array([0, 0, -p, 0, 0, 0])
    ds = np.abs(body["stress"][cells] - uniform).max() / p
    dv = np.abs(body["von_mises"][cells] - p).max() / p
    if not (far.sum() > 0 and cells.sum() > 0):
        fail("no face node or cell beyond x = %g" % args.beyond)
    if dp > args.rtol or ds > args.rtol or dv > args.rtol:
        fail("beyond x = %g: pressure off by %.2e, stress by %.2e, von Mises by %.2e of p (tolerance %g)" %
             (args.beyond, dp, ds, dv, args.rtol))
    print("%s: beyond x = %g (%d nodes, %d cells) pressure = p to %.1e, stress = (0,0,-p,0,0,0) to %.1e, "
          "von Mises = p to %.1e; %s" % (args.vtu, args.beyond, far.sum(), cells.sum(), dp, ds, dv,
                                         check_fields(run, body, face)))


def companion(path):
    return os.path.splitext(path)[0] + "_contact.vtu"


def check_run(args):
    with open(args.json) as f:
        run = json.load(f)
    ex, ey, ez = run["dims"]
    body, face = arrays(read(args.vtu)), arrays(read(companion(args.vtu)))
    nx, ny, nz = ex + 1, ey + 1, ez + 1
    if len(body["points"]) != nx * ny * nz:
        fail("body has %d points, expected %d" % (len(body["points"]), nx * ny * nz))
    if len(body["types"]) != ex * ey * ez or np.any(body["types"] != 12):
        fail("body cells are not %d hexahedra" % (ex * ey * ez))
    conn = body["connectivity"].reshape(-1, 8)
    if conn.min() < 0 or conn.max() >= nx * ny * nz:
        fail("connectivity out of range")
    # Jacobian at each hexahedron's centre (VTK node order) has the brick's volume
    q = body["points"][conn]  # cells x 8 x 3
    j0 = (q[:, 1] - q[:, 0] + q[:, 2] - q[:, 3] + q[:, 5] - q[:, 4] + q[:, 6] - q[:, 7]) / 4
    j1 = (q[:, 3] - q[:, 0] + q[:, 2] - q[:, 1] + q[:, 7] - q[:, 4] + q[:, 6] - q[:, 5]) / 4
    j2 = (q[:, 4] - q[:, 0] + q[:, 5] - q[:, 1] + q[:, 6] - q[:, 2] + q[:, 7] - q[:, 3]) / 4
    det = np.einsum("ij,ij->i", j0, np.cross(j1, j2))
    if not np.allclose(det, det[0], rtol=1e-9) or det[0] <= 0:
        fail("hexahedra of different or non-positive volume: %g..%g" % (det.min(), det.max()))
    m = nx * ny
    if len(face["points"]) != m or len(face["types"]) != ex * ey or np.any(face["types"] != 9):
        fail("contact face is not %d points and %d quads" % (m, ex * ey))
    if not np.array_equal(body["displacement"][:m], face["displacement"]):
        fail("the body's bottom plane and the contact file disagree")
    rows = list(csv.DictReader(open(args.csv)))
    if len(rows) != run["contact_nodes"]:
        fail("CSV has %d rows, JSON %d contact nodes" % (len(rows), run["contact_nodes"]))
    n = np.array([int(r["ix"]) + nx * int(r["iy"]) for r in rows])
    u = np.array([[float(r["ux"]), float(r["uy"]), float(r["uz"])] for r in rows])
    lam = np.array([float(r["lambda"]) for r in rows])
    code = np.array([1 if r["contact"] == "0" else (2 if r["stick"] == "1" else 3) for r in rows])
    scale = np.abs(u).max()
    if np.abs(face["displacement"][n] - u).max() > 1e-15 * scale:
        fail("contact displacement differs from the CSV by %g" % np.abs(face["displacement"][n] - u).max())
    if np.abs(face["contact_force"][n][:, 2] - lam).max() > 1e-15 * max(np.abs(lam).max(), 1):
        fail("lambda differs from the CSV")
    if not np.array_equal(face["contact_status"][n], code) or not np.array_equal(body["contact_status"][n], code):
        fail("contact_status differs from the CSV")
    if not np.array_equal(body["contact_force"][:m], face["contact_force"]):
        fail("the body's contact_force differs from the contact file's")
    summary = "%s: %d points, %d cells, %d contact nodes agree with the CSV; %s" % (
        args.vtu, len(body["points"]), len(body["types"]), len(rows), check_fields(run, body, face))
    if args.ascii:
        for b, a in ((body, arrays(read(args.ascii))), (face, arrays(read(companion(args.ascii))))):
            for k in b:
                x, y = b[k].astype(float), a[k].astype(float)
                if x.shape != y.shape or np.abs(x - y).max() > 1e-11 * max(np.abs(x).max(), 1e-300):
                    fail("binary and ASCII differ in " + k)
        sb = os.path.getsize(args.vtu) + os.path.getsize(companion(args.vtu))
        sa = os.path.getsize(args.ascii) + os.path.getsize(companion(args.ascii))
        summary += "; ASCII %d bytes, binary %d bytes: %.1fx smaller" % (sa, sb, sa / sb)
        if sa < args.min_ratio * sb:
            fail("binary is only %.2fx smaller than ASCII (need %g)" % (sa / sb, args.min_ratio))
    print(summary)


def check_pvd(args):
    # VTK's Python module has no .pvd reader (that one is ParaView's): the
    # collection is parsed here, and each file it names is read with VTK
    import xml.etree.ElementTree as ET
    sets = ET.parse(args.pvd).getroot().find("Collection").findall("DataSet")
    steps = sorted({float(d.get("timestep")) for d in sets})
    if args.json:  # the iterates of one Newton solve: x0 and one per step
        with open(args.json) as f:
            args.steps = json.load(f)["newton_iterations"] + 1
    if len(steps) != args.steps:
        fail("%s has %d steps, expected %d" % (args.pvd, len(steps), args.steps))
    for t in steps:
        parts = sorted(int(d.get("part")) for d in sets if float(d.get("timestep")) == t)
        if parts != [0, 1]:
            fail("step %g has parts %s, expected the body (0) and its contact face (1)" % (t, parts))
    for d in sets:
        read(os.path.join(os.path.dirname(args.pvd), d.get("file")))
    print("%s: %d steps of 2 parts each, all read by VTK" % (args.pvd, len(steps)))


def check_pvtu(args):
    r = vtk.vtkXMLPUnstructuredGridReader()
    r.SetFileName(args.pvtu)
    r.Update()
    g = r.GetOutput()
    if r.GetErrorCode() != 0 or g is None or g.GetNumberOfPoints() == 0:
        fail(args.pvtu + ": VTK's parallel reader could not read it")
    one = read(args.vtu)
    a, b = arrays(g), arrays(one)
    if g.GetNumberOfCells() != one.GetNumberOfCells():
        fail("%d cells in the pieces, %d in %s" % (g.GetNumberOfCells(), one.GetNumberOfCells(), args.vtu))
    # the pieces repeat the rows between them: match points by coordinates
    key = lambda pts: [tuple(np.round(x, 9)) for x in pts]
    index_b = {k: i for i, k in enumerate(key(b["points"]))}
    rows = np.array([index_b.get(k, -1) for k in key(a["points"])])
    if (rows < 0).any():
        fail("%d points of the pieces are not points of %s" % (int((rows < 0).sum()), args.vtu))
    if len(set(rows.tolist())) != one.GetNumberOfPoints():
        fail("the pieces do not cover every point of " + args.vtu)
    scale = np.abs(b["displacement"]).max()
    d = np.abs(a["displacement"] - b["displacement"][rows]).max() / scale
    fscale = max(np.abs(b["contact_force"]).max(), 1e-300)
    df = np.abs(a["contact_force"] - b["contact_force"][rows]).max() / fscale
    if d > args.rtol or df > args.rtol:
        fail("displacement differs by %.3e, contact force by %.3e of their largest (tolerance %g)" % (d, df, args.rtol))
    if (a["contact_status"] != b["contact_status"][rows]).any():
        fail("contact_status differs")
    ca, cb = arrays(read(companion(args.pvtu))), arrays(read(companion(args.vtu)))
    dc = np.abs(ca["displacement"] - cb["displacement"]).max() / max(np.abs(cb["displacement"]).max(), 1e-300)
    if dc > args.rtol or (ca["contact_status"] != cb["contact_status"]).any():
        fail("the contact files differ (displacement by %.3e)" % dc)
    print("%s: %d pieces, %d points (%d shared), %d cells; displacement within %.2e, contact force within %.2e of %s"
          % (args.pvtu, r.GetNumberOfPieces(), g.GetNumberOfPoints(), g.GetNumberOfPoints() - one.GetNumberOfPoints(),
             g.GetNumberOfCells(), d, df, args.vtu))


p = argparse.ArgumentParser()
p.add_argument("--vtu")
p.add_argument("--csv")
p.add_argument("--json")
p.add_argument("--ascii")
p.add_argument("--min-ratio", type=float, default=5)
p.add_argument("--pvd")
p.add_argument("--steps", type=int)
p.add_argument("--pvtu")
p.add_argument("--rtol", type=float, default=1e-10)
p.add_argument("--patch", type=float, help="the applied pressure p of the patch test [Pa]")
p.add_argument("--beyond", type=float, default=2.5, help="the patch test's uniform region: x > BEYOND")
a = p.parse_args()
if a.patch:
    check_patch(a)
elif a.pvtu:
    check_pvtu(a)
elif a.pvd:
    check_pvd(a)
else:
    check_run(a)
