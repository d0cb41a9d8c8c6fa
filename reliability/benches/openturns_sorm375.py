#!/usr/bin/env python3
"""FORM + SORM on the 375 gantry cases of reliability/benches/sorm.rs, through
OpenTURNS, beside chain: both answers and the time ratio (issue 15,
"FORM + SORM on all 375 gantry cases ... >= 100x OpenTURNS").

Run by hand (CI has no OpenTURNS):
    python3 -m venv /tmp/ot && /tmp/ot/bin/pip install openturns
    CHAIN_SORM_CASES=/tmp/sorm375.json cargo bench -p reliability --bench sorm
    /tmp/ot/bin/python reliability/benches/openturns_sorm375.py /tmp/sorm375.json [chain_ms]

The JSON holds chain's inputs (every marginal with its parameters and the
correlation pairs as given), each case's sensitivity row and tolerance, and
chain's FORM, Breitung, Hohenbichler-Rackwitz and Tvedt indices. The limit
state of each case is g = I - S.x, handed to OpenTURNS as a LinearFunction
(exact gradient and Hessian, the most favourable form for it). chain's
correlation 0.5 between dxx (lognormal) and dyx (normal) is the correlation of
the physical variables; OpenTURNS' NormalCopula takes the Gaussian one, so the
Nataf closed form for a normal-lognormal pair (Liu & Der Kiureghian 1986)
converts it: rho0 = rho * delta / sqrt(ln(1 + delta^2)), delta = std / (mean -
shift). chain_ms is chain's criterion median for the same 375 cases (default:
the figure of docs/performance.md).
"""
import json
import math
import sys
import time

import openturns as ot


def marginal(m):
    d = m["dist"]
    if d == "normal":
        return ot.Normal(m["mean"], m["std"])
    if d == "lognormal":
        return ot.LogNormalMuSigma(m["mean"], m["std"], m["shift"]).getDistribution()
    if d == "truncated_normal":
        return ot.TruncatedNormal(m["mean"], m["std"], m["min"], m["max"])
    raise SystemExit("marginal %r not handled by this script" % d)


def gaussian_rho(ma, mb, rho):
    """The Nataf Gaussian correlation of a pair (closed forms of the pairs used here)."""
    kinds = {ma["dist"], mb["dist"]}
    if kinds == {"normal"}:
        return rho
    if kinds == {"normal", "lognormal"}:
        ln = ma if ma["dist"] == "lognormal" else mb
        delta = ln["std"] / (ln["mean"] - ln["shift"])
        return rho * delta / math.sqrt(math.log1p(delta * delta))
    raise SystemExit("no closed form here for the pair %s" % sorted(kinds))


def main():
    path = sys.argv[1] if len(sys.argv) > 1 else "/tmp/sorm375.json"
    chain_ms = float(sys.argv[2]) if len(sys.argv) > 2 else 7.99
    doc = json.load(open(path))
    inputs = doc["inputs"]
    margs = inputs["marginals"]
    n = len(margs)
    r = ot.CorrelationMatrix(n)
    for p in inputs.get("correlation", {}).get("pairs", []):
        r[p["a"], p["b"]] = gaussian_rho(margs[p["a"]], margs[p["b"]], p["rho"])
    dist = ot.JointDistribution([marginal(m) for m in margs], ot.NormalCopula(r))
    x = ot.RandomVector(dist)
    mean = dist.getMean()
    center = ot.Point(n, 0.0)

    events = []
    for c in doc["cases"]:
        lin = ot.Matrix(1, n)
        for j, s in enumerate(c["row"]):
            lin[0, j] = -s
        g = ot.LinearFunction(center, [c["tolerance"]], lin)
        events.append(ot.ThresholdEvent(ot.CompositeRandomVector(g, x), ot.Less(), 0.0))

    def run():
        out = []
        for ev in events:
            solver = ot.AbdoRackwitz()
            solver.setMaximumIterationNumber(1000)
            solver.setMaximumAbsoluteError(1e-10)
            solver.setMaximumRelativeError(1e-10)
            solver.setMaximumResidualError(1e-10)
            solver.setMaximumConstraintError(1e-10)
            solver.setStartingPoint(mean)
            algo = ot.SORM(solver, ev)
            algo.run()
            res = algo.getResult()
            out.append(
                (
                    res.getHasoferReliabilityIndex(),
                    res.getGeneralisedReliabilityIndexBreitung(),
                    res.getGeneralisedReliabilityIndexHohenbichler(),
                    res.getGeneralisedReliabilityIndexTvedt(),
                )
            )
        return out

    times = []
    for _ in range(3):
        t0 = time.perf_counter()
        out = run()
        times.append(time.perf_counter() - t0)
    best = min(times)

    keys = ["beta_form", "beta_breitung", "beta_hohenbichler_rackwitz", "beta_tvedt"]
    print("OpenTURNS %s, %d cases, %d inputs" % (ot.__version__, len(events), n))
    for k, name in enumerate(keys):
        diffs = [abs(o[k] - c[name]) for o, c in zip(out, doc["cases"])]
        worst = max(range(len(diffs)), key=lambda i: diffs[i])
        print(
            "%-28s max |chain - OT| = %.2e (case %d: chain %.6f, OT %.6f)"
            % (name, diffs[worst], worst, doc["cases"][worst][name], out[worst][k])
        )
    print("OpenTURNS FORM+SORM, 375 cases: %.1f ms (best of 3: %s)" % (
        best * 1e3, ", ".join("%.0f" % (t * 1e3) for t in times)))
    print("chain (criterion median): %.2f ms -> ratio %.0fx" % (chain_ms, best * 1e3 / chain_ms))


if __name__ == "__main__":
    main()
