#!/usr/bin/env python3
"""50-digit reference torques for inverse dynamics where a heavy body's acceleration cancels.

Writes tools/dynamics_cancellation_reference.json, read by
crates/mechanica-dynamics/tests/estimate_cancellation.rs, and prints a summary (committed as
tools/dynamics_cancellation_reference.out):

    python3 tools/dynamics_cancellation_reference.py > tools/dynamics_cancellation_reference.out

Why. `Dynamics::inverse_dynamics` returns a first-order rounding estimate per coordinate. When
the joint accelerations q-ddot nearly annul each other at a heavy body (J q-ddot ~ 0 with
|J| |q-ddot| large), the body's computed acceleration is small but its rounding is not: it
carries u times the sizes of the cancelled terms, multiplied by the body's mass. An estimate
scaled by the computed accelerations misses that by the ratio of the two.

Family (CASES cases, seed SEED; case i draws everything from random.Random(SEED + 1000 i + attempt)):
  * chains (even i, 3-8 joints; a 3-joint chain only with a planar group, and this seed drew
    none) and trees (odd i, 5-8 joints, parents drawn among earlier bodies); every joint
    revolute or prismatic (about 30 %), with random unit axes, a quarter of them coordinate
    axes;
  * in the cases with floor(i / 2) even, a "planar group" on the heavy body's path: 4 consecutive
    joints (3 in a 3-joint chain) whose revolute axes are parallel and whose prismatic axis
    (at most one) is perpendicular to them. Four such columns span only 3 of the 6 spatial
    directions, so the heavy body's 6 x n Jacobian has a null space even on short paths;
  * placements: translations of length 10^U(-1, 0.5) m in random directions; rotations drawn
    from the 12 unit quaternions with entries in {0, +-1/2, +-1} (the tetrahedral group), the
    only rotations whose unit quaternion is exact in double precision; their matrices are
    signed permutations, which nalgebra's quaternion-to-matrix forms exactly, so the R_PJ of
    the Rust builder is exactly orthogonal and exactly the one used here. The generality of the
    frames comes from the axes and angles;
  * masses: the light bodies 10^U(-D/2, D/2) kg with D ~ U(0, 4) decades, one heavy body
    10^U(4, 8) times the heaviest light one, at a random body with at least 4 joints on its
    path (3 for the 3-joint chains with a planar group): up to 12 decades in all. Centres of
    mass within a link length, central inertias of boxes of about the link's size, turned to
    random axes and written exactly symmetric;
  * q: angles U(-3.1, 3.1), lengths U(-0.5, 0.5); q-dot zero (probability 1/2) or
    U(-1, 1) 10^U(-2, 0); gravity off (probability 1/2) or a random vector of about 9.81 m/s^2;
  * q-ddot = s v + r: s = 10^U(2, 8), v a random unit (inf-norm) vector of the null space of
    the heavy body's 6 x p Jacobian (angular velocity and centre-of-mass velocity, over the p
    joints of its path) when that null space is not empty, else of its 3 x p point Jacobian at
    its centre of mass; r a small random part U(-1, 1) 10^U(-3, -1) on every coordinate. A
    draw whose exact cancellation ratio sum_k |J_k| |q-ddot_k| / |a_C| (J the point Jacobian,
    a_C the centre-of-mass acceleration) is below 1e4 is drawn again (the next attempt).

Exactness of the inputs. Every input is a double, and the reference takes each as its exact
binary value. The Rust tree builder normalises joint axes (mechanica_kinematics::scaling::unit:
v / fl(sqrt((x^2 + y^2) + z^2))); every axis here is a fixed point of that map under each
order of the squares (checked below, and the Rust test checks the builder's axes bit for bit),
and its exact |a|^2 differs from 1 by less than 2^-66 ~ 1.4e-20: the model rotates about
a/|a|, and using a instead moves tau by less than 1e-4 u relative to the magnitudes, far
inside the estimate's 16 (d + 4) u. Placements and mass properties are used verbatim by the
builder (the Rust test checks R_PJ and p_PJ bit for bit).

Reference. A world-frame recursive Newton-Euler algorithm in mpmath, 60 working digits, 50
written (adapted from the independent checker's ref.py): joint frame R_WJ = R_WP R_PJ,
revolute R_JB = exp(q [a]x), prismatic o_B = o_J + q a; body wrench m (a_C - g),
J_C w-dot + w x J_C w moved to the origin; tau_k = (moment, force) . (axis, 0) or
(0, axis). It is validated here by
  * the closed forms of a double pendulum and of a cart-pole (random parameters and states);
  * Lagrange's equations on every case of the family, with A(q) built from the Jacobians of
    the forward kinematics (not from the recursion): tau = A q-ddot + (dA/dt) q-dot -
    (1/2) d(q-dot^T A q-dot)/dq + dV/dq, the derivatives by mpmath's numerical differentiation;
  * the same recursion at 90 digits (the summary gives both differences relative to max|tau|).

JSON: {"digits", "cases": [...]}, each case
  name, structure ("chain" | "tree"), heavy (body index), null_space ("spatial 6 x p" |
  "point 3 x p"), planar_group (body indices), scale (s), cancellation (the exact ratio above),
  bodies: [{parent (index or null), type ("revolute" | "prismatic"), axis [3],
            quaternion [w, x, y, z], rotation (R_PJ row-major [9], exact), translation [3],
            mass, com [3] (body frame), inertia (central, body axes, row-major [9])}],
  gravity [3], q, q_dot, q_ddot, tau (50 significant digits), tau_hi, tau_lo (tau = hi + lo
  to about 1e-32 relative).
Every double is a JSON string holding Python's repr (the shortest decimal that reads back to
the same double), so that Rust's correctly rounded str::parse recovers it exactly; serde_json's
default number parser is only best-effort. Bodies are in index order, parents first, one
coordinate per body (mechanica's coordinate k is body k's joint).
"""

