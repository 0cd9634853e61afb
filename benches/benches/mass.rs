//! Criterion benchmarks: mass properties.
//!
//! `mesh_mass_properties`: throughput in triangles per second of the full solid pipeline
//! (vertex and index checks, edge topology, exact volume integrals) on tessellated tori of
//! 20k, 205k and 2.1M triangles, the same meshes that tools/mass_trimesh_bench.py times with
//! trimesh (committed output: tools/mass_trimesh_bench.out). `mesh_topology` times the
//! closedness/orientation check alone, to show how the total splits, and
//! `mesh_mass_properties_known_topology` the pipeline without it (a deforming body whose
//! connectivity was checked once).
//!
//! `mass_matrix_crba_44dof`: forward kinematics plus the composite-rigid-body mass matrix of a
//! 44-DOF humanoid-like tree; tools/mass_pinocchio_bench.py builds the same tree in Pinocchio
//! and times `pin.crba` (committed output: tools/mass_pinocchio_bench.out). Ratios:
//! tools/mass_bench_comparison.md and docs/benchmarks.md.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use mechanica::kinematics::nalgebra::{Isometry3, Vector3};
use mechanica::kinematics::tree::{Joint, KinematicTree, TreeBuilder};
use mechanica::mass::mechanism::TreeMass;
use mechanica::mass::mesh::{MeshOptions, TopologySource, mesh_topology};
use mechanica::mass::tessellation::torus_mesh;
use mechanica::mass::{Amount, MassProperties, primitives};
use std::hint::black_box;

const SIZES: [(u32, u32); 3] = [(100, 100), (320, 320), (1024, 1024)];

fn meshes(c: &mut Criterion) {
    let mut group = c.benchmark_group("mesh_mass_properties");
    group.sample_size(10);
    for (nu, nv) in SIZES {
        let mesh = torus_mesh(2.0, 0.5, nu, nv);
        let n = mesh.triangles.len() as u64;
        group.throughput(Throughput::Elements(n));
        group.bench_with_input(BenchmarkId::new("mechanica", n), &mesh, |b, mesh| {
            b.iter(|| {
                mesh.mass_properties(Amount::Density(1.0), &MeshOptions::default())
                    .map(|r| r.properties.inertia_c[(2, 2)])
            })
        });
    }
    group.finish();
    // A deforming body re-integrated with the topology of an earlier call (TopologySource::Known).
    let mut group = c.benchmark_group("mesh_mass_properties_known_topology");
    group.sample_size(10);
    for (nu, nv) in SIZES {
        let mesh = torus_mesh(2.0, 0.5, nu, nv);
        let n = mesh.triangles.len() as u64;
        let Ok(first) = mesh.mass_properties(Amount::Density(1.0), &MeshOptions::default()) else {
            panic!("the benchmark torus is closed")
        };
        let known = MeshOptions {
            topology: TopologySource::Known(first.diagnostics.topology),
            ..MeshOptions::default()
        };
        group.throughput(Throughput::Elements(n));
        group.bench_with_input(BenchmarkId::new("mechanica", n), &mesh, |b, mesh| {
            b.iter(|| {
                mesh.mass_properties(Amount::Density(1.0), black_box(&known))
                    .map(|r| r.properties.inertia_c[(2, 2)])
            })
        });
    }
    group.finish();
    let mut group = c.benchmark_group("mesh_topology");
    group.sample_size(10);
    for (nu, nv) in SIZES {
        let mesh = torus_mesh(2.0, 0.5, nu, nv);
        let n = mesh.triangles.len() as u64;
        group.throughput(Throughput::Elements(n));
        group.bench_with_input(BenchmarkId::new("mechanica", n), &mesh, |b, mesh| {
            b.iter(|| mesh_topology(mesh.vertices.len(), black_box(&mesh.triangles)).map(|t| t.boundary_edges))
        });
    }
    group.finish();
}

fn composition(c: &mut Criterion) {
    let parts: Vec<MassProperties> = (0..64)
        .map(|k| {
            let mut p = primitives::solid_box(1.0, 2.0, 3.0, Amount::Mass(1.0 + f64::from(k))).expect("valid box");
            p.p_oc.x = f64::from(k);
            p
        })
        .collect();
    c.bench_function("sum_of_64_bodies", |b| {
        b.iter(|| MassProperties::sum(black_box(&parts)))
    });
    let body = parts[5];
    c.bench_function("principal_axes", |b| b.iter(|| black_box(&body).principal_axes()));
}

/// A 44-DOF humanoid-like tree: a free base (6) and 38 revolute joints in five branches
/// (two legs of 7, two arms of 8, a torso-and-head chain of 8), each body a solid box.
fn humanoid() -> (KinematicTree, TreeMass) {
    let mut b = TreeBuilder::new();
    let base = b.add_body(None, Joint::Free, Isometry3::identity());
    let axes = [Vector3::x(), Vector3::y(), Vector3::z()];
    for (branch, length) in [7usize, 7, 8, 8, 8].into_iter().enumerate() {
        let mut parent = base;
        for j in 0..length {
            let offset = if j == 0 {
                Vector3::new(0.1 * branch as f64 - 0.2, 0.0, 0.0)
            } else {
                Vector3::new(0.0, 0.0, -0.3)
            };
            parent = b.add_body(
                Some(parent),
                Joint::Revolute {
                    axis: axes[(branch + j) % 3],
                },
                Isometry3::translation(offset.x, offset.y, offset.z),
            );
        }
    }
    let tree = b.build().expect("valid tree");
    let bodies = (0..tree.body_count())
        .map(|_| {
            let mut p = primitives::solid_box(0.1, 0.1, 0.3, Amount::Mass(2.0)).expect("box");
            p.p_oc.z = -0.15;
            p
        })
        .collect();
    let mass = TreeMass::new(&tree, bodies).expect("bodies");
    (tree, mass)
}

fn mass_matrix(c: &mut Criterion) {
    let (tree, mut mass) = humanoid();
    let n = tree.dof();
    let q: Vec<f64> = (0..n).map(|k| 0.1 * (k as f64).sin()).collect();
    let mut ws = tree.workspace();
    let mut a = vec![0.0; n * n];
    c.bench_function(&format!("mass_matrix_crba_{n}dof"), |bench| {
        bench.iter(|| {
            tree.update_positions(&mut ws, black_box(&q)).expect("positions");
            mass.mass_matrix(&tree, &ws, &mut a).expect("mass matrix");
            a[0]
        })
    });
}

criterion_group!(benches, meshes, composition, mass_matrix);
criterion_main!(benches);
