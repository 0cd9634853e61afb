"""Inverse and forward dynamics of every URDF robot of example-robot-data, against Pinocchio.

The CLI prints no dynamics at a given (q, q-dot), so this sweep calls the C library
(libmechanica.so) through ctypes: mech_mechanism_from_urdf (default, strict options, as
tools/urdf_pinocchio_sweep.py: a file refused there is refused here), mech_dynamics_create,
then at three seeded random states per robot

  RNEA     tau = mech_dynamics_rnea(q, q-dot, q-ddot)     vs  pin.rnea(model, data, q, v, a)
  ABA      q-ddot = mech_dynamics_aba(q, q-dot, tau)      vs  pin.aba(model, data, q, v, tau)
  forward  q-ddot = mech_dynamics_forward(...)            vs  pin.aba (the checked route: ABA
           confirmed by the inverse dynamics, else the mass matrix and Cholesky)

with Pinocchio's model from buildModelFromUrdf (fixed base, mimic tags read as independent
joints, as mechanica does) and its gravity set to mechanica's URDF convention, -9.81 m/s^2
along the base z axis (which is also Pinocchio's default). Coordinates are matched by joint
name; a continuous joint is one angle in mechanica and (cos, sin) with one velocity in
Pinocchio. (A floating, planar or spherical joint, whose coordinates mechanica names joint[i],
would be reported as not comparable; example-robot-data's URDFs have none.)

States (numpy, per robot the seed sequence (20261130, index of the file in sorted order)):
q uniform in each revolute/prismatic joint's limits, or [-pi, pi] when unlimited or
continuous; q-dot and
q-ddot uniform in [-2, 2]; tau = pin.rnea(q, q-dot, b) for another b uniform in [-2, 2], so
that the forward dynamics' answer (~ b) is of order one.

Printed per robot, the worst over its three states of
  rel_rnea   |tau - tau_pin| / |tau_pin|
  rel_aba    |qdd - qdd_pin| / |qdd_pin|        (mech_dynamics_aba)
  rel_fwd    the same for mech_dynamics_forward
  bwd_aba    |pin.rnea(q, v, qdd) - tau| / |tau|, mechanica's ABA answer put back into
             Pinocchio's inverse dynamics (a backward error: small when the difference in
             rel_aba is only the conditioning of A(q) amplifying rounding)
  bwd_pin    the same for Pinocchio's own aba answer
  sens       u |A^-1| (|A| |qdd| + |tau - A qdd|) / |qdd| with A = pin.crba(q), qdd = Pinocchio's
             answer and u = 2^-53: the first-order change of qdd when A and the bias forces
             are perturbed by u relative, i.e. the forward error that rounding the data alone
             may cause. A rel_aba of the order of sens (or below) is the conditioning of the
             problem, not a disagreement: with tau dominated by gravity (|tau| >> |A qdd|) and
             light distal links, sens reaches 1e-11 and more.
and, at the zero configuration at rest under gravity alone (q = 0 in mechanica's
coordinates, where files often place singular configurations: iCub's neck at q = 0 leaves
point masses that its joints together do not move),
  q0_route   the route mech_dynamics_forward took there (aba, or crba: the mass matrix)
  q0_rel     |qdd - qdd_pin|_inf / |qdd_pin|_inf of that route's answer
  q0_est     its reported error estimate / |qdd|_inf (crba route only; '-' for aba, which
             reports a backward error alone): above q0_rel wherever the report is true,
             above 1 where it says that q-ddot has no correct digit
with |.| the Euclidean norm (2-norm for matrices). Each robot runs in a child process with a
time limit, so a crash or a hang is reported on its line instead of stopping the sweep. Links
without <inertial> whose mesh gives them mass in mechanica (1000 kg/m^3) are massless in
Pinocchio: such robots are marked "mesh mass" (from the note of
`mechanica run URDF --json`, the CLI next to the library) and their differences are not
disagreements.

Usage:  pip install pin example-robot-data
        cargo build --release                       # the CLI, target/release/mechanica
        cargo build --release -p mechanica          # the C library, target/release/libmechanica.so
        python3 tools/urdf_dynamics_sweep.py target/release/libmechanica.so \\
            > tools/urdf_dynamics_sweep.out
"""
import ctypes
import glob
import json
import math
import os
import subprocess
import sys

