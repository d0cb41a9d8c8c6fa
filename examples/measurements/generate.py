#!/usr/bin/env python3
"""Writes the worked measurement examples of vmc3_probe.yaml from known errors.

    python3 examples/measurements/generate.py

writes, beside this script:

  truth.yaml           the known errors (a values file, docs/values.md; um, urad)
  ballplate.csv        3-D tool-point deviations dpx,dpy,dpz of a 5x5 ball plate
                       in 9 placements, each ball probed with two styli
  interferometer.csv   1-D deviations ux,uy,uz,d along the three axis lines and
                       the four body diagonals (ISO 230-2, ISO 230-6)
  candidates.csv       every ball of every placement with both styli, for chain plan

Python 3 standard library only. The deviations are computed here, NOT by chain:
this script has its own model of the machine, the exact 4x4 product

  T(parent -> body) = Trans(offset) . E(location_errors) . J(q) . E(errors + squareness)
  E(d, eps) = [exp([eps x]) (Rodrigues), d]  (to first order the spec's small-angle matrix)
  T_wt = inv(P(x_table)) . P(tool),   p = T_wt(q, e) . tp - T_wt(q, 0) . tp

(machine-format spec section 1, the conventions of tests/it/common/mod.rs), so
that chain identify recovering truth.yaml from these files checks chain's own
derivation. Noise: Gaussian, random.Random(SEED).gauss, in the order the rows
are written; the std of each row is its `std` column.
"""

import math
import os
import random

SEED = 20240613
SIGMA_BALL = 1.0e-3  # mm: probing + ball-plate calibration, per coordinate
SIGMA_AXIS = 0.2e-3  # mm: interferometer along an axis line
SIGMA_DIAG = 0.5e-3  # mm: interferometer along a body diagonal (longer path, worse alignment)

# Styli (tool offsets tx, ty, tz in the spindle frame, mm): a straight one
# 150 mm long and a cranked one reaching 60 mm out and 40 mm back, 220 mm long.
STYLI = [(0.0, 0.0, -150.0), (60.0, -40.0, -220.0)]
# The retroreflector of the interferometer, on the spindle axis.
REFLECTOR = (0.0, 0.0, -150.0)

STROKE = {"x": (0.0, 800.0), "y": (0.0, 500.0), "z": (0.0, 500.0)}

# The known errors: Legendre coefficients (um for translational motions, urad
# for angular ones) of the assumed error motions of examples/values/README.md
# (a lead error of X, bows, a nodding head, ...), and the three squareness
# errors (urad). Each motion: (axis variable, slot, coefficients). Each
# squareness error: (axis variable, slot, value, where): "after" the joint of
# that axis (vmc3_probe.yaml's `squareness`: EC0Y on the Y saddle tilts the X
# travel of the table hanging below it) or "before" it (`location_errors`:
# EA0Z, EB0Z tilt the Z travel direction itself).
MOTIONS = {
    "EXY": ("y", "dx", [1.3, 0.5, -1.3, 0.2]),
    "EYY": ("y", "dy", [3.0, 3.0, 0.3, -0.2]),
    "EZY": ("y", "dz", [-1.4, 0.25, 1.7, 0.1]),
    "EAY": ("y", "ex", [0.2, -2.4, 0.4]),
    "EBY": ("y", "ey", [1.0, 4.0, 0.2]),
    "ECY": ("y", "ez", [-0.33, -2.0, -0.67]),
    "EXX": ("x", "dx", [6.0, 6.0, -0.5, 0.4]),
    "EYX": ("x", "dy", [-2.5, 0.8, 2.6, 0.3]),
    "EZX": ("x", "dz", [-2.0, -0.4, 2.0, -0.25]),
    "EAX": ("x", "ex", [2.8, -1.0, -2.6]),
    "EBX": ("x", "ey", [-0.33, 4.0, -0.67]),
    "ECX": ("x", "ez", [-1.0, -3.8, 0.3]),
    "EXZ": ("z", "dx", [0.9, 0.9, 0.3, -0.15]),
    "EYZ": ("z", "dy", [0.83, 1.25, 0.42, 0.05]),
    "EZZ": ("z", "dz", [2.5, 2.5, -0.3, 0.2]),
    "EAZ": ("z", "ex", [1.0, 3.0, 0.2]),
    "EBZ": ("z", "ey", [-3.67, 0.3, 4.67]),
    "ECZ": ("z", "ez", [1.27, 0.0, -1.33]),
}
SQUARENESS = {
    "EC0Y": ("y", "ez", 15.0, "after"),
    "EA0Z": ("z", "ex", 8.0, "before"),
    "EB0Z": ("z", "ey", -10.0, "before"),
}
SLOTS = ["dx", "dy", "dz", "ex", "ey", "ez"]


