#!/usr/bin/env python3
"""The simulated ISO 230-4 ballbar runs of `examples/circular/runs.csv`.

Run: `python3 examples/circular/generate.py` (numpy; seed 2304, so the file is reproduced byte for
byte). Everything the file holds follows from the parameters below; its header comment lines state
the truth (each error's value and unit) for comparison with a diagnosis.

The runs: a three-axis machine, R = 100 mm, three planes (xy, yz, zx) x two feeds (1000 and
3000 mm/min) x both directions, run ids `xy_f1000`, `xy_f3000`, ... Columns
`run,radius,feed,plane,angle,direction,deviation(um)` (the run file of docs/circular.md,
"Evaluation (ISO 230-4)").

Conventions: those of docs/circular.md. In a plane the first axis is a, the second b (xy: a = x,
b = y; yz: a = y, b = z; zx: a = z, b = x); theta is the commanded angle from +a towards +b;
d = +1 for ccw (theta increasing), -1 for cw; the deviation is the measured ball distance minus R,
positive outward. Every error is stated as its effect on the tool-side ball relative to the
table-side ball (the section "The common first-order relation"), so which axis carries the table
does not matter here.

The machine (per axis i = x, y, z, and per pair of axes):

- squareness S_ab (rad; "Squareness S"): a commanded b moves the tool by b*(S, 1), i.e.
  delta_a = S*u_b: b leans towards +a, the angle between +a and +b is 90 deg - S.
  S_xy = 20, S_yz = -15, S_zx = 10 urad.
- scale eps_i ("Scale mismatch eps_a - eps_b"; + = over-travel): delta_i = eps_i*u_i.
  eps_x = +10, eps_y = -5, eps_z = +8 ppm.
- backlash B_i ("Backlash B_a, B_b"): a symmetric dead band of width B_i between the drive and the
  slide; the slide moves only when the drive pushes it, and then trails it by B_i/2.
  B_x = 4, B_y = 2.5, B_z = 3 um.
- servo lag ("Servo mismatch dt"): a proportional position loop of gain K_v,i per axis,
  tau_i * dy_i/dt = x_i - y_i, tau_i = 1/K_v,i (no feed-forward).
  K_v,x = 30, K_v,y = 30.6, K_v,z = 29.5 1/s (gains matched to 2 %, as a tuned machine's are).
- set-up offset c = (c_a, c_b) per run (the same for both directions: the bar stays mounted),
  the commanded circle's centre relative to the table ball ("Set-up centre offset"). The table
  ball is located with the machine itself (the set-up fixture at the commanded centre), so the
  errors' constant parts at the circle's position are zero and the centre is c alone.
- measurement noise: white, N(0, 0.15 um) per sample.
  No straightness, cyclic error, reversal spikes or acceleration limits.

The simulation, per run and direction, in the time domain (cf. docs/circular.md "Checked against
simulation"), relative to the commanded centre:

    theta(t) = d*(omega*t - pi/4),  omega = F/(60 R),  t >= 0      (45 deg lead-in arc first)
    commanded  x_a = R cos theta,  x_b = R sin theta
    drive      tau_a y_a' = x_a - y_a,  y_a(0) = x_a(0)             (at rest at the start)
    slide      q_a = play(y_a; B_a):  q_a moves only when |y_a - q_a| would exceed B_a/2
    geometry   delta_a = eps_a q_a + S q_b,  delta_b = eps_b q_b
    ball       p = (q_a + delta_a + c_a, q_b + delta_b + c_b)
    sample     deviation = |p| - R + noise                          (the exact distance)

and the same for b. The loop is integrated exactly for a command linear between steps of 0.005 deg
of theta (the chord error of that is 1e-4 um); the dead band is applied at every step. The machine
starts at rest 45 deg before the data arc (the lead-in: the loops and the dead bands settle), and
the ballbar records one sample per 0.5 deg of the commanded angle theta from 0 deg over one full
circle, 720 per direction, angles written modulo 360. The 45 deg over-run arc after the data arc
does not change the recorded samples (the model is causal) and is not simulated; neither arc is in
the file.

What a first-order diagnosis reads (docs/circular.md "The fit"), per plane, and which the header
states as "derived":

    S = S_ab,  de = eps_a - eps_b,  B_a, B_b,  dt = tau_a - tau_b,  q = tau_a^2 - tau_b^2,
    radius offset r0 = R (eps_a + eps_b)/2 - (v^2/(4R)) (tau_a^2 + tau_b^2),  v = F/60,
    centre per run and direction = c, turned by d*omega*tau: the ballbar places each sample at the
    commanded angle while the tool lags it by about omega*tau, so the least-squares centre differs
    from c by up to |c|*omega*tau (0.08 um here, at 3000 mm/min).

At one feed the fitted de also holds the servo's gain term -(3 v^2/(4R)) q cos 2 theta ("Second
order: the radius loss and a cos 2 theta term"); with both feeds q is fitted and de is itself.
"""

