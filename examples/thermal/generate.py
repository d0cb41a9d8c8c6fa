#!/usr/bin/env python3
"""The simulated ISO 230-3 spindle drift test of `examples/thermal/spindle_drift.csv`.

Run: `python3 examples/thermal/generate.py` (numpy; seed 230, so the file is reproduced byte for
byte). Everything the file holds follows from the parameters below.

The test: 12 h sampled every 30 s (1441 rows) with the five-sensor set-up of ISO 230-3 (a test
mandrel in the spindle; X1, X2 and Y1, Y2 two sensors each 100 mm apart along it, X1 and Y1
nearer the spindle nose, Z on its end face), eight temperature sensors and the spindle speed.

- Spindle speed programme (rpm): 0-4 h steps through 3000, 6000, 9000, 12000 (1 h each); 4-6 h
  stopped (cooling); 6-9 h 6000; 9-12 h a duty cycle of 15 min at 12000 and 15 min stopped.
- Room: 20 °C + 1.0 °C·sin(2π(t − 2 h)/24 h) + 0.05 °C/h.
- Heat: first-order lags L(u; τ) (τ·dL/dt = u − L) of the speed u (per 1000 rpm) and of the room:
  front bearing   T_front  = room + 2.2·L(u; 20 min)
  rear bearing    T_rear   = room + 1.6·L(u; 30 min)
  headstock       T_head   = room + 0.9·L(u; 60 min)
  column top      T_coltop = room + 0.5·L(u; 2 h)
  column base     T_colbot = L(room; 90 min) + 0.2·L(u; 3 h)
  bed             T_bed    = L(room; 3 h)
  air             T_air    = room
  coolant         T_cool   = room + 0.3·L(u; 90 min)
  each with 0.02 °C of white noise.
- Displacements (µm), the mandrel against the table; ΔT = T(t) − T(0):
  Z  = −2.5·ΔT_front − 1.5·ΔT_head + 1.0·ΔT_coltop − 0.6·L(u; 5 min)   (spindle growth, the
       column lifting the head, the rotor's fast growth)
  X1 = 0.8·ΔT_coltop − 0.3·ΔT_colbot                                   (column bending)
  X2 = X1 − 0.6·ΔT_head                                                (headstock tilt in XZ)
  Y1 = 1.2·ΔT_head + 0.4·ΔT_air
  Y2 = Y1 + 0.9·ΔT_rear                                                (tilt in YZ)
  each with 0.3 µm of white noise.
"""

import os

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def lag(t, u, tau):
    """τ·dL/dt = u − L, L(0) = u(0) for the room (it has been there), 0 for a load."""
    out = np.zeros_like(u, dtype=float)
    out[0] = u[0] if tau < 0 else 0.0
    tau = abs(tau)
    for n in range(1, len(u)):
        a = np.exp(-(t[n] - t[n - 1]) / tau)
        out[n] = out[n - 1] * a + u[n - 1] * (1.0 - a)
    return out


def main():
    rng = np.random.default_rng(230)
    t = np.arange(0.0, 12 * 3600 + 1, 30.0)
    h = t / 3600
    speed = np.select(
        [h < 1, h < 2, h < 3, h < 4, h < 6, h < 9],
        [3000, 6000, 9000, 12000, 0, 6000],
        default=np.where(np.floor((h - 9) * 4) % 2 == 0, 12000, 0),
    ).astype(float)
    u = speed / 1000
    room = 20 + 1.0 * np.sin(2 * np.pi * (t - 7200) / 86400) + 0.05 * h
    sensors = {
        "T_front(°C)": room + 2.2 * lag(t, u, 1200),
        "T_rear(°C)": room + 1.6 * lag(t, u, 1800),
        "T_head(°C)": room + 0.9 * lag(t, u, 3600),
        "T_coltop(°C)": room + 0.5 * lag(t, u, 7200),
        "T_colbot(°C)": lag(t, room, -5400) + 0.2 * lag(t, u, 10800),
        "T_bed(°C)": lag(t, room, -10800),
        "T_air(°C)": room.copy(),
        "T_cool(°C)": room + 0.3 * lag(t, u, 5400),
    }
    for k in sensors:
        sensors[k] = sensors[k] + rng.normal(0, 0.02, len(t))
    d = {k: v - v[0] for k, v in sensors.items()}
    x1 = 0.8 * d["T_coltop(°C)"] - 0.3 * d["T_colbot(°C)"]
    y1 = 1.2 * d["T_head(°C)"] + 0.4 * d["T_air(°C)"]
    channels = {
        "Z(um)": -2.5 * d["T_front(°C)"] - 1.5 * d["T_head(°C)"] + 1.0 * d["T_coltop(°C)"] - 0.6 * lag(t, u, 300),
        "X1(um)": x1,
        "X2(um)": x1 - 0.6 * d["T_head(°C)"],
        "Y1(um)": y1,
        "Y2(um)": y1 + 0.9 * d["T_rear(°C)"],
    }
    for k in channels:
        channels[k] = channels[k] + rng.normal(0, 0.3, len(t))
    with open(os.path.join(HERE, "spindle_drift.csv"), "w", encoding="utf-8") as f:
        f.write("# a simulated ISO 230-3 spindle drift test: examples/thermal/generate.py\n")
        f.write(",".join(["time(s)", *channels, *sensors, "spindle(rpm)"]) + "\n")
        for n in range(len(t)):
            cells = [f"{t[n]:.0f}"]
            cells += [f"{channels[k][n]:.3f}" for k in channels]
            cells += [f"{sensors[k][n]:.3f}" for k in sensors]
            cells.append(f"{speed[n]:.0f}")
            f.write(",".join(cells) + "\n")


if __name__ == "__main__":
    main()
