"""Every URDF robot of example-robot-data through `mechanica run`, against Pinocchio.

For each robot that mechanica accepts with its default options, at three seeded random
configurations (revolute joints uniform in their limits, or [-pi, pi] when unlimited; prismatic
joints in their limits), compares mechanica's mass matrix A(q) and gravity gradient
(`run URDF --q ... --matrices --json`: `mass_matrix`, `gradient`) with Pinocchio's `crba` and
`computeGeneralizedGravity` of `buildModelFromUrdf` (fixed base), coordinates matched by joint
name. Reports max |A - A_pin| / max |A_pin| and the same for the gradient, per robot, and the
refusals with their first line. Links without <inertial> whose mesh gives them mass in
mechanica (water density) are massless in Pinocchio; such robots are marked "mesh mass" and
their difference is not a disagreement.

Usage:  pip install pin example-robot-data
        python3 tools/urdf_pinocchio_sweep.py target/release/mechanica > tools/urdf_pinocchio_sweep.out
"""
import glob
import json
import math
import os
import subprocess
import sys

import numpy as np
import pinocchio as pin


def robots_dir():
    """The robots of the example-robot-data package: <prefix>/share/example-robot-data/robots,
    with <prefix> the cmeel.prefix that holds Pinocchio."""
    prefix = os.path.normpath(os.path.join(os.path.dirname(pin.__file__), '..', '..', '..', '..'))
    robots = os.path.join(prefix, 'share', 'example-robot-data', 'robots')
    if not os.path.isdir(robots):
        raise SystemExit(f'example-robot-data not found under {prefix}: pip install example-robot-data')
    return robots


def pinocchio_state(model, names, q_mech):
    """Pinocchio's q (continuous joints as cos, sin) for mechanica's joint angles by name."""
    q = pin.neutral(model)
    for name, value in zip(names, q_mech):
        joint = model.joints[model.getJointId(name)]
        if joint.nq == 2:
            q[joint.idx_q:joint.idx_q + 2] = [math.cos(value), math.sin(value)]
        else:
            q[joint.idx_q] = value
    return q


def compare(exe, urdf, rng):
    probe = subprocess.run([exe, 'run', urdf, '--json'], capture_output=True, text=True)
    if probe.returncode != 0:
        return None, (probe.stderr.strip().splitlines() or ['refused'])[0]
    model = pin.buildModelFromUrdf(urdf)
    data = model.createData()
    report = json.loads(probe.stdout)
    steps = {s['analysis']: s for s in report['steps']}
    names = steps['build']['coordinates']
    mesh_mass = any('mass properties from mesh' in n for n in steps['build'].get('notes', []))
    if not names:
        return (0, 0.0, 0.0, mesh_mass), None
    worst_a = worst_g = 0.0
    for _ in range(3):
        q_mech = []
        for name in names:
            joint_id = model.getJointId(name)
            joint = model.joints[joint_id]
            lo, hi = model.lowerPositionLimit[joint.idx_q], model.upperPositionLimit[joint.idx_q]
            if joint.nq == 2 or not (np.isfinite(lo) and np.isfinite(hi)) or hi <= lo or hi - lo > 1e3:
                lo, hi = -math.pi, math.pi
            q_mech.append(float(rng.uniform(lo, hi)))
        text = ','.join(repr(v) for v in q_mech)
        run = subprocess.run([exe, 'run', urdf, '--json', '--matrices', '--q', text], capture_output=True, text=True)
        if run.returncode != 0:
            return None, run.stderr.strip().splitlines()[0]
        state = {s['analysis']: s for s in json.loads(run.stdout)['steps']}['state_matrices']
        a_mech = np.array(state['mass_matrix'])
        g_mech = np.array(state['gradient'])
        q_pin = pinocchio_state(model, names, q_mech)
        a_pin_full = pin.crba(model, data, q_pin)
        a_pin_full = np.triu(a_pin_full) + np.triu(a_pin_full, 1).T
        g_pin_full = pin.computeGeneralizedGravity(model, data, q_pin)
        index = [model.joints[model.getJointId(n)].idx_v for n in names]
        a_pin = a_pin_full[np.ix_(index, index)]
        g_pin = g_pin_full[index]
        worst_a = max(worst_a, np.abs(a_mech - a_pin).max() / np.abs(a_pin).max())
        worst_g = max(worst_g, np.abs(g_mech - g_pin).max() / max(np.abs(g_pin).max(), 1e-300))
    return (len(names), worst_a, worst_g, mesh_mass), None


def main():
    exe = sys.argv[1]
    rng = np.random.default_rng(20261130)
    print(f'# pinocchio {pin.__version__}; max |A - A_pin| / max |A_pin| and |g - g_pin| / max |g_pin| over 3 random q')
    print('# robot nv rel_A rel_gravity note')
    for urdf in sorted(glob.glob(os.path.join(robots_dir(), '**', '*.urdf'), recursive=True)):
        name = os.path.relpath(urdf, robots_dir())
        try:
            result, refusal = compare(exe, urdf, rng)
        except Exception as error:  # a file Pinocchio itself cannot read
            print(f'{name} - - - pinocchio: {str(error).splitlines()[0][:100]}')
            continue
        if refusal is not None:
            print(f'{name} - - - refused: {refusal.split(urdf + ": ", 1)[-1][:110]}')
            continue
        nv, rel_a, rel_g, mesh_mass = result
        note = 'mesh mass' if mesh_mass else ''
        print(f'{name} {nv} {rel_a:.1e} {rel_g:.1e} {note}')


if __name__ == '__main__':
    main()
