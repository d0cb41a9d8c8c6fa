"""Writes the example positioning runs of examples/positioning/ (a run of our
own making; see README.md there for the model behind every number).

    python3 examples/positioning/generate.py

Only the standard library: the run is reproducible from the seed alone.
"""
import math
import random
from pathlib import Path

HERE = Path(__file__).resolve().parent


def linear_x():
    """X axis of a 1,000 mm travel, ISO 230-2 linear cycle, 5 runs a direction.

    Targets: P_i = (i - 1) * 100 mm + r_i with a random r_i in [-4, 4] mm
    (rounded to 0.1 mm) except at the ends, so that a periodic error is not
    sampled at one phase (the standard's rule for the spacing).
    Deviation of run j at target P (mm):
      lead error of the ball screw      +8 um/m * P
      periodic error (period 230 mm)    1.5 um * sin(2 pi P / 230)
      reversal (lost motion)            up: +2.1 um, down: -2.1 um
      thermal drift over the test       +0.25 um per run (j - 1), both directions
      random                            N(0, 0.6 um)
    """
    rng = random.Random(2302)
    targets = [0.0]
    for i in range(1, 10):
        targets.append(round(i * 100.0 + rng.uniform(-4.0, 4.0), 1))
    targets.append(1000.0)
    rows = []
    for j in range(1, 6):
        for direction, sign, order in (("up", 1.0, targets), ("down", -1.0, targets[::-1])):
            for p in order:
                x_um = (
                    8.0e-3 * p
                    + 1.5 * math.sin(2.0 * math.pi * p / 230.0)
                    + sign * 2.1
                    + 0.25 * (j - 1)
                    + rng.gauss(0.0, 0.6)
                )
                rows.append((p, direction, j, round(p + x_um * 1e-3, 6)))
    with open(HERE / "x_axis_runs.csv", "w") as f:
        f.write("# X axis, laser interferometer, ISO 230-2 linear cycle; see README.md\n")
        f.write("target,direction,run,measured\n")
        for p, d, j, m in rows:
            f.write(f"{p:.1f},{d},{j},{m:.6f}\n")


def rotary_c():
    """C axis (rotary table), targets every 30 deg with the ISO principal
    positions 0, 90, 180, 270; 5 runs a direction; deviations in degrees.
    Deviation (arcsec): once-per-revolution eccentricity 4" sin(theta + 20 deg),
    twice-per-revolution 1.5" sin(2 theta), worm-gear reversal +-1.8",
    random N(0, 0.7").
    """
    rng = random.Random(2302)
    targets = [30.0 * i for i in range(12)]
    rows = []
    for j in range(1, 6):
        for direction, sign, order in (("up", 1.0, targets), ("down", -1.0, targets[::-1])):
            for t in order:
                th = math.radians(t)
                x_arcsec = (
                    4.0 * math.sin(th + math.radians(20.0))
                    + 1.5 * math.sin(2.0 * th)
                    + sign * 1.8
                    + rng.gauss(0.0, 0.7)
                )
                rows.append((t, direction, j, x_arcsec / 3600.0))
    with open(HERE / "c_axis_runs.csv", "w") as f:
        f.write("# C axis (rotary table), degrees; see README.md\n")
        f.write("target,direction,run,deviation\n")
        for t, d, j, x in rows:
            f.write(f"{t:.0f},{d},{j},{x:.9f}\n")


if __name__ == "__main__":
    linear_x()
    rotary_c()
