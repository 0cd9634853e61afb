#!/usr/bin/env python3
"""The sparse peer of benches/benches/modal.rs (group modal_sparse): the 10 lowest modes of the
5-point Dirichlet Laplacian of an N x N grid (unit spacing, mass matrix I), n = N^2, by
scipy.sparse.linalg.eigsh in shift-invert mode (ARPACK + SuperLU, sigma = 0, which='LM'),
the usual way SciPy users compute low modes.

Prints and writes tools/modal_sparse_scipy.out: N, n, best-of-k wall time (s), max relative
eigenvalue error against the closed form 4 sin^2(p pi/(2(N+1))) + 4 sin^2(q pi/(2(N+1))),
max backward error |Bx - w x| / ((|B|_F + |w| |I|_F) |x|), and the machine load, since the
comparison is only fair against a Rust run at similar load.

Rerun:  python3 tools/modal_sparse_scipy.py [N ...]      (default 100 300)
"""
import os
import sys
import time

import numpy as np
import scipy
import scipy.sparse as sp
import scipy.sparse.linalg as sla


def grid(m):
    t = sp.diags([-np.ones(m - 1), 2 * np.ones(m), -np.ones(m - 1)], [-1, 0, 1])
    i = sp.identity(m)
    return (sp.kron(i, t) + sp.kron(t, i)).tocsc()


def exact(m, k):
    s = 4 * np.sin(np.arange(1, m + 1) * np.pi / (2 * (m + 1))) ** 2
    return np.sort((s[:, None] + s[None, :]).ravel())[:k]


def best(f, k):
    times = []
    for _ in range(k):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return min(times)


def main():
    sizes = [int(s) for s in sys.argv[1:]] or [100, 300]
    k = 10
    lines = [
        "# tools/modal_sparse_scipy.py: scipy %s, numpy %s, eigsh(B, k=10, sigma=0, which='LM')"
        % (scipy.__version__, np.__version__),
        "# load average at start: %.1f %.1f %.1f" % os.getloadavg(),
        "# N  n  best_s  max_rel_eig_error  max_backward_error",
    ]
    for m in sizes:
        b = grid(m)
        n = m * m
        t = best(lambda: sla.eigsh(b, k=k, sigma=0, which="LM"), 3)
        w, x = sla.eigsh(b, k=k, sigma=0, which="LM")
        order = np.argsort(w)
        w, x = w[order], x[:, order]
        rel = np.max(np.abs(w - exact(m, k)) / exact(m, k))
        nb, na = sp.linalg.norm(b), np.sqrt(n)
        r = b @ x - x * w
        eta = np.max(np.linalg.norm(r, axis=0) / ((nb + np.abs(w) * na) * np.linalg.norm(x, axis=0)))
        line = f"{m} {n} {t:.4f} {rel:.2e} {eta:.2e}"
        print(line, flush=True)
        lines.append(line)
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "modal_sparse_scipy.out")
    with open(out, "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
