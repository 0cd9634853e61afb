#!/usr/bin/env python3
"""Times LAPACK's symmetric-definite solver (scipy.linalg.eigh(B, A), driver dsygvd) on the
family benches/benches/modal.rs uses: a fixed-fixed unit spring chain B = tridiag(-1, 2, -1)
with masses A = diag(1 + i/n), both rotated by a random orthogonal Q (numpy's, so the matrices
are the same family, not bit-identical to the Rust ones; the spectrum is identical).

Prints and writes tools/modal_scipy_bench.out: n, best-of-k wall time (s) for all pairs and for
values only, the max backward error eta = |Bx - w Ax| / ((|B|_F + |w| |A|_F) |x|) and the max
relative eigenvalue error against the unrotated problem. Threads: whatever OpenBLAS uses
(set OPENBLAS_NUM_THREADS to match the Rust run; the committed run used the machine's 2 cores).

Rerun:  python3 tools/modal_scipy_bench.py [n ...]
"""
import os
import sys
import time

import numpy as np
import scipy
import scipy.linalg as sl


def pencil(n, seed=42):
    rng = np.random.default_rng(seed)
    q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    a0 = np.diag(1.0 + np.arange(n) / n)
    b0 = 2.0 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1)
    a = q.T @ a0 @ q
    b = q.T @ b0 @ q
    return (a + a.T) / 2, (b + b.T) / 2, a0, b0


def best(f, k):
    times = []
    for _ in range(k):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return min(times)


def main():
    sizes = [int(s) for s in sys.argv[1:]] or [200, 1000, 2000]
    lines = [
        "# tools/modal_scipy_bench.py: scipy %s, numpy %s, LAPACK eigh(B, A) driver gvd" % (scipy.__version__, np.__version__),
        "# load average at start: %.1f %.1f %.1f (timings are only comparable with a Rust run at similar load)" % os.getloadavg(),
        "# n  all_pairs_s  values_only_s  max_backward_error  max_rel_eig_error",
    ]
    for n in sizes:
        a, b, a0, b0 = pencil(n)
        k = 5 if n <= 1000 else 3
        t_all = best(lambda: sl.eigh(b, a, driver="gvd"), k)
        t_val = best(lambda: sl.eigh(b, a, eigvals_only=True, driver="gvd"), k)
        w, x = sl.eigh(b, a, driver="gvd")
        na, nb = np.linalg.norm(a), np.linalg.norm(b)
        r = b @ x - (a @ x) * w
        eta = np.max(np.linalg.norm(r, axis=0) / ((nb + np.abs(w) * na) * np.linalg.norm(x, axis=0)))
        ref = np.sort(sl.eigh(b0, a0, eigvals_only=True))
        rel = np.max(np.abs(np.sort(w) - ref) / np.abs(ref))
        line = f"{n} {t_all:.4f} {t_val:.4f} {eta:.2e} {rel:.2e}"
        print(line, flush=True)
        lines.append(line)
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "modal_scipy_bench.out")
    with open(out, "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
