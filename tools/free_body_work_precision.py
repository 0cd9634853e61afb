#!/usr/bin/env python3
"""Work-precision of the free rigid body: mechanica's Lie-group integrators against SciPy's
solve_ivp (DOP853, Radau), in one invocation, on the problem of
crates/mechanica-dynamics/examples/free_body_work_precision.rs (moments (1, 2, 3), 1e-3 from the
separatrix, 100 periods).

Usage: pip install scipy mpmath; python3 tools/free_body_work_precision.py [--from-csv]
(--from-csv redraws the SVG and the summary from the committed CSV without running anything.)
Writes tools/free_body_work_precision.csv (both sides), tools/free_body_work_precision.svg
(attitude error against wall time, log-log) and prints, for the target attitude error 1e-10,
the fastest run of each method that reaches it, the ratio of SciPy DOP853's time to mechanica's
best, and how many mechanica points have a true error at or below their estimate.
"""

import csv
import math
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CSV_OUT = os.path.join(ROOT, "tools", "free_body_work_precision.csv")
SVG_OUT = os.path.join(ROOT, "tools", "free_body_work_precision.svg")
TARGET = 1e-10
COLOURS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2"]


def run_both(workdir):
    ours = os.path.join(workdir, "mechanica.csv")
    theirs = os.path.join(workdir, "scipy.csv")
    subprocess.run(["cargo", "run", "--release", "-q", "-p", "mechanica-dynamics", "--example",
                    "free_body_work_precision", "--", ours], cwd=ROOT, check=True)
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "free_body_scipy_reference.py"),
                    ours + ".problem.json", theirs], check=True)
    rows = []
    for path in (ours, theirs):
        with open(path) as f:
            rows.extend(csv.DictReader(f))
    return rows


def write_csv(rows):
    with open(CSV_OUT, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0].keys()), lineterminator="\n")
        writer.writeheader()
        writer.writerows(rows)


def series(rows):
    out = {}
    for r in rows:
        out.setdefault(f"{r['solver']} {r['method']}", []).append(
            (float(r["time_s"]), max(float(r["attitude_error"]), 1e-16)))
    return out


def write_svg(rows):
    width, height, margin = 720, 480, 60
    data = series(rows)
    times = [t for pts in data.values() for t, _ in pts]
    x_lo, x_hi = math.floor(math.log10(min(times))), math.ceil(math.log10(max(times)))
    y_lo, y_hi = -13, 1

    def x(t):
        return margin + (math.log10(t) - x_lo) / (x_hi - x_lo) * (width - 2 * margin)

    def y(e):
        e = min(max(e, 10.0**y_lo), 10.0**y_hi)
        return height - margin - (math.log10(e) - y_lo) / (y_hi - y_lo) * (height - 2 * margin)

    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
             f'font-family="sans-serif" font-size="11">',
             f'<rect width="{width}" height="{height}" fill="white"/>']
    for k in range(x_lo, x_hi + 1):
        parts.append(f'<line x1="{x(10.0**k):.1f}" y1="{margin}" x2="{x(10.0**k):.1f}" '
                     f'y2="{height - margin}" stroke="#ddd"/>')
        parts.append(f'<text x="{x(10.0**k):.1f}" y="{height - margin + 15}" '
                     f'text-anchor="middle">1e{k}</text>')
    for k in range(y_lo, y_hi + 1):
        parts.append(f'<line x1="{margin}" y1="{y(10.0**k):.1f}" x2="{width - margin}" '
                     f'y2="{y(10.0**k):.1f}" stroke="#ddd"/>')
        parts.append(f'<text x="{margin - 5}" y="{y(10.0**k) + 4:.1f}" text-anchor="end">1e{k}</text>')
    parts.append(f'<line x1="{margin}" y1="{y(TARGET):.1f}" x2="{width - margin}" y2="{y(TARGET):.1f}" '
                 f'stroke="black" stroke-dasharray="4 3"/>')
    parts.append(f'<text x="{width / 2}" y="{height - 20}" text-anchor="middle">wall time (s)</text>')
    parts.append(f'<text x="15" y="{height / 2}" transform="rotate(-90 15 {height / 2})" '
                 f'text-anchor="middle">attitude error after 100 periods (rad)</text>')
    parts.append(f'<text x="{width / 2}" y="20" text-anchor="middle">Free rigid body, 1e-3 from the '
                 f'separatrix: mechanica (Lie group) vs SciPy solve_ivp</text>')
    for i, (name, pts) in enumerate(sorted(data.items())):
        colour = COLOURS[i % len(COLOURS)]
        pts.sort()
        path = " ".join(f"{x(t):.1f},{y(e):.1f}" for t, e in pts)
        parts.append(f'<polyline points="{path}" fill="none" stroke="{colour}" stroke-width="1.5"/>')
        parts.extend(f'<circle cx="{x(t):.1f}" cy="{y(e):.1f}" r="2.5" fill="{colour}"/>' for t, e in pts)
        parts.append(f'<text x="{margin + 10}" y="{height - margin - 110 + 14 * i}" fill="{colour}">{name}</text>')
    parts.append("</svg>\n")
    with open(SVG_OUT, "w") as f:
        f.write("\n".join(parts))


def summary(rows):
    best = {}
    for r in rows:
        name = f"{r['solver']} {r['method']}"
        if float(r["attitude_error"]) <= TARGET:
            t = float(r["time_s"])
            if name not in best or t < best[name][0]:
                best[name] = (t, r["steps"], r["parameter"], float(r["attitude_error"]))
    for name in sorted(best):
        t, steps, parameter, error = best[name]
        print(f"{name}: {t:.4f} s ({steps} steps, parameter {parameter}) for attitude error {error:.2e}")
    ours = [v for k, v in best.items() if k.startswith("mechanica")]
    if ours and "scipy DOP853" in best:
        print(f"DOP853 time / mechanica best time at attitude error <= {TARGET:g}: "
              f"{best['scipy DOP853'][0] / min(ours)[0]:.1f}")
    else:
        dop = [r for r in rows if r["method"] == "DOP853"]
        floor = min(dop, key=lambda r: float(r["attitude_error"]))
        level = float(floor["attitude_error"])
        reach = [float(r["time_s"]) for r in rows
                 if r["solver"] == "mechanica" and float(r["attitude_error"]) <= level]
        print(f"SciPy DOP853 does not reach {TARGET:g}: its smallest attitude error is {level:.2e} "
              f"(rtol {floor['parameter']}, {float(floor['time_s']):.3f} s); mechanica's fastest run "
              f"at or below that error takes {min(reach):.4f} s, ratio {float(floor['time_s']) / min(reach):.1f}")
    estimated = [r for r in rows if r["estimate_attitude"]]
    honest = sum(float(r["attitude_error"]) <= float(r["estimate_attitude"])
                 and float(r["omega_error"]) <= float(r["estimate_omega"]) for r in estimated)
    print(f"mechanica points with true error <= estimate (attitude and w): {honest} of {len(estimated)}")


def main():
    if "--from-csv" in sys.argv:
        with open(CSV_OUT) as f:
            rows = list(csv.DictReader(f))
    else:
        with tempfile.TemporaryDirectory() as workdir:
            rows = run_both(workdir)
        write_csv(rows)
    write_svg(rows)
    summary(rows)


if __name__ == "__main__":
    main()
