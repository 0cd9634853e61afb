"""Hostile generalized symmetric pencils (A, B) for `mechanica modes`, B x = w^2 A x.

Each family is a function seed -> (A, B, meta) with A, B dense float64 numpy arrays
(A symmetric positive semidefinite, B symmetric) built from a fixed numpy Generator, so a
(family, seed) pair always gives the same bits.

  fe                consistent-mass finite-element bars and beams (fixed, cantilever, free)
  dense             dense random, stiff B against graded A and vice versa
  network           spring networks with cycles (grids, random graphs), grounded or free
  semidef_repeated  singular A (massless coordinates), exactly and nearly repeated eigenvalues
  cluster           complete graphs K_n, graded by power-of-two congruence (one eigenvalue of
                    multiplicity n-1, optionally split by ~1e-10)
  nearsing          near-singular pencils and singular non-diagonal A with integer entries
  indefinite        indefinite B (negative springs, compressed bars, dense indefinite)

Requires: pip install mpmath numpy   (this module only needs numpy)
"""
import math

import numpy as np


def q(x, bits=10):
    """Round x to `bits` significant bits (short mantissas, exact sums)."""
    if x == 0:
        return 0.0
    m, e = math.frexp(x)
    return math.ldexp(round(m * 2**bits), e - bits)


def lu(rng, lo, hi, size=None):
    """Log-uniform on [10^lo, 10^hi]."""
    return 10.0 ** rng.uniform(lo, hi, size)


def sym(X):
    return (X + X.T) / 2


def rand_orth(rng, n):
    Q, R = np.linalg.qr(rng.standard_normal((n, n)))
    return Q * np.sign(np.diag(R))


def fe_bar(rng, n, bc, quant):
    ne = {'fixed': n + 1, 'cant': n, 'free': n - 1}[bc]
    L = lu(rng, -2, 2, ne); EA = lu(rng, 0, 8, ne); rA = lu(rng, -3, 3, ne)
    k = EA / L; m = rA * L / 6
    if quant:
        k = np.array([q(x) for x in k]); m = np.array([q(x) for x in m])
    N = ne + 1
    A = np.zeros((N, N)); B = np.zeros((N, N))
    for e in range(ne):
        i, j = e, e + 1
        B[i, i] += k[e]; B[j, j] += k[e]; B[i, j] -= k[e]; B[j, i] -= k[e]
        A[i, i] += 2 * m[e]; A[j, j] += 2 * m[e]; A[i, j] += m[e]; A[j, i] += m[e]
    keep = list({'fixed': range(1, N - 1), 'cant': range(1, N), 'free': range(N)}[bc])
    return A[np.ix_(keep, keep)], B[np.ix_(keep, keep)]


def fe_beam(rng, nel, bc, lumped=False):
    L = lu(rng, -1, 1, nel); EI = lu(rng, 0, 8, nel); rA = lu(rng, -3, 3, nel)
    N = 2 * (nel + 1)
    A = np.zeros((N, N)); B = np.zeros((N, N))
    for e in range(nel):
        l = L[e]
        K = EI[e] / l**3 * np.array([[12, 6*l, -12, 6*l], [6*l, 4*l*l, -6*l, 2*l*l],
                                     [-12, -6*l, 12, -6*l], [6*l, 2*l*l, -6*l, 4*l*l]])
        if lumped:   # translational mass only: rotations massless
            M = rA[e] * l / 2 * np.diag([1.0, 0.0, 1.0, 0.0])
        else:
            M = rA[e] * l / 420 * np.array([[156, 22*l, 54, -13*l], [22*l, 4*l*l, 13*l, -3*l*l],
                                            [54, 13*l, 156, -22*l], [-13*l, -3*l*l, -22*l, 4*l*l]])
        idx = [2*e, 2*e+1, 2*e+2, 2*e+3]
        A[np.ix_(idx, idx)] += M; B[np.ix_(idx, idx)] += K
    if bc == 'clamped':
        keep = list(range(2, N))
    elif bc == 'cc':
        keep = list(range(2, N - 2))
    elif bc == 'pinned':
        keep = [i for i in range(N) if i not in (0, N - 2)]
    else:
        keep = list(range(N))
    return A[np.ix_(keep, keep)], B[np.ix_(keep, keep)]


