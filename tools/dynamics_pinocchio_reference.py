#!/usr/bin/env python3
"""Reference data for mechanica-dynamics: Pinocchio's rnea, aba and crba on UR5, Panda and Talos.

Models (example-robot-data's URDFs, parsed by Pinocchio):
  ur5    ur_description/urdf/ur5_robot.urdf, fixed base, 6 revolute joints (nv = 6)
  panda  panda_description/urdf/panda.urdf, fixed base, 7 revolute + 2 prismatic finger joints
         (nv = 9)
  talos  talos_data/robots/talos_full_v2.urdf with a free flyer: the largest Talos tree
         (legs, torso, arms, head and both grippers with every gripper joint free: 44 revolute
         joints + the free flyer, nv = 50). Pinocchio parses the grippers' mimic tags as
         independent joints, and so does this file.

Writes tools/dynamics_pinocchio_reference.json (read by crates/mechanica-dynamics/tests/
pinocchio_reference.rs and benches/benches/dynamics.rs) and prints a summary (committed as
tools/dynamics_pinocchio_reference.out).

Model, in a neutral form (no URDF needed): one entry per Pinocchio joint, in Pinocchio's order,
which is parents first; entry k is mechanica body k.
  parent      index of the parent entry, or null for the root (attached to the base/world)
  type        "revolute" | "prismatic" (with "axis", unit, joint-frame components) | "free"
  rotation    R_PJ, row-major 3 x 3; translation p_PJ: the joint placement X_PJ in the parent
              body frame (Pinocchio's jointPlacements)
  mass, com   the body mass (kg) and centre of mass (m, body frame = Pinocchio's joint frame)
  inertia     central inertia tensor (kg m^2, body frame axes), row-major 3 x 3
Bodies attached by fixed URDF joints are already lumped into their parent by Pinocchio
(model.inertias); those inertias are written as they are. Gravity is Pinocchio's model.gravity.

Coordinates. mechanica's joints have nq = nv and q-dot = dq/dt (tree/joint.rs). The mapping:
  * revolute, prismatic: identical. A continuous joint (Pinocchio's (cos, sin), nq = 2) maps
    to the angle atan2(sin, cos); its velocity is the same.
  * free flyer. Pinocchio: q = (p, quaternion of R), v = (v_B, w_B), the body-frame linear
    velocity of the origin and angular velocity: p-dot = R v_B, R-dot = R [w_B]x, and
    a = dv/dt. mechanica: q = (p, phi) with R = R_ref exp(phi). Each state is written with
    phi = 0 and R_ref = R (the state's "base_rotation", row-major). At phi = 0 the right
    Jacobian of exp is J_r(0) = I, so the body angular velocity J_r(phi) phi-dot is phi-dot:
        q-dot = (R v_B, w_B, joints)                                   = T v,
    with T = blockdiag(R, I_3, I). Differentiating p-dot = R v_B gives p-ddot = R (a_B + w_B x
    v_B). For the rotation, w_B = J_r(phi) phi-dot gives w_B-dot = J_r phi-ddot + (dJ_r/dt)
    phi-dot; J_r(phi) = I - [phi]x / 2 + O(|phi|^2), so at phi = 0 the second term is
    -[phi-dot]x phi-dot / 2 = 0 and phi-ddot = w_B-dot = a_w. Hence
        q-ddot = T a + (R (w_B x v_B), 0, 0).
    Generalized forces follow from the virtual power tau_mech . q-dot = tau_pin . v for every
    v, i.e. tau_mech = T^-T tau_pin = T tau_pin (T is orthogonal): the base force R f_B in
    world axes, the body-frame torque n_B unchanged. The kinetic energy v^T M v / 2 =
    q-dot^T A q-dot / 2 gives A = T M T^T.
  The script checks this mapping independently: Lagrange's equations in mechanica's
  coordinates, d/dt dL/dq-dot - dL/dq = tau, with L = T - U evaluated by Pinocchio
  (computeKineticEnergy, computePotentialEnergy) at mechanica coordinates converted back (for
  phi != 0: R = R_ref exp(phi), w_B = J_r(phi) phi-dot, v_B = R^T p-dot), differentiated by
  central differences; the summary prints the residual relative to |tau|.

States (per model, numpy seed 20240611 + model index): q uniform in [-pi, pi] (revolute),
[0, 0.04] m (prismatic), base position in [-1, 1]^3 m, base orientation a uniformly random
unit quaternion; v and a uniform in [-2, 2]; tau = rnea(q, v, b) for another random b uniform
in [-2, 2], so that aba's output (~ b) is of order one. Each state stores, in mechanica's
coordinates: q, v (= q-dot), a (= q-ddot), tau, rnea = rnea(q, v, a), aba = aba(q, v, tau),
crba = the mass matrix (row-major nv x nv, symmetric), and base_rotation for the free flyer.
Floats are written with Python's repr: the shortest string that reads back to the same double
(at most 17 significant digits).

Run:  pip install pin example-robot-data
      python3 tools/dynamics_pinocchio_reference.py > tools/dynamics_pinocchio_reference.out
"""

