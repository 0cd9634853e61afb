#!/usr/bin/env python3
"""Reference eigenvalues of small dense pencils whose entries span up to 80 decades.

Writes crates/mechanica-modal/tests/data/wide_range_pencils.txt: random symmetric pencils
(A positive definite: identity, a diagonal of powers of ten, or dense G Gᵀ + D; B symmetric and
indefinite with entries ±10^U(−e, e), random zero patterns, and a rank-one background of tiny
entries under a few huge ones), each with the exact ω² of det(λA + B) = 0 (ω² = −λ, the
eigenvalues of B x = ω² A x) computed by mpmath at 250 digits from the stored doubles.

Each eigenvalue is stored as two doubles (hi, lo) with hi + lo equal to it to about 32 digits,
so a test can measure errors far below the ulp of ω². The matrices are stored as Python's
shortest round-trip decimal form of each double (parsed exactly by Rust's f64::from_str).

Run: python3 tools/modal_wide_range_reference.py  (mpmath 1.3; about a minute)
"""

import random
from pathlib import Path

import mpmath as mp

mp.mp.dps = 250
OUT = Path(__file__).resolve().parent.parent / "crates/mechanica-modal/tests/data/wide_range_pencils.txt"
CASES = 200
# The last LARGE random pencils have orders 12 to 30.
LARGE = 20


def wide(rng, decades):
    return rng.choice((-1.0, 1.0)) * 10.0 ** rng.uniform(-decades, decades)


def mass_matrix(rng, n):
    kind = rng.randrange(4)
    if kind == 3 and n >= 3:
        # Lumped, with one or two massless coordinates: infinite modes, a condensed pencil.
        d = [10.0 ** rng.uniform(-8, 8) for _ in range(n)]
        for i in rng.sample(range(n), rng.randrange(1, 3)):
            d[i] = 0.0
        return [[d[i] if i == j else 0.0 for j in range(n)] for i in range(n)]
    kind = kind % 3
    if kind == 0:
        return [[1.0 if i == j else 0.0 for j in range(n)] for i in range(n)]
    if kind == 1:
        d = [10.0 ** rng.uniform(-8, 8) for _ in range(n)]
        return [[d[i] if i == j else 0.0 for j in range(n)] for i in range(n)]
    # Dense and positive definite: G Gᵀ + D, formed in double (the stored matrix is the data).
    g = [[rng.uniform(-1, 1) for _ in range(n)] for _ in range(n)]
    d = [10.0 ** rng.uniform(-3, 3) for _ in range(n)]
    a = [[sum(g[i][k] * g[j][k] for k in range(n)) + (d[i] if i == j else 0.0) for j in range(n)] for i in range(n)]
    return [[a[min(i, j)][max(i, j)] for j in range(n)] for i in range(n)]


def stiffness_matrix(rng, n):
    decades = rng.choice((5, 15, 30, 40))
    b = [[0.0] * n for _ in range(n)]
    if rng.random() < 0.3:
        # A tiny rank-one background under a few huge entries (the shape of a fuzzed failure).
        background = wide(rng, 2) * 10.0 ** -rng.uniform(20, 35)
        for i in range(n):
            for j in range(n):
                b[i][j] = background
        for _ in range(rng.randrange(1, 4)):
            i, j = rng.randrange(n), rng.randrange(n)
            b[i][j] = b[j][i] = wide(rng, decades)
        return b
    density = rng.uniform(0.3, 1.0)
    for i in range(n):
        for j in range(i, n):
            if i == j or rng.random() < density:
                b[i][j] = b[j][i] = wide(rng, decades)
    return b


def exact_omega_sq(a, b):
    """The finite ω² ascending, then +∞ once per massless coordinate (A lumped with zeros): the
    finite ones are those of the condensed pencil (B_mm − B_m0 B_00⁻¹ B_0m, A_mm)."""
    n = len(a)
    massless = [i for i in range(n) if all(a[i][j] == 0.0 for j in range(n))]
    if massless:
        kept = [i for i in range(n) if i not in massless]
        b_mm = mp.matrix([[mp.mpf(b[i][j]) for j in kept] for i in kept])
        b_m0 = mp.matrix([[mp.mpf(b[i][j]) for j in massless] for i in kept])
        b_00 = mp.matrix([[mp.mpf(b[i][j]) for j in massless] for i in massless])
        s = b_mm - b_m0 * mp.inverse(b_00) * b_m0.T
        a_mm = [[a[i][j] for j in kept] for i in kept]
        return finite_spectrum(a_mm, s) + [mp.inf] * len(massless)
    return finite_spectrum(a, mp.matrix([[mp.mpf(v) for v in row] for row in b]))


def finite_spectrum(a, bm):
    n = len(a)
    am = mp.matrix([[mp.mpf(v) for v in row] for row in a])
    l = mp.cholesky(am)
    li = mp.inverse(l)
    m = li * bm * li.T
    m = (m + m.T) / 2
    values = mp.eigsy(m, eigvals_only=True)
    return sorted(values[i] for i in range(n))


def split(value):
    if value == mp.inf:
        return float("inf"), 0.0
    hi = float(value)
    lo = float(value - mp.mpf(hi))
    return hi, lo


def fuzzed_pencil():
    """A pencil found by the abi_modal fuzz target: A = I, a rank-one background of −2⁻¹⁰³·1.0…
    under four huge entries; its near-zero modes were once reported with bounds 1e7 times too
    small and a NaN frequency."""
    n = 7
    c = -9.765625000000001e-32
    b = [[c] * n for _ in range(n)]
    b[4][6] = b[6][4] = -14291015.625
    b[5][5] = -2.64658203125e33
    b[5][6] = b[6][5] = -2541015.625
    b[6][6] = -26465820312500.0
    a = [[1.0 if i == j else 0.0 for j in range(n)] for i in range(n)]
    return a, b


def main():
    rng = random.Random(20261128)
    lines = [f"# {CASES + 1} pencils: n, A (row-major), B (row-major), then n lines 'hi lo' of exact ω², ascending"]
    for case in range(CASES + 1):
        n = rng.randrange(2, 10) if case < CASES - LARGE else rng.randrange(12, 31)
        a = mass_matrix(rng, n)
        b = stiffness_matrix(rng, n)
        if case == CASES:
            a, b = fuzzed_pencil()
            n = len(a)
        while True:
            try:
                omega = exact_omega_sq(a, b)
                break
            except ZeroDivisionError:
                # A singular massless block B_00: the pencil is singular; draw another B.
                b = stiffness_matrix(rng, n)
        lines.append(str(n))
        lines.append(" ".join(repr(v) for row in a for v in row))
        lines.append(" ".join(repr(v) for row in b for v in row))
        for w in omega:
            hi, lo = split(w)
            lines.append(f"{hi!r} {lo!r}")
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text("\n".join(lines) + "\n")
    print(f"wrote {OUT} ({CASES + 1} pencils)")


if __name__ == "__main__":
    main()
