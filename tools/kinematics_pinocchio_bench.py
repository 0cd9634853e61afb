#!/usr/bin/env python3
"""Times Pinocchio's forward kinematics on the same models as benches/benches/kinematics.rs.

Models (built identically in the Rust bench):
  arm7        7 revolute joints in a chain, axes z y z y z y z, links 0.3 m along z.
  humanoid34  pinocchio.buildSampleModelHumanoid(): free flyer + 28 revolute (nv = 34).
  humanoid44  free flyer + 43 revolute joints (nv = 49): legs 2x6, chest 3, head 2,
              arms 2x7, three 2-joint fingers per hand.

For each: forwardKinematics(q) and computeJointJacobians(q) (FK plus every joint's world
Jacobian), timed from Python with time.perf_counter, so the Python call overhead
(~0.1-0.3 us) is included, as in a Python user's loop. Reports the best of 7 repeats of
20000 calls, in ns per call.

Run:  pip install pin && python3 tools/kinematics_pinocchio_bench.py > tools/kinematics_pinocchio_bench.txt
"""
import platform
import time

import numpy as np
import pinocchio as pin


def chain(model, parent, axes, name, offset):
    for i, ax in enumerate(axes):
        jm = {"x": pin.JointModelRX(), "y": pin.JointModelRY(), "z": pin.JointModelRZ()}[ax]
        placement = pin.SE3(np.eye(3), np.array(offset if i == 0 else [0.0, 0.0, -0.25]))
        parent = model.addJoint(parent, jm, placement, f"{name}{i}")
    return parent


def arm7():
    m = pin.Model()
    parent = 0
    for i, ax in enumerate("zyzyzyz"):
        jm = {"y": pin.JointModelRY(), "z": pin.JointModelRZ()}[ax]
        parent = m.addJoint(parent, jm, pin.SE3(np.eye(3), np.array([0.0, 0.0, 0.3])), f"j{i}")
    return m


def humanoid44():
    m = pin.Model()
    root = m.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root")
    chain(m, root, "xyzyxy", "rleg", [0.0, -0.1, -0.1])
    chain(m, root, "xyzyxy", "lleg", [0.0, 0.1, -0.1])
    chest = chain(m, root, "xyz", "chest", [0.0, 0.0, 0.1])
    chain(m, chest, "xy", "head", [0.0, 0.0, 0.3])
    for side, y in (("r", -0.2), ("l", 0.2)):
        hand = chain(m, chest, "xyzyxyz", side + "arm", [0.0, y, 0.25])
        for f in range(3):
            chain(m, hand, "yy", f"{side}finger{f}", [0.02 * f, 0.0, -0.05])
    return m


def bench(fn, calls=20000, repeats=7):
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(calls):
            fn()
        best = min(best, (time.perf_counter() - t0) / calls)
    return best * 1e9


def main():
    print(f"# pinocchio {pin.__version__}, numpy {np.__version__}, python {platform.python_version()}, {platform.machine()}")
    print("# model nq nv joints fk_ns fk_plus_joint_jacobians_ns")
    models = {"arm7": arm7(), "humanoid34": pin.buildSampleModelHumanoid(), "humanoid44": humanoid44()}
    rng = np.random.default_rng(1)
    for name, model in models.items():
        data = model.createData()
        q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq)) if model.nq else np.zeros(0)
        if name != "arm7":
            q[:3] = rng.uniform(-1, 1, 3)
        fk = bench(lambda: pin.forwardKinematics(model, data, q))
        jac = bench(lambda: pin.computeJointJacobians(model, data, q))
        print(f"{name} {model.nq} {model.nv} {model.njoints - 1} {fk:.0f} {jac:.0f}")


if __name__ == "__main__":
    main()
