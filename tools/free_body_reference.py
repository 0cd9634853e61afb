#!/usr/bin/env python3
"""Reference states of torque-free rigid bodies, integrated by a Taylor-series method of order
30 in mpmath arithmetic at 40 significant digits (local error below 1e-34 per step), for the
attitude test of crates/mechanica-dynamics/src/free_body/exact.rs. Euler's equations and
R' = R [w]x are quadratic, so the Taylor coefficients follow from Cauchy products; the script
checks that T, L and R R^T (constant, as R(t) = R(0) U(t) with U orthogonal) hold to 1e-25 at every
output time.

Usage: pip install mpmath; python3 tools/free_body_reference.py > tools/free_body_reference.json

Each case gives principal moments (I1, I2, I3) in the body axes, the body-frame angular
velocity w(0), the attitude R(0) (body -> space, row-major) and, at each listed time t, w(t) and
R(t) from Euler's equations I1 w1' = (I2 - I3) w2 w3 (and cyclic) with R' = R [w]x. The times
are multiples of the period 4K/sigma of w, written out as numbers. Every number is a JSON string
holding the repr of the nearest f64.
"""

import json
import sys

import mpmath as mp

DIGITS = 40
ORDER = 30
TOLERANCE = mp.mpf(10) ** -34

# (name, moments, w0, axis-angle of R(0), times in units of the period)
CASES = [
    ("major axis", [1.0, 2.0, 3.0], [0.3, 0.2, 1.1], [0.3, -0.5, 0.8], [0.37, 10.0, 100.0]),
    ("minor axis", [3.5, 1.25, 2.0], [0.2, 1.3, 0.4], [-0.7, 0.1, 0.2], [0.61, 10.0, 100.0]),
    # w3 puts 2T I2 - Gamma^2 at relative distance 1e-6 from the separatrix (Gamma^2 > 2T I2)
    ("near separatrix", [1.0, 1.5, 2.75], [0.9, 0.01, 0.9 * (0.5 * (1 + 1e-6) / (2.75 * 1.25 * (1 - 1e-6))) ** 0.5],
     [0.1, 0.2, 0.3], [0.5, 3.0, 10.0]),
    ("axisymmetric", [2.0, 2.0, 0.5], [0.4, -0.3, 2.0], [1.0, 1.0, 0.0], [0.25, 10.0, 100.0]),
]


def rotation(axis_angle):
    angle = mp.sqrt(sum(a * a for a in axis_angle))
    n = [a / angle for a in axis_angle]
    c, s = mp.cos(angle), mp.sin(angle)
    k = [[0, -n[2], n[1]], [n[2], 0, -n[0]], [-n[1], n[0], 0]]
    return [[(1 if i == j else 0) * c + (1 - c) * n[i] * n[j] + s * k[i][j] for j in range(3)] for i in range(3)]


def period(moments, w):
    """4K/sigma from the sorted moments (only to place the sample times)."""
    order = sorted(range(3), key=lambda i: moments[i])
    i1, i2, i3 = (moments[i] for i in order)
    w1, w2, w3 = (w[i] for i in order)
    two_t = i1 * w1**2 + i2 * w2**2 + i3 * w3**2
    gamma2 = (i1 * w1) ** 2 + (i2 * w2) ** 2 + (i3 * w3) ** 2
    if gamma2 > two_t * i2:
        sigma2 = (i3 - i2) * (gamma2 - two_t * i1) / (i1 * i2 * i3)
        m = (i2 - i1) * (two_t * i3 - gamma2) / ((i3 - i2) * (gamma2 - two_t * i1))
    else:
        sigma2 = (i2 - i1) * (two_t * i3 - gamma2) / (i1 * i2 * i3)
        m = (i3 - i2) * (gamma2 - two_t * i1) / ((i2 - i1) * (two_t * i3 - gamma2))
    return 4 * mp.ellipk(m) / mp.sqrt(sigma2)


