#!/usr/bin/env python3
"""Reference impact sequences of a planar double pendulum of point masses striking a wall,
computed independently of mechanica: the classical equations of motion in absolute angles,
SciPy's DOP853 with event location (solve_ivp events) at rtol 1e-13, and the frictionless
Newton impact map written out here,

    P = -(1 + e) u_n / (J_n A^-1 J_n^T),   q_dot+ = q_dot- + A^-1 J_n^T P,

with A(q) the mass matrix in relative joint angles and J_n the gradient of the gap.

Model (mechanica's conventions): revolute joints about y; a turn theta about y takes the rod
(0, 0, -l) to (-l sin theta, 0, -l cos theta); q = (theta1, theta2) relative angles, absolute
angles phi1 = theta1, phi2 = theta1 + theta2; masses m1 at l1 below the shoulder, m2 at l2
below the elbow; gravity g along -z. The tip (mass 2) meets the wall x = w, whose normal
(-1, 0, 0) points back at the pendulum: gap = w - x2 = w + l1 sin phi1 + l2 sin phi2.

The accuracy of each reference is estimated by repeating it at rtol 1e-11 and is written with
it (err_t, err_q): the difference of the two runs, which bounds the 1e-13 run's error by
tolerance proportionality with a wide margin.

Usage: pip install scipy numpy; python3 tools/impact_sequence_reference.py
Writes tools/impact_sequence_reference.json.
"""

import json
import math
import os

import numpy as np
from scipy.integrate import solve_ivp

G = 9.81


def mass_matrix(p, q):
    m1, m2, l1, l2 = p["m1"], p["m2"], p["l1"], p["l2"]
    c = math.cos(q[1])  # cos(phi1 - phi2) = cos(theta2)
    a_phi = np.array([[(m1 + m2) * l1 * l1, m2 * l1 * l2 * c], [m2 * l1 * l2 * c, m2 * l2 * l2]])
    t = np.array([[1.0, 0.0], [1.0, 1.0]])
    return t.T @ a_phi @ t


def rhs(p, t, y):
    """d/dt (phi1, phi2, w1, w2) of the double pendulum in absolute angles."""
    m1, m2, l1, l2 = p["m1"], p["m2"], p["l1"], p["l2"]
    phi1, phi2, w1, w2 = y
    d = phi1 - phi2
    a = np.array([[(m1 + m2) * l1, m2 * l2 * math.cos(d)], [l1 * math.cos(d), l2]])
    b = np.array([
        -m2 * l2 * w2 * w2 * math.sin(d) - (m1 + m2) * G * math.sin(phi1),
        l1 * w1 * w1 * math.sin(d) - G * math.sin(phi2),
    ])
    acc = np.linalg.solve(a, b)
    return [w1, w2, acc[0], acc[1]]


def gap(p, y):
    return p["wall"] + p["l1"] * math.sin(y[0]) + p["l2"] * math.sin(y[1])


def gap_gradient_q(p, q):
    """d gap / d (theta1, theta2)."""
    phi1, phi2 = q[0], q[0] + q[1]
    c1, c2 = p["l1"] * math.cos(phi1), p["l2"] * math.cos(phi2)
    return np.array([c1 + c2, c2])


def impact(p, y):
    """Newton's frictionless impact at the state y (absolute angles and rates)."""
    q = np.array([y[0], y[1] - y[0]])
    q_dot = np.array([y[2], y[3] - y[2]])
    a = mass_matrix(p, q)
    j = gap_gradient_q(p, q)
    u = j @ q_dot
    a_inv_j = np.linalg.solve(a, j)
    impulse = -(1.0 + p["e"]) * u / (j @ a_inv_j)
    q_dot_after = q_dot + a_inv_j * impulse
    energy = lambda v: 0.5 * v @ a @ v
    lost = energy(q_dot) - energy(q_dot_after)
    return q_dot_after, u, lost


def run(p, rtol):
    y = [p["q0"][0], p["q0"][0] + p["q0"][1], 0.0, 0.0]
    t = 0.0
    impacts = []
    event = lambda t, y: gap(p, y)
    event.terminal = True
    event.direction = -1
    while t < p["t_end"]:
        sol = solve_ivp(lambda t, y: rhs(p, t, y), (t, p["t_end"]), y, method="DOP853", rtol=rtol,
                        atol=rtol * 1e-2, events=event)
        if sol.status == 1 and sol.t_events[0].size:
            t = float(sol.t_events[0][0])
            y = list(sol.y_events[0][0])
            q_dot_after, u, lost = impact(p, y)
            impacts.append({"t": t, "approach_speed": -u, "energy_lost": lost})
            y[2], y[3] = q_dot_after[0], q_dot_after[0] + q_dot_after[1]
            if len(impacts) > 50:
                raise RuntimeError("too many impacts")
        else:
            t = p["t_end"]
            y = list(sol.y[:, -1])
    q_end = [y[0], y[1] - y[0]]
    q_dot_end = [y[2], y[3] - y[2]]
    return impacts, q_end, q_dot_end


def main():
    rng = np.random.default_rng(20261128)
    cases = []
    for _ in range(10):
        p = {
            "m1": float(10 ** rng.uniform(-1, 1)),
            "m2": float(10 ** rng.uniform(-1, 1)),
            "l1": float(rng.uniform(0.4, 1.0)),
            "l2": float(rng.uniform(0.3, 0.8)),
            "e": float(rng.uniform(0.5, 1.0)),
            "t_end": 4.0,
        }
        p["wall"] = float(rng.uniform(0.2, 0.7) * (p["l1"] + p["l2"]))
        p["q0"] = [float(rng.uniform(1.0, 1.6)), float(rng.uniform(-0.5, 0.5))]
        fine = run(p, 1e-13)
        coarse = run(p, 1e-11)
        if len(fine[0]) != len(coarse[0]) or not fine[0]:
            continue
        err_t = max(abs(a["t"] - b["t"]) for a, b in zip(fine[0], coarse[0]))
        err_q = max(abs(a - b) for a, b in zip(fine[1] + fine[2], coarse[1] + coarse[2]))
        p.update({"impacts": fine[0], "q_end": fine[1], "q_dot_end": fine[2], "err_t": err_t, "err_q": err_q})
        cases.append(p)
        print(f"{len(fine[0])} impacts, err_t {err_t:.1e}, err_q {err_q:.1e}")
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "impact_sequence_reference.json")
    with open(out, "w") as f:
        json.dump({"model": "planar double pendulum of point masses striking the wall x = wall, Newton frictionless",
                   "g": G, "cases": cases}, f, indent=1)
    print(f"{len(cases)} cases written to {out}")


if __name__ == "__main__":
    main()
