#!/usr/bin/env python3
"""Side-by-side: `chain reliability` over a grid against the numpy pipeline a
user writes over chain's own sensitivities (issue 54; docs/performance.md,
"The main job at the speed of its kernel").

The case: the gantry grinder (examples/machines/gantry_grinder.yaml: 21
independent normal errors, mean 0, tolerance 0.03 mm on px, py, pz, one-sided)
over x = 0..1000, y = -1500..1500, z = 600..1400, N values each (N = 100: 10^6
points; 3 x 10^6 FORM cases, every one in the closed form).

- numpy: `Machine.sensitivity` on the grid's points (the batched tape, every
  core), then per component sigma_c = sqrt(sum_j (S_cj std_j)^2),
  R = Phi(T / sigma_c) (scipy.special.ndtr), and the mean, least and largest
  R: the numbers of the CLI's summary. Taken warm (one run first, then the
  best of three), the points built once outside the timing.
- chain: `chain reliability FILE --grid ... --format table > /dev/null`, the
  release binary, the best of three wall times and the largest peak RSS
  (GNU time's %M).

The summaries of both sides are compared (relative 1e-12) before any time is
reported. Not part of the test suite. Needs numpy, scipy and the chain Python
package (`pip install ./python`, a release wheel) and the release binary
(`cargo build --release`); from the repository root:

    python3 benches/numpy_grid.py [N] [CHAIN_BINARY]

Say the machine's load with the figures (run it on a quiet machine).
"""

import json
import os
import subprocess
import sys
import time

import numpy as np
from scipy.special import ndtr

import chain

N = int(sys.argv[1]) if len(sys.argv) > 1 else 100
BINARY = sys.argv[2] if len(sys.argv) > 2 else "target/release/chain"
FILE = "examples/machines/gantry_grinder.yaml"
AXES = {"x": (0.0, 1000.0), "y": (-1500.0, 1500.0), "z": (600.0, 1400.0)}
TOLERANCE = 0.03
# The file's `statistics` (Table 1 over 6, angles over 6000, squareness over
# 3000; every mean 0).
STD = {
    "dxx": 0.05 / 6, "dyx": 0.05 / 6, "dzx": 0.05 / 6,
    "exx": 0.03 / 6000, "eyx": 0.06 / 6000, "ezx": 0.05 / 6000,
    "dxy": 0.04 / 6, "dyy": 0.05 / 6, "dzy": 0.04 / 6,
    "exy": 0.05 / 6000, "eyy": 0.04 / 6000, "ezy": 0.04 / 6000,
    "dxz": 0.03 / 6, "dyz": 0.03 / 6, "dzz": 0.05 / 6,
    "exz": 0.03 / 6000, "eyz": 0.04 / 6000, "ezz": 0.03 / 6000,
    "Sxy": 0.03 / 3000, "Sxz": 0.03 / 3000, "Syz": 0.02 / 3000,
}


def grid_points(machine):
    """The grid's points, one row per point in the model's variable order."""
    axes = [np.linspace(*AXES[v], N) for v in machine.variables]
    mesh = np.meshgrid(*axes, indexing="ij")
    return np.ascontiguousarray(np.stack([m.ravel() for m in mesh], axis=1))


def numpy_side(machine, points, std):
    """The user's pipeline: sensitivities, sigma per component, Phi(T/sigma)."""
    s = machine.sensitivity(points)
    out = []
    for c in range(3):
        sigma = np.sqrt(np.square(s[:, c, :] * std).sum(axis=1))
        r = ndtr(TOLERANCE / sigma)
        out.append((r.mean(), r.min(), r.max()))
    return out


def best_of(f, n=3):
    best, out = float("inf"), None
    for _ in range(n):
        start = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - start)
    return best, out


def chain_side():
    args = [BINARY, "reliability", FILE, "--format", "json" if N <= 20 else "table"]
    for v, (lo, hi) in AXES.items():
        args += ["--grid", f"{v}={lo:g}:{hi:g}:{N}"]
    return args


def main():
    machine = chain.Machine.load(FILE)
    std = np.array([STD[e] for e in machine.errors])
    points = grid_points(machine)
    numpy_side(machine, points, std)  # warm
    t_numpy, summary = best_of(lambda: numpy_side(machine, points, std))

    # The summaries agree (on a small grid, from the CLI's JSON).
    check_against_cli(machine, std)

    args = chain_side()
    t_chain, peak_kb = float("inf"), 0
    for _ in range(3):
        start = time.perf_counter()
        run = subprocess.run(
            ["/usr/bin/time", "-f", "%M"] + args, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True
        )
        t_chain = min(t_chain, time.perf_counter() - start)
        peak_kb = max(peak_kb, int(run.stderr.strip().splitlines()[-1]))
    print(f"grid {N}^3 = {N**3} points, load {os.getloadavg()[0]:.2f}")
    print(f"numpy pipeline (warm, best of 3): {t_numpy * 1e3:.1f} ms; summary {summary}")
    print(f"chain reliability --format table (best of 3): {t_chain * 1e3:.1f} ms, peak {peak_kb / 1024:.1f} MB")
    print(f"ratio chain / numpy: {t_chain / t_numpy:.2f}")


def check_against_cli(machine, std):
    global N
    n, N = N, 7
    small = grid_points(machine)
    mine = numpy_side(machine, small, std)
    doc = json.loads(subprocess.run(chain_side(), check=True, capture_output=True, text=True).stdout)
    N = n
    for (mean, lo, hi), c in zip(mine, ("px", "py", "pz")):
        s = doc["summary"][c]
        for a, b in ((mean, s["mean"]), (lo, s["min"]), (hi, s["max"])):
            if abs(a - b) > 1e-12 * abs(b):
                raise SystemExit(f"numpy and chain disagree on {c}: {a} vs {b}")


if __name__ == "__main__":
    main()
