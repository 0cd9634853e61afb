#!/usr/bin/env python3
"""Reference mass properties of real robot meshes from trimesh, for mechanica's vertex welding.

The meshes are the copies in crates/mechanica-mass/tests/data/robot-meshes/ (taken from the
example-robot-data package, see the README there). Five of them are closed solids whose
patches meet along hairline cracks (bit-different copies of the same corner, e.g. 0 and
1e-18): merging only bit-identical positions leaves them with 12-174 boundary edges, and
trimesh's default vertex merge (process=True) closes them. The others are accepted either way.

For each mesh this writes, to tools/mesh_weld_reference.json:
  file                       name in the test-data folder
  sha256                     of the file's bytes
  boundary_edges_exact_merge edges used by one triangle after merging bit-identical positions
                             only (counted here with numpy, independently of mechanica)
  watertight                 trimesh's is_watertight after its default processing
  vertices                   trimesh's vertex count after processing
  volume, center_mass, inertia
                             trimesh's mass_properties at density 1: volume (file units^3),
                             centre of mass, inertia tensor about the centre of mass
                             (row-major 3 x 3, products of inertia with the minus sign).

Run: pip install trimesh numpy && python3 tools/mesh_weld_reference.py
"""

import hashlib
import json
import pathlib

import numpy as np
import trimesh

ROOT = pathlib.Path(__file__).resolve().parent.parent
DATA = ROOT / "crates" / "mechanica-mass" / "tests" / "data" / "robot-meshes"
OUT = ROOT / "tools" / "mesh_weld_reference.json"

MESHES = [
    # Refused by an exact-only merge (hairline cracks).
    "allegro_link_3.0.stl",
    "allegro_link_15.0_tip.stl",
    "solo12_lower_leg_left_side.stl",
    "solo12_upper_leg_left_side.stl",
    "tiago_finger_flex_tip_collision.stl",
    # Closed with an exact merge already.
    "allegro_link_0.0.stl",
    "tiago_thumb_abd_collision.stl",
    "solo_lower_leg_left_side.obj",
]


def boundary_edges_exact(path):
    """Edges used by one non-degenerate triangle after merging bit-identical positions."""
    raw = trimesh.load(path, process=False, force="mesh")
    _, inverse = np.unique(np.asarray(raw.vertices), axis=0, return_inverse=True)
    faces = inverse.reshape(-1)[np.asarray(raw.faces)]
    distinct = (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 2] != faces[:, 0])
    faces = faces[distinct]
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return int(np.sum(counts == 1))


def reference(name):
    path = DATA / name
    mesh = trimesh.load(path, process=True, force="mesh")
    props = mesh.mass_properties
    return {
        "file": name,
        "sha256": hashlib.sha256(path.read_bytes()).hexdigest(),
        "boundary_edges_exact_merge": boundary_edges_exact(path),
        "watertight": bool(mesh.is_watertight),
        "vertices": int(len(mesh.vertices)),
        "volume": float(props["volume"]),
        "center_mass": [float(x) for x in props["center_mass"]],
        "inertia": [float(x) for x in np.asarray(props["inertia"]).reshape(-1)],
    }


def main():
    meshes = [reference(name) for name in MESHES]
    document = {
        "source": "trimesh " + trimesh.__version__ + ", load(process=True), mass_properties at density 1",
        "meshes": meshes,
    }
    OUT.write_text(json.dumps(document, indent=1) + "\n")
    for m in meshes:
        print(
            f"{m['file']:40s} exact-merge boundary edges {m['boundary_edges_exact_merge']:4d}  "
            f"watertight {m['watertight']}  volume {m['volume']:.9e}"
        )


if __name__ == "__main__":
    main()
