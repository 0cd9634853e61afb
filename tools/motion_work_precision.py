#!/usr/bin/env python3
"""Work-precision of the motion crate's integrators on three planar chains, with SciPy's
solve_ivp (DOP853, Radau) on the same equations written here independently, and MuJoCo's RK4
and implicit integrators on matching MJCF models, in one invocation.

Problems (links on revolute joints about y, each link a mass m_i with central inertia J_i at
l_i below its joint, the next joint at that point, gravity g along -z; q are the relative joint
angles, springs and dampers act on them):
  double_pendulum  two links, chaotic (q0 = (2, 0.5) rad at rest), t = 5 s;
  arm7             seven links with joint springs (50 N m/rad) and dampers (0.5 N m s/rad), t = 2 s;
  stiff_chain      five links, the first joint free, springs of 1e6 N m/rad on the other four, t = 1 s.

References. The double pendulum's reference state at t = 5 s comes from the closed-form
Lagrangian equations in absolute angles evaluated in mpmath and integrated by mpmath's Taylor
series method (odefun) at 30 and at 20 significant digits; their difference bounds the error of
the 20-digit run and is written to the reference file. The other two use SciPy DOP853 at
rtol = 2.3e-14 (its smallest) and atol = 1e-16 on the same equations in float64, checked against
DOP853 at rtol = 1e-12 and against Radau at rtol = 1e-10 (independent method); the reference
error quoted is the difference to the rtol = 1e-12 run (tolerance proportionality makes the
tighter run's error smaller by a factor of order 40).

Usage: pip install scipy mpmath mujoco; python3 tools/motion_work_precision.py [--from-csv]
Writes tools/motion_work_precision.csv (every solver's points with their true errors),
tools/motion_work_precision.svg (error of q at t_end against wall time, one panel per problem),
tools/motion_work_precision_reference.json (the references, reused when present), and prints
the ratios at matched error and the count of mechanica points whose true error is within the
global error estimate.
"""

import csv
import json
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CSV_OUT = os.path.join(ROOT, "tools", "motion_work_precision.csv")
SVG_OUT = os.path.join(ROOT, "tools", "motion_work_precision.svg")
REF_OUT = os.path.join(ROOT, "tools", "motion_work_precision_reference.json")
FLOOR = 1e-16
TARGETS = (1e-4, 1e-8)

PROBLEMS = {
    "double_pendulum": dict(
        t_end=5.0, g=9.81, mass=[1.0, 1.0], length=[1.0, 1.0], inertia=[0.01, 0.01],
        stiffness=[0.0, 0.0], damping=[0.0, 0.0], q0=[2.0, 0.5], v0=[0.0, 0.0],
        mechanica={"rk4": [1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4], "dopri": [1e-4, 1e-6, 1e-8, 1e-10, 1e-12],
                   "verlet": [1e-2, 3e-3, 1e-3, 3e-4], "midpoint": [1e-2, 3e-3, 1e-3, 3e-4]},
        scipy={"DOP853": [1e-4, 1e-6, 1e-8, 1e-10, 1e-12], "Radau": [1e-4, 1e-6, 1e-8]},
        mujoco={"RK4": [1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4], "implicit": [1e-2, 1e-3, 1e-4]}),
    "arm7": dict(
        t_end=2.0, g=9.81, mass=[3.0, 2.5, 2.0, 1.5, 1.0, 0.8, 0.5],
        length=[0.3, 0.3, 0.25, 0.25, 0.2, 0.15, 0.1],
        inertia=[0.02, 0.02, 0.01, 0.01, 0.005, 0.002, 0.001],
        stiffness=[50.0] * 7, damping=[0.5] * 7, q0=[0.5, -0.3, 0.4, 0.2, -0.5, 0.3, 0.1], v0=[0.0] * 7,
        mechanica={"rk4": [1e-2, 5e-3, 2e-3, 1e-3, 5e-4], "dopri": [1e-4, 1e-6, 1e-8, 1e-10, 1e-12],
                   "verlet": [1e-2, 3e-3, 1e-3], "midpoint": [1e-2, 3e-3, 1e-3]},
        scipy={"DOP853": [1e-4, 1e-6, 1e-8, 1e-10, 1e-12], "Radau": [1e-4, 1e-6, 1e-8]},
        mujoco={"RK4": [1e-2, 5e-3, 2e-3, 1e-3, 5e-4], "implicit": [1e-2, 1e-3, 1e-4]}),
    "stiff_chain": dict(
        t_end=1.0, g=9.81, mass=[1.0] * 5, length=[0.2] * 5, inertia=[1e-3] * 5,
        stiffness=[0.0] + [1e6] * 4, damping=[0.0] * 5, q0=[1.0, 0.0, 0.0, 0.0, 0.0], v0=[0.0] * 5,
        mechanica={"rk4": [2e-4, 1e-4, 5e-5, 2e-5], "dopri": [1e-4, 1e-6, 1e-8, 1e-10],
                   "midpoint": [1e-2, 3e-3, 1e-3, 3e-4, 1e-4]},
        scipy={"DOP853": [1e-4, 1e-6, 1e-8, 1e-10], "Radau": [1e-4, 1e-6, 1e-8]},
        mujoco={"RK4": [2e-4, 1e-4, 5e-5], "implicit": [1e-3, 1e-4, 1e-5]}),
}


