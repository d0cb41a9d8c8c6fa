#!/usr/bin/env python3
"""Which sensor-selection method `chain thermal --fit` implements: the comparison.

For each displacement channel of an ISO 230-3 drift test, spec thermal.md fits

    delta_c(t) = c0 + sum_i a_i * dT_i(t)  [ + sum_k b_k * L_k(t; tau_k) ]

with at most K temperature sensors chosen from the data and optional first-order
lag responses L_k to a load column.  This script simulates drift tests (see
`simulate_drift_test`), fits every channel with several selection methods on the
first 70 % of the test, and scores them on the held-out 30 %, which runs a
different spindle programme.  docs/thermal.md quotes its output.

    python3 scripts/thermal_selection.py            # the full study (~1 min)
    python3 scripts/thermal_selection.py --reps 5   # a quick look
    python3 scripts/thermal_selection.py --extra    # + the 20-block exhaustive search (~1.5 min)
    python3 scripts/thermal_selection.py --seed 777 --reps 20   # another draw

numpy only; deterministic (fixed seed; every replication has its own seed
spawned from it, so the numbers do not depend on the order things run in).
"""
import argparse
import itertools
import math
import os
import time

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")  # tiny matrices: threads only cost time

import numpy as np  # noqa: E402

SEED = 2303  # ISO 230-3
DT = 15.0  # s, sampling interval
DURATION = 12 * 3600.0  # s
HOLDOUT = 0.3  # fraction of the duration held out (the end of the test)
K_MAX = 4  # at most K temperature sensors per channel (spec default)
N_BLOCKS = 10  # contiguous CV blocks inside the fit period
MARGIN = 0.01  # a term must lower the CV RMS by at least 1 % to be added
MAX_LAGS = 2  # at most this many load-lag terms per channel
N_TAU = 12  # lag candidates: N_TAU log-spaced time constants ...
TAU_MIN_SAMPLES = 4  # ... from 4 sample intervals to the fit duration
S_MAX = 12000.0  # rpm
CHANNELS = ("Z", "X1", "X2", "Y1", "Y2")  # the five-sensor set-up of ISO 230-3
MIN = 60.0

# Heat-source states every sensor is a mix of (all zero at t = 0):
#   qf, qs  spindle heat q = (speed/S_MAX)^p through a fast (~20 min) and a slow (~2 h) lag
#   ax      axis/machine activity (1 while the spindle runs) through a ~45 min lag
#   R, Rs   room air temperature change, and the same through a 2-4 h lag (structure)
#   cool    coolant: 0.6 q + 0.4 activity through a ~1 h lag
SOURCES = ("qf", "qs", "ax", "R", "Rs", "cool")

# The sensor layout: name, group, twin (a near-duplicate of that sensor, its gains
# within ~3 % and its own lag slightly longer), own lag (min), steady gains (degC per unit
# source).  Groups decide which sensors can be true drivers of a channel.
LAYOUT = [
    ("spindle_front_1", "spindle", None, 2, dict(qf=6.0, qs=4.0, R=0.2, Rs=0.3)),
    ("spindle_front_2", "spindle", "spindle_front_1", 3, None),
    ("spindle_rear", "spindle", None, 5, dict(qf=3.0, qs=4.0, Rs=0.4)),
    ("spindle_motor", "spindle", None, 1, dict(qf=8.0, qs=2.0, R=0.1)),
    ("headstock_left", "spindle", None, 10, dict(qf=1.0, qs=3.0, ax=0.5, Rs=0.5)),
    ("headstock_right", "spindle", "headstock_left", 12, None),
    ("ram", "spindle", None, 20, dict(qf=0.5, qs=2.5, ax=0.5, Rs=0.6)),
    ("column_top_front", "column", None, 30, dict(qs=1.5, ax=0.5, R=0.1, Rs=0.8)),
    ("column_top_rear", "column", "column_top_front", 32, None),
    ("column_middle", "column", None, 35, dict(qs=1.0, ax=0.4, Rs=0.85)),
    ("column_bottom", "column", None, 40, dict(qs=0.5, ax=0.3, Rs=0.9, cool=0.2)),
    ("column_base", "column", None, 60, dict(qs=0.2, Rs=0.95, cool=0.3)),
    ("bed_left", "base", None, 60, dict(ax=0.2, Rs=0.9, cool=0.4)),
    ("bed_right", "base", "bed_left", 70, None),
    ("table", "base", None, 20, dict(ax=0.8, R=0.2, Rs=0.6, cool=0.6)),
    ("room_air_high", "base", None, 1, dict(R=1.1)),
    ("room_air_low", "base", None, 2, dict(R=0.9)),
    ("coolant_tank", "base", None, 5, dict(R=0.3, cool=1.0)),
    ("coolant_return", "base", None, 2, dict(qf=0.3, cool=1.4)),
    ("x_ballscrew_nut", "axes", None, 8, dict(ax=3.0, Rs=0.3)),
    ("y_ballscrew_nut", "axes", None, 10, dict(ax=2.5, Rs=0.3)),
    ("z_ballscrew_nut", "axes", None, 8, dict(qs=0.5, ax=2.0)),
    ("z_motor", "axes", None, 3, dict(ax=4.0)),
    ("cabinet", "axes", None, 15, dict(qf=0.5, ax=1.0, R=0.5)),
]
NAMES = [row[0] for row in LAYOUT]
P = len(LAYOUT)
TWIN_ROOT = [NAMES.index(row[2]) if row[2] else i for i, row in enumerate(LAYOUT)]
GROUP = [row[1] for row in LAYOUT]