def legendre(k, t):
    """P_k(t) by Bonnet's recurrence."""
    p0, p1 = 1.0, t
    if k == 0:
        return p0
    for n in range(1, k):
        p0, p1 = p1, ((2 * n + 1) * t * p1 - n * p0) / (n + 1)
    return p1


def slot_values(var, q, errors_on):
    """The six slot values (mm, rad) after the joint of the body moved by `var`
    at q[var]: its error motions and the squareness errors placed "after"."""
    lo, hi = STROKE[var]
    t = (2.0 * q[var] - lo - hi) / (hi - lo)
    v = [0.0] * 6
    if not errors_on:
        return v
    for name, (mv, slot, coeffs) in MOTIONS.items():
        if mv != var:
            continue
        unit = 1e-3 if slot.startswith("d") else 1e-6
        v[SLOTS.index(slot)] += unit * sum(c * legendre(k, t) for k, c in enumerate(coeffs))
    for name, (sv, slot, value, where) in SQUARENESS.items():
        if sv == var and where == "after":
            v[SLOTS.index(slot)] += 1e-6 * value
    return v


def location_values(var, errors_on):
    """The six slot values (mm, rad) before the joint of the body moved by
    `var`: the squareness errors placed "before" (position-independent)."""
    v = [0.0] * 6
    if not errors_on:
        return v
    for name, (sv, slot, value, where) in SQUARENESS.items():
        if sv == var and where == "before":
            v[SLOTS.index(slot)] += 1e-6 * value
    return v


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def rigid(r, t):
    return [r[0] + [t[0]], r[1] + [t[1]], r[2] + [t[2]], [0.0, 0.0, 0.0, 1.0]]


def translation(t):
    return rigid([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], t)


def exp_so3(w):
    """exp([w x]) by Rodrigues' formula."""
    th2 = w[0] ** 2 + w[1] ** 2 + w[2] ** 2
    th = math.sqrt(th2)
    if th < 1e-6:
        a, b = 1.0 - th2 / 6.0, 0.5 - th2 / 24.0
    else:
        a, b = math.sin(th) / th, (1.0 - math.cos(th)) / th2
    k = [[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]]
    k2 = [[sum(k[i][m] * k[m][j] for m in range(3)) for j in range(3)] for i in range(3)]
    return [[(1.0 if i == j else 0.0) + a * k[i][j] + b * k2[i][j] for j in range(3)] for i in range(3)]


def error_transform(v):
    return rigid(exp_so3(v[3:6]), v[0:3])


def rigid_inverse(m):
    rt = [[m[j][i] for j in range(3)] for i in range(3)]
    t = [sum(rt[i][k] * m[k][3] for k in range(3)) for i in range(3)]
    return rigid(rt, [-t[0], -t[1], -t[2]])


def t_wt(q, errors_on):
    """inv(P(x_table)) . P(tool) of vmc3_probe.yaml, exact."""
    # Workpiece chain: bed -> y_saddle (joint -y) -> x_table (joint -x).
    y_saddle = matmul(translation([0.0, -q["y"], 0.0]), error_transform(slot_values("y", q, errors_on)))
    x_table = matmul(translation([-q["x"], 0.0, 0.0]), error_transform(slot_values("x", q, errors_on)))
    workpiece = matmul(y_saddle, x_table)
    # Tool chain: bed -> column (offset) -> z_head (offset, location errors,
    # joint +z, error motions) -> tool.
    column = translation([0.0, -500.0, 0.0])
    z_head = matmul(
        matmul(
            matmul(translation([0.0, 500.0, 250.0]), error_transform(location_values("z", errors_on))),
            translation([0.0, 0.0, q["z"]]),
        ),
        error_transform(slot_values("z", q, errors_on)),
    )
    tool = matmul(column, z_head)
    return matmul(rigid_inverse(workpiece), tool)