import numpy as np
import pinocchio as pin

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from urdf_pinocchio_sweep import pinocchio_state, robots_dir  # noqa: E402

SEED = 20261130
STATES = 3
TIME_LIMIT = 120  # seconds per robot
U = 2.0 ** -53  # unit roundoff of double precision
GRAVITY = np.array([0.0, 0.0, -9.81])  # mechanica's URDF gravity (base-frame components)


# ---------------------------------------------------------------------------------------------
# mechanica through ctypes


class UrdfOptions(ctypes.Structure):
    _fields_ = [('repair_inertia', ctypes.c_int32), ('allow_missing_mesh', ctypes.c_int32)]


class ForwardReport(ctypes.Structure):
    _fields_ = [('method', ctypes.c_int32), ('backward_error', ctypes.c_double),
                ('condition', ctypes.c_double), ('error_estimate', ctypes.c_double),
                ('dissipation', ctypes.c_double)]


class MechanicaError(Exception):
    pass


class Mechanica:
    """The few C functions the sweep needs; every failed call raises MechanicaError with
    mech_status_str and mech_last_error."""

    def __init__(self, path):
        lib = ctypes.CDLL(os.path.abspath(path))
        P, D, S = ctypes.c_void_p, ctypes.POINTER(ctypes.c_double), ctypes.c_size_t
        lib.mech_status_str.restype = ctypes.c_char_p
        lib.mech_status_str.argtypes = [ctypes.c_int32]
        lib.mech_version.restype = ctypes.c_char_p
        lib.mech_last_error.restype = S
        lib.mech_last_error.argtypes = [ctypes.c_char_p, S]
        signatures = {
            'mech_urdf_options_default': [ctypes.POINTER(UrdfOptions)],
            'mech_mechanism_from_urdf': [ctypes.c_char_p, ctypes.POINTER(UrdfOptions), ctypes.POINTER(P)],
            'mech_mechanism_dof': [P, ctypes.POINTER(S)],
            'mech_mechanism_coordinate_name': [P, S, ctypes.c_char_p, S, ctypes.POINTER(S)],
            'mech_dynamics_create': [P, ctypes.POINTER(P)],
            'mech_dynamics_rnea': [P, D, D, D, S, D],
            'mech_dynamics_aba': [P, D, D, D, S, D],
            'mech_dynamics_forward': [P, D, D, D, ctypes.c_double, S, D, ctypes.POINTER(ForwardReport)],
        }
        for name, argtypes in signatures.items():
            function = getattr(lib, name)
            function.restype = ctypes.c_int32
            function.argtypes = argtypes
        lib.mech_mechanism_destroy.argtypes = [P]
        lib.mech_mechanism_destroy.restype = None
        lib.mech_dynamics_destroy.argtypes = [P]
        lib.mech_dynamics_destroy.restype = None
        self.lib = lib

    def version(self):
        return self.lib.mech_version().decode()

    def check(self, status):
        if status != 0:
            length = self.lib.mech_last_error(None, 0)
            buffer = ctypes.create_string_buffer(length + 1)
            self.lib.mech_last_error(buffer, length + 1)
            raise MechanicaError(f'{self.lib.mech_status_str(status).decode()}: {buffer.value.decode()}')


