#!/usr/bin/env python3
"""OpenTURNS' SORM on the three non-normal cases of reliability/tests/it/sorm.rs.

Run by hand (CI has no OpenTURNS):
    python3 -m venv /tmp/ot && /tmp/ot/bin/pip install openturns
    /tmp/ot/bin/python reliability/benches/openturns_sorm.py
It prints, per case, FORM's beta and the generalised reliability indices of
Breitung, Hohenbichler-Rackwitz and Tvedt, recorded as constants in
reliability/tests/it/sorm.rs. OpenTURNS 1.27.
"""
import openturns as ot


def lognormal(mean, std, shift=0.0):
    return ot.LogNormalMuSigma(mean, std, shift).getDistribution()


# Each case: marginals (the Rust test's, same parameters), the error rows S,
# the tolerance I and the criterion: "upper" g = I - S.x (one row), "norm"
# g = I - |S.x|.
CASES = {
    "lognormal-weibull-gumbel": (
        [lognormal(1.0, 0.3), ot.WeibullMin(1.2, 2.5, 0.0), ot.Gumbel(0.2, 0.5)],
        [[1.0, 0.8, 1.1]],
        4.2,
        "upper",
    ),
    "truncated-triangular-rayleigh-normal": (
        [
            ot.TruncatedNormal(0.0, 1.0, -1.0, 3.0),
            ot.Triangular(0.0, 0.4, 2.0),
            ot.Rayleigh(0.5, 0.0),
            ot.Normal(0.2, 0.3),
        ],
        [[1.0, 1.0, 0.7, -0.5]],
        4.0,
        "upper",
    ),
    "volumetric-lognormal-rayleigh-weibull": (
        [lognormal(0.1, 0.05, -0.2), ot.Rayleigh(0.3, 0.0), ot.WeibullMin(0.5, 1.8, 0.0)],
        [[1.0, 0.5, 0.0], [-0.3, 0.0, 1.0]],
        1.6,
        "norm",
    ),
}


def run(marginals, rows, tol, criterion):
    n = len(marginals)
    xs = ["x%d" % i for i in range(n)]
    es = ["(" + "+".join("(%r)*%s" % (s, x) for s, x in zip(r, xs)) + ")" for r in rows]
    if criterion == "upper":
        expr = "%r - %s" % (tol, es[0])
    else:
        expr = "%r - sqrt(%s)" % (tol, "+".join("%s^2" % e for e in es))
    g = ot.SymbolicFunction(xs, [expr])
    dist = ot.JointDistribution(marginals)
    x = ot.RandomVector(dist)
    y = ot.CompositeRandomVector(g, x)
    event = ot.ThresholdEvent(y, ot.Less(), 0.0)
    solver = ot.AbdoRackwitz()
    solver.setMaximumIterationNumber(1000)
    solver.setMaximumAbsoluteError(1e-12)
    solver.setMaximumRelativeError(1e-12)
    solver.setMaximumResidualError(1e-12)
    solver.setMaximumConstraintError(1e-12)
    algo = ot.SORM(solver, event, dist.getMean())
    algo.run()
    r = algo.getResult()
    return (
        r.getHasoferReliabilityIndex(),
        r.getGeneralisedReliabilityIndexBreitung(),
        r.getGeneralisedReliabilityIndexHohenbichler(),
        r.getGeneralisedReliabilityIndexTvedt(),
        list(r.getSortedCurvatures()),
    )


if __name__ == "__main__":
    for name, case in CASES.items():
        b, bb, bh, bt, k = run(*case)
        print("%s: form %.15e breitung %.15e hr %.15e tvedt %.15e curvatures %s" % (name, b, bb, bh, bt, k))