def apply(m, p):
    return [m[i][0] * p[0] + m[i][1] * p[1] + m[i][2] * p[2] + m[i][3] for i in range(3)]


def deviation(x, y, z, tp):
    """The tool-point deviation p (mm) in the workpiece (table) frame."""
    q = {"x": x, "y": y, "z": z}
    a = apply(t_wt(q, True), tp)
    b = apply(t_wt(q, False), tp)
    return [a[i] - b[i] for i in range(3)]


def fmt(v):
    return repr(float(v)) if isinstance(v, float) else str(v)


def axis_positions_for(point, tp):
    """The axis values x, y, z that bring the nominal tool point to `point`
    (table frame): (x + tx, y + ty, z + 250 + tz)."""
    return point[0] - tp[0], point[1] - tp[1], point[2] - 250.0 - tp[2]


# The ball plate: 5 x 5 balls at a 100 mm pitch (a 400 mm plate), ball
# centres on a grid in the plate's own (a, b) coordinates, in 9 placements
# (table-frame coordinates of the balls, mm, nominal tool point):
#   XY plane at heights 150, 300, 450 over the table, left (x 100..500) and right (x 400..800),
#   y 50..450 (on risers; the two overlap by one column of balls);
#   XZ plane at y 250, z 100..500, left and right;  YZ plane at x 400, y 50..450, z 100..500.
# Each placement: origin, the direction of a, the direction of b.
def placements():
    out = []
    for height in (150.0, 300.0, 450.0):
        for x0 in (100.0, 400.0):
            out.append((f"XY z{int(height)} x{int(x0)}", (x0, 50.0, height), (1, 0, 0), (0, 1, 0)))
    for x0 in (100.0, 400.0):
        out.append((f"XZ y250 x{int(x0)}", (x0, 250.0, 100.0), (1, 0, 0), (0, 0, 1)))
    out.append(("YZ x400", (400.0, 50.0, 100.0), (0, 1, 0), (0, 0, 1)))
    return out


def ball_points():
    """(placement index, ball index, table-frame centre) of every ball."""
    pts = []
    for pi, (_, origin, ua, ub) in enumerate(placements()):
        for i in range(5):
            for j in range(5):
                c = [origin[k] + 100.0 * i * ua[k] + 100.0 * j * ub[k] for k in range(3)]
                pts.append((pi, 5 * i + j, c))
    return pts


def in_stroke(x, y, z):
    return all(STROKE[v][0] <= w <= STROKE[v][1] for v, w in (("x", x), ("y", y), ("z", z)))