class Robot:
    """A URDF robot's mechanism and dynamics handles, freed by close()."""

    def __init__(self, mech, path):
        self.mech, lib = mech, mech.lib
        options = UrdfOptions()
        mech.check(lib.mech_urdf_options_default(ctypes.byref(options)))
        self.mechanism, self.dynamics = ctypes.c_void_p(), ctypes.c_void_p()
        mech.check(lib.mech_mechanism_from_urdf(path.encode(), ctypes.byref(options), ctypes.byref(self.mechanism)))
        mech.check(lib.mech_dynamics_create(self.mechanism, ctypes.byref(self.dynamics)))
        dof = ctypes.c_size_t()
        mech.check(lib.mech_mechanism_dof(self.mechanism, ctypes.byref(dof)))
        self.n = dof.value
        self.names = [self._coordinate_name(k) for k in range(self.n)]

    def _coordinate_name(self, k):
        lib, length = self.mech.lib, ctypes.c_size_t()
        self.mech.check(lib.mech_mechanism_coordinate_name(self.mechanism, k, None, 0, ctypes.byref(length)))
        buffer = ctypes.create_string_buffer(length.value + 1)
        self.mech.check(lib.mech_mechanism_coordinate_name(self.mechanism, k, buffer, length.value + 1,
                                                            ctypes.byref(length)))
        return buffer.value.decode()

    def _evaluate(self, function, a, b, c, *rest):
        """function(dynamics, a, b, c, *rest[:-1], n, out, rest[-1]) for the three n-vectors
        a, b, c; returns out. `rest` is () for rnea and aba, (t, report) for forward."""
        pointer = ctypes.POINTER(ctypes.c_double)
        inputs = [np.ascontiguousarray(v, dtype=float) for v in (a, b, c)]
        out = np.zeros(self.n)
        args = [x.ctypes.data_as(pointer) for x in inputs] + list(rest[:-1])
        args += [self.n, out.ctypes.data_as(pointer)] + list(rest[-1:])
        self.mech.check(function(self.dynamics, *args))
        return out

    def rnea(self, q, qd, qdd):
        return self._evaluate(self.mech.lib.mech_dynamics_rnea, q, qd, qdd)

    def aba(self, q, qd, tau):
        return self._evaluate(self.mech.lib.mech_dynamics_aba, q, qd, tau)

    def forward(self, q, qd, tau):
        """q-ddot of the checked route (t = 0) and its report (method 0 ABA, 1 mass matrix)."""
        report = ForwardReport()
        qdd = self._evaluate(self.mech.lib.mech_dynamics_forward, q, qd, tau, ctypes.c_double(0.0),
                             ctypes.byref(report))
        return qdd, report

    def close(self):
        self.mech.lib.mech_dynamics_destroy(self.dynamics)
        self.mech.lib.mech_mechanism_destroy(self.mechanism)


# ---------------------------------------------------------------------------------------------
# Pinocchio and the comparison


def random_q(model, names, rng):
    """As tools/urdf_pinocchio_sweep.py: uniform in the joint's limits, else in [-pi, pi]."""
    q = []
    for name in names:
        joint = model.joints[model.getJointId(name)]
        lo, hi = model.lowerPositionLimit[joint.idx_q], model.upperPositionLimit[joint.idx_q]
        if joint.nq == 2 or not (np.isfinite(lo) and np.isfinite(hi)) or hi <= lo or hi - lo > 1e3:
            lo, hi = -math.pi, math.pi
        q.append(float(rng.uniform(lo, hi)))
    return np.array(q)


def relative(x, ref):
    return float(np.linalg.norm(x - ref) / max(np.linalg.norm(ref), 1e-300))


