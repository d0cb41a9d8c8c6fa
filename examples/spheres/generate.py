#!/usr/bin/env python3
"""Writes the sphere-probing and R-test examples of ac_trunnion_rotary.yaml and
the sphere-probing example of bc_table_rotary.yaml.

    python3 examples/spheres/generate.py

writes, beside this script:

  truth.yaml     the known location errors of the A and C axes (a values
                 file, docs/values.md; mm and rad)
  probing.csv    two spheres probed at 20 rotary positions each (A -60..60
                 deg by 30, C 0..270 deg by 90): the linear axis positions
                 x, y, z at which the probe centre sits at each sphere's
                 centre, rotary positions in degrees (five-axis spec)
  validate.csv   the same spheres at 12 other positions, for --validate
  rtest.csv      an R-test: the nest commanded onto the ball's nominal place
                 at 25 positions (A -45..45, C 0..288 deg by 72), the ball's
                 displacement dpx, dpy, dpz against the nest (measurement CSV:
                 rotary in radians)
  bc_truth.yaml  the known location errors of the B/C table's B and C axes
  bc_probing.csv two spheres on the B/C table probed at B -60..60 deg by 30,
                 C 0..270 deg by 90

Python 3 standard library only. The positions are computed here, NOT by
chain: this script has its own model of the machine, the exact 4x4 product

  T(parent -> body) = Trans(offset) . E(location_errors) . J(q)
  E(d, eps) = [exp([eps x]) (Rodrigues), d]
  T_wt = inv(P(c_table)) . P(spindle),   probe centre = T_wt(q, e) . 0

(the A/C trunnion: the table on Y, the A cradle about x, the C table; the
tool on X and Z. The B/C table: the table on X, the B cradle about y, the C
table; the tool on Y and Z)

(machine-format spec section 1), so that chain identify recovering
truth.yaml from these files checks chain's own derivation. A probing solves
T_wt(q, e) . 0 = s for the three slides by Newton's method (the map is
affine in them). Noise: Gaussian, random.Random(SEED).gauss, on every
written x, y, z (probing) or dpx, dpy, dpz (R-test), in the order written.
"""

import math
import os
import random

SEED = 20261206
SIGMA_PROBE = 0.5e-3  # mm: touch-probe repeatability per coordinate
SIGMA_RTEST = 0.3e-3  # mm: R-test displacement sensors
TOOL_LENGTH = 150.0  # the machine file's tool_length (mm)
CRADLE = 200.0  # the machine file's cradle_height (mm)

# The true location errors (mm, rad).
TRUTH = {
    "EY0A": 0.020,
    "EZ0A": -0.015,
    "EB0A": 3.0e-5,
    "EC0A": -2.0e-5,
    "EX0C": 0.010,
    "EY0C": -0.025,
    "EA0C": 4.0e-5,
    "EB0C": -3.0e-5,
}
# The spheres' centres in the table (C) frame, mm: one low near the table,
# one on a 160 mm column (what a second height adds: docs/five-axis.md).
SPHERES = {"low": (80.0, -50.0, 20.0), "high": (-60.0, 40.0, 180.0)}
# The B/C table (bc_table_rotary.yaml): its parameters, true location
# errors (mm, rad) and spheres.
BC_TOOL_LENGTH = 120.0
BC_CRADLE = 150.0
BC_TRUTH = {
    "EX0B": -0.012,
    "EZ0B": 0.018,
    "EA0B": -2.5e-5,
    "EC0B": 1.5e-5,
    "EX0C": 0.008,
    "EY0C": 0.014,
    "EA0C": -3.5e-5,
    "EB0C": 2.0e-5,
}
BC_SPHERES = {"low": (-70.0, 60.0, 25.0), "high": (50.0, -40.0, 160.0)}
# The R-test ball's nominal place on the table and its set-up offset (the
# unknown the fit estimates beside the errors), mm.
BALL = (60.0, 30.0, 90.0)
BALL_OFFSET = (0.05, -0.03, 0.02)


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def trans(x, y, z):
    return [[1, 0, 0, x], [0, 1, 0, y], [0, 0, 1, z], [0, 0, 0, 1]]


def rot(axis, angle):
    c, s = math.cos(angle), math.sin(angle)
    m = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    m[i][i], m[i][j], m[j][i], m[j][j] = c, -s, s, c
    return m


def err(dx, dy, dz, ex, ey, ez):
    """E(d, eps): the rotation by the rotation vector eps (Rodrigues), then d."""
    th = math.sqrt(ex * ex + ey * ey + ez * ez)
    k = [[0, -ez, ey], [ez, 0, -ex], [-ey, ex, 0]]
    k2 = [[sum(k[i][l] * k[l][j] for l in range(3)) for j in range(3)] for i in range(3)]
    a = math.sin(th) / th if th > 0 else 1.0
    b = (1 - math.cos(th)) / (th * th) if th > 0 else 0.5
    r = [[(1 if i == j else 0) + a * k[i][j] + b * k2[i][j] for j in range(3)] for i in range(3)]
    return [r[0] + [dx], r[1] + [dy], r[2] + [dz], [0, 0, 0, 1]]


def inverse(t):
    r = [[t[j][i] for j in range(3)] for i in range(3)]
    p = [-sum(r[i][k] * t[k][3] for k in range(3)) for i in range(3)]
    return [r[0] + [p[0]], r[1] + [p[1]], r[2] + [p[2]], [0, 0, 0, 1]]


