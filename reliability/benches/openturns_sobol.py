#!/usr/bin/env python3
"""Side-by-side Sobol indices of chain and OpenTURNS on the same case: the
gantry grinder (seed 000) at (x, y, z) = (500, 1500, 600), 21 independent
normal errors (Table 1 as standard deviations), outputs px, py, pz and the
volumetric error |p| = sqrt(px^2 + py^2 + pz^2) (the model of
`chain derive examples/machines/gantry_grinder.yaml`), N = 10^5 base samples.

OpenTURNS: SobolIndicesExperiment (A, B and the A_B^(i), N(k+2) rows), the
outputs through one native SymbolicFunction (no Python callback), then
SaltelliSensitivityAlgorithm (and JansenSensitivityAlgorithm, for the total
indices chain computes with Jansen's estimator) with a bootstrap of the same
size as chain's, 100 (OpenTURNS' default). chain: `chain sobol --at ...
--samples N --bootstrap 100 --format json` (the whole process: load,
compile, sample, estimate, bootstrap, JSON). Both sides use 2 threads
(ot.TBB.SetThreadsNumber(2); chain's rayon pool on the 2 cores); best of 3.

Not part of the test suite. Needs `pip install openturns` and a built
`target/release/chain`; run from the repository root:

    python3 reliability/benches/openturns_sobol.py [N]

Prints both answers (first-order and total indices of px and |p| for the
leading errors, with the closed form of px) and the time ratio. Results go
to docs/performance.md.
"""

import json
import math
import subprocess
import sys
import time

import openturns as ot

N = int(sys.argv[1]) if len(sys.argv) > 1 else 100_000
BOOTSTRAP = 100
X, Y, Z = 500.0, 1500.0, 600.0

# Table 1 standard deviations.
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
# `chain derive`: the position components, linear in the errors.
PX = {"dxx": -1, "eyx": -Z, "ezx": Y, "Sxy": Y, "dxz": 1, "ezz": -Y, "dxy": 1}
PY = {"dyx": -1, "exx": Z, "ezx": X, "Sxy": X, "dyz": 1, "dyy": 1}
PZ = {"dzx": -1, "exx": -Y, "eyx": -X, "dzz": 1, "exz": Y, "Syz": Y, "dzy": 1}


def expr(row):
    return " + ".join(f"({c!r})*{n}" for n, c in row.items())


def best_of(f, n=3):
    t, out = math.inf, None
    for _ in range(n):
        s = time.perf_counter()
        out = f()
        t = min(t, time.perf_counter() - s)
    return t, out


def openturns_side():
    ot.TBB.SetThreadsNumber(2)
    ot.RandomGenerator.SetSeed(1)
    ot.ResourceMap.SetAsUnsignedInteger("SobolIndicesAlgorithm-DefaultBootstrapSize", BOOTSTRAP)
    dist = ot.JointDistribution([ot.Normal(0.0, STD[n]) for n in NAMES])
    px, py, pz = expr(PX), expr(PY), expr(PZ)
    f = ot.SymbolicFunction(
        NAMES, [px, py, pz, f"sqrt(({px})^2 + ({py})^2 + ({pz})^2)"]
    )

    def run(cls):
        design = ot.SobolIndicesExperiment(dist, N).generate()
        out = f(design)
        algo = cls(design, out, N)
        algo.setBootstrapSize(BOOTSTRAP)
        res = {}
        for o, name in enumerate(["px", "py", "pz", "volumetric"]):
            res[name] = {
                "first": list(algo.getFirstOrderIndices(o)),
                "total": list(algo.getTotalOrderIndices(o)),
            }
        # The intervals (the bootstrap), as chain computes them.
        algo.getFirstOrderIndicesInterval()
        algo.getTotalOrderIndicesInterval()
        return res

    t_saltelli, saltelli = best_of(lambda: run(ot.SaltelliSensitivityAlgorithm))
    t_jansen, jansen = best_of(lambda: run(ot.JansenSensitivityAlgorithm))
    return t_saltelli, saltelli, t_jansen, jansen


def chain_side():
    args = [
        "target/release/chain", "sobol", "examples/machines/gantry_grinder.yaml",
        "--at", f"x={X},y={Y},z={Z}", "--samples", str(N),
        "--bootstrap", str(BOOTSTRAP), "--seed", "1", "--format", "json",
    ]
    return best_of(lambda: json.loads(subprocess.run(args, check=True, capture_output=True).stdout))


def main():
    t_chain, doc = chain_side()
    t_s, saltelli, t_j, jansen = openturns_side()
    var = {n: (PX.get(n, 0.0) * STD[n]) ** 2 for n in NAMES}
    total = sum(var.values())
    print(f"gantry at (x, y, z) = ({X}, {Y}, {Z}), N = {N}, k = 21, bootstrap {BOOTSTRAP}")
    for out in ["px", "volumetric"]:
        ch = {e["error"]: e for e in doc["outputs"][out]["errors"]}
        lead = sorted(NAMES, key=lambda n: -ch[n]["total"]["value"])[:7]
        print(f"\n{out}: {'error':<6} {'exact':>9} {'chain S':>9} {'OT Salt S':>9} {'chain T':>9} {'OT Salt T':>9} {'OT Jans T':>9}")
        for n in lead:
            j = NAMES.index(n)
            ex = f"{var[n] / total:9.5f}" if out == "px" else f"{'-':>9}"
            print(
                f"    {n:<6} {ex} {ch[n]['first']['value']:9.5f} {saltelli[out]['first'][j]:9.5f}"
                f" {ch[n]['total']['value']:9.5f} {saltelli[out]['total'][j]:9.5f} {jansen[out]['total'][j]:9.5f}"
            )
    print(f"\nchain sobol (whole process, 2 threads): {t_chain * 1e3:9.1f} ms")
    print(f"OpenTURNS Saltelli (2 threads):         {t_s * 1e3:9.1f} ms  ratio {t_s / t_chain:6.1f}x")
    print(f"OpenTURNS Jansen (2 threads):           {t_j * 1e3:9.1f} ms  ratio {t_j / t_chain:6.1f}x")


if __name__ == "__main__":
    main()