import json
import os
import platform
import sys

import numpy as np
import pinocchio as pin

STATES = 10
SEED = 20240611
MODELS = [
    ("ur5", "ur_description/urdf/ur5_robot.urdf", False),
    ("panda", "panda_description/urdf/panda.urdf", False),
    ("talos", "talos_data/robots/talos_full_v2.urdf", True),
]
HERE = os.path.dirname(os.path.abspath(__file__))


def robots_dir():
    """example-robot-data's robots/ directory inside the pip package's cmeel prefix."""
    path = os.path.normpath(os.path.join(os.path.dirname(pin.__file__), "..", "..", "..", "..", "share",
                                         "example-robot-data", "robots"))
    if not os.path.isdir(path):
        sys.exit(f"example-robot-data's robots/ not found at {path}: pip install example-robot-data")
    return path


def load(relative, free_flyer):
    path = os.path.join(robots_dir(), relative)
    if free_flyer:
        return pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer())
    return pin.buildModelFromUrdf(path)


def joint_kind(model, data, i):
    """(type, axis) of Pinocchio joint i in mechanica's terms, from its motion subspace."""
    joint = model.joints[i]
    name = joint.shortname()
    if name == "JointModelFreeFlyer":
        return "free", None
    if joint.nv != 1:
        raise SystemExit(f"joint {model.names[i]} ({name}) has no mechanica counterpart")
    s = np.array(data.joints[i].S).reshape(6)  # (linear; angular), joint frame
    linear, angular = s[:3], s[3:]
    if np.linalg.norm(angular) > 0.5 and np.linalg.norm(linear) < 1e-15:
        return "revolute", angular
    if np.linalg.norm(linear) > 0.5 and np.linalg.norm(angular) < 1e-15:
        return "prismatic", linear
    raise SystemExit(f"joint {model.names[i]} ({name}) is neither revolute nor prismatic")


def neutral_model(model):
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    joints = []
    for i in range(1, model.njoints):
        kind, axis = joint_kind(model, data, i)
        placement = model.jointPlacements[i]
        inertia = model.inertias[i]
        entry = {
            "name": model.names[i],
            "parent": None if model.parents[i] == 0 else int(model.parents[i]) - 1,
            "type": kind,
        }
        if axis is not None:
            entry["axis"] = floats(axis)
        entry.update({
            "rotation": floats(placement.rotation.reshape(9)),
            "translation": floats(placement.translation),
            "mass": float(inertia.mass),
            "com": floats(inertia.lever),
            "inertia": floats(inertia.inertia.reshape(9)),
        })
        joints.append(entry)
    return joints


def floats(values):
    return [float(x) for x in np.asarray(values).reshape(-1)]