# ---------------------------------------------------------------- equations (independent)

def chain_rhs(p, sin, cos, solve, matrix):
    """y' for y = (q, q'): in absolute angles th = S q (S lower-triangular ones) the Lagrangian
    of point masses plus central inertias gives M(th) th'' + c(th, th') + G(th) = Q with
    M_jk = mu_max(j,k) l_j l_k cos(th_j - th_k) + delta_jk J_j, mu_i = sum_{r >= i} m_r,
    c_j = sum_k mu_max(j,k) l_j l_k sin(th_j - th_k) th_k'^2, G_j = mu_j g l_j sin th_j; in q:
    S^T M S q'' = -S^T (c + G) + tau, tau_i = -k_i q_i - c_i q_i'."""
    n, m, l, J = len(p["mass"]), p["mass"], p["length"], p["inertia"]
    mu = [sum(m[i:]) for i in range(n)]
    g, k, d = p["g"], p["stiffness"], p["damping"]

    def f(t, y):
        q, v = y[:n], y[n:]
        th, w = [], []
        a = b = 0
        for i in range(n):
            a, b = a + q[i], b + v[i]
            th.append(a)
            w.append(b)
        M = [[0] * n for _ in range(n)]
        rhs = []
        for j in range(n):
            s = -mu[j] * g * l[j] * sin(th[j])
            for kk in range(n):
                c = mu[max(j, kk)] * l[j] * l[kk]
                M[j][kk] = c * cos(th[j] - th[kk]) + (J[j] if j == kk else 0)
                s -= c * sin(th[j] - th[kk]) * w[kk] ** 2
            rhs.append(s)
        # S^T x: suffix sums; S^T M S: suffix sums over rows and columns.
        Mq = [[sum(M[r][c] for r in range(i, n) for c in range(jj, n)) for jj in range(n)] for i in range(n)]
        bq = [sum(rhs[i:]) - k[i] * q[i] - d[i] * v[i] for i in range(n)]
        acc = solve(matrix(Mq), matrix(bq))
        return list(v) + [acc[i] for i in range(n)]

    return f


def numpy_rhs(p):
    n, m, l, J = len(p["mass"]), np.array(p["mass"]), np.array(p["length"]), np.array(p["inertia"])
    mu = np.cumsum(m[::-1])[::-1]
    mu_max = mu[np.maximum.outer(np.arange(n), np.arange(n))]
    ll = np.outer(l, l) * mu_max
    S = np.tril(np.ones((n, n)))
    g, k, d = p["g"], np.array(p["stiffness"]), np.array(p["damping"])

    def f(t, y):
        q, v = y[:n], y[n:]
        th, w = S @ q, S @ v
        diff = th[:, None] - th[None, :]
        M = ll * np.cos(diff) + np.diag(J)
        rhs = -(ll * np.sin(diff)) @ (w * w) - mu * g * l * np.sin(th)
        acc = np.linalg.solve(S.T @ M @ S, S.T @ rhs - k * q - d * v)
        return np.concatenate([v, acc])

    return f


