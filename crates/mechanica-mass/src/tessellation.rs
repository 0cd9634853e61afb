//! Closed, outward-oriented triangle meshes of simple shapes: for tests, benchmarks and quick
//! approximate bodies. Every mesh here is a closed 2-manifold.

use crate::mesh::TriangleMesh;
use std::f64::consts::PI;

/// An axis-aligned box with edge lengths `size` centred at `centre`: 8 vertices, 12 triangles.
pub fn box_mesh(size: [f64; 3], centre: [f64; 3]) -> TriangleMesh {
    let mut vertices = Vec::with_capacity(8);
    for k in 0..8u32 {
        let s = |bit: u32, axis: usize| {
            let sign = if k & bit != 0 { 0.5 } else { -0.5 };
            centre[axis] + sign * size[axis]
        };
        vertices.push([s(1, 0), s(2, 1), s(4, 2)]);
    }
    // Vertex k has x bit 1, y bit 2, z bit 4. Faces counter-clockwise seen from outside.
    let triangles = vec![
        [0, 2, 3],
        [0, 3, 1], // z = −
        [4, 5, 7],
        [4, 7, 6], // z = +
        [0, 1, 5],
        [0, 5, 4], // y = −
        [2, 6, 7],
        [2, 7, 3], // y = +
        [0, 4, 6],
        [0, 6, 2], // x = −
        [1, 3, 7],
        [1, 7, 5], // x = +
    ];
    TriangleMesh { vertices, triangles }
}

/// A latitude-longitude sphere of radius `radius` centred at the origin with `stacks` ≥ 2
/// latitude bands and `slices` ≥ 3 meridians: 2·slices·(stacks − 1) triangles.
pub fn uv_sphere(radius: f64, stacks: u32, slices: u32) -> TriangleMesh {
    let stacks = stacks.max(2);
    let slices = slices.max(3);
    let mut vertices = vec![[0.0, 0.0, -radius]];
    for i in 1..stacks {
        let theta = PI * f64::from(i) / f64::from(stacks) - PI / 2.0;
        for j in 0..slices {
            let phi = 2.0 * PI * f64::from(j) / f64::from(slices);
            vertices.push([
                radius * theta.cos() * phi.cos(),
                radius * theta.cos() * phi.sin(),
                radius * theta.sin(),
            ]);
        }
    }
    let top = vertices.len() as u32;
    vertices.push([0.0, 0.0, radius]);
    let ring = |i: u32, j: u32| 1 + (i - 1) * slices + (j % slices);
    let mut triangles = Vec::new();
    for j in 0..slices {
        triangles.push([0, ring(1, j + 1), ring(1, j)]);
        triangles.push([top, ring(stacks - 1, j), ring(stacks - 1, j + 1)]);
    }
    for i in 1..stacks - 1 {
        for j in 0..slices {
            let (a, b, c, d) = (ring(i, j), ring(i, j + 1), ring(i + 1, j), ring(i + 1, j + 1));
            triangles.push([a, b, d]);
            triangles.push([a, d, c]);
        }
    }
    TriangleMesh { vertices, triangles }
}

/// A torus around the z axis with ring radius `ring_radius`, tube radius `tube_radius`, and
/// `ring_segments` × `tube_segments` quads (2× as many triangles).
pub fn torus_mesh(ring_radius: f64, tube_radius: f64, ring_segments: u32, tube_segments: u32) -> TriangleMesh {
    let (nu, nv) = (ring_segments.max(3), tube_segments.max(3));
    let mut vertices = Vec::with_capacity((nu * nv) as usize);
    for i in 0..nu {
        let u = 2.0 * PI * f64::from(i) / f64::from(nu);
        for j in 0..nv {
            let v = 2.0 * PI * f64::from(j) / f64::from(nv);
            let rho = ring_radius + tube_radius * v.cos();
            vertices.push([rho * u.cos(), rho * u.sin(), tube_radius * v.sin()]);
        }
    }
    let id = |i: u32, j: u32| (i % nu) * nv + (j % nv);
    let mut triangles = Vec::with_capacity((2 * nu * nv) as usize);
    for i in 0..nu {
        for j in 0..nv {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i, j + 1), id(i + 1, j + 1));
            triangles.push([a, b, d]);
            triangles.push([a, d, c]);
        }
    }
    TriangleMesh { vertices, triangles }
}
