"""The gantry grinder's reliability map (Wang & Yuan 2021, Tables 2-4) from Python.

    python examples/python/gantry_reliability_map.py
"""

import pathlib

import numpy as np

import chain

ROOT = pathlib.Path(__file__).resolve().parents[2]
m = chain.Machine.load(ROOT / "examples/machines/gantry_grinder.yaml")
r = m.reliability(method="form")
print(f"{m.name}: {r.method}, {len(r.results)} cases")
for target, s in r.summary.items():
    print(f"  {target}: mean {100 * s['mean']:.2f} %, min {100 * s['min']:.2f} %, max {100 * s['max']:.2f} %")

# px over (x, y) at the lowest z, as a numpy array
cases = [c for c in r.results if c["component"] == "px"]
xs = sorted({c["point"]["x"] for c in cases})
ys = sorted({c["point"]["y"] for c in cases})
z0 = min(c["point"]["z"] for c in cases)
grid = np.full((len(xs), len(ys)), np.nan)
for c in cases:
    if c["point"]["z"] == z0:
        grid[xs.index(c["point"]["x"]), ys.index(c["point"]["y"])] = 100 * c["reliability"]
print(f"px reliability (%) at z = {z0:g}, rows x = {xs}, columns y = {ys}:")
print(np.array2string(grid, precision=2))
