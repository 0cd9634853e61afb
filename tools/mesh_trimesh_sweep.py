"""Every STL and OBJ mesh of example-robot-data through `mechanica mass`, against trimesh.

For each mesh that mechanica accepts as a solid (closed and consistently oriented after its
default weld), compares volume, centre of mass and inertia tensor about the centre (density 1)
with trimesh's `mass_properties` of the same file loaded with vertex merging, where trimesh
also finds the mesh watertight. Prints the largest relative differences over all compared
meshes and the refusals grouped by reason (mechanica refuses open and non-manifold meshes as
solids; trimesh computes a number for them, which is not a volume).

Usage:  pip install trimesh pin example-robot-data
        python3 tools/mesh_trimesh_sweep.py target/release/mechanica > tools/mesh_trimesh_sweep.out
"""
import collections
import glob
import json
import os
import re
import subprocess
import sys

import numpy as np
import pinocchio as pin
import trimesh


def robots_dir():
    prefix = os.path.normpath(os.path.join(os.path.dirname(pin.__file__), '..', '..', '..', '..'))
    return os.path.join(prefix, 'share', 'example-robot-data', 'robots')


def mechanica_mass(exe, path):
    run = subprocess.run([exe, '--json', 'mass', path, '--density', '1'], capture_output=True, text=True)
    if run.returncode != 0:
        return None, (run.stderr.strip().splitlines() or ['refused'])[0]
    steps = {s['analysis']: s for s in json.loads(run.stdout)['steps']}
    props = steps['mesh_mass_properties']
    return props, None


def main():
    exe = sys.argv[1]
    root = robots_dir()
    meshes = sorted(p for p in glob.glob(os.path.join(root, '**', '*'), recursive=True)
                    if p.lower().endswith(('.stl', '.obj')))
    worst = collections.defaultdict(float)
    compared, not_watertight, not_read, inside_out, refusals = 0, 0, 0, 0, collections.Counter()
    for path in meshes:
        props, refusal = mechanica_mass(exe, path)
        if refusal is not None:
            reason = refusal.split(path + ': ', 1)[-1]
            refusals[re.sub(r'\d+', 'N', reason.split(' (')[0])] += 1
            continue
        try:
            # Geometry only: materials and textures would need image libraries.
            mesh = trimesh.load(path, force='mesh', skip_materials=True)
        except Exception:  # a file trimesh cannot read
            not_read += 1
            continue
        if not mesh.is_watertight:
            not_watertight += 1
            continue
        reference = mesh.mass_properties
        volume = abs(reference['volume'])
        scale = volume ** (1.0 / 3.0)
        measure = props['measure']
        worst['volume'] = max(worst['volume'], abs(measure - volume) / volume)
        centre = np.array(props['centre_of_mass'])
        worst['centre / size'] = max(worst['centre / size'],
                                     np.abs(centre - reference['center_mass']).max() / scale)
        inertia = np.array(props['inertia'])
        # trimesh integrates an inside-out file (inward normals) to a negative volume and
        # tensor; mechanica turns it outward (its diagnostics report `flipped`).
        sign = 1.0 if reference['volume'] > 0 else -1.0
        inside_out += sign < 0
        tensor = sign * np.array(reference['inertia'])
        worst['inertia'] = max(worst['inertia'], np.abs(inertia - tensor).max() / np.abs(tensor).max())
        compared += 1
    print(f'# trimesh {trimesh.__version__}: {len(meshes)} meshes, {compared} solids compared '
          f'({inside_out} inside out; {not_watertight} accepted by mechanica but not watertight for trimesh, '
          f'{not_read} trimesh could not read)')
    for key, value in worst.items():
        print(f'max relative difference, {key}: {value:.1e}')
    print('# refused by mechanica as solids:')
    for reason, count in refusals.most_common():
        print(f'{count} {reason}')


if __name__ == '__main__':
    main()
