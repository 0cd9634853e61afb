#!/usr/bin/env python3
"""Independent reference for the 3-D swerving-slip impact of mechanica-impulse.

A thin rod (m = 1 kg, L = 1 m) along a = (0.6, 0.5, 0.3)/|.|, centre 0.5 a, struck at its end
(the origin) by the ground (normal +y), e = 0.8, f = 0.25, Stronge's energetic restitution.
The impulse-parameterised slip ODE (Stronge, Impact Mechanics, ch. 5) is integrated here with
SciPy's DOP853 (rtol 1e-13) and event location, independently of the Rust code (different
integrator, different tangent basis, stick/ray phases solved with numpy).

Run:  python3 tools/impulse_swerve_reference.py > tools/impulse_swerve_reference.out
The Rust test crates/mechanica-impulse/tests/invariants.rs compares against these numbers.
"""
import numpy as np
from scipy.integrate import solve_ivp

m, L, e, f = 1.0, 1.0, 0.8, 0.25
a = np.array([0.6, 0.5, 0.3]); a /= np.linalg.norm(a)
c = 0.5 * a
J = (np.eye(3) - np.outer(a, a)) * m * L**2 / 12.0
Jp = np.linalg.pinv(J)
v = np.array([0.4, -1.0, -0.7])
w = np.array([0.3, 0.0, 0.2]); w = w - a * (a @ w)
d = -c  # contact point (origin) minus centre
def skew(x):
    return np.array([[0, -x[2], x[1]], [x[2], 0, -x[0]], [-x[1], x[0], 0]])
W = np.eye(3) / m - skew(d) @ Jp @ skew(d)
u0 = v + np.cross(w, d)
T = [0, 2]  # tangent components x, z; normal is y
N = 1

def vel(p, pt):
    P = np.array([pt[0], p, pt[1]])
    return u0 + W @ P

def rhs(p, y):
    u = vel(p, y[:2])
    ut = u[T]
    s = ut / np.linalg.norm(ut)
    return [-f * s[0], -f * s[1], u[N]]

def halt(p, y):
    return np.linalg.norm(vel(p, y[:2])[T]) - 1e-13
halt.terminal = True

def compression(p, y):
    return vel(p, y[:2])[N]
compression.terminal = True
compression.direction = 1

state = {"pc": None, "wc": None}

def termination(p, y):
    return y[2] - (1 - e * e) * state["wc"]
termination.terminal = True
termination.direction = 1

p, y = 0.0, np.zeros(3)
opts = dict(method="DOP853", rtol=1e-13, atol=1e-16)
halted = False
while True:
    events = [halt, compression] if state["pc"] is None else [halt, termination]
    sol = solve_ivp(rhs, (p, p + 100.0), y, events=events, **opts)
    p, y = sol.t[-1], sol.y[:, -1]
    hit = [len(ev) > 0 for ev in sol.t_events]
    if hit[0]:
        halted = True
        break
    if state["pc"] is None:
        state["pc"], state["wc"] = p, y[2]
        continue
    break

if halted:
    Wtt = W[np.ix_(T, T)]
    Wtn = W[T, N]
    t = -np.linalg.solve(Wtt, Wtn)
    if np.linalg.norm(t) <= f:
        ratio = t
        mode = "SlipThenStick"
    else:
        raise SystemExit("ray slip after halting is not expected for this case")
    dvec = np.array([ratio[0], 1.0, ratio[1]])
    b = (W @ dvec)[N]
    def advance(s):
        global p, y
        an = vel(p, y[:2])[N]
        y = y + np.array([ratio[0] * s, ratio[1] * s, an * s + 0.5 * b * s * s])
        p = p + s
    if state["pc"] is None:
        an = vel(p, y[:2])[N]
        advance(-an / b)
        state["pc"], state["wc"] = p, y[2]
    an = vel(p, y[:2])[N]
    delta = (1 - e * e) * state["wc"] - y[2]
    s = 2 * delta / (an + np.sqrt(an * an + 2 * b * delta))
    advance(s)
else:
    mode = "Slip"

P = np.array([y[0], p, y[1]])
print(f"mode {mode}")
print(f"impulse {P[0]:.17e} {P[1]:.17e} {P[2]:.17e}")
print(f"compression_impulse {state['pc']:.17e}")