import json
import math
import os
import platform
import random
import sys
from fractions import Fraction

import mpmath as mp
from mpmath import mpf

CASES = 24
SEED = 20250701
DIGITS = 50  # written
WORK_DIGITS = 60  # computed
CHECK_DIGITS = 90  # the precision check
HERE = os.path.dirname(os.path.abspath(__file__))
TETRAHEDRAL = [(1.0, 0.0, 0.0, 0.0), (0.0, 1.0, 0.0, 0.0), (0.0, 0.0, 1.0, 0.0), (0.0, 0.0, 0.0, 1.0)] + [
    (0.5, x, y, z) for x in (0.5, -0.5) for y in (0.5, -0.5) for z in (0.5, -0.5)
]


# ---------------------------------------------------------------- 3-vectors in mpmath
def add(a, b):
    return [a[0] + b[0], a[1] + b[1], a[2] + b[2]]


def sub(a, b):
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def scl(s, a):
    return [s * a[0], s * a[1], s * a[2]]


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def mv(m, a):
    return [m[i][0] * a[0] + m[i][1] * a[1] + m[i][2] * a[2] for i in range(3)]


def mm(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def tr(a):
    return [[a[j][i] for j in range(3)] for i in range(3)]


def norm(a):
    return mp.sqrt(dot(a, a))


def eye():
    return [[mpf(int(i == j)) for j in range(3)] for i in range(3)]


def rodrigues(k, th):
    """exp(th [k]x) for a unit k: I + sin th [k]x + (1 - cos th) [k]x^2."""
    s, c = mp.sin(th), 1 - mp.cos(th)
    kx = [[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]]
    kx2 = mm(kx, kx)
    return [[int(i == j) + s * kx[i][j] + c * kx2[i][j] for j in range(3)] for i in range(3)]


# ---------------------------------------------------------------- exact inputs
def quaternion_matrix(w, x, y, z):
    """nalgebra's UnitQuaternion::to_rotation_matrix, exact for these entries."""
    return [
        [w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (w * y + x * z)],
        [2 * (w * z + x * y), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (w * x + y * z), w * w - x * x - y * y + z * z],
    ]


def builder_keeps(a):
    """True when mechanica_kinematics::scaling::unit returns `a` itself for every order of the
    components (the power-of-two prescaling is exact and does not change the quotient)."""
    big = max(abs(t) for t in a)
    if not 0.5 <= big <= 1.0:
        return False
    for i in range(3):
        u, v, w = a[i], a[(i + 1) % 3], a[(i + 2) % 3]
        if math.sqrt((u * u + v * v) + w * w) != 1.0:
            return False
    return True


def unit_defect(a):
    return abs(sum(Fraction(t) ** 2 for t in a) - 1)


def exact_unit_axis(rng, zero=None):
    """A random axis the builder keeps, with |exact |a|^2 - 1| < 2^-66; `zero`: index of a
    component forced to 0 (planar groups need one, so that a coordinate axis is normal to it)."""
    while True:
        d = [rng.gauss(0, 1) for _ in range(3)]
        if zero is not None:
            d[zero] = 0.0
        n = math.sqrt(sum(t * t for t in d))
        if n < 0.1:
            continue
        a = [t / n for t in d]
        if builder_keeps(a) and unit_defect(a) < Fraction(1, 2**66):
            return a


def coordinate_axis(rng):
    a = [0.0, 0.0, 0.0]
    a[rng.randrange(3)] = rng.choice((1.0, -1.0))
    return a


def random_rotation(rng):
    """A random rotation matrix (floats), for the inertia axes only."""
    w, x, y, z = (rng.gauss(0, 1) for _ in range(4))
    n = math.sqrt(w * w + x * x + y * y + z * z)
    return quaternion_matrix(w / n, x / n, y / n, z / n)


def random_inertia(rng, mass, size):
    """Central inertia of a box with half-sides in [0.1, 1] size, turned to random axes, exactly
    symmetric (the triangle inequality holds with a margin of 2 min(side)^2 m / 3)."""
    a, b, c = (rng.uniform(0.1, 1.0) * size for _ in range(3))
    d = [mass * (b * b + c * c) / 3, mass * (a * a + c * c) / 3, mass * (a * a + b * b) / 3]
    r = random_rotation(rng)
    full = [[sum(r[i][k] * d[k] * r[j][k] for k in range(3)) for j in range(3)] for i in range(3)]
    return [[(full[i][j] + full[j][i]) / 2 for j in range(3)] for i in range(3)]


# ---------------------------------------------------------------- the model in mpmath
class Model:
    """Bodies in index order (parents first), one coordinate per body; every float exact."""

    def __init__(self, bodies, gravity):
        self.n = len(bodies)
        self.b = []
        for body in bodies:
            a = [mpf(t) for t in body["axis"]]
            self.b.append(dict(
                parent=body["parent"], type=body["type"], axis=scl(1 / norm(a), a),
                r_pj=[[mpf(body["rotation"][3 * i + j]) for j in range(3)] for i in range(3)],
                t=[mpf(t) for t in body["translation"]], m=mpf(body["mass"]),
                c=[mpf(t) for t in body["com"]],
                inertia=[[mpf(body["inertia"][3 * i + j]) for j in range(3)] for i in range(3)]))
        self.g = [mpf(t) for t in gravity]

    def path(self, body):
        out = []
        while body is not None:
            out.append(body)
            body = self.b[body]["parent"]
        return out[::-1]

    def poses(self, q):
        """Per body: R_WB, o_B, the joint's world axis; q as mpf."""
        out = []
        for i, b in enumerate(self.b):
            if b["parent"] is None:
                r_p, o_p = eye(), [mpf(0)] * 3
            else:
                r_p, o_p = out[b["parent"]][0], out[b["parent"]][1]
            r_j = mm(r_p, b["r_pj"])
            o = add(o_p, mv(r_p, b["t"]))
            ax = mv(r_j, b["axis"])
            if b["type"] == "revolute":
                r = mm(r_j, rodrigues(b["axis"], q[i]))
            else:
                r, o = r_j, add(o, scl(q[i], ax))
            out.append((r, o, ax))
        return out

    def rnea(self, q, qd, qdd, accelerations=False):
        """tau at exact doubles q, q-dot, q-ddot (and each body's a_C when asked)."""
        q, qd, qdd = ([mpf(t) for t in v] for v in (q, qd, qdd))
        pose = self.poses(q)
        st = []
        z = [mpf(0)] * 3
        for i, b in enumerate(self.b):
            w_p, wd_p, a_p, o_p = (z, z, z, z) if b["parent"] is None else st[b["parent"]][:4]
            _, o, ax = pose[i]
            r = sub(o, o_p)
            a = add(a_p, add(cross(wd_p, r), cross(w_p, cross(w_p, r))))
            if b["type"] == "revolute":
                w = add(w_p, scl(qd[i], ax))
                wd = add(wd_p, add(cross(w_p, scl(qd[i], ax)), scl(qdd[i], ax)))
            else:
                w, wd = w_p, wd_p
                a = add(a, add(scl(2 * qd[i], cross(w_p, ax)), scl(qdd[i], ax)))
            st.append((w, wd, a, o))
        force, moment, a_c = [], [], []
        for i, b in enumerate(self.b):
            w, wd, a, _ = st[i]
            r_b = pose[i][0]
            c = mv(r_b, b["c"])
            acc = add(a, add(cross(wd, c), cross(w, cross(w, c))))
            a_c.append(acc)
            inertia = mm(r_b, mm(b["inertia"], tr(r_b)))
            f = scl(b["m"], sub(acc, self.g))
            force.append(f)
            moment.append(add(add(mv(inertia, wd), cross(w, mv(inertia, w))), cross(c, f)))
        tau = [mpf(0)] * self.n
        for i in reversed(range(self.n)):
            ax = pose[i][2]
            tau[i] = dot(ax, moment[i]) if self.b[i]["type"] == "revolute" else dot(ax, force[i])
            p = self.b[i]["parent"]
            if p is not None:
                force[p] = add(force[p], force[i])
                moment[p] = add(moment[p], add(moment[i], cross(sub(st[i][3], st[p][3]), force[i])))
        return (tau, a_c) if accelerations else tau

    def jacobians(self, q, body, pose=None):
        """The angular and centre-of-mass Jacobian columns of `body` (zero off its path), from
        the forward kinematics alone."""
        pose = pose or self.poses(q)
        r_b, o_b, _ = pose[body]
        x = add(o_b, mv(r_b, self.b[body]["c"]))
        on_path = set(self.path(body))
        jw, jv = [], []
        for k in range(self.n):
            ax, o_k = pose[k][2], pose[k][1]
            if k not in on_path:
                jw.append([mpf(0)] * 3)
                jv.append([mpf(0)] * 3)
            elif self.b[k]["type"] == "revolute":
                jw.append(ax)
                jv.append(cross(ax, sub(x, o_k)))
            else:
                jw.append([mpf(0)] * 3)
                jv.append(ax)
        return jw, jv, x

    def mass_matrix(self, q):
        pose = self.poses(q)
        a = [[mpf(0)] * self.n for _ in range(self.n)]
        for i, b in enumerate(self.b):
            jw, jv, _ = self.jacobians(q, i, pose)
            inertia = mm(pose[i][0], mm(b["inertia"], tr(pose[i][0])))
            for k in range(self.n):
                iw = mv(inertia, jw[k])
                for l in range(self.n):
                    a[k][l] += b["m"] * dot(jv[k], jv[l]) + dot(jw[l], iw)
        return a

    def potential(self, q):
        pose = self.poses(q)
        return -sum(b["m"] * dot(self.g, add(pose[i][1], mv(pose[i][0], b["c"]))) for i, b in enumerate(self.b))

    def lagrange(self, q, qd, qdd):
        """tau from Lagrange's equations with A(q) from the Jacobians (validation)."""
        q, qd, qdd = ([mpf(t) for t in v] for v in (q, qd, qdd))
        n = self.n
        a = self.mass_matrix(q)
        tau = [sum(a[k][l] * qdd[l] for l in range(n)) for k in range(n)]
        if any(qd):
            for k in range(n):
                tau[k] += mp.diff(lambda e: sum(self.mass_matrix([q[i] + e * qd[i] for i in range(n)])[k][l] * qd[l]
                                                for l in range(n)), 0)
        for k in range(n):
            def lag(e, k=k):
                qq = [q[i] + (e if i == k else 0) for i in range(n)]
                t = 0
                if any(qd):
                    am = self.mass_matrix(qq)
                    t = sum(qd[i] * am[i][j] * qd[j] for i in range(n) for j in range(n)) / 2
                return t - self.potential(qq)
            tau[k] -= mp.diff(lag, 0)
        return tau


# ---------------------------------------------------------------- the family
def null_space(rows, p_cols):
    """Orthonormal basis of the null space of the exact matrix `rows` restricted to the
    columns `p_cols`, from the eigenvectors of its Gram matrix with eigenvalue ~0."""
    m = mp.matrix([[r[k] for k in p_cols] for r in rows])
    e, v = mp.eigsy(m.T * m)
    e = [e[j] for j in range(len(p_cols))]
    top = max(abs(x) for x in e)
    return [[v[i, j] for i in range(len(p_cols))] for j in range(len(e)) if abs(e[j]) < mpf(10) ** -40 * top]


def draw(case, attempt):
    rng = random.Random(SEED + 1000 * case + attempt)
    chain = case % 2 == 0
    group = (case // 2) % 2 == 0
    while True:
        n = rng.randint(3, 8) if chain else rng.randint(5, 8)
        if n == 3 and not group:
            continue
        parents = [None] + [i - 1 if chain else rng.randrange(i) for i in range(1, n)]
        depth = [0] * n
        for i in range(1, n):
            depth[i] = depth[parents[i]] + 1
        need = 3 if n == 3 else 4
        candidates = [i for i in range(n) if depth[i] + 1 >= need]
        if candidates:
            break
    heavy = rng.choice(candidates)
    path = []
    b = heavy
    while b is not None:
        path.append(b)
        b = parents[b]
    path.reverse()
    members = []
    if group:
        size = min(4, len(path))
        start = rng.randrange(len(path) - size + 1)
        members = path[start:start + size]
        prismatic_member = rng.choice(members) if size == 4 and rng.random() < 0.5 else None
    bodies = []
    group_dir = {}  # body -> the group direction in the body frame (exact)
    spread = rng.uniform(0.0, 4.0)
    for i in range(n):
        quat = rng.choice(TETRAHEDRAL)
        rot = quaternion_matrix(*quat)
        length = 10 ** rng.uniform(-1.0, 0.5)
        d = [rng.gauss(0, 1) for _ in range(3)]
        dn = math.sqrt(sum(t * t for t in d))
        translation = [length * t / dn for t in d]
        if i in members:
            if members.index(i) == 0:
                g_j = exact_unit_axis(rng, zero=rng.randrange(3))
            else:  # R_PJ^T g_B(parent): a signed permutation, exact
                g_p = group_dir[parents[i]]
                g_j = [sum(rot[k][j] * g_p[k] for k in range(3)) + 0.0 for j in range(3)]
            group_dir[i] = g_j
            if i == prismatic_member:  # along the coordinate axis where g_J has its zero
                kind, axis = "prismatic", [1.0 if t == 0.0 else 0.0 for t in g_j]
            else:
                kind, axis = "revolute", g_j
        else:
            kind = "prismatic" if rng.random() < 0.3 else "revolute"
            axis = coordinate_axis(rng) if rng.random() < 0.25 else exact_unit_axis(rng)
        assert builder_keeps(axis) and unit_defect(axis) < Fraction(1, 2**66)
        mass = 10 ** rng.uniform(-spread / 2, spread / 2)
        bodies.append(dict(parent=parents[i], type=kind, axis=axis, quaternion=list(quat),
                           rotation=[t for row in rot for t in row], translation=translation,
                           mass=mass, com=[rng.uniform(-length, length) for _ in range(3)],
                           size=max(length, 0.05)))
    light = max(b["mass"] for i, b in enumerate(bodies) if i != heavy)
    bodies[heavy]["mass"] = light * 10 ** rng.uniform(4.0, 8.0)
    for b in bodies:
        inertia = random_inertia(rng, b["mass"], b.pop("size"))
        b["inertia"] = [t for row in inertia for t in row]
    q = [rng.uniform(-3.1, 3.1) if b["type"] == "revolute" else rng.uniform(-0.5, 0.5) for b in bodies]
    q_dot = [0.0] * n
    if rng.random() < 0.5:
        sigma = 10 ** rng.uniform(-2.0, 0.0)
        q_dot = [rng.uniform(-1.0, 1.0) * sigma for _ in range(n)]
    gravity = [0.0, 0.0, 0.0]
    if rng.random() < 0.5:
        d = [rng.gauss(0, 1) for _ in range(3)]
        dn = math.sqrt(sum(t * t for t in d))
        gravity = [9.81 * t / dn for t in d]
    model = Model(bodies, gravity)
    qm = [mpf(t) for t in q]
    jw, jv, _ = model.jacobians(qm, heavy)
    angular = [[col[r] for col in jw] for r in range(3)]
    linear = [[col[r] for col in jv] for r in range(3)]
    basis = null_space(angular + linear, path)
    kind = "spatial 6 x p"
    if not basis:
        basis = null_space(linear, path)
        kind = "point 3 x p"
    assert basis, "the point Jacobian has a null space on paths of 4 joints or planar groups"
    coefficients = [mpf(rng.gauss(0, 1)) for _ in basis]
    v = [sum(c * vec[j] for c, vec in zip(coefficients, basis)) for j in range(len(path))]
    big = max(abs(t) for t in v)
    s = 10 ** rng.uniform(2.0, 8.0)
    rho = 10 ** rng.uniform(-3.0, -1.0)
    q_ddot = [rng.uniform(-1.0, 1.0) * rho for _ in range(n)]
    for j, k in enumerate(path):
        q_ddot[k] = float(mpf(s) * v[j] / big + mpf(q_ddot[k]))
    return dict(chain=chain, heavy=heavy, path=path, members=members, kind=kind, s=s, bodies=bodies, q=q,
                q_dot=q_dot, q_ddot=q_ddot, gravity=gravity, model=model)


def cancellation(case):
    model, heavy = case["model"], case["heavy"]
    _, a_c = model.rnea(case["q"], case["q_dot"], case["q_ddot"], accelerations=True)
    _, jv, _ = model.jacobians([mpf(t) for t in case["q"]], heavy)
    terms = sum(norm(jv[k]) * abs(mpf(case["q_ddot"][k])) for k in range(model.n))
    return terms / norm(a_c[heavy])


# ---------------------------------------------------------------- validation
def closed_forms():
    """Worst relative errors of the recursion against a double pendulum and a cart-pole."""
    rng = random.Random(SEED - 1)
    g = 9.81
    worst = {"double pendulum": mpf(0), "cart-pole": mpf(0)}

    def body(parent, kind, axis, translation, mass, com):
        return dict(parent=parent, type=kind, axis=axis, rotation=[1.0, 0, 0, 0, 1.0, 0, 0, 0, 1.0],
                    translation=translation, mass=mass, com=com, inertia=[0.0] * 9)

    for _ in range(20):
        m1, m2, l1, l2 = (rng.uniform(0.1, 10.0) for _ in range(4))
        q, qd, qdd = ([rng.gauss(0, 1) for _ in range(2)] for _ in range(3))
        model = Model([body(None, "revolute", [0.0, 1.0, 0.0], [0.0] * 3, m1, [0.0, 0.0, -l1]),
                       body(0, "revolute", [0.0, 1.0, 0.0], [0.0, 0.0, -l1], m2, [0.0, 0.0, -l2])],
                      [0.0, 0.0, -g])
        tau = model.rnea(q, qd, qdd)
        m1, m2, l1, l2, gg = map(mpf, (m1, m2, l1, l2, g))
        (q1, q2), (d1, d2), (a1, a2) = ([mpf(t) for t in v] for v in (q, qd, qdd))
        a11 = m1 * l1**2 + m2 * (l1**2 + l2**2 + 2 * l1 * l2 * mp.cos(q2))
        a12 = m2 * (l2**2 + l1 * l2 * mp.cos(q2))
        a22 = m2 * l2**2
        h1 = -m2 * l1 * l2 * mp.sin(q2) * (2 * d1 * d2 + d2**2) + (m1 + m2) * gg * l1 * mp.sin(q1) \
            + m2 * gg * l2 * mp.sin(q1 + q2)
        h2 = m2 * l1 * l2 * mp.sin(q2) * d1**2 + m2 * gg * l2 * mp.sin(q1 + q2)
        exact = [a11 * a1 + a12 * a2 + h1, a12 * a1 + a22 * a2 + h2]
        err = max(abs(t - e) for t, e in zip(tau, exact)) / max(abs(e) for e in exact)
        worst["double pendulum"] = max(worst["double pendulum"], err)
    for _ in range(20):
        mc, mpend, l = (rng.uniform(0.1, 10.0) for _ in range(3))
        q, qd, qdd = ([rng.gauss(0, 1) for _ in range(2)] for _ in range(3))
        model = Model([body(None, "prismatic", [1.0, 0.0, 0.0], [0.0] * 3, mc, [0.0] * 3),
                       body(0, "revolute", [0.0, 1.0, 0.0], [0.0] * 3, mpend, [0.0, 0.0, -l])],
                      [0.0, 0.0, -g])
        tau = model.rnea(q, qd, qdd)
        mc, mpend, l, gg = map(mpf, (mc, mpend, l, g))
        th, dth = mpf(q[1]), mpf(qd[1])
        ax, ath = mpf(qdd[0]), mpf(qdd[1])
        # pendulum bob at (x - l sin th, -l cos th) in the xz-plane (rotation about +y)
        force = (mc + mpend) * ax - mpend * l * mp.cos(th) * ath + mpend * l * mp.sin(th) * dth**2
        torque = mpend * l**2 * ath - mpend * l * mp.cos(th) * ax + mpend * gg * l * mp.sin(th)
        err = max(abs(tau[0] - force) / abs(force), abs(tau[1] - torque) / abs(torque))
        worst["cart-pole"] = max(worst["cart-pole"], err)
    return worst


def fmt(x):
    return repr(float(x))


def main():
    mp.mp.dps = WORK_DIGITS
    print(f"# tools/dynamics_cancellation_reference.py: mpmath {mp.__version__}, python {platform.python_version()}")
    print(f"# {CASES} cases, seed {SEED}, {DIGITS} digits; per case: structure, joints (R revolute, P prismatic,"
          " * in the planar group), heavy body, heavy/light mass ratio and the masses' span,")
    print("# null space used, s, q-dot, gravity, exact cancellation sum|J_k||q-ddot_k| / |a_C|,"
          " max|tau|, and the validation residuals")
    for name, err in closed_forms().items():
        print(f"validation: {name:16s} worst relative error {mp.nstr(err, 3)} (20 random cases)")
    cases, worst_lagrange, worst_precision, redraws = [], mpf(0), mpf(0), 0
    for i in range(CASES):
        for attempt in range(50):
            case = draw(i, attempt)
            ratio = cancellation(case)
            if ratio >= 1e4:
                break
            redraws += 1
        else:
            sys.exit(f"case {i}: no draw cancels")
        model = case["model"]
        tau = model.rnea(case["q"], case["q_dot"], case["q_ddot"])
        lag = model.lagrange(case["q"], case["q_dot"], case["q_ddot"])
        scale = max(abs(t) for t in tau)
        lag_err = max(abs(a - b) for a, b in zip(tau, lag)) / scale
        with mp.workdps(CHECK_DIGITS):
            tau80 = model.rnea(case["q"], case["q_dot"], case["q_ddot"])
            prec_err = max(abs(a - b) for a, b in zip(tau, tau80)) / scale
        worst_lagrange, worst_precision = max(worst_lagrange, lag_err), max(worst_precision, prec_err)
        bodies = case["bodies"]
        masses = [b["mass"] for b in bodies]
        light = max(m for k, m in enumerate(masses) if k != case["heavy"])
        joints = "".join(("R" if b["type"] == "revolute" else "P") + ("*" if k in case["members"] else "")
                         for k, b in enumerate(bodies))
        print(f"case{i:02d} {'chain' if case['chain'] else 'tree '} n={len(bodies)} {joints:12s} heavy={case['heavy']}"
              f" (path {len(case['path'])}) x{masses[case['heavy']] / light:.1e} span {max(masses) / min(masses):.1e}"
              f" {case['kind']:13s} s={case['s']:.1e} q_dot={'0' if not any(case['q_dot']) else 'rand'}"
              f" g={'on ' if any(case['gravity']) else 'off'} cancel {mp.nstr(ratio, 2):8s}"
              f" max|tau| {mp.nstr(scale, 3):9s} lagrange {mp.nstr(lag_err, 2)} dps{CHECK_DIGITS} {mp.nstr(prec_err, 2)}")
        for b in bodies:
            b["axis"] = [fmt(t) for t in b["axis"]]
            for key in ("quaternion", "rotation", "translation", "com", "inertia"):
                b[key] = [fmt(t) for t in b[key]]
            b["mass"] = fmt(b["mass"])
        his = [float(mp.nstr(t, DIGITS, strip_zeros=False)) for t in tau]
        cases.append(dict(
            name=f"case{i:02d}", structure="chain" if case["chain"] else "tree", heavy=case["heavy"],
            null_space=case["kind"], planar_group=case["members"], scale=fmt(case["s"]),
            cancellation=float(ratio), bodies=bodies, gravity=[fmt(t) for t in case["gravity"]],
            q=[fmt(t) for t in case["q"]], q_dot=[fmt(t) for t in case["q_dot"]],
            q_ddot=[fmt(t) for t in case["q_ddot"]], tau=[mp.nstr(t, DIGITS, strip_zeros=False) for t in tau],
            tau_hi=[repr(h) for h in his], tau_lo=[fmt(t - mpf(h)) for t, h in zip(tau, his)]))
    print(f"validation: Lagrange's equations (A from the Jacobians) vs the recursion, worst"
          f" |difference|/max|tau| over the cases {mp.nstr(worst_lagrange, 3)}")
    print(f"validation: {WORK_DIGITS} vs {CHECK_DIGITS} digits, worst |difference|/max|tau| {mp.nstr(worst_precision, 3)}")
    print(f"redraws for a cancellation ratio below 1e4: {redraws}")
    path = os.path.join(HERE, "dynamics_cancellation_reference.json")
    with open(path, "w") as f:
        json.dump(dict(generator="tools/dynamics_cancellation_reference.py", digits=DIGITS, seed=SEED, cases=cases),
                  f, indent=1)
        f.write("\n")
    print(f"# wrote tools/dynamics_cancellation_reference.json: {os.path.getsize(path)} bytes")


if __name__ == "__main__":
    main()