def first_order_lag(u, t, tau):
    """tau dL/dt = u - L, L(0) = 0, exact for u constant on [t_n, t_n+1).

    L_{n+1} = L_n e^{-h/tau} + u_n (1 - e^{-h/tau}), h = t_{n+1} - t_n.
    u: (N,) or (N, m); tau: scalar or (m,).  Returns the shape of u.
    """
    U = np.asarray(u, float)
    one = U.ndim == 1
    if one:
        U = U[:, None]
    tau = np.broadcast_to(np.asarray(tau, float), (U.shape[1],))
    h = np.diff(t)
    if np.ptp(h) > 1e-9 * h[0]:  # the recursion itself
        a = np.exp(-h[:, None] / tau)
        L = np.zeros_like(U)
        for n in range(len(U) - 1):
            L[n + 1] = L[n] * a[n] + U[n] * (1 - a[n])
    else:  # uniform sampling: the same recursion, 64 steps per matrix product
        m, M = U.shape[1], 64
        a = np.exp(-h[0] / tau)
        n_ch = -(-(len(U) - 1) // M)
        Up = np.zeros((n_ch * M, m))
        Up[:len(U) - 1] = U[:-1]
        lag = np.subtract.outer(np.arange(M), np.arange(M))  # r - k
        T = np.where(lag >= 0, a[:, None, None] ** np.maximum(lag, 0), 0.0) * (1 - a)[:, None, None]
        V = np.matmul(T, Up.reshape(n_ch, M, m).transpose(2, 1, 0)).transpose(2, 1, 0)  # zero-start response
        pw = a[None, :] ** (np.arange(M)[:, None] + 1)
        start = np.zeros((n_ch, m))
        for i in range(1, n_ch):
            start[i] = start[i - 1] * pw[-1] + V[i - 1, -1]
        L = np.concatenate([np.zeros((1, m)), (pw * start[:, None, :] + V).reshape(-1, m)[:len(U) - 1]])
    return L[:, 0] if one else L


def speed_programme(rng, t, t_fit):
    """Spindle speed (rpm), piecewise constant; a different programme after t_fit.

    Fit period: idle 15-30 min, then four steps up through 25/50/75/100 % of S_MAX
    (each level x U(0.9, 1.1), capped at S_MAX) of 60-95 min each, with one 20-40 min
    stop after the 2nd or 3rd step; the last level runs on to t_fit.
    Held-out period, one of (equally likely):
      duty      on 10-30 min at U(0.3, 1.0) S_MAX (rounded to 500 rpm), off 5-20 min, repeated;
      cooldown  spindle stopped throughout;
      stepdown  50 % S_MAX for 30-60 min, 25 % for 30-60 min, then stopped.
    """
    segs = [(rng.uniform(15, 30) * MIN, 0.0)]
    pause_after = rng.integers(1, 3)
    for i, frac in enumerate((0.25, 0.5, 0.75, 1.0)):
        segs.append((rng.uniform(60, 95) * MIN, min(S_MAX, frac * S_MAX * rng.uniform(0.9, 1.1))))
        if i == pause_after:
            segs.append((rng.uniform(20, 40) * MIN, 0.0))
    segs.append((t_fit, segs[-1][1]))  # the last level runs on (truncated at t_fit)
    kind = ("duty", "cooldown", "stepdown")[rng.integers(3)]
    tail = []
    if kind == "duty":
        while sum(d for d, _ in tail) < DURATION:
            tail.append((rng.uniform(10, 30) * MIN, 500.0 * round(rng.uniform(0.3, 1.0) * S_MAX / 500)))
            tail.append((rng.uniform(5, 20) * MIN, 0.0))
    elif kind == "stepdown":
        tail = [(rng.uniform(30, 60) * MIN, 0.5 * S_MAX), (rng.uniform(30, 60) * MIN, 0.25 * S_MAX)]
    tail.append((DURATION, 0.0))
    s = np.zeros_like(t)
    for start, programme in ((0.0, segs), (t_fit, tail)):
        edge = start
        for dur, speed in programme:
            sel = (t >= edge) & (t < edge + dur) & ((t < t_fit) if start == 0.0 else (t >= t_fit))
            s[sel] = speed
            edge += dur
    return s, kind


def simulate_drift_test(rng, hidden, direct_lag, scale=1.0):
    """One simulated ISO 230-3 drift test: 12 h sampled every 15 s (2881 rows).

    Spindle: `speed_programme`; heat q = (speed/S_MAX)^p, p ~ U(0.9, 1.3); activity m = 1
    while the spindle turns.  Room: 20 + A sin(2 pi t/24 h + phi) + d t, A ~ U(0.5, 1.5) degC,
    phi ~ U(0, 2 pi), d ~ U(-0.15, 0.15) degC/h, plus a random walk (0.05 degC/sqrt(h))
    through a 20 min lag.  Source states (SOURCES): qf = lag(q, U(15, 25) min),
    qs = lag(q, U(90, 150) min), ax = lag(m, U(30, 60) min), R = room change,
    Rs = lag(R, U(2, 4) h), cool = lag(0.6 q + 0.4 m, U(45, 75) min).
    Sensors (LAYOUT, 24): each gain x U(0.8, 1.2) per test (a twin: its parent's gains
    x (1 + N(0, 0.03)) and own lag x U(1.0, 1.3)); T_i = 20 + U(-1, 1) + lag(sum_j w_ij
    source_j, own lag) + a local disturbance (white noise through a U(20, 60) min lag, scaled
    to a std of U(0.01, 0.05) degC: drafts, mounting; real at the sensor's spot, unknown to
    the rest of the structure) + white measurement noise of sigma_i ~ U(0.02, 0.05) degC.
    Displacements (CHANNELS, 5, each drawn independently): 2 or 3 drivers, the first
    from the spindle group, the second from the column group, the third (probability
    1/2) from the base or axes groups.  hidden=False: the drivers ARE those sensors' true
    temperature changes (all but the white measurement noise); hidden=True: each driver is a
    hidden internal temperature, lag(sum_j w_j source_j, U(10, 60) min) with w a random convex
    mix of two sensors' gains of that group, each gain x (1 + N(0, 0.2)), which no sensor
    measures exactly.  Each driver contributes a range of U(5, 20), U(3, 12), U(1, 6) um
    (1st, 2nd, 3rd) x `scale`, with a random sign.  direct_lag=True adds b lag(q, tau) with tau log-uniform in
    [5, 60] min and a range of U(3, 10) um x `scale`, random sign (a response no sensor sees;
    note it lags q, not the logged speed, so it is only approximately a lag of the load
    column when p != 1).  Probe noise: white, sigma ~ U(0.3, 0.5) um per channel;
    delta(t) = x(t) - x(0) as the spec defines it, dT = T(t) - T(0).
    """
    t = np.arange(0.0, DURATION + DT / 2, DT)
    t_fit = (1 - HOLDOUT) * DURATION
    speed, kind = speed_programme(rng, t, t_fit)
    q = (speed / S_MAX) ** rng.uniform(0.9, 1.3)
    m = (speed > 0).astype(float)
    room = (rng.uniform(0.5, 1.5) * np.sin(2 * np.pi * t / 86400 + rng.uniform(0, 2 * np.pi))
            + rng.uniform(-0.15, 0.15) * t / 3600
            + first_order_lag(np.cumsum(rng.normal(0, 0.05 * math.sqrt(DT / 3600), len(t))), t, 20 * MIN))
    R = room - room[0]
    qf, qs, ax = first_order_lag(np.column_stack([q, q, m]), t,
                                 [rng.uniform(15, 25) * MIN, rng.uniform(90, 150) * MIN,
                                  rng.uniform(30, 60) * MIN]).T
    Rs, cool = first_order_lag(np.column_stack([R, 0.6 * q + 0.4 * m]), t,
                               [rng.uniform(2, 4) * 3600, rng.uniform(45, 75) * MIN]).T
    S = np.column_stack([qf, qs, ax, R, Rs, cool])

    W = np.zeros((P, len(SOURCES)))
    tau = np.zeros(P)
    for i, (name, group, twin, own, gains) in enumerate(LAYOUT):
        if twin is None:
            W[i] = [gains.get(s, 0.0) for s in SOURCES] * rng.uniform(0.8, 1.2, len(SOURCES))
            tau[i] = own * MIN
        else:
            j = NAMES.index(twin)
            W[i] = W[j] * (1 + rng.normal(0, 0.03, len(SOURCES)))
            tau[i] = tau[j] * rng.uniform(1.0, 1.3)
    local = first_order_lag(rng.normal(0, 1, (len(t), P)), t, rng.uniform(20, 60, P) * MIN)
    local *= rng.uniform(0.01, 0.05, P) / local.std(0)
    true_dT = first_order_lag(S @ W.T, t, tau) + local  # the temperature change at each sensor's spot
    temps = 20 + rng.uniform(-1, 1, P) + true_dT + rng.normal(0, 1, (len(t), P)) * rng.uniform(0.02, 0.05, P)

    groups = [[i for i in range(P) if GROUP[i] == g] for g in ("spindle", "column")]
    groups.append([i for i in range(P) if GROUP[i] in ("base", "axes")])
    ranges = [(5, 20), (3, 12), (1, 6)]
    nc = len(CHANNELS)
    drivers = []  # per channel: [(sensor or None, gains or None, tau or None, signed range)]
    for c in range(nc):
        drv = []
        for d in range(2 + int(rng.random() < 0.5)):
            r = rng.choice([-1, 1]) * scale * rng.uniform(*ranges[d])
            if hidden:
                a, b = rng.choice(groups[d], 2, replace=False)
                theta = rng.uniform()
                w = (theta * W[a] + (1 - theta) * W[b]) * (1 + rng.normal(0, 0.2, len(SOURCES)))
                drv.append((None, w, rng.uniform(10, 60) * MIN, r))
            else:
                drv.append((int(rng.choice(groups[d])), None, None, r))
        drivers.append(drv)
    if hidden:  # all hidden temperatures through one call
        flat = [x for drv in drivers for x in drv]
        H = first_order_lag(S @ np.array([x[1] for x in flat]).T, t, [x[2] for x in flat])
    lag_taus = np.exp(rng.uniform(math.log(5 * MIN), math.log(60 * MIN), nc))
    lag_ranges = rng.choice([-1, 1], nc) * scale * rng.uniform(3, 10, nc)
    lag_q = first_order_lag(np.repeat(q[:, None], nc, 1), t, lag_taus)
    disp = np.zeros((len(t), nc))
    truth = []
    h = 0
    for c, drv in enumerate(drivers):
        signal = np.zeros(len(t))
        coef = np.zeros(P)
        for i, _, _, r in drv:
            x = true_dT[:, i] if i is not None else H[:, h]
            h += i is None
            k = r / np.ptp(x)
            signal += k * x
            if i is not None:
                coef[i] = k
        if direct_lag:
            signal += lag_ranges[c] / np.ptp(lag_q[:, c]) * lag_q[:, c]
        x_meas = signal + rng.normal(0, rng.uniform(0.3, 0.5), len(t))
        disp[:, c] = x_meas - x_meas[0]
        truth.append(dict(sensors=None if hidden else sorted(x[0] for x in drv),
                          coef=None if hidden else coef, lag_tau=lag_taus[c] if direct_lag else None))
    if direct_lag:  # for the oracle: the true tau applied to the logged speed
        speed_lags = first_order_lag(np.repeat(speed[:, None], nc, 1), t, lag_taus)
        for c in range(nc):
            truth[c]["speed_lag"] = speed_lags[:, c]
    return dict(t=t, t_fit=t_fit, speed=speed, temps=temps, disp=disp, truth=truth, holdout=kind)


# ---------------------------------------------------------------------------------------------
# Fitting.  Every CV fold works on Gram matrices of the standardised design
# Z = [1, dT_1..dT_P, L_1..L_G, y_1..y_C] (fit period): column 0 is the intercept, present in
# every model and never penalised; sensor i is column 1 + i, lag candidate g column 1 + P + g.


class Design:
    """The fit-period design of one test, its CV folds, and the raw columns for refits."""

    def __init__(self, test, n_blocks=N_BLOCKS):
        t = test["t"]
        self.fit = t < test["t_fit"]  # as --fit-until: fit on time < t_fit, predict the rest
        self.hold = ~self.fit
        dT = test["temps"] - test["temps"][0]
        h = float(np.median(np.diff(t)))
        t_fit_len = t[self.fit][-1] - t[0]
        self.taus = np.geomspace(TAU_MIN_SAMPLES * h, t_fit_len, N_TAU)
        lags = first_order_lag(np.repeat(test["speed"][:, None], N_TAU, 1), t, self.taus)
        self.F = np.column_stack([dT, lags])  # raw candidate columns (sensors then lags)
        self.Y = test["disp"]
        Zraw = np.column_stack([self.F, self.Y])[self.fit]
        self.mean, self.std = Zraw.mean(0), Zraw.std(0)
        self.std[self.std == 0] = 1.0
        self.Z = np.column_stack([np.ones(len(Zraw)), (Zraw - self.mean) / self.std])
        self.sensors = list(range(1, P + 1))
        self.lags = list(range(P + 1, P + 1 + N_TAU))
        self.ycol = [P + 1 + N_TAU + c for c in range(self.Y.shape[1])]
        self.folds = {}
        self.blocks = {}
        for scheme, b in (("lobo", 5), ("lobo", 10), ("lobo", 20), ("fc", n_blocks)):
            self.folds[scheme, b] = make_folds(self.Z, b, scheme, self.blocks)
        self.gram = self.Z.T @ self.Z
        self.folds["whole"] = centred(self.gram[None], self.gram[None])  # in-sample: train = test
        self.cache = {}

    def refit(self, cols, c):
        """OLS on the raw fit-period columns; returns (c0, {col: coef}, held-out residual)."""
        key = (tuple(cols), c, self.F.shape[1])
        if key not in self.cache:
            self.cache[key] = self._refit(cols, c)
        return self.cache[key]

    def _refit(self, cols, c):
        X = np.column_stack([np.ones(self.fit.sum())] + [self.F[self.fit, j - 1] for j in cols])
        beta = np.linalg.lstsq(X, self.Y[self.fit, c], rcond=None)[0]
        return self.predict(beta[0], dict(zip(cols, beta[1:])), c)

    def predict(self, c0, coef, c):
        pred = c0 + sum(v * self.F[self.hold, j - 1] for j, v in coef.items())
        return c0, coef, self.Y[self.hold, c] - pred


def make_folds(Z, n_blocks, scheme, cache):
    """Contiguous equal-count blocks; 'lobo' leaves each block out in turn, 'fc' trains on
    blocks 1..b-1 and tests on block b (b = 2..n_blocks).  Returns, stacked over the folds
    (F, D, D): the raw training and test Grams, and the same centred at the training means
    (the intercept of every fold's fit is then implicit: it is the training mean)."""
    if n_blocks not in cache:
        blocks = np.array_split(np.arange(len(Z)), n_blocks)
        cache[n_blocks] = np.array([Z[b].T @ Z[b] for b in blocks])
    G = cache[n_blocks]
    return centred(*((G.sum(0) - G, G) if scheme == "lobo" else (np.cumsum(G, 0)[:-1], G[1:])))


def centred(Gtr, Gte):
    """(Gtr, Gte, Ctr, Cte): the Grams, and the same centred at the training means."""
    mu = Gtr[:, 0, :] / Gtr[:, :1, 0]  # training means (column 0 is the constant 1)
    s, n = Gte[:, 0, :], Gte[:, :1, :1]  # test sums and counts
    Ctr = Gtr - Gtr[:, :1, :1] * mu[:, :, None] * mu[:, None, :]
    Cte = (Gte - s[:, :, None] * mu[:, None, :] - mu[:, :, None] * s[:, None, :]
           + n * mu[:, :, None] * mu[:, None, :])
    return Gtr, Gte, Ctr, Cte


def cv_mse(folds, subsets, y):
    """Blocked-CV mean squared error of OLS (with intercept) for each row of `subsets`.

    subsets: (S, k) Z columns (k may be 0); y: a Z column or a list of them.  For every fold
    the centred training normal equations are solved by Cholesky and the test error is
    expanded through the test Gram centred at the training means:
    SSE = y'y - 2 b'X'y + b'X'X b.  Written element by element over the batch of
    (fold, subset) pairs so that 10^5 tiny systems vectorise.
    Returns (S,) or (S, len(y)), in standardised units.
    """
    _, Gte, Ctr, Cte = folds
    F, D, _ = Ctr.shape
    subsets = np.asarray(subsets, int).reshape(len(subsets), -1)
    idx = [subsets[:, k] for k in range(subsets.shape[1])]
    m = len(idx)
    ys = np.atleast_1d(y)
    flat_tr, flat_te = Ctr.reshape(F, D * D), Cte.reshape(F, D * D)
    y_tr, y_te = Ctr[:, :, ys], Cte[:, :, ys]  # (F, D, ny)

    def pair(flat, i, j):  # entries (F, S) of the Gram at the subsets' columns i, j
        return np.take(flat, idx[i] * D + idx[j], axis=1)

    L = [[None] * m for _ in range(m)]  # Cholesky factor, entries (F, S)
    for j in range(m):
        d = pair(flat_tr, j, j) * (1 + 1e-12) - sum(L[j][k] ** 2 for k in range(j))
        L[j][j] = np.sqrt(np.maximum(d, 1e-300))
        for i in range(j + 1, m):
            L[i][j] = (pair(flat_tr, i, j) - sum(L[i][k] * L[j][k] for k in range(j))) / L[j][j]
    z = []  # forward substitution, entries (F, S, ny)
    for i in range(m):
        rhs = np.take(y_tr, idx[i], axis=1) - sum(L[i][k][..., None] * z[k] for k in range(i))
        z.append(rhs / L[i][i][..., None])
    beta = [None] * m  # back substitution
    for i in reversed(range(m)):
        beta[i] = (z[i] - sum(L[k][i][..., None] * beta[k] for k in range(i + 1, m))) / L[i][i][..., None]
    sse = np.broadcast_to(Cte[:, ys, ys][:, None, :], (F, len(subsets), len(ys)))
    for i in range(m):
        sse = sse + beta[i] * (beta[i] * pair(flat_te, i, i)[..., None] - 2 * np.take(y_te, idx[i], axis=1))
        for j in range(i + 1, m):
            sse = sse + 2 * beta[i] * beta[j] * pair(flat_te, i, j)[..., None]
    out = sse.sum(0) / Gte[:, 0, 0].sum()
    return out[:, 0] if np.ndim(y) == 0 else out


def forward_select(folds, y, sensors, lags=(), k_max=K_MAX, max_lags=0, margin=MARGIN, start=()):
    """Greedy forward selection by blocked CV.  At each step every remaining candidate is
    scored by the CV RMS of OLS on (chosen + candidate); the best one (ties: the lowest
    column, i.e. the first sensor in file order, lags after sensors in increasing tau) is
    added if it lowers the CV RMS by at least `margin` (relative); else stop.
    Returns (chosen columns, CV RMS after each accepted step, starting with the start model)."""
    chosen = list(start)
    cur = math.sqrt(cv_mse(folds, [chosen], y)[0])
    trace = [cur]
    while True:
        n_s = sum(j in sensors for j in chosen)
        n_l = len(chosen) - n_s
        cands = ([j for j in sensors if j not in chosen] if n_s < k_max else []) + \
                ([j for j in lags if j not in chosen] if n_l < max_lags else [])
        if not cands:
            break
        e = np.sqrt(np.maximum(cv_mse(folds, [chosen + [j] for j in cands], y), 0))
        b = int(np.argmin(e))
        if not e[b] < (1 - margin) * cur:
            break
        chosen.append(cands[b])
        cur = e[b]
        trace.append(cur)
    return chosen, trace


def forward_bic(design, y, sensors, k_max=K_MAX):
    """Greedy forward selection by in-sample BIC = n ln(RSS/n) + (k+1) ln n (no CV): the
    same machinery with the whole fit period as both training and test set."""
    whole = design.folds["whole"]
    n = design.gram[0, 0]
    chosen = []
    cur = n * math.log(cv_mse(whole, [chosen], y)[0]) + math.log(n)
    while len(chosen) < k_max:
        cands = [j for j in sensors if j not in chosen]
        bic = n * np.log(cv_mse(whole, [chosen + [j] for j in cands], y)) + (len(chosen) + 2) * math.log(n)
        b = int(np.argmin(bic))
        if not bic[b] < cur:
            break
        chosen.append(cands[b])
        cur = bic[b]
    return chosen


def exhaustive(folds, ys, k_max=K_MAX, combos=None):
    """Best subset of each size 0..k_max by blocked CV, for all channels at once (sensor
    columns 1..P).  Returns, per channel, [(columns, CV RMS)] for sizes 0..k_max; ties go to
    the first subset in lexicographic order of columns (np.argmin)."""
    best = [[([], math.sqrt(v)) for v in cv_mse(folds, np.zeros((1, 0), int), ys)[0]]]
    for k in range(1, k_max + 1):
        e = np.sqrt(np.maximum(cv_mse(folds, combos[k], ys), 0))
        b = np.argmin(e, 0)
        best.append([(list(combos[k][b[c]]), e[b[c], c]) for c in range(len(ys))])
    return [[best[k][c] for k in range(k_max + 1)] for c in range(len(ys))]


def stop_at(trace, margin):
    """The size rule: grow while the next size lowers the CV RMS by at least `margin`."""
    k = 0
    while k + 1 < len(trace) and trace[k + 1] < (1 - margin) * trace[k]:
        k += 1
    return k


def fold_moments(G, cols, y):
    """Centred, standardised moments of a training Gram: Q (unit diagonal), c, means, scales."""
    n = G[0, 0]
    mu = G[0, cols] / n
    ybar = G[0, y] / n
    C = G[np.ix_(cols, cols)] / n - np.outer(mu, mu)
    s = np.sqrt(np.maximum(np.diag(C), 1e-300))
    Q = C / np.outer(s, s)
    c = (G[cols, y] / n - mu * ybar) / s
    return Q, c, mu, s, ybar


def test_sse(Gte, cols, y, w0, W):
    """SSE on a test Gram of predictions w0 + Z[:, cols] @ W.T for each row of W."""
    idx = [0] + list(cols)
    V = np.column_stack([w0, W])
    Gi = Gte[np.ix_(idx, idx)]
    return Gte[y, y] - 2 * V @ Gte[idx, y] + np.einsum("lk,kj,lj->l", V, Gi, V)


def ridge_cv(design, folds, y, lams=np.logspace(-6, 1, 36)):
    """Ridge on all sensors (standardised within each training fold), lambda by blocked CV."""
    cols = design.sensors

    def path(G):
        Q, c, mu, s, ybar = fold_moments(G, cols, y)
        e, V = np.linalg.eigh(Q)
        B = (V @ ((V.T @ c)[:, None] / (e[:, None] + lams[None, :]))).T / s  # (L, P) per Z unit
        return ybar - B @ mu, B

    sse = sum(test_sse(Gte, cols, y, *path(Gtr)) for Gtr, Gte in zip(*folds[:2]))
    w0, B = path(design.gram)
    lam = int(np.argmin(sse))
    return w0[lam], B[lam]


def lars_lasso(Q, c, lam_stop, max_active):
    """The exact LASSO path (LARS with the lasso modification, Efron et al. 2004) of
    min 1/2 b'Qb - c'b + lam |b|_1, from lam_max down to lam_stop or until more than
    max_active variables are active.  Returns the knots [(lam, b)], lam decreasing;
    b is linear in lam between knots."""
    p = len(c)
    b = np.zeros(p)
    lam = float(np.max(np.abs(c)))
    active = [int(np.argmax(np.abs(c)))]
    knots = [(lam, b.copy())]
    while lam > lam_stop and len(active) <= max_active:
        r = c - Q @ b
        d = np.zeros(p)
        d[active] = np.linalg.solve(Q[np.ix_(active, active)], np.sign(r[active]))
        a = Q @ d  # along the path, r changes by -gamma a
        gamma, event = lam - lam_stop, None
        inactive = np.setdiff1d(np.arange(p), active)
        with np.errstate(divide="ignore", invalid="ignore"):
            cand = np.concatenate([(lam - r[inactive]) / (1 - a[inactive]), (lam + r[inactive]) / (1 + a[inactive])])
            cand[~(cand > 1e-12)] = np.inf
            if len(cand) and cand.min() < gamma:
                gamma, event = cand.min(), ("add", int(inactive[np.argmin(cand) % len(inactive)]))
            drop = -b[active] / d[active]
            drop[~(drop > 1e-12)] = np.inf
            if len(drop) and drop.min() < gamma:
                gamma, event = drop.min(), ("drop", active[int(np.argmin(drop))])
        b = b + gamma * d
        lam -= gamma
        if event and event[0] == "add":
            active.append(event[1])
        elif event:
            active.remove(event[1])
            b[event[1]] = 0.0
        knots.append((lam, b.copy()))
    return knots


def path_at(knots, lams):
    """The path's coefficients at each lambda (NaN below the last knot)."""
    kl = np.array([k[0] for k in knots])
    kb = np.array([k[1] for k in knots])
    j = np.clip(np.searchsorted(-kl, -lams), 1, max(len(kl) - 1, 1))  # kl[j-1] >= lam >= kl[j]
    if len(kl) == 1:
        return np.where((lams >= kl[0])[:, None], kb[0], np.nan)
    w = np.clip((kl[j - 1] - lams) / np.maximum(kl[j - 1] - kl[j], 1e-300), 0, 1)[:, None]
    out = (1 - w) * kb[j - 1] + w * kb[j]
    out[lams < kl[-1]] = np.nan
    return out


def lasso_cv(design, folds, y, k_max=K_MAX, n_lam=40):
    """LASSO on standardised dT (standardised within each training fold; the intercept is the
    unpenalised mean), lambda on a log grid from lambda_max down to 1e-3 lambda_max chosen by
    blocked CV among the lambdas whose full-fit solution has 1..k_max non-zeros; then OLS on
    that support (relaxed LASSO).  Exact path by LARS-lasso."""
    cols = design.sensors
    Q, c, *_ = fold_moments(design.gram, cols, y)
    lams = np.max(np.abs(c)) * np.logspace(0, -3, n_lam)
    full = lars_lasso(Q, c, lams[-1], k_max)
    B = path_at(full, lams)
    nnz = np.count_nonzero(np.nan_to_num(B, nan=1.0), 1)
    ok = (nnz >= 1) & (nnz <= k_max) & ~np.isnan(B[:, 0])
    if not ok.any():
        return []
    lam_stop = lams[ok][-1]
    sse = np.zeros(len(lams))
    for Gtr, Gte in zip(*folds[:2]):
        Qf, cf, mu, s, ybar = fold_moments(Gtr, cols, y)
        Bf = path_at(lars_lasso(Qf, cf, lam_stop, len(cols)), lams)
        W = np.nan_to_num(Bf) / s
        sse += test_sse(Gte, cols, y, ybar - W @ mu, W)
    sse[~ok] = np.inf
    best = int(np.argmin(sse))
    return [cols[j] for j in np.flatnonzero(B[best])]


def forward_swap(folds, y, sensors, k_max=K_MAX, margin=MARGIN):
    """Forward selection with replacement: after each accepted addition, swap any chosen
    sensor for an unchosen one while the best swap lowers the CV RMS (by any amount)."""
    chosen = []
    cur = math.sqrt(cv_mse(folds, [chosen], y)[0])
    while len(chosen) < k_max:
        cands = [j for j in sensors if j not in chosen]
        e = np.sqrt(np.maximum(cv_mse(folds, [chosen + [j] for j in cands], y), 0))
        b = int(np.argmin(e))
        if not e[b] < (1 - margin) * cur:
            break
        chosen.append(cands[b])
        cur = e[b]
        for _ in range(20):
            swaps = [(i, j) for i in range(len(chosen)) for j in sensors if j not in chosen]
            subs = [chosen[:i] + [j] + chosen[i + 1:] for i, j in swaps]
            e = np.sqrt(np.maximum(cv_mse(folds, subs, y), 0))
            b = int(np.argmin(e))
            if not e[b] < cur * (1 - 1e-9):
                break
            chosen, cur = subs[b], e[b]
    return chosen


# ---------------------------------------------------------------------------------------------
# The study.  Methods (all CV: N_BLOCKS contiguous blocks, leave one block out, unless named):
#   oracle       OLS on the true sensors (+ the true lag on the speed column): A and C only
#   ols_all      OLS on all 24 sensors; ridge: all sensors, lambda by CV (both ignore K)
#   exhaustive   best subset of each size 0..K by CV; the size rule of stop_at (MARGIN)
#   fs_cv        forward selection by CV, same rule; fs_swap: + swaps after each addition;
#                fs_fc: forward-chaining CV (train on the blocks before the test block)
#   lasso        LASSO path, lambda by CV among <= K non-zeros, OLS refit on the support
#   ex_bic       best subset of each size by in-sample RSS, size by BIC; fs_bic: greedy, BIC
#   ex_lag       exhaustive, then up to MAX_LAGS lag terms by forward selection (MARGIN;
#                _m5: 5 %, _m0: 0 %); fs_lag: the same after fs_cv; fs_lag_joint: lags and
#                sensors compete in one forward selection

SCENARIOS = [  # name, hidden drivers, direct load lag, drift scale
    ("A exact", False, False, 1.0),
    ("B hidden", True, False, 1.0),
    ("C exact+lag", False, True, 1.0),
    ("D hidden+lag", True, True, 1.0),
    ("E weak", True, False, 0.1),
]
MAIN_METHODS = ["oracle", "ols_all", "ridge", "exhaustive", "fs_cv", "fs_swap", "fs_fc", "lasso", "ex_bic", "fs_bic"]
LAG_METHODS = ["exhaustive", "ex_lag", "ex_lag_m5", "ex_lag_m0", "fs_cv", "fs_lag", "fs_lag_joint"]
MARGINS = (0.0, 0.01, 0.02, 0.05)
PATHS = [("fs", "lobo", 5), ("fs", "lobo", 10), ("fs", "lobo", 20), ("ex", "lobo", 5), ("ex", "lobo", 10)]
PATHS_EXTRA = [("ex", "lobo", 20)]  # --extra: a third exhaustive search per test (slow)


def run_replication(seed, hidden, direct_lag, scale, combos, paths=PATHS):
    """One simulated test, every channel fitted by every method; per channel a dict
    method -> metrics, and per method the fit time per channel."""
    rng = np.random.default_rng(seed)
    test = simulate_drift_test(rng, hidden, direct_lag, scale)
    timing = {}

    def timed(name, f, per=1):
        t0 = time.perf_counter()
        r = f()
        timing[name] = timing.get(name, 0.0) + (time.perf_counter() - t0) / per
        return r

    d = timed("setup", lambda: Design(test), len(CHANNELS))
    folds = d.folds["lobo", N_BLOCKS]
    nc = len(CHANNELS)
    ex = {(sch, nb): timed("exhaustive" if (sch, nb) == ("lobo", N_BLOCKS) else "_",
                           lambda: exhaustive(d.folds[sch, nb], d.ycol, combos=combos), nc)
          for _, sch, nb in paths if _ == "ex"}
    ex_whole = exhaustive(d.folds["whole"], d.ycol, combos=combos)  # best in-sample RSS of each size
    n_fit = d.gram[0, 0]
    rows = []
    for c, y in enumerate(d.ycol):
        truth = test["truth"][c]
        bic = [n_fit * math.log(e ** 2) + (k + 1) * math.log(n_fit) for k, (_, e) in enumerate(ex_whole[c])]
        best = ex["lobo", N_BLOCKS][c]
        ex_cols = best[stop_at([e for _, e in best], MARGIN)][0]
        fs_cols = timed("fs_cv", lambda: forward_select(folds, y, d.sensors)[0])

        def lag_stage(start, margin=MARGIN):
            return forward_select(folds, y, d.sensors, d.lags, k_max=0, max_lags=MAX_LAGS,
                                  margin=margin, start=start)[0]

        sel = {
            "exhaustive": ex_cols,
            "fs_cv": fs_cols,
            "fs_swap": timed("fs_swap", lambda: forward_swap(folds, y, d.sensors)),
            "fs_fc": forward_select(d.folds["fc", N_BLOCKS], y, d.sensors)[0],
            "fs_bic": timed("fs_bic", lambda: forward_bic(d, y, d.sensors)),
            "ex_bic": ex_whole[c][int(np.argmin(bic))][0],
            "lasso": timed("lasso", lambda: lasso_cv(d, folds, y)),
            "ols_all": d.sensors,
            "ex_lag": timed("lag stage", lambda: lag_stage(ex_cols)),
            "ex_lag_m5": lag_stage(ex_cols, 0.05),
            "ex_lag_m0": lag_stage(ex_cols, 0.0),
            "fs_lag": lag_stage(fs_cols),
            "fs_lag_joint": forward_select(folds, y, d.sensors, d.lags, max_lags=MAX_LAGS)[0],
        }
        # the CV scheme, block count and margin: neither the greedy path nor the best subset
        # of each size depends on the margin, only where the size rule stops
        for kind, sch, nb in paths:
            if kind == "fs":
                path, trace = forward_select(d.folds[sch, nb], y, d.sensors, margin=-np.inf)
                for m in MARGINS:
                    sel["sens", kind, sch, nb, m] = path[:stop_at(trace, m)]
            else:
                b = ex[sch, nb][c]
                for m in MARGINS:
                    sel["sens", kind, sch, nb, m] = b[stop_at([e for _, e in b], m)][0]
        res = {name: d.refit(cols, c) for name, cols in sel.items()}
        w0, w = timed("ridge", lambda: ridge_cv(d, folds, y))
        sy, my = d.std[P + N_TAU + c], d.mean[P + N_TAU + c]  # back to raw units
        coef = {j: sy * w[k] / d.std[j - 1] for k, j in enumerate(d.sensors)}
        res["ridge"] = d.predict(my + sy * w0 - sum(v * d.mean[j - 1] for j, v in coef.items()), coef, c)
        if not hidden:  # OLS on the true sensors (and the true lag, its tau on the speed column)
            cols = [1 + i for i in truth["sensors"]]
            if direct_lag:
                d.F = np.column_stack([d.F, truth["speed_lag"]])
                cols.append(d.F.shape[1])
            res["oracle"] = d.refit(cols, c)
            d.F = d.F[:, :P + N_TAU]

        before = math.sqrt(np.mean(d.Y[d.hold, c] ** 2))
        row = {"holdout": test["holdout"]}
        for name, (c0, coef, resid) in res.items():
            sens = sorted(j - 1 for j in coef if j <= P)
            lag_cols = [j - P - 1 for j in coef if P < j <= P + N_TAU]
            r = {"rel": math.sqrt(np.mean(resid ** 2)) / before, "n_sensors": len(sens), "n_lags": len(lag_cols)}
            if truth["lag_tau"] is not None and lag_cols:
                r["tau_ok"] = bool(np.any(np.abs(np.log(d.taus[lag_cols] / truth["lag_tau"])) < math.log(2)))
            if not hidden:
                r["exact"] = sens == truth["sensors"]
                r["contains"] = set(truth["sensors"]) <= set(sens)
                r["twin"] = {TWIN_ROOT[i] for i in sens} == {TWIN_ROOT[i] for i in truth["sensors"]}
                a = np.zeros(P)
                for j, v in coef.items():
                    if j <= P:
                        a[j - 1] = v
                sx = d.std[:P]
                r["coef_err"] = np.linalg.norm((a - truth["coef"]) * sx) / np.linalg.norm(truth["coef"] * sx)
            row[name] = r
        rows.append(row)
    timing.pop("_", None)
    for k in ("fs_cv", "fs_swap", "fs_bic", "lasso", "ridge", "lag stage"):
        timing[k] /= nc
    return rows, timing


def q(v, p):
    v = np.asarray(v, float)
    return float(np.quantile(v, p)) if len(v) else float("nan")


def cell(v):
    return f"{q(v, .5):.3f} / {q(v, .9):.3f}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=30, help="replications per scenario (default 30)")
    ap.add_argument("--extra", action="store_true", help="also the exhaustive search with 20 blocks")
    ap.add_argument("--seed", type=int, default=SEED, help=f"master seed (default {SEED})")
    args = ap.parse_args()
    paths = PATHS + PATHS_EXTRA if args.extra else PATHS
    combos = {k: np.array(list(itertools.combinations(range(1, P + 1), k))) for k in range(1, K_MAX + 1)}
    seeds = np.random.SeedSequence(args.seed).spawn(len(SCENARIOS) * args.reps)
    results, timing = {}, {}
    t_start = time.perf_counter()
    for s, (name, hidden, lag, scale) in enumerate(SCENARIOS):
        results[name] = []
        for r in range(args.reps):
            rows, tt = run_replication(seeds[s * args.reps + r], hidden, lag, scale, combos, paths)
            results[name] += rows
            for k, v in tt.items():
                timing.setdefault(k, []).append(v)
    elapsed = time.perf_counter() - t_start
    names = [sc[0] for sc in SCENARIOS]
    exact = [sc[0] for sc in SCENARIOS if not sc[1]]

    def rel(m, scen):
        return [row[m]["rel"] for sc in scen for row in results[sc] if m in row]

    n = args.reps * len(CHANNELS)
    print(f"# Thermal sensor selection: {args.reps} tests x {len(CHANNELS)} channels per scenario, "
          f"{P} sensors, K = {K_MAX}, {N_BLOCKS} blocks (leave one out), margin {MARGIN:.0%}, seed {args.seed}\n")
    print(f"## Held-out RMS after correction / held-out RMS before (median / p90 of {n} channels), sensors only\n")
    print("| method | " + " | ".join(names) + " | sensors (A/B) |")
    print("|" + "---|" * (len(names) + 2))
    for m in MAIN_METHODS:
        cells = [cell(rel(m, [sc])) if rel(m, [sc]) else "-" for sc in names]
        ns = "/".join(f"{np.mean([row[m]['n_sensors'] for row in results[sc]]):.1f}" if m in results[sc][0] else "-"
                      for sc in names[:2])
        print(f"| {m} | " + " | ".join(cells) + f" | {ns} |")

    print("\n## True drivers (exact scenarios): set recovered exactly / up to twins / true set contained"
          " in the selection; coefficient error ||(a - a_true) s|| / ||a_true s|| (s: the sensor's"
          " fit-period std), median / p90\n")
    print("| method | " + " | ".join(f"{sc}: exact / twin / contains | {sc}: coef err" for sc in exact) + " |")
    print("|" + "---|" * (2 * len(exact) + 1))
    for m in MAIN_METHODS + ["ex_lag"]:
        cells = []
        for sc in exact:
            rs = [row[m] for row in results[sc]]
            cells.append(" / ".join(f"{np.mean([r[k] for r in rs]):.0%}" for k in ("exact", "twin", "contains")))
            cells.append(cell([r["coef_err"] for r in rs]))
        print(f"| {m} | " + " | ".join(cells) + " |")

    print("\n## Lag terms (candidates: the speed column through tau = " +
          ", ".join(f"{x:.0f}" for x in np.geomspace(TAU_MIN_SAMPLES * DT, (1 - HOLDOUT) * DURATION, N_TAU)) +
          " s); relative held-out RMS median / p90; share of channels given a lag; lag tau within"
          " x2 of the true one (C/D)\n")
    print("| method | " + " | ".join(names) + " | with a lag | tau ok |")
    print("|" + "---|" * (len(names) + 3))
    for m in LAG_METHODS:
        used = "/".join(f"{np.mean([row[m]['n_lags'] > 0 for row in results[sc]]):.0%}" for sc in names)
        ok = "/".join(f"{np.mean([row[m].get('tau_ok', False) for row in results[sc]]):.0%}"
                      for sc in names if SCENARIOS[names.index(sc)][2])
        print(f"| {m} | " + " | ".join(cell(rel(m, [sc])) for sc in names) + f" | {used} | {ok} |")

    print("\n## CV scheme, blocks and size rule (sensors only): relative held-out RMS median / p90"
          " pooled over A+B, C+D and E; mean sensors over A+B; share of E channels made worse (rel > 1)\n")
    print("| selection | CV | blocks | margin | A+B | C+D | E | sensors A+B | E worse |")
    print("|---|---|---|---|---|---|---|---|---|")
    for kind, sch, nb in paths:
        for mg in MARGINS:
            key = ("sens", kind, sch, nb, mg)
            e = rel(key, ["E weak"])
            ns = np.mean([row[key]["n_sensors"] for sc in names[:2] for row in results[sc]])
            print(f"| {kind} | {sch} | {nb} | {mg:.0%} | {cell(rel(key, names[:2]))} | {cell(rel(key, names[2:4]))} "
                  f"| {cell(e)} | {ns:.2f} | {np.mean(np.array(e) > 1):.0%} |")

    print("\n## Head to head (A-D pooled): share of channels where the method's held-out RMS is"
          " lower than the exhaustive search's (ties count half)\n")
    others = [m for m in MAIN_METHODS if m not in ("oracle", "exhaustive")] + ["ex_lag"]
    print("| " + " | ".join(others) + " |")
    print("|" + "---|" * len(others))
    allrows = [row for sc in names[:4] for row in results[sc]]
    ex_rel = np.array([row["exhaustive"]["rel"] for row in allrows])
    print("| " + " | ".join(f"{np.mean(np.where(np.isclose(v, ex_rel), 0.5, v < ex_rel)):.0%}"
                            for v in (np.array([row[m]["rel"] for row in allrows]) for m in others)) + " |")

    print("\n## By held-out programme (all scenarios but E): median / p90\n")
    ms = ["ex_lag", "exhaustive", "fs_cv", "ols_all", "ridge"]
    print("| held-out programme | channels | " + " | ".join(ms) + " |")
    print("|" + "---|" * (len(ms) + 2))
    for kind in ("duty", "cooldown", "stepdown"):
        rs = [row for row in allrows if row["holdout"] == kind]
        print(f"| {kind} | {len(rs)} | " + " | ".join(cell([r[m]["rel"] for r in rs]) for m in ms) + " |")

    print("\n## Python time per channel (median, ms; numpy on this machine; setup = the test's"
          " standardised design, lag columns and block Grams, shared by all methods)\n")
    print("| " + " | ".join(timing) + " |")
    print("|" + "---|" * len(timing))
    print("| " + " | ".join(f"{1e3 * np.median(v):.1f}" for v in timing.values()) + " |")
    print(f"\nTotal {elapsed:.0f} s.")


if __name__ == "__main__":
    main()