def compare(lib_path, urdf, seed_sequence):
    """The worst errors over STATES random states of one robot, as a dict (or its refusal)."""
    mech = Mechanica(lib_path)
    try:
        robot = Robot(mech, urdf)
    except MechanicaError as error:
        return {'refused': str(error).splitlines()[0]}
    try:
        try:
            model = pin.buildModelFromUrdf(urdf)
        except Exception as error:  # a file Pinocchio itself cannot read
            return {'refused': f'pinocchio: {str(error).splitlines()[0][:100]}'}
        model.gravity = pin.Motion(GRAVITY, np.zeros(3))
        data = model.createData()
        names = robot.names
        unknown = [n for n in names if not model.existJointName(n)]
        if unknown:
            return {'refused': f'coordinates without a Pinocchio joint: {unknown[:3]}'}
        index = [model.joints[model.getJointId(n)].idx_v for n in names]
        if sorted(index) != list(range(model.nv)):
            return {'refused': f'mechanica has {len(names)} coordinates, Pinocchio nv = {model.nv}'}
        rng = np.random.default_rng(seed_sequence)
        worst = dict(rnea=0.0, aba=0.0, fwd=0.0, bwd_aba=0.0, bwd_pin=0.0, sens=0.0)
        methods = set()
        for _ in range(STATES if robot.n else 0):
            q_mech = random_q(model, names, rng)
            qd, qdd, b = (rng.uniform(-2.0, 2.0, robot.n) for _ in range(3))
            q_pin = pinocchio_state(model, names, q_mech)
            v_pin, a_pin, b_pin = (np.zeros(model.nv) for _ in range(3))
            v_pin[index], a_pin[index], b_pin[index] = qd, qdd, b
            tau_pin = pin.rnea(model, data, q_pin, v_pin, b_pin).copy()
            tau = tau_pin[index]

            rnea_ref = pin.rnea(model, data, q_pin, v_pin, a_pin).copy()[index]
            aba_ref_full = pin.aba(model, data, q_pin, v_pin, tau_pin).copy()
            aba_ref = aba_ref_full[index]
            mass = pin.crba(model, data, q_pin)
            mass = np.triu(mass) + np.triu(mass, 1).T

            rnea_mech = robot.rnea(q_mech, qd, qdd)
            aba_mech = robot.aba(q_mech, qd, tau)
            fwd_mech, report = robot.forward(q_mech, qd, tau)
            methods.add(report.method)
            for value in (rnea_mech, aba_mech, fwd_mech):
                if not np.all(np.isfinite(value)):
                    return {'error': 'non-finite result with status OK'}

            def backward(qdd_answer):
                a = np.zeros(model.nv)
                a[index] = qdd_answer
                return relative(pin.rnea(model, data, q_pin, v_pin, a)[index], tau)

            worst['rnea'] = max(worst['rnea'], relative(rnea_mech, rnea_ref))
            worst['aba'] = max(worst['aba'], relative(aba_mech, aba_ref))
            worst['fwd'] = max(worst['fwd'], relative(fwd_mech, aba_ref))
            worst['bwd_aba'] = max(worst['bwd_aba'], backward(aba_mech))
            worst['bwd_pin'] = max(worst['bwd_pin'], backward(aba_ref))
            singular_values = np.linalg.svd(mass, compute_uv=False)
            bias = np.linalg.norm(tau_pin - mass @ aba_ref_full)
            sens = U / singular_values[-1] * (singular_values[0] * np.linalg.norm(aba_ref) + bias)
            worst['sens'] = max(worst['sens'], sens / np.linalg.norm(aba_ref))
        worst['nv'] = robot.n
        worst['route'] = '+'.join(ROUTES.get(m, str(m)) for m in sorted(methods)) or '-'
        worst.update(at_zero(robot, model, data, names, index))
        return worst
    except MechanicaError as error:
        return {'error': str(error).splitlines()[0]}
    finally:
        robot.close()


ROUTES = {0: 'aba', 1: 'crba'}