class Coordinates:
    """Maps between Pinocchio's (q, v, a, tau) and mechanica's coordinates for one model."""

    def __init__(self, model):
        self.model = model
        self.free = [i for i in range(1, model.njoints) if model.joints[i].shortname() == "JointModelFreeFlyer"]
        if self.free and (self.free != [1] or model.parents[1] != 0):
            raise SystemExit("only a root free flyer is mapped")

    def base_rotation(self, q_pin):
        if not self.free:
            return None
        return pin.Quaternion(q_pin[3:7]).toRotationMatrix()

    def to_mechanica_q(self, q_pin):
        out = []
        for i in range(1, self.model.njoints):
            joint = self.model.joints[i]
            qi = q_pin[joint.idx_q:joint.idx_q + joint.nq]
            if i in self.free:
                out += list(qi[:3]) + [0.0, 0.0, 0.0]
            elif joint.nq == 2:
                out.append(np.arctan2(qi[1], qi[0]))
            else:
                out += list(qi)
        return np.array(out)

    def transform(self, q_pin):
        """T with q-dot = T v (orthogonal)."""
        t = np.eye(self.model.nv)
        r = self.base_rotation(q_pin)
        if r is not None:
            t[0:3, 0:3] = r
        return t

    def velocity(self, q_pin, v):
        return self.transform(q_pin) @ v

    def acceleration(self, q_pin, v, a):
        out = self.transform(q_pin) @ a
        r = self.base_rotation(q_pin)
        if r is not None:
            out[0:3] += r @ np.cross(v[3:6], v[0:3])
        return out

    def force(self, q_pin, tau):
        return self.transform(q_pin) @ tau

    def mass_matrix(self, q_pin, m):
        t = self.transform(q_pin)
        return t @ m @ t.T

    def to_pinocchio(self, q_mech, qd_mech, r_ref):
        """Pinocchio's (q, v) at mechanica coordinates with any phi (R = R_ref exp(phi))."""
        q = pin.neutral(self.model)
        v = np.zeros(self.model.nv)
        for i in range(1, self.model.njoints):
            joint = self.model.joints[i]
            iq, iv = joint.idx_q, joint.idx_v
            if i in self.free:
                phi, phi_dot = q_mech[iv + 3:iv + 6], qd_mech[iv + 3:iv + 6]
                r = r_ref @ pin.exp3(phi)
                q[iq:iq + 3] = q_mech[iv:iv + 3]
                q[iq + 3:iq + 7] = pin.Quaternion(r).coeffs()
                v[iv:iv + 3] = r.T @ qd_mech[iv:iv + 3]
                v[iv + 3:iv + 6] = right_jacobian(phi) @ phi_dot
            elif joint.nq == 2:
                q[iq], q[iq + 1] = np.cos(q_mech[iv]), np.sin(q_mech[iv])
                v[iv] = qd_mech[iv]
            else:
                q[iq] = q_mech[iv]
                v[iv] = qd_mech[iv]
        return q, v


def right_jacobian(phi):
    """J_r(phi) = I - (1 - cos t)/t^2 [phi]x + (t - sin t)/t^3 [phi]x^2, t = |phi|."""
    t = np.linalg.norm(phi)
    k = pin.skew(phi)
    if t < 1e-6:
        return np.eye(3) - 0.5 * k + k @ k / 6.0
    return np.eye(3) - (1.0 - np.cos(t)) / t**2 * k + (t - np.sin(t)) / t**3 * k @ k


def random_state(model, rng):
    q = pin.neutral(model)
    for i in range(1, model.njoints):
        joint = model.joints[i]
        iq = joint.idx_q
        name = joint.shortname()
        if name == "JointModelFreeFlyer":
            q[iq:iq + 3] = rng.uniform(-1.0, 1.0, 3)
            quat = rng.normal(size=4)
            q[iq + 3:iq + 7] = quat / np.linalg.norm(quat)
        elif joint.nq == 2:
            angle = rng.uniform(-np.pi, np.pi)
            q[iq], q[iq + 1] = np.cos(angle), np.sin(angle)
        elif name.startswith("JointModelP"):
            q[iq] = rng.uniform(0.0, 0.04)
        else:
            q[iq] = rng.uniform(-np.pi, np.pi)
    v = rng.uniform(-2.0, 2.0, model.nv)
    a = rng.uniform(-2.0, 2.0, model.nv)
    b = rng.uniform(-2.0, 2.0, model.nv)
    return q, v, a, b


def symmetric(m):
    upper = np.triu(m)
    return upper + np.triu(m, 1).T


def lagrange_residual(model, coords, q_pin, v, a, tau_mech):
    """|d/dt dL/dq-dot - dL/dq - tau|_inf / |tau|_inf in mechanica's coordinates by central
    differences of Pinocchio's energies (an independent check of the mapping)."""
    data = model.createData()
    r_ref = coords.base_rotation(q_pin)
    r_ref = np.eye(3) if r_ref is None else r_ref
    q0 = coords.to_mechanica_q(q_pin)
    qd0 = coords.velocity(q_pin, v)
    qdd0 = coords.acceleration(q_pin, v, a)
    n = model.nv

    def lagrangian(qm, qdm):
        qp, vp = coords.to_pinocchio(qm, qdm, r_ref)
        kinetic = pin.computeKineticEnergy(model, data, qp, vp)
        return kinetic - pin.computePotentialEnergy(model, data, qp)

    def momentum(qm, qdm):
        # L is quadratic in q-dot: central differences are exact up to rounding.
        out = np.zeros(n)
        for k in range(n):
            e = np.zeros(n)
            e[k] = 1.0
            out[k] = (lagrangian(qm, qdm + e) - lagrangian(qm, qdm - e)) / 2.0
        return out

    h = 1e-5
    dp_dt = (momentum(q0 + h * qd0 + 0.5 * h * h * qdd0, qd0 + h * qdd0)
             - momentum(q0 - h * qd0 + 0.5 * h * h * qdd0, qd0 - h * qdd0)) / (2.0 * h)
    dl_dq = np.zeros(n)
    for k in range(n):
        e = np.zeros(n)
        e[k] = h
        dl_dq[k] = (lagrangian(q0 + e, qd0) - lagrangian(q0 - e, qd0)) / (2.0 * h)
    return np.max(np.abs(dp_dt - dl_dq - tau_mech)) / np.max(np.abs(tau_mech))


