#!/usr/bin/env python3
"""Reference values of Carlson's symmetric integrals, Legendre's integrals of the first and third
kind and Jacobi's elliptic functions, computed with mpmath at 50 significant digits and confirmed
by a second evaluation at 70 digits (the two must agree to 20 digits), for the ulp tests of
crates/mechanica-dynamics/src/free_body/.

Usage: pip install mpmath; python3 tools/elliptic_reference.py > tools/elliptic_reference.json

Arguments are f64 values; every number is written as a JSON string holding Python's repr
(the shortest decimal that reads back to the same f64), so that the test parses it with a
correctly rounded parser; the modulus k
enters mpmath as the exact parameter m = k² (50 digits hold the 106-bit square). Every result is the f64
nearest to the 50-digit value. Conventions: F(phi, k), Pi(n; phi, k) = int_0^phi dt / ((1 - n sin^2 t) sqrt(1 - k^2
sin^2 t)), sn/cn/dn(u, k), am(u, k) with am(u + 2K) = am(u) + pi.
"""

import json
import math
import random

import mpmath as mp

DIGITS = 50
CHECK_DIGITS = 70


def evaluate(function, *args):
    """function(*args) at DIGITS, checked against CHECK_DIGITS; returned as the nearest f64."""
    with mp.workdps(DIGITS):
        precise = function(*[mp.mpf(a) for a in args])
    with mp.workdps(CHECK_DIGITS):
        value = function(*[mp.mpf(a) for a in args])
    with mp.workdps(DIGITS):
        if precise != 0 and abs((value - precise) / precise) > mp.mpf(10) ** -20:
            raise SystemExit(f"mpmath disagrees with itself at {function.__name__}{args}")
    return float(precise)


def am(u, k):
    m = k * k
    quarter = mp.ellipk(m)
    turns = mp.nint(u / (2 * quarter))
    rest = u - 2 * turns * quarter
    return turns * mp.pi + mp.atan2(mp.ellipfun("sn", rest, m=m), mp.ellipfun("cn", rest, m=m))


def sn(u, k):
    return mp.ellipfun("sn", u, m=k * k)


def cn(u, k):
    return mp.ellipfun("cn", u, m=k * k)


def dn(u, k):
    return mp.ellipfun("dn", u, m=k * k)


def ellipk(k):
    return mp.ellipk(k * k)


def ellipf(phi, k):
    return mp.ellipf(phi, k * k)


def ellippi(n, phi, k):
    return mp.ellippi(n, phi, k * k)


def ellippi_complete(n, k):
    return mp.ellippi(n, k * k)


def log_uniform(rng, low, high):
    return math.exp(rng.uniform(math.log(low), math.log(high)))


def moduli(rng, count):
    """Moduli spread over [0, 1]: exact 0, tiny, uniform, and 1 - 10^-j up to 1 - 1e-12."""
    fixed = [0.0, 1e-12, 1e-8, 1e-4, 0.5, 0.9, 0.99, 1 - 1e-3, 1 - 1e-6, 1 - 1e-9, 1 - 1e-12]
    return fixed + [rng.random() for _ in range(count - len(fixed))]


def carlson_points(rng):
    rf, rd, rj, rc = [], [], [], []
    for i in range(40):
        x, y, z = (log_uniform(rng, 1e-8, 1e8) for _ in range(3))
        if i % 8 == 0:
            x = 0.0
        rf.append([x, y, z, evaluate(mp.elliprf, x, y, z)])
        if i < 30:
            rd.append([x, y, z, evaluate(mp.elliprd, x, y, z)])
        p = log_uniform(rng, 1e-8, 1e8) if i % 3 else y * (1 + rng.uniform(-1e-6, 1e-6))
        rj.append([x, y, z, p, evaluate(mp.elliprj, x, y, z, p)])
        if i < 30:
            cx = 0.0 if i % 7 == 0 else log_uniform(rng, 1e-8, 1e8)
            cy = log_uniform(rng, 1e-8, 1e8)
            rc.append([cx, cy, evaluate(mp.elliprc, cx, cy)])
    return {"rf": rf, "rd": rd, "rj": rj, "rc": rc}


def legendre_points(rng):
    ks = moduli(rng, 30)
    complete = [[k, evaluate(ellipk, k)] for k in ks]
    first, third, third_complete = [], [], []
    characteristics = [-100.0, -5.0, -1.0, -0.1, 0.0, 0.3, 0.9, 0.999, 1 - 1e-8]
    for k in ks:
        phis = [rng.uniform(-1.5, 1.5), math.pi / 2, math.pi / 2 - 1e-8, rng.uniform(-12.0, 12.0)]
        if k == 1 - 1e-12:
            phis = [p for p in phis if abs(p) < math.pi / 2]
        for phi in phis:
            if abs(phi) >= math.pi / 2 and k > 1 - 1e-12:
                continue
            first.append([phi, k, evaluate(ellipf, phi, k)])
        for phi in phis[:3] if k < 1 - 1e-10 else phis[:1]:
            n = rng.choice(characteristics)
            third.append([n, phi, k, evaluate(ellippi, n, phi, k)])
        if k < 1 - 1e-10 and rng.random() < 0.7:
            phi = rng.uniform(-12.0, 12.0)
            n = rng.choice(characteristics)
            third.append([n, phi, k, evaluate(ellippi, n, phi, k)])
        n = rng.choice(characteristics)
        third_complete.append([n, k, evaluate(ellippi_complete, n, k)])
    return {"k": complete, "f": first, "pi": third, "pi_complete": third_complete}


def jacobi_points(rng):
    points = []
    for k in moduli(rng, 30) + [1.0]:
        arguments = [rng.uniform(-3.0, 3.0), rng.uniform(-30.0, 30.0), rng.uniform(-1e4, 1e4)]
        arguments += [log_uniform(rng, 1e-10, 1e-2), rng.uniform(100.0, 1000.0)]
        for u in arguments:
            if k == 1.0:
                with mp.workdps(DIGITS):
                    exact = [mp.tanh(u), mp.sech(u), mp.sech(u), mp.atan(mp.sinh(u))]
                points.append([u, k] + [float(v) for v in exact])
                continue
            points.append([u, k, evaluate(sn, u, k), evaluate(cn, u, k), evaluate(dn, u, k), evaluate(am, u, k)])
    return {"jacobi": points}


def main():
    rng = random.Random(20240611)
    reference = {
        "generator": "tools/elliptic_reference.py (mpmath %s, %d digits, confirmed at %d)" % (mp.__version__, DIGITS, CHECK_DIGITS),
    }
    reference.update(carlson_points(rng))
    reference.update(legendre_points(rng))
    reference.update(jacobi_points(rng))
    as_text = {key: [[repr(float(v)) for v in row] for row in rows] if isinstance(rows, list) else rows
               for key, rows in reference.items()}
    print(json.dumps(as_text, indent=0))


if __name__ == "__main__":
    main()
