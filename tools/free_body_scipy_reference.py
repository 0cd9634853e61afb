#!/usr/bin/env python3
"""Work-precision of SciPy's solve_ivp (DOP853 and Radau) on the torque-free rigid body problem
of crates/mechanica-dynamics/examples/free_body_work_precision.rs: the same equations, Euler's
equations I1 w1' = (I2 - I3) w2 w3 (and cyclic) with the attitude matrix ODE R' = R [w]x
(12 unknowns), from the same initial state over the same 100 periods.

Errors at the end, as on the Rust side: the geodesic angle |log(R_exact^T R)| and
|w - w_exact| / |w_exact|. The exact state is read from the problem file the example writes
(TorqueFreeBody, checked against 40-digit Taylor integrations in tests/free_body.rs); this script
recomputes w(T) independently from the closed form (EB1911 (7)) with mpmath's Jacobi functions at
30 digits and stops if the two disagree by more than 1e-12.

Usage: pip install scipy mpmath
       python3 tools/free_body_scipy_reference.py PROBLEM.json OUT.csv
Each run is timed once with time.perf_counter (wall time of solve_ivp alone).
"""

import json
import sys
import time

import mpmath as mp
import numpy as np
from scipy.integrate import solve_ivp

DOP853_RTOL = [10.0**-e for e in (4, 5, 6, 7, 8, 9, 10, 11, 12)] + [3e-13, 1e-13, 5e-14, 3e-14]
RADAU_RTOL = [10.0**-e for e in (4, 5, 6, 7, 8)]
RADAU_TIME_LIMIT = 120.0


def exact_omega(moments, w0, t):
    """w(t) from EB1911 (7) for sorted moments, Gamma^2 != 2 T I2, in 30-digit arithmetic."""
    mp.mp.dps = 30
    i = [mp.mpf(m) for m in moments]
    w = [mp.mpf(x) for x in w0]
    assert i[0] < i[1] < i[2], "the problem's moments are sorted"
    two_t = sum(i[k] * w[k] ** 2 for k in range(3))
    gamma2 = sum((i[k] * w[k]) ** 2 for k in range(3))
    e = [abs(gamma2 - two_t * i[k]) for k in range(3)]
    c, d = (0, 2) if gamma2 > two_t * i[1] else (2, 0)
    sigma = mp.sqrt(abs(i[d] - i[1]) * e[c] / (i[0] * i[1] * i[2]))
    m = abs(i[1] - i[c]) * e[d] / (abs(i[d] - i[1]) * e[c])
    a_c = mp.sqrt(e[d] / (i[c] * abs(i[d] - i[c])))
    a_d = mp.sqrt(e[c] / (i[d] * abs(i[d] - i[c]))) * mp.sign(w[d])
    a_2 = mp.sqrt(e[d] / (i[1] * abs(i[d] - i[1]))) * mp.sign(a_c * a_d)
    phi0 = mp.atan2(w[1] / a_2, w[c] / a_c)
    u = sigma * mp.mpf(t) + mp.ellipf(phi0, m)
    out = [0, 0, 0]
    out[c] = a_c * mp.ellipfun("cn", u, m=m)
    out[1] = a_2 * mp.ellipfun("sn", u, m=m)
    out[d] = a_d * mp.ellipfun("dn", u, m=m)
    return np.array([float(x) for x in out])


def rhs_factory(moments):
    i1, i2, i3 = moments

    def rhs(_t, y):
        w1, w2, w3 = y[0], y[1], y[2]
        r = y[3:].reshape(3, 3)
        skew = np.array([[0.0, -w3, w2], [w3, 0.0, -w1], [-w2, w1, 0.0]])
        dw = [(i2 - i3) * w2 * w3 / i1, (i3 - i1) * w3 * w1 / i2, (i1 - i2) * w1 * w2 / i3]
        return np.concatenate((dw, (r @ skew).ravel()))

    return rhs


def geodesic_angle(r_exact, r):
    m = r_exact.T @ r
    v = 0.5 * np.array([m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1]])
    return float(np.arctan2(np.linalg.norm(v), 0.5 * (np.trace(m) - 1.0)))


def main():
    problem_path, out_path = sys.argv[1], sys.argv[2]
    with open(problem_path) as f:
        p = json.load(f)
    moments, w0 = p["moments"], np.array(p["omega0"])
    r0 = np.array(p["r0"]).reshape(3, 3)
    duration = p["duration"]
    w_exact = np.array(p["omega_exact"])
    r_exact = np.array(p["r_exact"]).reshape(3, 3)
    w_mp = exact_omega(moments, w0, duration)
    gap = np.linalg.norm(w_mp - w_exact) / np.linalg.norm(w_exact)
    print(f"w(T): mpmath closed form vs TorqueFreeBody, relative {gap:.2e}")
    if gap > 1e-12:
        sys.exit("the exact states disagree")
    rhs = rhs_factory(moments)
    y0 = np.concatenate((w0, r0.ravel()))
    rows = []
    for method, rtols in (("DOP853", DOP853_RTOL), ("Radau", RADAU_RTOL)):
        for rtol in rtols:
            start = time.perf_counter()
            sol = solve_ivp(rhs, (0.0, duration), y0, method=method, rtol=rtol, atol=rtol * 1e-3)
            elapsed = time.perf_counter() - start
            y = sol.y[:, -1]
            attitude = geodesic_angle(r_exact, y[3:].reshape(3, 3))
            omega = float(np.linalg.norm(y[:3] - w_exact) / np.linalg.norm(w_exact))
            print(f"{method} rtol {rtol:.0e}: {sol.nfev} evaluations, {elapsed:.3f} s, "
                  f"attitude {attitude:.2e}, w {omega:.2e}", flush=True)
            rows.append(f"scipy,{method},,{sol.t.size - 1},{rtol:e},{elapsed:e},{attitude:e},{omega:e},,\n")
            if method == "Radau" and elapsed > RADAU_TIME_LIMIT:
                break
    with open(out_path, "w") as f:
        f.write("solver,method,order,steps,parameter,time_s,attitude_error,omega_error,"
                "estimate_attitude,estimate_omega\n")
        f.writelines(rows)


if __name__ == "__main__":
    main()
