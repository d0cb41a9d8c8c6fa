"""Writes x_axis.csv, y_axis.csv and z_axis.csv: the assumed error motions of
the example machine vmc3 (examples/machines/vmc3.yaml), in micrometres and
microradians, 21 positions per axis. See README.md for what the shapes are.

    python3 examples/values/make_tables.py
"""
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def axis(name, stroke, shapes):
    """One CSV: the axis variable, then the six ISO 230-1 error motions."""
    path = os.path.join(HERE, f"{name.lower()}_axis.csv")
    columns = [f"E{c}{name}" for c in "XYZABC"]
    with open(path, "w") as f:
        f.write(f"# vmc3, {name} axis: assumed error motions (examples/values/README.md)\n")
        f.write("# positions in mm; EX, EY, EZ in um; EA, EB, EC in urad\n")
        f.write(",".join([name.lower()] + columns) + "\n")
        for i in range(21):
            q = stroke * i / 20
            s = q / stroke  # 0 .. 1 along the stroke
            row = [f"{q:g}"] + [f"{shape(q, s):.2f}" for shape in shapes]
            f.write(",".join(row) + "\n")


sin, pi = math.sin, math.pi

# X, 0..800 mm: lead error 1.5 um/100 mm with a 200 mm waviness (positioning),
# a 4 um bow (horizontal straightness), a 3 um sag with a slight twist
# (vertical straightness), roll, pitch and yaw of some 10 urad.
axis("X", 800.0, [
    lambda q, s: 0.015 * q + 1.0 * sin(2 * pi * q / 200),
    lambda q, s: -16.0 * s * (1 - s) + 0.3 * sin(2 * pi * q / 300),
    lambda q, s: -12.0 * s * (1 - s) + 1.5 * (s - 0.5) ** 3,
    lambda q, s: 6.0 * sin(pi * s) - 2.0 * s,
    lambda q, s: -5.0 + 12.0 * s - 4.0 * s * s,
    lambda q, s: 4.0 * math.cos(pi * s) - 1.0,
])
# Y, 0..500 mm: 1.2 um/100 mm lead error, 3 um bows, smaller angles.
axis("Y", 500.0, [
    lambda q, s: 0.012 * q - 0.6 * sin(2 * pi * q / 125),
    lambda q, s: 8.0 * s * (1 - s),
    lambda q, s: -10.0 * s * (1 - s) + 0.5 * s,
    lambda q, s: 3.0 * sin(2 * pi * s),
    lambda q, s: 8.0 * s - 3.0,
    lambda q, s: -4.0 * s * s + 1.0,
])
# Z, 0..500 mm: 1.0 um/100 mm, column lean and a nodding head.
axis("Z", 500.0, [
    lambda q, s: 1.8 * s + 0.4 * sin(2 * pi * q / 250),
    lambda q, s: 2.5 * s * s,
    lambda q, s: 0.010 * q - 0.5 * sin(2 * pi * q / 100),
    lambda q, s: 6.0 * s - 2.0,
    lambda q, s: -7.0 * s * (1 - s) * 4 + 1.0,
    lambda q, s: 2.0 * sin(pi * s),
])