def write_truth(path):
    lines = [
        "# The known errors of the worked measurements (written by generate.py; do not",
        "# edit: change generate.py and rerun it). Legendre coefficients of every",
        "# error motion of vmc3_probe.yaml and the three squareness errors.",
        "#",
        "#   chain map examples/measurements/vmc3_probe.yaml --values examples/measurements/truth.yaml \\",
        "#       --param tx=0 --param ty=0 --param tz=-150",
        "machine: vmc3_probe",
        "description: the assumed errors the worked measurements were generated from",
        "units: {linear: um, angular: urad}",
        "values:",
    ]
    for name, (_, _, value, _) in SQUARENESS.items():
        lines.append(f"  {name}: {value}")
    for name, (_, _, coeffs) in MOTIONS.items():
        for k, c in enumerate(coeffs):
            lines.append(f"  {name}_{k}: {c}")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    rng = random.Random(SEED)
    write_truth(os.path.join(here, "truth.yaml"))

    # Ball plate: every ball with both styli; each row one probed ball centre.
    names = [p[0] for p in placements()]
    with open(os.path.join(here, "ballplate.csv"), "w") as f, open(
        os.path.join(here, "candidates.csv"), "w"
    ) as c:
        f.write("# Ball plate (5 x 5 balls, 100 mm pitch) in 9 placements, two styli; generate.py.\n")
        f.write("# Placements: " + "; ".join(f"{i} = {n}" for i, n in enumerate(names)) + "\n")
        f.write(f"# Noise: Gaussian, std {SIGMA_BALL} mm per coordinate, seed {SEED}.\n")
        f.write("x,y,z,tx,ty,tz,dpx,dpy,dpz,std\n")
        # No comment line: chain plan's candidate reader does not skip them.
        c.write("x,y,z,tx,ty,tz\n")
        rows = 0
        for pi, bi, centre in ball_points():
            for tp in STYLI:
                x, y, z = axis_positions_for(centre, tp)
                if not in_stroke(x, y, z):
                    raise SystemExit(f"ball {bi} of placement {names[pi]} out of stroke: {x}, {y}, {z}")
                d = deviation(x, y, z, tp)
                noisy = [d[k] + rng.gauss(0.0, SIGMA_BALL) for k in range(3)]
                pose = [x, y, z, tp[0], tp[1], tp[2]]
                f.write(",".join(fmt(v) for v in pose) + "," + ",".join(f"{v:.6f}" for v in noisy))
                f.write(f",{SIGMA_BALL}\n")
                c.write(",".join(fmt(v) for v in pose) + "\n")
                rows += 1
    print(f"ballplate.csv: {rows} rows")

    # Interferometer lines, each run forward and back (two readings a position).
    tp = REFLECTOR
    lines = []  # (label, start axis values, end axis values, count, std)
    cx, cy, cz = 400.0, 250.0, 250.0
    lines.append(("X", (0.0, cy, cz), (800.0, cy, cz), 33, SIGMA_AXIS))
    lines.append(("Y", (cx, 0.0, cz), (cx, 500.0, cz), 21, SIGMA_AXIS))
    lines.append(("Z", (cx, cy, 0.0), (cx, cy, 500.0), 21, SIGMA_AXIS))
    corners = [(0.0, 0.0, 0.0), (800.0, 0.0, 0.0), (0.0, 500.0, 0.0), (800.0, 500.0, 0.0)]
    for a in corners:
        b = (800.0 - a[0], 500.0 - a[1], 500.0)
        lines.append((f"diagonal from ({a[0]:g}, {a[1]:g}, 0)", a, b, 21, SIGMA_DIAG))
    rows = 0
    with open(os.path.join(here, "interferometer.csv"), "w") as f:
        f.write("# Laser interferometer: axis lines through the volume's centre (400, 250, 250)\n")
        f.write("# and the four body diagonals of the volume 800 x 500 x 500, forward and back;\n")
        f.write(f"# reflector at tool offset {tp}; noise Gaussian, std {SIGMA_AXIS} mm (axes),\n")
        f.write(f"# {SIGMA_DIAG} mm (diagonals), seed {SEED}, continuing after ballplate.csv; generate.py.\n")
        f.write("x,y,z,tx,ty,tz,ux,uy,uz,d,std\n")
        for label, a, b, count, sigma in lines:
            span = [b[k] - a[k] for k in range(3)]
            length = math.sqrt(sum(s * s for s in span))
            u = [s / length for s in span]
            f.write(f"# {label}: {count} positions, u = ({u[0]:.9f}, {u[1]:.9f}, {u[2]:.9f})\n")
            for run in (range(count), reversed(range(count))):
                for i in run:
                    s = i / (count - 1)
                    x, y, z = (a[k] + s * span[k] for k in range(3))
                    p = deviation(x, y, z, tp)
                    d = sum(u[k] * p[k] for k in range(3)) + rng.gauss(0.0, sigma)
                    pose = [x, y, z, tp[0], tp[1], tp[2]]
                    f.write(",".join(fmt(v) for v in pose))
                    f.write("," + ",".join(f"{v:.12f}" for v in u) + f",{d:.6f},{sigma}\n")
                    rows += 1
    print(f"interferometer.csv: {rows} rows")


if __name__ == "__main__":
    main()