def states(model, coords, rng, checks):
    data = model.createData()
    out = []
    worst_inverse = worst_lagrange = 0.0
    for s in range(STATES):
        q, v, a, b = random_state(model, rng)
        tau_rnea = pin.rnea(model, data, q, v, a).copy()
        tau = pin.rnea(model, data, q, v, b).copy()
        a_aba = pin.aba(model, data, q, v, tau).copy()
        m = symmetric(pin.crba(model, data, q).copy())
        worst_inverse = max(worst_inverse, np.max(np.abs(a_aba - b)) / np.max(np.abs(b)))
        entry = {
            "q": floats(coords.to_mechanica_q(q)),
            "v": floats(coords.velocity(q, v)),
            "a": floats(coords.acceleration(q, v, a)),
            "tau": floats(coords.force(q, tau)),
            "rnea": floats(coords.force(q, tau_rnea)),
            "aba": floats(coords.acceleration(q, v, a_aba)),
            "crba": floats(coords.mass_matrix(q, m)),
        }
        r = coords.base_rotation(q)
        if r is not None:
            entry["base_rotation"] = floats(r.reshape(9))
        if s < checks:
            worst_lagrange = max(worst_lagrange,
                                 lagrange_residual(model, coords, q, v, a, np.array(entry["rnea"])))
        out.append(entry)
    return out, worst_inverse, worst_lagrange


def main():
    print(f"# tools/dynamics_pinocchio_reference.py: pinocchio {pin.__version__}, numpy {np.__version__}, "
          f"python {platform.python_version()}, {platform.machine()}")
    print(f"# {STATES} states per model, seed {SEED} + model index; JSON floats are shortest round-trip reprs")
    print("# lagrange: |d/dt dL/dq-dot - dL/dq - tau| / |tau| (inf-norms) in mechanica's coordinates, by")
    print("#   central differences of Pinocchio's energies, over the first 3 states: checks the mapping")
    print("# aba_vs_b: |aba(q, v, rnea(q, v, b)) - b| / |b| over all states (Pinocchio's own consistency)")
    print("# cond: 2-norm condition number of the mass matrix, min..max over the states")
    models = []
    for index, (name, relative, free_flyer) in enumerate(MODELS):
        model = load(relative, free_flyer)
        coords = Coordinates(model)
        rng = np.random.default_rng(SEED + index)
        entries, worst_inverse, worst_lagrange = states(model, coords, rng, checks=3)
        conds = [np.linalg.cond(np.array(e["crba"]).reshape(model.nv, model.nv)) for e in entries]
        models.append({
            "name": name,
            "urdf": relative,
            "free_flyer": free_flyer,
            "nv": model.nv,
            "gravity": floats(model.gravity.linear),
            "joints": neutral_model(model),
            "states": entries,
        })
        mass = sum(model.inertias[i].mass for i in range(1, model.njoints))
        print(f"{name:6s} urdf {relative} free_flyer {free_flyer} joints {model.njoints - 1} nq {model.nq} "
              f"nv {model.nv} mass {mass:.4f} kg lagrange {worst_lagrange:.1e} aba_vs_b {worst_inverse:.1e} "
              f"cond {min(conds):.2e}..{max(conds):.2e}")
    path = os.path.join(HERE, "dynamics_pinocchio_reference.json")
    document = {
        "generator": "tools/dynamics_pinocchio_reference.py",
        "pinocchio": pin.__version__,
        "seed": SEED,
        "models": models,
    }
    with open(path, "w") as f:
        json.dump(document, f, separators=(",", ":"))
        f.write("\n")
    print(f"# wrote {os.path.relpath(path, os.path.dirname(HERE))}: {os.path.getsize(path)} bytes")


if __name__ == "__main__":
    main()
