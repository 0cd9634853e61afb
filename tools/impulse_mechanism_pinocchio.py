"""Reference for mechanica-impulse's multi-contact impacts: Pinocchio's impulseDynamics.

The humanoid-like tree of benches/benches/impulse.rs and crates/mechanica-impulse/tests/
mechanism.rs (free torso, head, four limbs of three spherical joints: 45 DOF), at the
configuration with every rotation at its reference (all rotation vectors zero, torso origin at
(0, 1, 0)), moving with q̇_k = 0.3 cos(1.3 k) except q̇_1 = -2 (falling), lands with both hands and
both feet (4 contacts, normal +y).

Pinocchio's impulseDynamics with 3-D rigid contacts and restitution r = 0 stops every contact
point (v⁺ = 0). That is mechanica's simultaneous model with e = 0 and f = +inf whenever all
normal impulses come out positive, which the script checks. It prints Δq̇ (45 numbers) and the
contact impulses; the output is committed as tools/impulse_mechanism_pinocchio.out and read by
the Rust test `pinocchio_impulse_dynamics_reference`. It also times impulseDynamics.

The `residual` line is the largest contact-point speed after the impact (m/s).

Run: python3 tools/impulse_mechanism_pinocchio.py > tools/impulse_mechanism_pinocchio.out
(Pinocchio 4.1.0, numpy 2.4.6 produced the committed file.)
"""

import time

import numpy as np
import pinocchio as pin


def link(mass, length):
    r = 0.05
    ia, it = 0.5 * mass * r * r, mass * (3 * r * r + length * length) / 12.0
    return pin.Inertia(mass, np.array([0.0, -0.5 * length, 0.0]), np.diag([it, ia, it]))


def humanoid():
    model = pin.Model()
    torso = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "torso")
    model.appendBodyToJoint(torso, pin.Inertia(30.0, np.zeros(3), np.diag([1.2, 0.6, 1.0])), pin.SE3.Identity())
    head = model.addJoint(torso, pin.JointModelSpherical(), pin.SE3(np.eye(3), np.array([0.0, 0.3, 0.0])), "head")
    model.appendBodyToJoint(head, pin.Inertia(5.0, np.array([0.0, 0.12, 0.0]), np.eye(3) * 0.03), pin.SE3.Identity())
    ends = []
    limbs = [
        (0.2, 0.25, [0.3, 0.28, 0.08], [2.5, 1.5, 0.5]),
        (-0.2, 0.25, [0.3, 0.28, 0.08], [2.5, 1.5, 0.5]),
        (0.1, -0.3, [0.45, 0.42, 0.1], [8.0, 4.0, 1.2]),
        (-0.1, -0.3, [0.45, 0.42, 0.1], [8.0, 4.0, 1.2]),
    ]
    for i, (x, y, lengths, masses) in enumerate(limbs):
        parent = torso
        offset = np.array([x, y, 0.0])
        for k in range(3):
            parent = model.addJoint(parent, pin.JointModelSpherical(), pin.SE3(np.eye(3), offset), f"limb{i}_{k}")
            model.appendBodyToJoint(parent, link(masses[k], lengths[k]), pin.SE3.Identity())
            offset = np.array([0.0, -lengths[k], 0.0])
        ends.append((parent, offset))
    return model, ends


def main():
    model, ends = humanoid()
    data = model.createData()
    q = pin.neutral(model)
    q[1] = 1.0
    nv = model.nv
    v = np.array([0.3 * np.cos(1.3 * k) for k in range(nv)])
    v[1] = -2.0
    contacts = [
        pin.RigidConstraintModel(
            pin.ContactType.CONTACT_3D, model, joint, pin.SE3(np.eye(3), p), pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        )
        for joint, p in ends
    ]
    contacts = pin.StdVec_RigidConstraintModel(contacts)
    contact_datas = pin.StdVec_RigidConstraintData([c.createData() for c in contacts])
    pin.initConstraintDynamics(model, data, contacts, contact_datas)
    settings = pin.ProximalSettings(1e-14, 1e-12, 1)
    dq = pin.impulseDynamics(model, data, q, v, contacts, contact_datas, 0.0, settings).copy() - v
    impulses = data.impulse_c.copy().reshape(-1, 3)
    # Residual: the largest contact-point speed after the impact (m/s).
    v_after = v + dq
    pin.forwardKinematics(model, data, q, v_after)
    residual = 0.0
    for joint, p in ends:
        twist = pin.getVelocity(model, data, joint, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        arm = data.oMi[joint].rotation @ p
        residual = max(residual, np.linalg.norm(twist.linear + np.cross(twist.angular, arm)))
    assert np.all(impulses[:, 1] > 0.0), "every normal impulse must be positive"
    runs = 2000
    start = time.perf_counter()
    for _ in range(runs):
        pin.impulseDynamics(model, data, q, v, contacts, contact_datas, 0.0, settings)
    micro = (time.perf_counter() - start) / runs * 1e6
    print(f"# pinocchio {pin.__version__}; nv {nv}; impulseDynamics {micro:.1f} us per call (Python loop)")
    print(f"residual {residual:.3e}")
    print("# impulses (world, per contact):")
    for row in impulses:
        print("#", " ".join(f"{x:.17e}" for x in row))
    print("delta_q_dot", " ".join(f"{x:.17e}" for x in dq))


if __name__ == "__main__":
    main()
