#!/usr/bin/env python3
"""Read a mechanica JSON report: the first mode's frequency and the coordinate that moves most.

    mechanica run robot.urdf --json > report.json
    python3 examples/read_report.py report.json      (or pipe the report in on stdin)

The layout is described in docs/json-report.md and docs/report.schema.json.
"""
import json
import sys

source = open(sys.argv[1]) if len(sys.argv) > 1 else sys.stdin
report = json.load(source)
if report.get("schema_version") != 2:
    sys.exit(f"expected a schema_version 2 report, got {report.get('schema_version')}")

for step in report["steps"]:
    if step["analysis"] != "modes":
        continue
    mode = step["modes"][0]
    shape = mode["shape"]
    largest = max(range(len(shape)), key=lambda k: abs(shape[k]))
    print(f"{step.get('scene', report['title'])}:")
    print(f"  stability: {step['stability']['verdict']}")
    print(f"  first mode: {mode['kind']}, f = {mode['frequency_hz']} Hz (omega^2 = {mode['omega_sq']} +- {mode['bound']})")
    print(f"  moves most: {step['coordinates'][largest]}")
