//! Vertex welding on real robot meshes against trimesh, and on random closed meshes whose
//! vertices were duplicated and jittered.
//!
//! The reference numbers are trimesh's (an independent implementation: its own loader, its own
//! vertex merge by rounding, its own volume integrals), read from tools/mesh_weld_reference.json,
//! written by tools/mesh_weld_reference.py from the meshes in tests/data/robot-meshes/. Python
//! is not run here.

use mechanica_mass::io::load_mesh_welded;
use mechanica_mass::mesh::{MeshOptions, TriangleMesh, mesh_topology};
use mechanica_mass::tessellation::{box_mesh, torus_mesh, uv_sphere};
use mechanica_mass::{Amount, DEFAULT_WELD_TOLERANCE, MassError, MassProperties, weld_vertices};
use nalgebra::{Matrix3, Unit, UnitQuaternion, Vector3};
use proptest::prelude::*;
use serde_json::Value;
use std::path::PathBuf;

/// Agreement asked of mechanica and trimesh: 1e-9 relative.
const RELATIVE: f64 = 1e-9;

fn manifest_path(relative: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(relative)
}

fn reference() -> Value {
    let text = std::fs::read_to_string(manifest_path("../../tools/mesh_weld_reference.json")).expect("reference JSON");
    serde_json::from_str(&text).expect("valid JSON")
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect()
}

fn diagonal(mesh: &TriangleMesh) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for v in &mesh.vertices {
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    Vector3::from(hi).metric_distance(&Vector3::from(lo))
}

#[test]
fn robot_meshes_refused_by_an_exact_merge_are_welded_closed_and_match_trimesh() {
    let doc = reference();
    let meshes = doc["meshes"].as_array().expect("meshes");
    assert_eq!(meshes.len(), 8);
    let mut cracked = 0;
    for m in meshes {
        let name = m["file"].as_str().expect("name");
        let path = manifest_path("tests/data/robot-meshes").join(name);
        // Exact merge only: the boundary counted by numpy in the script.
        let (raw, none) = load_mesh_welded(&path, 0.0).expect("loads");
        assert_eq!(none.max_displacement, 0.0, "{name}");
        let raw_topology = mesh_topology(raw.vertices.len(), &raw.triangles).expect("in range");
        let expected_boundary = m["boundary_edges_exact_merge"].as_u64().expect("count") as usize;
        assert_eq!(raw_topology.boundary_edges, expected_boundary, "{name}");
        let raw_result = raw.mass_properties(Amount::Density(1.0), &MeshOptions::default());
        if expected_boundary > 0 {
            cracked += 1;
            assert!(matches!(raw_result, Err(MassError::OpenMesh { .. })), "{name}");
        }
        // The default weld, as `load_mesh` and the CLI apply it.
        let (mesh, weld) = load_mesh_welded(&path, DEFAULT_WELD_TOLERANCE).expect("loads");
        assert!(weld.max_displacement <= weld.tolerance, "{name}");
        assert_eq!(
            mesh.vertices.len() as u64,
            m["vertices"].as_u64().expect("count"),
            "{name}"
        );
        let r = mesh
            .mass_properties(Amount::Density(1.0), &MeshOptions::default())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(r.diagnostics.topology.is_closed() && !r.diagnostics.flipped, "{name}");
        compare_with_trimesh(name, &r.properties, r.measure, diagonal(&mesh), m);
    }
    assert_eq!(cracked, 5);
}

/// Volume relative to trimesh's, the centre relative to the mesh size, the inertia tensor
/// entry-wise relative to its largest entry.
fn compare_with_trimesh(name: &str, p: &MassProperties, volume: f64, diag: f64, m: &Value) {
    let v_ref = m["volume"].as_f64().expect("volume");
    assert!(
        (volume - v_ref).abs() <= RELATIVE * v_ref,
        "{name}: volume {volume} vs {v_ref}"
    );
    assert!((p.mass - v_ref).abs() <= RELATIVE * v_ref, "{name}: mass at density 1");
    let c_ref = Vector3::from_vec(numbers(&m["center_mass"]));
    let dc = (p.p_oc - c_ref).amax();
    assert!(dc <= RELATIVE * diag, "{name}: centre off by {dc} (diagonal {diag})");
    let j_ref = Matrix3::from_row_slice(&numbers(&m["inertia"]));
    let dj = (p.inertia_c - j_ref).amax();
    assert!(
        dj <= RELATIVE * j_ref.amax(),
        "{name}: inertia off by {dj} (largest entry {})",
        j_ref.amax()
    );
}

/// A closed test mesh: a box, a sphere or a torus, by `kind`.
fn closed_mesh(kind: u8) -> TriangleMesh {
    match kind % 3 {
        0 => box_mesh([1.0, 0.7, 0.4], [0.1, -0.2, 0.3]),
        1 => uv_sphere(0.8, 9, 13),
        _ => torus_mesh(1.0, 0.3, 14, 9),
    }
}

/// `mesh` scaled by `scale`, rotated about `axis` by `angle` and moved by `shift` × scale.
fn placed(mesh: &TriangleMesh, scale: f64, axis: [f64; 3], angle: f64, shift: [f64; 3]) -> TriangleMesh {
    let axis = Unit::try_new(Vector3::from(axis), 1e-6).unwrap_or(Vector3::z_axis());
    let q = UnitQuaternion::from_axis_angle(&axis, angle);
    let vertices = mesh
        .vertices
        .iter()
        .map(|v| (q * (Vector3::from(*v) * scale) + Vector3::from(shift) * scale).into())
        .collect();
    TriangleMesh {
        vertices,
        triangles: mesh.triangles.clone(),
    }
}

