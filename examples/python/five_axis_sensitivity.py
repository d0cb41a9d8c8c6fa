"""The five-axis A/C trunnion's exact sensitivity over a million points, in one call.

    python examples/python/five_axis_sensitivity.py
"""

import pathlib
import time

import numpy as np

import chain

ROOT = pathlib.Path(__file__).resolve().parents[2]
m = chain.Machine.load(ROOT / "examples/machines/ac_trunnion.yaml")
print(m, m.variables)
n = 1_000_000
rng = np.random.default_rng(0)
lo = np.array([-200.0, -np.pi / 2, -np.pi, -300.0, -200.0])  # y, A, C, x, z
q = rng.uniform(lo, -lo, size=(n, 5))
t = time.perf_counter()
S = m.sensitivity(q)
dt = time.perf_counter() - t
print(f"sensitivity of {n:,} points: {S.shape} {S.dtype} in {dt:.2f} s ({1e9 * dt / n:.0f} ns a point)")
# which error moves the tool point most, on average over the workspace
reach = np.sqrt((S[:, :3, :] ** 2).sum(axis=1)).mean(axis=0)
for j in np.argsort(reach)[::-1][:5]:
    print(f"  {m.errors[j]:>6}: mean |dp/de| = {reach[j]:.3f}")
