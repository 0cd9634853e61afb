#!/usr/bin/env python3
"""One point of a work-precision series for SciPy's scipy.linalg.eigh(B, A) (LAPACK dsygvd,
all pairs): called by benches/benches/modal_report.rs with a scratch file of the pencil.

    python3 tools/scipy_eigh_point.py FILE N RUNS

FILE holds A then B, each N x N, column-major little-endian doubles. Times RUNS solves
(median, time.perf_counter; the input copies are inside the timed region, as for the Rust
methods) and prints two lines: "seconds max_backward_error scipy_version", then the ascending
eigenvalues. The backward error is eta = |Bx - w Ax| / ((|B|_F + |w| |A|_F) |x|), as the Rust
report computes it. Exits 3 when NumPy or SciPy is missing.
"""
import sys
import time

try:
    import numpy as np
    import scipy
    import scipy.linalg as sl
except ImportError as e:  # the bench skips the series
    print(f"unavailable: {e}")
    sys.exit(3)


def main():
    path, n, runs = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    data = np.fromfile(path, dtype="<f8")
    a = data[: n * n].reshape((n, n), order="F")
    b = data[n * n :].reshape((n, n), order="F")
    times = []
    for _ in range(max(runs, 1)):
        start = time.perf_counter()
        w, x = sl.eigh(b.copy(), a.copy())
        times.append(time.perf_counter() - start)
    times.sort()
    norm_a, norm_b = np.linalg.norm(a), np.linalg.norm(b)
    r = b @ x - (a @ x) * w
    eta = np.linalg.norm(r, axis=0) / ((norm_b + np.abs(w) * norm_a) * np.linalg.norm(x, axis=0))
    print(f"{times[len(times) // 2]:.9e} {eta.max():.3e} {scipy.__version__}")
    print(" ".join(f"{v:.17e}" for v in w))


if __name__ == "__main__":
    main()
