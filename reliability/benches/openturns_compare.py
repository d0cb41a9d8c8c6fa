#!/usr/bin/env python3
"""Side-by-side timing of chain's reliability engine and OpenTURNS on the same
case: px of the gantry grinder (seed 000) at the worst corner
(x, y, z) = (1000, 1500, 1400), 21 independent normal errors (Table 1 as
standard deviations), g = 0.03 - px (Eq. 34 with the -y*ezz term of Eq. 17).

SORM against OpenTURNS (issue 15, part A): reliability/benches/openturns_sorm.py.

Not part of the test suite. Needs `pip install openturns` and a Rust
toolchain; run from the repository root:

    python3 reliability/benches/openturns_compare.py [SAMPLES]

Both sides run on one thread (OpenTURNS: ot.TBB.SetThreadsNumber(1); chain:
a one-thread rayon pool) and report the best of three runs. Results go to
docs/performance.md.
Subset simulation against OpenTURNS' SubsetSampling: openturns_subset.py.
Sobol indices (SaltelliSensitivityAlgorithm) side by side: openturns_sobol.py.
"""

import json
import math
import subprocess
import sys
import time

import openturns as ot

SAMPLES = int(sys.argv[1]) if len(sys.argv) > 1 else 1 << 22

# Table 1 standard deviations, in the model's error order.
STD = {
    "dxx": 0.05 / 6, "dyx": 0.05 / 6, "dzx": 0.05 / 6,
    "exx": 0.03 / 6000, "eyx": 0.06 / 6000, "ezx": 0.05 / 6000,
    "dxy": 0.04 / 6, "dyy": 0.05 / 6, "dzy": 0.04 / 6,
    "exy": 0.05 / 6000, "eyy": 0.04 / 6000, "ezy": 0.04 / 6000,
    "dxz": 0.03 / 6, "dyz": 0.03 / 6, "dzz": 0.05 / 6,
    "exz": 0.03 / 6000, "eyz": 0.04 / 6000, "ezz": 0.03 / 6000,
    "Sxy": 0.03 / 3000, "Sxz": 0.03 / 3000, "Syz": 0.02 / 3000,
}
NAMES = list(STD)
X, Y, Z = 1000.0, 1500.0, 1400.0
# px = -dxx - z*eyx + y*(ezx + Sxy) + dxz - y*ezz + dxy
COEF = {"dxx": -1.0, "eyx": -Z, "ezx": Y, "Sxy": Y, "dxz": 1.0, "ezz": -Y, "dxy": 1.0}


def best_of(f, n=3):
    t, out = math.inf, None
    for _ in range(n):
        s = time.perf_counter()
        out = f()
        t = min(t, time.perf_counter() - s)
    return t, out


def openturns_side():
    ot.TBB.SetThreadsNumber(1)
    ot.RandomGenerator.SetSeed(1)
    dist = ot.JointDistribution([ot.Normal(0.0, STD[n]) for n in NAMES])
    # g(e) = 0.03 - px(e): a native linear function (no Python callback).
    linear = ot.Matrix(1, len(NAMES))
    for j, n in enumerate(NAMES):
        linear[0, j] = -COEF.get(n, 0.0)
    g = ot.LinearFunction([0.0] * len(NAMES), [0.03], linear)
    event = ot.ThresholdEvent(ot.CompositeRandomVector(g, ot.RandomVector(dist)), ot.LessOrEqual(), 0.0)

    def form():
        algo = ot.FORM(ot.AbdoRackwitz(), event, dist.getMean())
        algo.run()
        return algo.getResult()

    t_form, form_result = best_of(form)

    block = 1 << 16

    def simulate(experiment, ev):
        algo = ot.ProbabilitySimulationAlgorithm(ev, experiment)
        algo.setBlockSize(block)
        algo.setMaximumOuterSampling(SAMPLES // block)
        algo.setMaximumCoefficientOfVariation(0.0)
        algo.setMaximumStandardDeviation(0.0)
        algo.run()
        return algo.getResult().getProbabilityEstimate()

    t_mc, pf_mc = best_of(lambda: simulate(ot.MonteCarloExperiment(), event))
    # OpenTURNS' importance sampling around the FORM design point, in standard
    # space (the closest of its algorithms to the paper's Eq. 23-28).
    std_event = ot.StandardEvent(event)
    design = form_result.getStandardSpaceDesignPoint()
    is_dist = ot.Normal(design, ot.CovarianceMatrix(len(NAMES)))
    t_is, pf_is = best_of(lambda: simulate(ot.ImportanceSamplingExperiment(is_dist), std_event))
    return {
        "form_one_case_s": t_form,
        "form_pf": form_result.getEventProbability(),
        "mc_s": t_mc,
        "mc_pf": pf_mc,
        "is_s": t_is,
        "is_pf": pf_is,
    }


def chain_side():
    out = subprocess.run(
        ["cargo", "run", "--quiet", "--release", "-p", "reliability", "--example", "gantry_throughput", str(SAMPLES)],
        check=True,
        capture_output=True,
        text=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def main():
    c = chain_side()
    o = openturns_side()
    n = (SAMPLES // (1 << 16)) * (1 << 16)
    print(f"case: gantry px at (1000, 1500, 1400), exact pf = {c['form_pf']:.6f}; {SAMPLES} samples, one thread")
    print(f"{'':28}{'chain':>14}{'OpenTURNS ' + ot.__version__:>22}{'ratio':>10}")
    rows = [
        ("FORM, one case", c["form_one_case_s"], o["form_one_case_s"], "s"),
        ("Monte Carlo", c["mc_s"], o["mc_s"], "s"),
        ("importance sampling", c["is_s"], o["is_s"], "s"),
    ]
    for name, a, b, unit in rows:
        print(f"{name:28}{a:>13.4g}{unit}{b:>21.4g}{unit}{b / a:>9.1f}x")
    print(f"{'MC samples/s':28}{SAMPLES / c['mc_s']:>14.3g}{n / o['mc_s']:>22.3g}")
    print(f"{'IS samples/s':28}{SAMPLES / c['is_s']:>14.3g}{n / o['is_s']:>22.3g}")
    print(f"pf: chain FORM {c['form_pf']:.6f} IS {c['is_pf']:.6f} MC {c['mc_pf']:.6f}; "
          f"OpenTURNS FORM {o['form_pf']:.6f} IS {o['is_pf']:.6f} MC {o['mc_pf']:.6f}")
    print(f"chain FORM over all 375 gantry cases: {c['form_375_cases_s'] * 1e3:.3f} ms")


if __name__ == "__main__":
    main()
