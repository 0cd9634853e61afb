#!/usr/bin/env python3
"""Times Pinocchio's mass matrix (crba) on the 44-DOF humanoid-like tree of benches/benches/mass.rs.

Peer for the `mass_matrix_crba_44dof` criterion bench (forward kinematics + composite-rigid-body
mass matrix). The tree, built identically in the Rust bench: a free base and five revolute
chains of 7, 7, 8, 8, 8 joints (axis x, y, z cycling with (branch + joint) mod 3; the first
joint of branch b at (0.1 b − 0.2, 0, 0) from the base, the others 0.3 m below their parent);
every body, the base included, a 2 kg box 0.1 × 0.1 × 0.3 m with its centre 0.15 m below the
joint. Pinocchio's free flyer has 7 coordinates (quaternion) and 6 velocities, so nv = 44 as in
mechanica (whose free joint uses a rotation vector). pin.crba runs its own forward pass, so
both sides include forward kinematics. Timed from Python with time.perf_counter (the Python
call overhead, ~0.1-0.3 us, is included, as in a Python user's loop); best of 7 repeats of 20000
calls.

Run:  pip install pin && python3 tools/mass_pinocchio_bench.py > tools/mass_pinocchio_bench.out
"""
import platform
import time

import numpy as np
import pinocchio as pin


def humanoid():
    model = pin.Model()
    box = pin.Inertia.FromBox(2.0, 0.1, 0.1, 0.3)
    below = pin.SE3(np.eye(3), np.array([0.0, 0.0, -0.15]))
    body = box.se3Action(below)
    base = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "base")
    model.appendBodyToJoint(base, body, pin.SE3.Identity())
    joints = [pin.JointModelRX, pin.JointModelRY, pin.JointModelRZ]
    for branch, length in enumerate([7, 7, 8, 8, 8]):
        parent = base
        for j in range(length):
            offset = [0.1 * branch - 0.2, 0.0, 0.0] if j == 0 else [0.0, 0.0, -0.3]
            jm = joints[(branch + j) % 3]()
            parent = model.addJoint(parent, jm, pin.SE3(np.eye(3), np.array(offset)), f"b{branch}j{j}")
            model.appendBodyToJoint(parent, body, pin.SE3.Identity())
    return model


def main():
    model = humanoid()
    data = model.createData()
    q = pin.neutral(model)
    for k in range(7, model.nq):
        q[k] = 0.1 * np.sin(k)
    calls = 20000
    best = float("inf")
    for _ in range(7):
        t0 = time.perf_counter()
        for _ in range(calls):
            pin.crba(model, data, q)
        best = min(best, (time.perf_counter() - t0) / calls)
    print(f"# pinocchio {pin.__version__}, numpy {np.__version__}, python {platform.python_version()}, {platform.machine()}")
    print(f"# model: nq = {model.nq}, nv = {model.nv}, bodies = {model.njoints - 1}, total mass = {pin.computeTotalMass(model):.1f} kg")
    print(f"crba_44dof_us {best * 1e6:.3f}")


if __name__ == "__main__":
    main()