# ---------------------------------------------------------------- references

def mpmath_reference(p, dps):
    import mpmath
    mpmath.mp.dps = dps
    mp = {key: [mpmath.mpf(str(x)) for x in p[key]] for key in ("mass", "length", "inertia", "stiffness", "damping")}
    mp["g"] = mpmath.mpf(str(p["g"]))
    f = chain_rhs(mp, mpmath.sin, mpmath.cos, mpmath.lu_solve, mpmath.matrix)
    y0 = [mpmath.mpf(str(x)) for x in p["q0"] + p["v0"]]
    solution = mpmath.odefun(lambda t, y: f(t, y), 0, y0)
    return [float(x) for x in solution(mpmath.mpf(str(p["t_end"])))]


def scipy_solution(p, method, rtol, atol):
    from scipy.integrate import solve_ivp
    f = numpy_rhs(p)
    start = time.perf_counter()
    sol = solve_ivp(f, (0.0, p["t_end"]), np.array(p["q0"] + p["v0"]), method=method, rtol=rtol, atol=atol)
    seconds = time.perf_counter() - start
    return sol.y[:, -1], seconds, sol.t.size - 1, sol.success


def references():
    if os.path.exists(REF_OUT):
        with open(REF_OUT) as fh:
            return json.load(fh)
    out = {}
    p = PROBLEMS["double_pendulum"]
    start = time.perf_counter()
    fine, coarse = mpmath_reference(p, 30), mpmath_reference(p, 20)
    out["double_pendulum"] = dict(
        state=fine, method="mpmath odefun (Taylor) at 30 digits",
        check="mpmath odefun at 20 digits", error=max(abs(a - b) for a, b in zip(fine, coarse)),
        seconds=time.perf_counter() - start)
    for name in ("arm7", "stiff_chain"):
        p = PROBLEMS[name]
        ref, _, _, _ = scipy_solution(p, "DOP853", 2.3e-14, 1e-16)
        check, _, _, _ = scipy_solution(p, "DOP853", 1e-12, 1e-14)
        radau, _, _, _ = scipy_solution(p, "Radau", 1e-10, 1e-12)
        out[name] = dict(state=list(ref), method="SciPy DOP853 rtol 2.3e-14 atol 1e-16",
                         check="SciPy DOP853 rtol 1e-12", error=float(np.max(np.abs(ref - check))),
                         radau_difference=float(np.max(np.abs(ref - radau))))
    # The float64 DOP853 run against the mpmath reference of the double pendulum, as a check.
    p = PROBLEMS["double_pendulum"]
    dop, _, _, _ = scipy_solution(p, "DOP853", 2.3e-14, 1e-16)
    out["double_pendulum"]["dop853_difference"] = float(np.max(np.abs(dop - np.array(out["double_pendulum"]["state"]))))
    with open(REF_OUT, "w") as fh:
        json.dump(out, fh, indent=1)
    return out


# ---------------------------------------------------------------- peers

def mjcf(p, integrator, step):
    n = len(p["mass"])
    body = ""
    for i in reversed(range(n)):
        pos = "0 0 0" if i == 0 else f"0 0 {-p['length'][i - 1]!r}"
        J = p["inertia"][i]
        body = (f'<body pos="{pos}"><joint type="hinge" axis="0 1 0" stiffness="{p["stiffness"][i]!r}" '
                f'damping="{p["damping"][i]!r}"/><inertial pos="0 0 {-p["length"][i]!r}" mass="{p["mass"][i]!r}" '
                f'diaginertia="{J!r} {J!r} {J!r}"/>{body}</body>')
    return (f'<mujoco><option timestep="{step!r}" integrator="{integrator}" gravity="0 0 {-p["g"]!r}">'
            f'<flag contact="disable" constraint="disable"/></option><worldbody>{body}</worldbody></mujoco>')