def probe_centre(x, y, z, a, c, e):
    """The A/C trunnion's T_wt(q, e) . 0 in the table frame (a, c in rad)."""
    table = matmul(trans(0, y, 0), trans(0, 0, CRADLE))
    table = matmul(table, err(0, e["EY0A"], e["EZ0A"], 0, e["EB0A"], e["EC0A"]))
    table = matmul(table, rot(0, a))
    table = matmul(table, trans(0, 0, -CRADLE))
    table = matmul(table, err(e["EX0C"], e["EY0C"], 0, e["EA0C"], e["EB0C"], 0))
    table = matmul(table, rot(2, c))
    tool = matmul(matmul(trans(x, 0, 0), trans(0, 0, z)), trans(0, 0, TOOL_LENGTH))
    t = matmul(inverse(table), tool)
    return [t[0][3], t[1][3], t[2][3]]


def bc_probe_centre(x, y, z, b, c, e):
    """The B/C table's T_wt(q, e) . 0 in the table frame (b, c in rad)."""
    table = matmul(trans(x, 0, 0), trans(0, 0, BC_CRADLE))
    table = matmul(table, err(e["EX0B"], 0, e["EZ0B"], e["EA0B"], 0, e["EC0B"]))
    table = matmul(table, rot(1, b))
    table = matmul(table, trans(0, 0, -BC_CRADLE))
    table = matmul(table, err(e["EX0C"], e["EY0C"], 0, e["EA0C"], e["EB0C"], 0))
    table = matmul(table, rot(2, c))
    tool = matmul(matmul(trans(0, y, 0), trans(0, 0, z)), trans(0, 0, BC_TOOL_LENGTH))
    t = matmul(inverse(table), tool)
    return [t[0][3], t[1][3], t[2][3]]


def solve(s, a, c, e, centre=probe_centre):
    """The slides x, y, z at which the probe centre sits at s."""
    q = [0.0, 0.0, 0.0]
    for _ in range(4):
        f0 = centre(*q, a, c, e)
        cols = []
        for k in range(3):
            q1 = list(q)
            q1[k] += 1.0
            f1 = centre(*q1, a, c, e)
            cols.append([f1[i] - f0[i] for i in range(3)])
        r = [s[i] - f0[i] for i in range(3)]

        def det(c0, c1, c2):
            return (c0[0] * (c1[1] * c2[2] - c1[2] * c2[1]) - c1[0] * (c0[1] * c2[2] - c0[2] * c2[1])
                    + c2[0] * (c0[1] * c1[2] - c0[2] * c1[1]))

        d = det(*cols)
        step = [det(r, cols[1], cols[2]) / d, det(cols[0], r, cols[2]) / d, det(cols[0], cols[1], r) / d]
        q = [q[k] + step[k] for k in range(3)]
    return q


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    rng = random.Random(SEED)
    zero = {k: 0.0 for k in TRUTH}

    def probings(name, angles):
        rows = ["sphere,A,C,x,y,z,std"]
        for sphere, s in SPHERES.items():
            for a, c in angles:
                x, y, z = solve(s, math.radians(a), math.radians(c), TRUTH)
                noisy = [v + rng.gauss(0.0, SIGMA_PROBE) for v in (x, y, z)]
                rows.append(f"{sphere},{a:g},{c:g},{noisy[0]:.6f},{noisy[1]:.6f},{noisy[2]:.6f},{SIGMA_PROBE:g}")
        with open(os.path.join(here, name), "w") as f:
            f.write("\n".join(rows) + "\n")

    probings("probing.csv", [(a, c) for a in (-60, -30, 0, 30, 60) for c in (0, 90, 180, 270)])
    probings("validate.csv", [(a, c) for a in (-45, 15, 45) for c in (45, 135, 225, 315)])

    rows = ["A,C,x,y,z,dpx,dpy,dpz,std"]
    for a in (-45, -20, 0, 20, 45):
        for c in (0, 72, 144, 216, 288):
            ar, cr = math.radians(a), math.radians(c)
            x, y, z = solve(BALL, ar, cr, zero)
            actual = probe_centre(x, y, z, ar, cr, TRUTH)
            d = [actual[i] - BALL[i] - BALL_OFFSET[i] + rng.gauss(0.0, SIGMA_RTEST) for i in range(3)]
            rows.append(f"{ar!r},{cr!r},{x!r},{y!r},{z!r},{d[0]:.7f},{d[1]:.7f},{d[2]:.7f},{SIGMA_RTEST:g}")
    with open(os.path.join(here, "rtest.csv"), "w") as f:
        f.write("\n".join(rows) + "\n")

    def truth(name, machine, values):
        lines = [
            f"# The true location errors of examples/machines/{machine}.yaml",
            "# (written by examples/spheres/generate.py).",
            f"machine: {machine}",
            "units: {linear: mm, angular: rad}",
            "values:",
        ] + [f"  {k}: {v!r}" for k, v in values.items()]
        with open(os.path.join(here, name), "w") as f:
            f.write("\n".join(lines) + "\n")

    truth("truth.yaml", "ac_trunnion_rotary", TRUTH)

    # The B/C table, after the A/C files (their noise is drawn first).
    rows = ["sphere,B,C,x,y,z,std"]
    for sphere, s in BC_SPHERES.items():
        for b in (-60, -30, 0, 30, 60):
            for c in (0, 90, 180, 270):
                x, y, z = solve(s, math.radians(b), math.radians(c), BC_TRUTH, bc_probe_centre)
                noisy = [v + rng.gauss(0.0, SIGMA_PROBE) for v in (x, y, z)]
                rows.append(f"{sphere},{b:g},{c:g},{noisy[0]:.6f},{noisy[1]:.6f},{noisy[2]:.6f},{SIGMA_PROBE:g}")
    with open(os.path.join(here, "bc_probing.csv"), "w") as f:
        f.write("\n".join(rows) + "\n")
    truth("bc_truth.yaml", "bc_table_rotary", BC_TRUTH)


if __name__ == "__main__":
    main()
