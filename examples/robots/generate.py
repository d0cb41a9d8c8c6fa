#!/usr/bin/env python3
"""Writes the simulated laser-tracker calibration of puma560_dh.yaml.

    python3 examples/robots/generate.py

writes, beside this script:

  puma560_truth.yaml     the known DH errors (a values file, docs/values.md; mm, urad)
  puma560_tracker.csv    reflector deviations dpx,dpy,dpz at 80 poses (the fit)
  puma560_validate.csv   the same at 30 other poses (for --validate)

Python 3 standard library only. The deviations are computed here, NOT by
chain: each link is the Denavit-Hartenberg matrix of its row with the
parameters perturbed by their errors,

  A_i = Rot_z(theta_i + dtheta_i + q_i) . Trans_z(d_i + dd_i)
        . Trans_x(a_i + da_i) . Rot_x(alpha_i + dalpha_i) . Rot_y(beta_i)

(beta only on link 2, Hayati's parameter for the parallel joints 2 and 3),
then the reflector Trans(40 + TX, TY, 90 + TZ); the deviation is
A_1...A_6 . reflector with the errors minus the same without them, in the
base frame. Noise: Gaussian, random.Random(SEED).gauss, in the order the
rows are written; the std of each row is its `std` column.
"""

import math
import os
import random

SEED = 20261204
STD = 0.02  # mm per coordinate: a laser tracker at 1-2 m
HERE = os.path.dirname(os.path.abspath(__file__))

# (d, a, alpha) of the six rows, mm and rad (theta offsets are all 0).
DH = [
    (672.0, 0.0, math.pi / 2),
    (0.0, 431.8, 0.0),
    (150.05, 20.3, -math.pi / 2),
    (431.8, 0.0, math.pi / 2),
    (0.0, 0.0, -math.pi / 2),
    (0.0, 0.0, 0.0),
]
REFLECTOR = (40.0, 0.0, 90.0)
# Joint ranges (degrees; converted by poses()), the Robotics Toolbox's Puma560 limits.
LIMITS = [(-160, 160), (-45, 225), (-225, 45), (-110, 170), (-100, 100), (-266, 266)]

# The truth: angles in urad, lengths in mm.
TRUTH = {
    "DD1": 0.30, "DT1": 800.0, "DA1": 0.20, "DAL1": 500.0,
    "DD2": -0.20, "DT2": -500.0, "DA2": -0.40, "DAL2": -700.0, "B2": 600.0,
    "DD3": 0.40, "DT3": 1200.0, "DA3": 0.30, "DAL3": 400.0,
    "DD4": -0.30, "DT4": -900.0, "DA4": -0.25, "DAL4": 900.0,
    "DD5": 0.20, "DT5": 600.0, "DA5": 0.15, "DAL5": -600.0,
    "DD6": 0.25, "DT6": 1500.0, "DA6": 0.10, "DAL6": 300.0,
    "TX": 0.30, "TY": -0.20, "TZ": 0.50,
}
ANGULAR = {k for k in TRUTH if k.startswith(("DT", "DAL", "B"))}


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def rot(axis, t):
    c, s = math.cos(t), math.sin(t)
    m = [[1.0, 0, 0, 0], [0, 1.0, 0, 0], [0, 0, 1.0, 0], [0, 0, 0, 1.0]]
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    m[i][i], m[i][j], m[j][i], m[j][j] = c, -s, s, c
    return m


def trans(x, y, z):
    return [[1.0, 0, 0, x], [0, 1.0, 0, y], [0, 0, 1.0, z], [0, 0, 0, 1.0]]


def error(name, e):
    """The value of error `name` in mm or rad (0 without errors)."""
    if e is None:
        return 0.0
    v = e.get(name, 0.0)
    return v * 1e-6 if name in ANGULAR else v


def tool_point(q, e):
    t = trans(0, 0, 0)
    for i, ((d, a, alpha), qi) in enumerate(zip(DH, q), start=1):
        t = matmul(t, rot(2, qi + error(f"DT{i}", e)))
        t = matmul(t, trans(0, 0, d + error(f"DD{i}", e)))
        t = matmul(t, trans(a + error(f"DA{i}", e), 0, 0))
        t = matmul(t, rot(0, alpha + error(f"DAL{i}", e)))
        if i == 2:
            t = matmul(t, rot(1, error("B2", e)))
    x, y, z = REFLECTOR
    t = matmul(t, trans(x + error("TX", e), y + error("TY", e), z + error("TZ", e)))
    return [t[0][3], t[1][3], t[2][3]]


def poses(rng, count):
    out = []
    for _ in range(count):
        out.append([math.radians(rng.uniform(lo, hi)) for lo, hi in LIMITS])
    return out


def write_csv(name, header, rows, rng):
    with open(os.path.join(HERE, name), "w") as f:
        f.write(header)
        f.write("q1,q2,q3,q4,q5,q6,dpx,dpy,dpz,std\n")
        for q in rows:
            with_e = tool_point(q, TRUTH)
            nominal = tool_point(q, None)
            dp = [w - n + rng.gauss(0.0, STD) for w, n in zip(with_e, nominal)]
            cells = [f"{v:.9f}" for v in q] + [f"{v:.6f}" for v in dp] + [f"{STD}"]
            f.write(",".join(cells) + "\n")


def main():
    rng = random.Random(SEED)
    fit, validate = poses(rng, 80), poses(rng, 30)
    note = (
        f"# Noise: Gaussian, std {STD} mm per coordinate, seed {SEED}.\n"
        "# Joint values in rad (uniform within the joint limits); deviations in mm,\n"
        "# base frame. Written by generate.py from puma560_truth.yaml: do not edit.\n"
    )
    write_csv("puma560_tracker.csv", "# Simulated laser-tracker calibration of puma560_dh.yaml.\n" + note, fit, rng)
    write_csv("puma560_validate.csv", "# 30 further poses of the same simulation, for --validate.\n" + note, validate, rng)
    with open(os.path.join(HERE, "puma560_truth.yaml"), "w") as f:
        f.write(
            "# The known DH errors of the simulated calibration (written by generate.py;\n"
            "# do not edit: change TRUTH there and rerun it).\n"
            "machine: puma560\n"
            "description: the assumed errors puma560_tracker.csv was generated from\n"
            "units: {linear: mm, angular: urad}\n"
            "values:\n"
        )
        for k, v in TRUTH.items():
            f.write(f"  {k}: {v}\n")


if __name__ == "__main__":
    main()