import math
import os

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))

SEED = 2304
RADIUS = 100.0  # mm
FEEDS = (1000.0, 3000.0)  # mm/min
PLANES = {"xy": ("x", "y"), "yz": ("y", "z"), "zx": ("z", "x")}
SQUARENESS_URAD = {"xy": 20.0, "yz": -15.0, "zx": 10.0}
SCALE_PPM = {"x": 10.0, "y": -5.0, "z": 8.0}
BACKLASH_UM = {"x": 4.0, "y": 2.5, "z": 3.0}
KV = {"x": 30.0, "y": 30.6, "z": 29.5}  # 1/s
NOISE_UM = 0.15
# Set-up offset (c_a, c_b) per run, um, along the plane's a and b.
SETUP_UM = {
    "xy_f1000": (4.0, -2.5),
    "xy_f3000": (-3.0, 1.5),
    "yz_f1000": (2.0, 3.5),
    "yz_f3000": (-1.5, -4.0),
    "zx_f1000": (3.0, -1.0),
    "zx_f3000": (-2.5, 2.0),
}
STEP_DEG = 0.5  # one sample per 0.5 deg of the commanded angle
SUB = 100  # simulation steps per sample (0.005 deg)
LEAD_DEG = 45.0


def servo(x, dt, tau):
    """tau*y' = x - y, y(0) = x(0), exact for x linear between samples (first-order hold)."""
    al = math.exp(-dt / tau)
    k = tau / dt
    y = np.empty_like(x)
    yn = float(x[0])
    y[0] = yn
    xs = x.tolist()
    for n in range(1, len(xs)):
        m = (xs[n] - xs[n - 1]) * k  # slope times tau
        yn = xs[n] - m + al * (yn - xs[n - 1] + m)
        y[n] = yn
    return y


def play(y, b):
    """The slide behind a dead band of width b: it moves only when the drive pushes it."""
    h = b / 2
    q = np.empty_like(y)
    qn = float(y[0])
    for n, yn in enumerate(y.tolist()):
        if yn - qn > h:
            qn = yn - h
        elif yn - qn < -h:
            qn = yn + h
        q[n] = qn
    return q


def simulate(plane, feed, d, setup_um):
    """Deviation (mm, noise-free) at the 720 commanded angles k*0.5 deg*d, k = 0..719."""
    a, b = PLANES[plane]
    v = feed / 60.0
    omega = v / RADIUS
    h = math.radians(STEP_DEG / SUB)
    dt = h / omega
    lead = round(LEAD_DEG / STEP_DEG) * SUB
    steps = np.arange(lead + 719 * SUB + 1)
    theta = d * (steps - lead) * h
    qa = play(servo(RADIUS * np.cos(theta), dt, 1.0 / KV[a]), BACKLASH_UM[a] * 1e-3)
    qb = play(servo(RADIUS * np.sin(theta), dt, 1.0 / KV[b]), BACKLASH_UM[b] * 1e-3)
    s = SQUARENESS_URAD[plane] * 1e-6
    pa = qa + SCALE_PPM[a] * 1e-6 * qa + s * qb + setup_um[0] * 1e-3
    pb = qb + SCALE_PPM[b] * 1e-6 * qb + setup_um[1] * 1e-3
    idx = lead + SUB * np.arange(720)
    return np.hypot(pa[idx], pb[idx]) - RADIUS


