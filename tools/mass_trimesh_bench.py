#!/usr/bin/env python3
"""Times trimesh's mass_properties on the tessellated tori that benches/benches/mass.rs uses.

Peer for the `mesh_mass_properties` criterion bench. The torus is built with the same
vertex and triangle order as mechanica_mass::tessellation::torus_mesh(2.0, 0.5, nu, nv).
For each size it reports the best of several runs of building a fresh Trimesh (process=False,
so no merging or repair) and evaluating mass_properties (trimesh caches the result on the object,
so each run uses a new object). It also prints the volume and inertia for a cross-check.

Usage:  pip install trimesh numpy && python3 tools/mass_trimesh_bench.py > tools/mass_trimesh_bench.out
"""
import json
import platform
import sys
import time

import numpy as np
import trimesh


def torus(ring, tube, nu, nv):
    i = np.arange(nu)
    j = np.arange(nv)
    u = 2.0 * np.pi * i / nu
    v = 2.0 * np.pi * j / nv
    uu, vv = np.meshgrid(u, v, indexing="ij")
    rho = ring + tube * np.cos(vv)
    verts = np.stack([rho * np.cos(uu), rho * np.sin(uu), tube * np.sin(vv)], axis=-1).reshape(-1, 3)
    ii, jj = np.meshgrid(i, j, indexing="ij")
    a = (ii % nu) * nv + (jj % nv)
    b = ((ii + 1) % nu) * nv + (jj % nv)
    c = (ii % nu) * nv + ((jj + 1) % nv)
    d = ((ii + 1) % nu) * nv + ((jj + 1) % nv)
    faces = np.stack([np.stack([a, b, d], -1), np.stack([a, d, c], -1)], axis=2).reshape(-1, 3)
    return verts, faces


def main():
    sizes = [(100, 100), (320, 320), (1024, 1024)]  # 20k, 205k, 2.1M triangles (as the bench)
    results = []
    for nu, nv in sizes:
        verts, faces = torus(2.0, 0.5, nu, nv)
        best = float("inf")
        repeats = 7 if len(faces) < 1_000_000 else 3
        for _ in range(repeats):
            t0 = time.perf_counter()
            mesh = trimesh.Trimesh(vertices=verts, faces=faces, process=False)
            props = mesh.mass_properties
            best = min(best, time.perf_counter() - t0)
        results.append(
            {
                "triangles": int(len(faces)),
                "best_seconds": best,
                "triangles_per_second": len(faces) / best,
                "volume": float(props["volume"]),
                "inertia_zz_density_1": float(props["inertia"][2][2]),
            }
        )
    out = {
        "tool": "trimesh " + trimesh.__version__,
        "numpy": np.__version__,
        "python": sys.version.split()[0],
        "machine": platform.machine(),
        "results": results,
    }
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