def mujoco_run(p, integrator, step):
    import mujoco
    from mujoco import rollout
    model = mujoco.MjModel.from_xml_string(mjcf(p, integrator, step))
    data = mujoco.MjData(model)
    n = model.nq
    data.qpos[:] = p["q0"]
    data.qvel[:] = p["v0"]
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state0 = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, state0, spec)
    steps = round(p["t_end"] / step)
    best = math.inf
    for _ in range(3):
        start = time.perf_counter()
        states, _ = rollout.rollout(model, data, state0[None, :], nstep=steps)
        best = min(best, time.perf_counter() - start)
    last = states[0, -1]
    # FULLPHYSICS: time, qpos, qvel, ... MuJoCo resets a diverging state (bad qacc) to the
    # model's rest state at time 0: a final time short of t_end marks a divergence.
    if abs(last[0] - steps * step) > 1e-9 * p["t_end"]:
        return np.full(2 * n, np.inf), best, steps
    return np.concatenate([last[1:1 + n], last[1 + n:1 + 2 * n]]), best, steps


# ---------------------------------------------------------------- runs

def run_mechanica(workdir):
    spec = os.path.join(workdir, "spec.txt")
    out = os.path.join(workdir, "mechanica.csv")
    with open(spec, "w") as fh:
        for name, p in PROBLEMS.items():
            fh.write(f"problem {name} {p['t_end']!r} {p['g']!r}\n")
            for key in ("mass", "length", "inertia", "stiffness", "damping", "q0", "v0"):
                fh.write(key + " " + " ".join(repr(float(x)) for x in p[key]) + "\n")
            for kind, values in p["mechanica"].items():
                fh.write(f"method {kind} " + " ".join(repr(v) for v in values) + "\n")
    env = dict(os.environ, CARGO_PROFILE_RELEASE_LTO="off", CARGO_PROFILE_RELEASE_CODEGEN_UNITS="16")
    subprocess.run(["cargo", "run", "--release", "-q", "-p", "mechanica-motion", "--example", "work_precision",
                    "--", spec, out], cwd=ROOT, check=True, env=env)
    with open(out) as fh:
        return list(csv.DictReader(fh))


def error_pair(state, reference, n):
    state, reference = np.asarray(state, float), np.asarray(reference, float)
    return float(np.max(np.abs(state[:n] - reference[:n]))), float(np.max(np.abs(state[n:] - reference[n:])))


def collect(workdir):
    refs = references()
    rows = []
    mechanica = run_mechanica(workdir)
    os.chdir(workdir)  # MuJoCo writes MUJOCO_LOG.TXT into the working directory on a divergence
    for r in mechanica:
        p, ref = PROBLEMS[r["problem"]], refs[r["problem"]]["state"]
        n = len(p["mass"])
        row = dict(problem=r["problem"], solver="mechanica", method=r["method"], parameter=r["parameter"],
                   time_s=r["time_s"], steps=r["steps"], error_q="", error_q_dot="",
                   estimate_q=r["estimate_q"], estimate_q_dot=r["estimate_q_dot"], reference_error=refs[r["problem"]]["error"],
                   energy_drift=r["energy_drift"])
        if r["q"]:
            state = [float(x) for x in (r["q"] + " " + r["q_dot"]).split()]
            row["error_q"], row["error_q_dot"] = error_pair(state, ref, n)
        rows.append(row)
    for name, p in PROBLEMS.items():
        n, ref = len(p["mass"]), refs[name]["state"]
        for method, tolerances in p["scipy"].items():
            for rtol in tolerances:
                state, seconds, steps, ok = scipy_solution(p, method, rtol, rtol * 1e-2)
                eq, ev = error_pair(state, ref, n) if ok else ("", "")
                rows.append(dict(problem=name, solver="scipy", method=method, parameter=rtol, time_s=seconds,
                                 steps=steps, error_q=eq, error_q_dot=ev, estimate_q="", estimate_q_dot="",
                                 reference_error=refs[name]["error"], energy_drift=""))
                print(name, method, rtol, seconds, eq, flush=True)
        for integrator, steps_list in p["mujoco"].items():
            for h in steps_list:
                state, seconds, steps = mujoco_run(p, integrator, h)
                eq, ev = error_pair(state, ref, n) if np.all(np.isfinite(state)) else (math.inf, math.inf)
                rows.append(dict(problem=name, solver="mujoco", method=integrator, parameter=h, time_s=seconds,
                                 steps=steps, error_q=eq, error_q_dot=ev, estimate_q="", estimate_q_dot="",
                                 reference_error=refs[name]["error"], energy_drift=""))
                print(name, "mujoco", integrator, h, seconds, eq, flush=True)
    return rows