def graph_edges(rng, n, kind):
    E = set()
    if kind == 'grid':
        r = max(2, int(round(math.sqrt(n)))); c = max(2, n // r); n = r * c
        for i in range(r):
            for j in range(c):
                v = i * c + j
                if j + 1 < c: E.add((v, v + 1))
                if i + 1 < r: E.add((v, v + c))
    else:   # random spanning tree plus extra edges (cycles)
        perm = rng.permutation(n)
        for t in range(1, n):
            p = perm[rng.integers(0, t)]
            E.add(tuple(sorted((int(perm[t]), int(p)))))
        extra = int(rng.integers(1, max(2, n // 4) + 1))
        while extra > 0:
            a, b = rng.integers(0, n, 2)
            if a != b and tuple(sorted((int(a), int(b)))) not in E:
                E.add(tuple(sorted((int(a), int(b))))); extra -= 1
    return n, sorted(E)


def network(rng, n, kind, grounded, quant, mlo=0, mhi=8, klo=0, khi=12):
    n, E = graph_edges(rng, n, kind)
    m = lu(rng, mlo, mhi, n)
    B = np.zeros((n, n))
    ks = lu(rng, klo, khi, len(E))
    if quant:
        ks = np.array([q(x, 8) for x in ks]); m = np.array([q(x, 8) for x in m])
    for (a, b), k in zip(E, ks):
        B[a, a] += k; B[b, b] += k; B[a, b] -= k; B[b, a] -= k
    if grounded:
        g = rng.choice(n, size=int(rng.integers(1, 3)), replace=False)
        for v in g:
            kg = lu(rng, klo, khi)
            if quant: kg = q(kg, 8)
            B[v, v] += kg
    return np.diag(m), B


def ring(n, m=1.0, k=1.0):
    A = np.eye(n) * m; B = np.zeros((n, n))
    for i in range(n):
        j = (i + 1) % n
        B[i, i] += k; B[j, j] += k; B[i, j] -= k; B[j, i] -= k
    return A, B


def fe(seed):
    rng = np.random.default_rng(1000 + seed)
    kind = seed % 6
    if kind < 3:
        bc = ['fixed', 'cant', 'free'][kind]
        n = int(rng.integers(5, 61))
        quant = bool(rng.integers(0, 2))
        A, B = fe_bar(rng, n, bc, quant)
        return A, B, dict(sub=f'bar-{bc}', quant=quant)
    bc = ['clamped', 'free', 'cc'][kind - 3]
    A, B = fe_beam(rng, int(rng.integers(3, 30)), bc)
    return A, B, dict(sub=f'beam-{bc}')


def dense(seed):
    rng = np.random.default_rng(2000 + seed)
    n = int(rng.integers(5, 61))
    Q = rand_orth(rng, n); Q2 = rand_orth(rng, n)
    C = sym(Q2 @ np.diag(rng.uniform(1, 10, n)) @ Q2.T)
    if seed % 2 == 0:
        B = sym(Q @ np.diag(lu(rng, 0, 12, n)) @ Q.T)
        D = np.diag(lu(rng, -4, 0, n))
        return sym(D @ C @ D), B, dict(sub='stiffB-gradedA')
    D = np.diag(lu(rng, -6, 0, n))
    A = sym(D @ C @ D) if seed % 4 == 1 else sym(Q @ np.diag(lu(rng, -11, 0, n)) @ Q.T)
    B = sym(Q2 @ np.diag(rng.uniform(1, 10, n)) @ Q2.T)
    return A, B, dict(sub='gradedA-mildB' + ('-DCD' if seed % 4 == 1 else '-Qdiag'))


def network_family(seed):
    rng = np.random.default_rng(3000 + seed)
    n = int(rng.integers(5, 61))
    kind = 'grid' if seed % 2 == 0 else 'random'
    grounded = (seed % 4) < 2
    quant = bool(rng.integers(0, 2))
    A, B = network(rng, n, kind, grounded, quant)
    return A, B, dict(sub=f'{kind}-{"grounded" if grounded else "free"}', quant=quant)


def semidef_repeated(seed):
    rng = np.random.default_rng(4000 + seed)
    kind = seed % 6
    n = int(rng.integers(5, 61))
    if kind == 0:   # spring network with some zero masses
        A, B = network(rng, n, 'random', bool(rng.integers(0, 2)), False)
        z = rng.choice(A.shape[0], size=int(rng.integers(1, max(2, A.shape[0] // 3))), replace=False)
        for v in z: A[v, v] = 0.0
        return A, B, dict(sub='network-zeromass')
    if kind == 1:   # beam with lumped translational mass, massless rotations
        nel = int(rng.integers(3, 30))
        A, B = fe_beam(rng, nel, ['clamped', 'cc', 'free'][int(rng.integers(0, 3))], lumped=True)
        return A, B, dict(sub='beam-lumped-massless-rot')
    if kind == 2:   # ring (double eigenvalues), optionally shifted, power-of-two graded
        A, B = ring(n)
        if rng.integers(0, 2):
            B += np.eye(n) * 0.5
        d = np.array([2.0 ** int(x) for x in rng.integers(-20, 21, n)])
        return A * np.outer(d, d), B * np.outer(d, d), dict(sub='ring-pow2-graded')
    if kind in (3, 4):   # two copies of one network: exactly (3) or nearly (4, 1e-10) repeated
        h = max(3, n // 2)
        A1, B1 = network(rng, h, 'random', True, kind == 3, mlo=0, mhi=6, klo=0, khi=8)
        B2 = B1.copy()
        if kind == 4:
            i = int(rng.integers(0, h)); B2[i, i] *= (1 + 1e-10)
        A = np.zeros((2 * h, 2 * h)); B = np.zeros((2 * h, 2 * h))
        A[:h, :h] = A1; A[h:, h:] = A1; B[:h, :h] = B1; B[h:, h:] = B2
        P = rng.permutation(2 * h)
        return A[np.ix_(P, P)], B[np.ix_(P, P)], dict(
            sub='twin-exact-repeated' if kind == 3 else 'twin-nearly-repeated')
    # dense B with triple eigenvalue clusters (1e-11 split), diagonal A with zero masses
    Q = rand_orth(rng, n)
    ev = np.repeat(lu(rng, 0, 8, (n + 2) // 3), 3)[:n] * (1 + 1e-11 * rng.standard_normal(n))
    B = sym(Q @ np.diag(ev) @ Q.T)
    A = np.diag(lu(rng, -4, 4, n))
    z = rng.choice(n, size=int(rng.integers(1, max(2, n // 3))), replace=False)
    for v in z: A[v, v] = 0.0
    return A, B, dict(sub='dense-cluster-zeromass')


def cluster(seed):
    rng = np.random.default_rng(6000 + seed)
    n = int(rng.integers(17, 61))
    k = 2.0 ** int(rng.integers(-5, 6))
    B = k * (n * np.eye(n) - np.ones((n, n)))
    free = seed % 3 == 0
    if not free:
        B += np.eye(n) * 2.0 ** int(rng.integers(-3, 4))
    split = seed % 3 == 2
    if split:   # perturb two springs by k 2^-33 (exact doubles)
        for _ in range(2):
            a, b = rng.choice(n, 2, replace=False)
            d = k * 2.0 ** -33
            B[a, a] += d; B[b, b] += d; B[a, b] -= d; B[b, a] -= d
    d = np.array([2.0 ** int(x) for x in rng.integers(-20, 21, n)])   # 12 decades of mass
    A = np.eye(n) * np.outer(d, d); B = B * np.outer(d, d)
    return A, B, dict(sub=f'complete-{"free" if free else "grounded"}{"-split" if split else ""}')


def nearsing(seed):
    rng = np.random.default_rng(7000 + seed)
    n = int(rng.integers(5, 41))
    P = rng.integers(-3, 4, (n, n - 1)).astype(float)
    R = rng.integers(-2, 3, (n - 1, n - 1)).astype(float); R = R @ R.T + np.eye(n - 1) * n
    A0 = P @ P.T; B0 = P @ R @ P.T          # integer matrices with a common null vector
    kind = seed % 3
    if kind == 0:     # one diagonal entry of each perturbed by 2^-40 / 2^-30 relative
        i = int(rng.integers(0, n))
        A = A0.copy(); B = B0.copy()
        A[i, i] = A0[i, i] * (1 + 2.0 ** -40) if A0[i, i] else 2.0 ** -40
        j = int(rng.integers(0, n))
        B[j, j] = B0[j, j] * (1 + 2.0 ** -30) if B0[j, j] else 2.0 ** -30
        sub = 'near-singular-pencil'
    elif kind == 1:   # A of rank n-1 (null vector not a coordinate), B positive definite
        A = A0; B = B0 + np.eye(n) * float(n)
        sub = 'singular-A-nondiag'
    else:             # A positive definite but nearly singular along B's near-null direction
        A = A0 + np.eye(n) * 2.0 ** -44; B = B0 + np.eye(n) * 2.0 ** -20
        sub = 'near-common-null'
    d = np.array([2.0 ** int(x) for x in rng.integers(-8, 9, n)])
    return A * np.outer(d, d), B * np.outer(d, d), dict(sub=sub)


def indefinite(seed):
    rng = np.random.default_rng(5000 + seed)
    n = int(rng.integers(5, 61))
    kind = seed % 3
    if kind == 0:
        Q = rand_orth(rng, n)
        s = np.where(rng.uniform(size=n) < 0.3, -1.0, 1.0)
        B = sym(Q @ np.diag(s * lu(rng, 0, 12, n)) @ Q.T)
        D = np.diag(lu(rng, -4, 0, n)); Q2 = rand_orth(rng, n)
        A = sym(D @ sym(Q2 @ np.diag(rng.uniform(1, 10, n)) @ Q2.T) @ D)
        return A, B, dict(sub='dense-indefinite')
    if kind == 1:   # network with a few weak negative springs
        n2, E = graph_edges(rng, n, 'random')
        m = lu(rng, 0, 8, n2); ks = lu(rng, 0, 12, len(E))
        neg = rng.uniform(size=len(E)) < 0.15
        ks[neg] *= -1e-2
        B = np.zeros((n2, n2))
        for (a, b), k in zip(E, ks):
            B[a, a] += k; B[b, b] += k; B[a, b] -= k; B[b, a] -= k
        for v in rng.choice(n2, 2, replace=False): B[v, v] += lu(rng, 0, 12)
        return np.diag(m), B, dict(sub='network-negsprings')
    # consistent-mass bar whose springs carry a compressive (destabilising) part
    ne = n + 1
    L = lu(rng, -2, 1, ne); EA = lu(rng, 0, 8, ne); rA = lu(rng, -3, 3, ne)
    N = ne + 1
    A = np.zeros((N, N)); B = np.zeros((N, N))
    P = -lu(rng, 0, 4)
    for e in range(ne):
        k = EA[e] / L[e] * (1 if rng.uniform() < 0.7 else 0) + P / L[e]
        mm = rA[e] * L[e] / 6
        i, j = e, e + 1
        B[i, i] += k; B[j, j] += k; B[i, j] -= k; B[j, i] -= k
        A[i, i] += 2 * mm; A[j, j] += 2 * mm; A[i, j] += mm; A[j, i] += mm
    keep = list(range(1, N - 1))
    return A[np.ix_(keep, keep)], B[np.ix_(keep, keep)], dict(sub='bar-compressed')


FAMILIES = {'fe': fe, 'dense': dense, 'network': network_family,
            'semidef_repeated': semidef_repeated, 'cluster': cluster,
            'nearsing': nearsing, 'indefinite': indefinite}


def write_mtx(path, M):
    """Lower triangle in Matrix Market coordinate format; repr() round-trips every double."""
    n = M.shape[0]
    ent = [(i, j, M[i, j]) for j in range(n) for i in range(j, n) if M[i, j] != 0.0]
    with open(path, 'w') as f:
        f.write('%%MatrixMarket matrix coordinate real symmetric\n')
        f.write(f'{n} {n} {len(ent)}\n')
        for i, j, v in ent:
            f.write(f'{i+1} {j+1} {float(v)!r}\n')


def read_mtx(path):
    with open(path) as f:
        lines = [l for l in f if not l.startswith('%')]
    n = int(lines[0].split()[0]); M = np.zeros((n, n))
    for l in lines[1:]:
        i, j, v = l.split(); i = int(i) - 1; j = int(j) - 1
        M[i, j] = float(v); M[j, i] = float(v)
    return M