/// Small deterministic pseudo-random unit vectors and fractions (SplitMix64).
struct Noise(u64);

impl Noise {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    fn unit(&mut self) -> Vector3<f64> {
        loop {
            let v = Vector3::new(
                2.0 * self.next() - 1.0,
                2.0 * self.next() - 1.0,
                2.0 * self.next() - 1.0,
            );
            let n = v.norm();
            if n > 0.1 && n <= 1.0 {
                return v / n;
            }
        }
    }
}

/// A triangle soup of `mesh`: every corner its own vertex, displaced from the shared position
/// by `displacement(copy index of that position, noise)`.
fn soup(
    mesh: &TriangleMesh,
    mut displacement: impl FnMut(usize, &mut Noise) -> Vector3<f64>,
    seed: u64,
) -> TriangleMesh {
    let mut noise = Noise(seed);
    let mut copies = vec![0usize; mesh.vertices.len()];
    let mut out = TriangleMesh::default();
    for t in &mesh.triangles {
        let mut corners = [0u32; 3];
        for (c, &i) in t.iter().enumerate() {
            let d = displacement(copies[i as usize], &mut noise);
            copies[i as usize] += 1;
            corners[c] = out.vertices.len() as u32;
            out.vertices.push((Vector3::from(mesh.vertices[i as usize]) + d).into());
        }
        out.triangles.push(corners);
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Copies of every vertex jittered by less than t/2 (so pairwise within t) are welded back
    /// to exactly the original connectivity, and the mass properties match the unjittered mesh
    /// to O(tolerance); copies spread wider than t stay apart.
    #[test]
    fn jittered_copies_weld_back_to_the_original_mesh(
        kind in 0u8..3,
        log_scale in -6.0f64..6.0,
        log_tol in -10.0f64..-5.0,
        axis in proptest::array::uniform3(-1.0f64..1.0),
        angle in 0.0f64..std::f64::consts::TAU,
        shift in proptest::array::uniform3(-3.0f64..3.0),
        seed in any::<u64>(),
    ) {
        let mesh = placed(&closed_mesh(kind), 10f64.powf(log_scale), axis, angle, shift);
        let rel = 10f64.powf(log_tol);
        let exact = mesh.mass_properties(Amount::Density(1.0), &MeshOptions::default()).expect("closed");
        // Jitter each copy by < 0.49 t, t from the original mesh's diagonal: copies are then
        // within 0.98 t of each other, below the soup's own t (its diagonal differs by < t).
        let t = rel * diagonal(&mesh);
        let jittered = soup(&mesh, |_, n| n.unit() * (0.49 * t * n.next()), seed);
        let (welded, report) = weld_vertices(&jittered, rel).expect("welds");
        prop_assert_eq!(welded.vertices.len(), mesh.vertices.len());
        prop_assert_eq!(report.vertices_welded, jittered.vertices.len() - mesh.vertices.len());
        prop_assert_eq!(report.triangles_dropped, 0);
        prop_assert!(report.max_displacement <= report.tolerance);
        // The same connectivity: welded triangle k is original triangle k under one bijection
        // of the vertices.
        let mut original_of = vec![u32::MAX; welded.vertices.len()];
        for (w, o) in welded.triangles.iter().zip(&mesh.triangles) {
            for c in 0..3 {
                let slot = &mut original_of[w[c] as usize];
                prop_assert!(*slot == u32::MAX || *slot == o[c]);
                *slot = o[c];
            }
        }
        let mut seen = original_of.clone();
        seen.sort_unstable();
        seen.dedup();
        prop_assert_eq!(seen.len(), mesh.vertices.len());
        // Every vertex moved less than t/2 from its original: the properties change by O(t).
        let r = welded.mass_properties(Amount::Density(1.0), &MeshOptions::default()).expect("closed");
        let area_over_volume = shell_area(&mesh) / exact.measure;
        let volume_bound = area_over_volume * 0.5 * t * 1.01;
        prop_assert!((r.measure - exact.measure).abs() <= volume_bound * exact.measure,
            "volume {} vs {}", r.measure, exact.measure);
        prop_assert!((r.properties.p_oc - exact.properties.p_oc).amax() <= 8.0 * (1.0 + area_over_volume * diagonal(&mesh)) * t);
        let j_scale = exact.properties.inertia_c.amax();
        prop_assert!((r.properties.inertia_c - exact.properties.inertia_c).amax()
            <= 8.0 * (1.0 + area_over_volume * diagonal(&mesh)) * rel * j_scale);

        // Copies 1.5 t apart along one random line per copy index: nothing is near enough.
        let spread = soup(&mesh, |copy, n| n.unit() * (1.5 * t * copy as f64), seed);
        let (apart, report) = weld_vertices(&spread, rel).expect("welds");
        prop_assert_eq!(report.vertices_welded, 0);
        prop_assert_eq!(report.max_displacement, 0.0);
        prop_assert_eq!(apart.vertices.len(), spread.vertices.len());
    }
}

/// The surface area of a mesh (for the O(t) volume bound: moving a surface by at most h
/// changes the volume by at most about area × h).
fn shell_area(mesh: &TriangleMesh) -> f64 {
    mesh.triangles
        .iter()
        .map(|t| {
            let p = t.map(|i| Vector3::from(mesh.vertices[i as usize]));
            0.5 * (p[1] - p[0]).cross(&(p[2] - p[0])).norm()
        })
        .sum()
}