# ---------------------------------------------------------------- report

def write_csv(rows):
    with open(CSV_OUT, "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0].keys()), lineterminator="\n")
        writer.writeheader()
        writer.writerows(rows)


def points(rows, problem):
    out = {}
    for r in rows:
        if r["problem"] != problem or r["error_q"] in ("", None):
            continue
        e = float(r["error_q"])
        out.setdefault(f"{r['solver']} {r['method']}", []).append((float(r["parameter"]), float(r["time_s"]), e))
    for pts in out.values():
        pts.sort(key=lambda x: -x[0])  # loosest tolerance or largest step first
    return out


COLOURS = {"mechanica rk4": "#1f77b4", "mechanica dopri": "#0b3d91", "mechanica verlet": "#17becf",
           "mechanica midpoint": "#2ca02c", "scipy DOP853": "#d62728", "scipy Radau": "#ff7f0e",
           "mujoco RK4": "#9467bd", "mujoco implicit": "#e377c2"}


def panel(rows, problem, x0, width, height, y_lo=-16, y_hi=1):
    data = points(rows, problem)
    times = [t for pts in data.values() for _, t, _ in pts]
    x_lo, x_hi = math.floor(math.log10(min(times))), math.ceil(math.log10(max(times)))
    left, top, bottom = x0 + 55, 40, height - 45
    right = x0 + width - 10

    def x(t):
        return left + (math.log10(t) - x_lo) / (x_hi - x_lo) * (right - left)

    def y(e):
        e = min(max(e, 10.0 ** y_lo), 10.0 ** y_hi)
        return bottom - (math.log10(e) - y_lo) / (y_hi - y_lo) * (bottom - top)

    parts = [f'<text x="{(left + right) / 2}" y="25" text-anchor="middle" font-weight="bold">{problem}</text>']
    for k in range(x_lo, x_hi + 1):
        parts.append(f'<line x1="{x(10.0**k):.1f}" y1="{top}" x2="{x(10.0**k):.1f}" y2="{bottom}" stroke="#ddd"/>')
        parts.append(f'<text x="{x(10.0**k):.1f}" y="{bottom + 15}" text-anchor="middle">10<tspan dy="-5" '
                     f'font-size="8">{k}</tspan></text>')
    for k in range(y_lo, y_hi + 1, 2):
        parts.append(f'<line x1="{left}" y1="{y(10.0**k):.1f}" x2="{right}" y2="{y(10.0**k):.1f}" stroke="#ddd"/>')
        parts.append(f'<text x="{left - 4}" y="{y(10.0**k) + 4:.1f}" text-anchor="end">10<tspan dy="-5" '
                     f'font-size="8">{k}</tspan></text>')
    parts.append(f'<text x="{left + 3}" y="{y(FLOOR) - 3:.1f}" font-size="9">error 0 or below 1e-16 (floor)</text>')
    parts.append(f'<line x1="{left}" y1="{y(FLOOR):.1f}" x2="{right}" y2="{y(FLOOR):.1f}" stroke="black" '
                 f'stroke-dasharray="2 2"/>')
    parts.append(f'<text x="{(left + right) / 2}" y="{height - 10}" text-anchor="middle">wall time (s)</text>')
    for i, (name, pts) in enumerate(sorted(data.items())):
        colour = COLOURS.get(name, "#555")
        path = " ".join(f"{x(t):.1f},{y(e):.1f}" for _, t, e in pts)
        parts.append(f'<polyline points="{path}" fill="none" stroke="{colour}" stroke-width="1.5"/>')
        for _, t, e in pts:
            shape = "rect" if e > 10.0 ** y_hi or e < FLOOR else "circle"
            if shape == "circle":
                parts.append(f'<circle cx="{x(t):.1f}" cy="{y(e):.1f}" r="2.5" fill="{colour}"/>')
            else:
                parts.append(f'<rect x="{x(t) - 3:.1f}" y="{y(e) - 3:.1f}" width="6" height="6" fill="none" '
                             f'stroke="{colour}"/>')
    return parts


def write_svg(rows):
    width, height = 380, 400
    names = list(PROBLEMS)
    total = width * len(names)
    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{total}" height="{height + 90}" '
             f'font-family="sans-serif" font-size="11">', f'<rect width="{total}" height="{height + 90}" fill="white"/>']
    for i, name in enumerate(names):
        parts.extend(panel(rows, name, i * width, width, height))
    parts.append(f'<text x="15" y="{height / 2}" transform="rotate(-90 15 {height / 2})" text-anchor="middle">'
                 f'max |q - q_ref| at t_end (rad)</text>')
    for i, name in enumerate(COLOURS):
        parts.append(f'<text x="{20 + (i % 4) * 250}" y="{height + 25 + 18 * (i // 4)}" fill="{COLOURS[name]}">'
                     f'&#9679; {name}</text>')
    parts.append(f'<text x="20" y="{height + 75}" font-size="10">each series from the loosest tolerance or largest '
                 f'step to the tightest; squares: error above 10 or diverged (drawn at 10), or error below the floor</text>')
    parts.append("</svg>\n")
    with open(SVG_OUT, "w") as fh:
        fh.write("\n".join(parts))


