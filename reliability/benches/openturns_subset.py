#!/usr/bin/env python3
"""OpenTURNS' SubsetSampling on the case of `benches/subset.rs` (issue 15,
point 6: subset simulation to p_f ~ 1e-6 at CoV ~ 10 %), for the time ratio
in docs/performance.md.

The case: px of the gantry grinder (seed 000) at the corner
(x, y, z) = (1000, 1500, 1400) in standard normal space, g = I - a.u with the
px row times the Table 1 stds (the 7 errors px depends on; the other 14 do
not enter g and integrate out), I = 4.7534 |a|: p_f = Phi(-4.7534) = 1.00e-6.
The coefficients are printed by `PRINT_CASE=1 cargo bench -p reliability
--bench subset`. Both tools: N = 10,000 samples per level, p0 = 0.1.

Run by hand (CI has no OpenTURNS):
    python3 -m venv /tmp/ot && /tmp/ot/bin/pip install openturns
    cargo bench -p reliability --bench subset   # note its median, in ms
    /tmp/ot/bin/python reliability/benches/openturns_subset.py <chain_ms>
"""
import math
import sys
import time

import openturns as ot

A = [-8.333333333333333e-3, -1.3999999999999999e-2, 1.25e-2, 1.5e-2, 5e-3,
     -7.5e-3, 6.666666666666667e-3]
TOLERANCE = 1.3210594761585195e-1
N = 10_000
REPEATS = 20

n = len(A)
g = ot.SymbolicFunction([f"u{i}" for i in range(n)],
                        [f"{TOLERANCE!r} - (" + " + ".join(f"({a!r})*u{i}" for i, a in enumerate(A)) + ")"])
X = ot.RandomVector(ot.Normal(n))
Y = ot.CompositeRandomVector(g, X)
event = ot.ThresholdEvent(Y, ot.LessOrEqual(), 0.0)
exact = ot.Normal().computeComplementaryCDF(TOLERANCE / math.sqrt(sum(a * a for a in A)))


def run(seed):
    ot.RandomGenerator.SetSeed(seed)
    algo = ot.SubsetSampling(event)
    algo.setMaximumOuterSampling(N)   # N samples per level (block size 1)
    algo.setConditionalProbability(0.1)
    algo.run()
    return algo.getResult(), algo.getStepsNumber()


run(0)  # warm-up
times, pfs, covs = [], [], []
for s in range(REPEATS):
    t0 = time.perf_counter()
    r, levels = run(s + 1)
    times.append(time.perf_counter() - t0)
    pfs.append(r.getProbabilityEstimate())
    covs.append(r.getCoefficientOfVariation())
times.sort()
median = times[len(times) // 2]
print(f"OpenTURNS {ot.__version__} SubsetSampling, N = {N} per level, p0 = 0.1")
print(f"exact pf {exact:.4e}; mean pf over {REPEATS} runs {sum(pfs) / REPEATS:.4e}; "
      f"mean reported CoV {sum(covs) / REPEATS:.3f}; levels of the last run {levels}")
print(f"median time per run: {median * 1e3:.1f} ms")
# chain's criterion median of subset/px_pf_1e-6_N10000, measured just before
# (argument 1; default: the figure of docs/performance.md).
CHAIN_MS = float(sys.argv[1]) if len(sys.argv) > 1 else 3.79
print(f"chain (criterion): {CHAIN_MS} ms -> ratio {median * 1e3 / CHAIN_MS:.0f}x")