def taylor_coefficients(moments, y):
    """Taylor coefficients c[0..ORDER] of the 12 components (w, R row-major) about y."""
    i1, i2, i3 = moments
    a = [(i2 - i3) / i1, (i3 - i1) / i2, (i1 - i2) / i3]
    c = [[v] for v in y]
    for k in range(ORDER):
        def conv(p, q):
            return mp.fsum(c[p][j] * c[q][k - j] for j in range(k + 1))
        w1w2, w2w3, w3w1 = conv(0, 1), conv(1, 2), conv(2, 0)
        nxt = [a[0] * w2w3, a[1] * w3w1, a[2] * w1w2]
        for row in range(3):
            ra, rb, rc = 3 + 3 * row, 4 + 3 * row, 5 + 3 * row
            nxt += [conv(rb, 2) - conv(rc, 1), conv(rc, 0) - conv(ra, 2), conv(ra, 1) - conv(rb, 0)]
        for index in range(12):
            c[index].append(nxt[index] / (k + 1))
    return c


def step_size(c):
    """The step at which the last two Taylor terms are below TOLERANCE relative to the state."""
    scale = max(abs(c[i][0]) for i in range(12))
    sizes = []
    for order in (ORDER - 1, ORDER):
        largest = max(abs(c[i][order]) for i in range(12))
        if largest > 0:
            sizes.append((TOLERANCE * scale / largest) ** (mp.mpf(1) / order))
    return min(sizes) if sizes else mp.mpf(1)


def advance(moments, y, t, target):
    """y(target) from y(t) by Taylor steps."""
    while t < target:
        c = taylor_coefficients(moments, y)
        h = min(step_size(c), target - t)
        y = [mp.polyval(list(reversed(ci)), h) for ci in c]
        t += h
    return y


def check_invariants(moments, y0, y):
    def invariants(state):
        w, r = state[0:3], state[3:12]
        energy = sum(moments[i] * w[i] ** 2 for i in range(3))
        momentum = [sum(r[3 * i + j] * moments[j] * w[j] for j in range(3)) for i in range(3)]
        gram = [sum(r[3 * i + k] * r[3 * j + k] for k in range(3)) for i in range(3) for j in range(3)]
        return energy, momentum, gram
    e0, l0, o0 = invariants(y0)
    e, l, o = invariants(y)
    drift = max(abs(e - e0) / e0, max(abs(l[i] - l0[i]) for i in range(3)) / mp.sqrt(sum(v * v for v in l0)))
    gram_drift = max(abs(a - b) for a, b in zip(o, o0))
    if drift > mp.mpf(10) ** -25 or gram_drift > mp.mpf(10) ** -25:
        raise SystemExit(f"the reference integration drifted: {drift}, {gram_drift}")


def main():
    mp.mp.dps = DIGITS
    cases = []
    for name, moments, w0, axis_angle, multiples in CASES:
        moments = [mp.mpf(m) for m in moments]
        w0 = [mp.mpf(w) for w in w0]
        r0 = rotation([mp.mpf(a) for a in axis_angle])
        r0 = [[mp.mpf(float(v)) for v in row] for row in r0]  # exactly the f64 R(0) the test reads
        y0 = w0 + [v for row in r0 for v in row]
        p = period(moments, w0)
        states, y, t = [], y0, mp.mpf(0)
        for multiple in multiples:
            target = mp.mpf(float(multiple * p))
            y = advance(moments, y, t, target)
            t = target
            check_invariants(moments, y0, y)
            states.append([t] + list(y))
            print(f"{name}: t = {float(t):.6g} done", file=sys.stderr)
        cases.append({
            "name": name,
            "moments": [repr(float(v)) for v in moments],
            "omega0": [repr(float(v)) for v in w0],
            "r0": [repr(float(v)) for row in r0 for v in row],
            "period": repr(float(p)),
            "states": [[repr(float(v)) for v in state] for state in states],
        })
    print(json.dumps({"generator": f"tools/free_body_reference.py (mpmath {mp.__version__}, Taylor order {ORDER} at {DIGITS} digits)",
                      "cases": cases}, indent=1))


if __name__ == "__main__":
    main()