def summary(rows):
    for problem in PROBLEMS:
        data = points(rows, problem)
        for target in TARGETS:
            best = {}
            for name, pts in data.items():
                reach = [t for _, t, e in pts if e <= target]
                if reach:
                    best[name] = min(reach)
            ours = {k: v for k, v in best.items() if k.startswith("mechanica")}
            line = ", ".join(f"{k} {v:.3g} s" for k, v in sorted(best.items(), key=lambda kv: kv[1]))
            print(f"{problem}, error <= {target:g}: {line}")
            if ours:
                fastest = min(ours.values())
                ratios = ", ".join(f"{k} {v / fastest:.2g}" for k, v in best.items() if not k.startswith("mechanica"))
                print(f"  peer time / fastest mechanica: {ratios}")
    honest, total, lines = 0, 0, []
    for r in rows:
        if r["solver"] != "mechanica" or r["error_q"] in ("", None):
            continue
        total += 1
        slack = float(r["reference_error"])
        ok = (float(r["error_q"]) <= float(r["estimate_q"]) + slack
              and float(r["error_q_dot"]) <= float(r["estimate_q_dot"]) + slack)
        honest += ok
        if not ok:
            lines.append(f"  {r['problem']} {r['method']} {r['parameter']}: true {float(r['error_q']):.2e} / "
                         f"{float(r['error_q_dot']):.2e}, estimate {float(r['estimate_q']):.2e} / "
                         f"{float(r['estimate_q_dot']):.2e}")
    print(f"mechanica points with true error <= estimate (q and q', within the reference error): {honest} of {total}")
    print("\n".join(lines))


def main():
    if "--from-csv" in sys.argv:
        with open(CSV_OUT) as fh:
            rows = list(csv.DictReader(fh))
    else:
        with tempfile.TemporaryDirectory() as workdir:
            rows = collect(workdir)
        write_csv(rows)
    write_svg(rows)
    summary(rows)


if __name__ == "__main__":
    main()
