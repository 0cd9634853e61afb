"""Exact ω² of the pencil in crates/mechanica-modal/tests/data/buried (a 7-link chain whose two
softest modes lie below the stiff modes' rounding), by mpmath at 60 digits on the stored
doubles: Cholesky of A, then the symmetric eigenvalues of L⁻¹BL⁻ᵀ. Writes omega_sq.txt."""
import pathlib
import mpmath as mp

mp.mp.dps = 60
here = pathlib.Path(__file__).resolve().parent.parent / "crates/mechanica-modal/tests/data/buried"


def read(name):
    lines = [l for l in (here / name).read_text().splitlines() if not l.startswith("%")]
    n = int(lines[0].split()[0])
    m = mp.matrix(n, n)
    for line in lines[1:]:
        i, j, v = line.split()
        m[int(i) - 1, int(j) - 1] = mp.mpf(float(v))  # the stored double, not the decimal
    return m


a, b = read("a.mtx"), read("b.mtx")
n = a.rows
sym = mp.matrix(n, n)
for i in range(n):
    for j in range(n):
        sym[i, j] = a[max(i, j), min(i, j)]  # the lower triangle, as the solver reads it
l_inv = mp.cholesky(sym) ** -1
values = sorted(mp.eigsy(l_inv * b * l_inv.T)[0])
(here / "omega_sq.txt").write_text("".join(mp.nstr(v, 25) + "\n" for v in values))
print([mp.nstr(v, 17) for v in values])
