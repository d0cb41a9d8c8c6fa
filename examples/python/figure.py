"""A matplotlib figure: the gantry grinder's px reliability over (x, y) at the lowest z.

    python examples/python/figure.py [OUT_DIR]

Without matplotlib it says so and writes nothing.
"""

import pathlib
import sys

import numpy as np

import chain

ROOT = pathlib.Path(__file__).resolve().parents[2]
out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
m = chain.Machine.load(ROOT / "examples/machines/gantry_grinder.yaml")
cases = [c for c in m.reliability().results if c["component"] == "px"]
z0 = min(c["point"]["z"] for c in cases)
xs = sorted({c["point"]["x"] for c in cases})
ys = sorted({c["point"]["y"] for c in cases})
grid = np.zeros((len(ys), len(xs)))
for c in cases:
    if c["point"]["z"] == z0:
        grid[ys.index(c["point"]["y"]), xs.index(c["point"]["x"])] = 100 * c["reliability"]
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed: no figure (pip install matplotlib)")
    sys.exit(0)
fig, ax = plt.subplots(figsize=(5, 4))
im = ax.pcolormesh(xs, ys, grid, shading="nearest")
ax.set_xlabel("x (mm)")
ax.set_ylabel("y (mm)")
ax.set_title(f"{m.name}: px reliability (%) at z = {z0:g}")
fig.colorbar(im, ax=ax)
path = out / "gantry_px_reliability.png"
fig.savefig(path, dpi=100)
print(f"wrote {path}")