def truth_lines():
    tau = {i: 1e3 / KV[i] for i in KV}  # ms
    out = [
        "# truth: R 100 mm; planes xy (a=x, b=y), yz (a=y, b=z), zx (a=z, b=x); conventions of docs/circular.md",
        "# truth: squareness S (urad; delta_a = S*u_b, b leans towards +a): "
        + " ".join(f"{p}={SQUARENESS_URAD[p]:g}" for p in PLANES),
        "# truth: scale eps (ppm; + = over-travel): " + " ".join(f"{i}={SCALE_PPM[i]:g}" for i in "xyz"),
        "# truth: backlash B (um; symmetric dead band): " + " ".join(f"{i}={BACKLASH_UM[i]:g}" for i in "xyz"),
        "# truth: position-loop gain Kv (1/s; first-order loop, tau = 1/Kv): "
        + " ".join(f"{i}={KV[i]:g}" for i in "xyz")
        + "; tau (ms): "
        + " ".join(f"{i}={tau[i]:.3f}" for i in "xyz"),
        "# truth: set-up offset c (um; along a, b; both directions): "
        + " ".join(f"{r}=({c[0]:g},{c[1]:g})" for r, c in SETUP_UM.items())
        + " (the least-squares centre reads it to within |c|*omega*tau < 0.1 um)",
        f"# truth: noise {NOISE_UM:g} um std (white); no straightness, cyclic error or reversal spikes",
    ]
    for p, (a, b) in PLANES.items():
        line = (
            f"# derived {p}: S={SQUARENESS_URAD[p]:g} urad, de=eps_{a}-eps_{b}={SCALE_PPM[a] - SCALE_PPM[b]:g} ppm, "
            f"B_a=B_{a}={BACKLASH_UM[a]:g} um, B_b=B_{b}={BACKLASH_UM[b]:g} um, "
            f"dt=tau_{a}-tau_{b}={tau[a] - tau[b]:.4f} ms, q=tau_{a}^2-tau_{b}^2={tau[a] ** 2 - tau[b] ** 2:.2f} ms^2, r0 (um):"
        )
        for f in FEEDS:
            v = f / 60.0
            r0 = RADIUS * (SCALE_PPM[a] + SCALE_PPM[b]) * 1e-6 / 2 - v * v / (4 * RADIUS) * (
                (tau[a] * 1e-3) ** 2 + (tau[b] * 1e-3) ** 2
            )
            line += f" f{f:.0f}={r0 * 1e3:.3f}"
        out.append(line)
    out.append(
        "# sampling: one sample per 0.5 deg of the commanded angle from 0 deg, 720 per direction (one full circle);"
        " the 45 deg lead-in and over-run arcs are not recorded"
    )
    return out


def main():
    rng = np.random.default_rng(SEED)
    lines = ["# simulated ISO 230-4 ballbar runs: examples/circular/generate.py (seed 2304; model in its docstring)"]
    lines += truth_lines()
    lines.append("run,radius,feed,plane,angle,direction,deviation(um)")
    for plane in PLANES:
        for feed in FEEDS:
            run = f"{plane}_f{feed:.0f}"
            for d, name in ((1, "ccw"), (-1, "cw")):
                dev_um = simulate(plane, feed, d, SETUP_UM[run]) * 1e3 + rng.normal(0.0, NOISE_UM, 720)
                for k in range(720):
                    angle = (d * k * STEP_DEG) % 360.0
                    lines.append(f"{run},{RADIUS:g},{feed:.0f},{plane},{angle:.1f},{name},{dev_um[k]:.4f}")
    with open(os.path.join(HERE, "runs.csv"), "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