def at_zero(robot, model, data, names, index):
    """The checked forward dynamics at q = 0, at rest, under gravity alone, against pin.aba."""
    if not robot.n:
        return dict(q0_route='-', q0_rel=0.0, q0_est=None)
    zero = np.zeros(robot.n)
    qdd, report = robot.forward(zero, zero, zero)
    q_pin = pinocchio_state(model, names, zero)
    reference = pin.aba(model, data, q_pin, np.zeros(model.nv), np.zeros(model.nv)).copy()[index]
    scale = max(np.abs(reference).max(), 1e-300)
    estimate = report.error_estimate / max(np.abs(qdd).max(), 1e-300) if report.method == 1 else None
    return dict(q0_route=ROUTES.get(report.method, str(report.method)),
                q0_rel=float(np.abs(qdd - reference).max() / scale), q0_est=estimate)


def mesh_mass(exe, urdf):
    """Whether mechanica gives a link without <inertial> the mass of its mesh (the CLI's note)."""
    run = subprocess.run([exe, 'run', urdf, '--json'], capture_output=True, text=True)
    if run.returncode != 0:
        return False
    steps = {s['analysis']: s for s in json.loads(run.stdout)['steps']}
    return any('mass properties from mesh' in n for n in steps['build'].get('notes', []))


def child(lib_path, urdf, seed):
    """One robot, in this (child) process: prints its result as one JSON line."""
    print(json.dumps(compare(lib_path, urdf, np.random.SeedSequence(seed))))


def main():
    if len(sys.argv) == 5 and sys.argv[1] == '--one':
        child(sys.argv[2], sys.argv[3], [int(x) for x in sys.argv[4].split(',')])
        return
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    lib_path = sys.argv[1]
    exe = os.path.join(os.path.dirname(os.path.abspath(lib_path)), 'mechanica')
    print(f'# mechanica {Mechanica(lib_path).version()}, pinocchio {pin.__version__}; gravity {GRAVITY.tolist()}; '
          f'{STATES} random states per robot, seed {SEED}')
    print('# worst over the states of |x - x_pin| / |x_pin| (2-norms); bwd_*: |rnea_pin(q, v, qdd) - tau| / |tau|; '
          'sens: forward error from rounding the data (see the docstring)')
    print('# robot nv rel_rnea rel_aba rel_fwd bwd_aba bwd_pin sens fwd_route q0_route q0_rel q0_est note')
    for number, urdf in enumerate(sorted(glob.glob(os.path.join(robots_dir(), '**', '*.urdf'), recursive=True))):
        name = os.path.relpath(urdf, robots_dir())
        # Each robot draws from its own stream (SEED, file number): adding a file does not
        # change the states of the others.
        command = [sys.executable, os.path.abspath(__file__), '--one', lib_path, urdf, f'{SEED},{number}']
        try:
            run = subprocess.run(command, capture_output=True, text=True, timeout=TIME_LIMIT)
        except subprocess.TimeoutExpired:
            print(f'{name} - - - - - - - - - - - HANG: no answer in {TIME_LIMIT} s')
            continue
        lines = run.stdout.strip().splitlines()
        if run.returncode != 0 or not lines:
            why = (run.stderr.strip().splitlines() or [f'exit status {run.returncode}'])[-1]
            print(f'{name} - - - - - - - - - - - CRASH: {why[:120]}')
            continue
        result = json.loads(lines[-1])
        if 'refused' in result:
            print(f'{name} - - - - - - - - - - - refused: {result["refused"].split(urdf + ": ", 1)[-1][:110]}')
            continue
        if 'error' in result:
            print(f'{name} - - - - - - - - - - - ERROR: {result["error"][:120]}')
            continue
        note = 'mesh mass' if os.path.exists(exe) and mesh_mass(exe, urdf) else ''
        estimate = '-' if result['q0_est'] is None else f'{result["q0_est"]:.1e}'
        print(f'{name} {result["nv"]} {result["rnea"]:.1e} {result["aba"]:.1e} {result["fwd"]:.1e} '
              f'{result["bwd_aba"]:.1e} {result["bwd_pin"]:.1e} {result["sens"]:.1e} {result["route"]} '
              f'{result["q0_route"]} {result["q0_rel"]:.1e} {estimate} {note}'.rstrip())


if __name__ == '__main__':
    main()
