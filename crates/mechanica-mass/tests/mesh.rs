//! Mesh mass properties against closed forms (boxes, spheres, tori, cube shells), invariance
//! under rigid motion, topology diagnostics and bad input.

use mechanica_mass::mesh::{DegeneratePolicy, InsideOutPolicy, MeshModel, MeshOptions, OpenMeshPolicy, TriangleMesh};
use mechanica_mass::tessellation::{box_mesh, torus_mesh, uv_sphere};
use mechanica_mass::{Amount, MassError, MassProperties, primitives};
use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use proptest::prelude::*;

const EPS: f64 = f64::EPSILON;

fn solid(mesh: &TriangleMesh, amount: Amount) -> MassProperties {
    mesh.mass_properties(amount, &MeshOptions::default())
        .expect("valid closed mesh")
        .properties
}

fn box_inertia(m: f64, a: f64, b: f64, c: f64) -> Matrix3<f64> {
    Matrix3::from_diagonal(&Vector3::new(
        m * (b * b + c * c) / 12.0,
        m * (a * a + c * c) / 12.0,
        m * (a * a + b * b) / 12.0,
    ))
}

proptest! {
    /// A cube of side 2^k (k up to 200, volume to 2^600) given a mass of 2^j (j down to −1070,
    /// subnormal): I = m s²/6 whenever that is a normal number, though the density m/s³ may
    /// underflow (it was formed first, and a light body of large volume got a zero tensor).
    #[test]
    fn a_light_cube_of_large_volume_keeps_its_moments(k in 0i32..200, j in -1070i32..0) {
        let side = 2f64.powi(k);
        let mass = 2f64.powi(j / 2) * 2f64.powi(j - j / 2);
        let want = mass * side * side / 6.0;
        prop_assume!(want >= f64::MIN_POSITIVE && want.is_finite());
        let mesh = box_mesh([side, side, side], [0.0, 0.0, 0.0]);
        let p = solid(&mesh, Amount::Mass(mass));
        for axis in 0..3 {
            let got = p.inertia_c[(axis, axis)];
            prop_assert!((got - want).abs() <= 64.0 * EPS * want, "I = {:e}, want {:e}", got, want);
        }
    }
}

#[test]
fn unit_cube_is_exact_at_the_origin_and_at_1e6() {
    for offset in [0.0, 1e6, -3.7e6] {
        let mesh = box_mesh([1.0, 1.0, 1.0], [offset, offset, offset]);
        let r = mesh
            .mass_properties(Amount::Density(2.0), &MeshOptions::default())
            .expect("closed");
        assert!((r.measure - 1.0).abs() <= 8.0 * EPS, "volume {}", r.measure);
        assert!(r.relative_error_bound <= 1e-12);
        let p = r.properties;
        assert!((p.mass - 2.0).abs() <= 16.0 * EPS);
        assert!((p.p_oc - Vector3::repeat(offset)).norm() <= 8.0 * EPS * offset.abs().max(1.0));
        let expected = box_inertia(2.0, 1.0, 1.0, 1.0);
        assert!(
            (p.inertia_c - expected).norm() <= 16.0 * EPS * expected.norm(),
            "{} vs {expected}",
            p.inertia_c
        );
        assert!(!r.diagnostics.flipped && r.diagnostics.topology.is_closed());
    }
}

proptest! {
    #[test]
    fn rotated_off_origin_box_equals_r_diag_rt(
        a in 0.1f64..3.0, b in 0.1f64..3.0, c in 0.1f64..3.0,
        r1 in -3.1f64..3.1, r2 in -1.5f64..1.5, r3 in -3.1f64..3.1,
        t in proptest::array::uniform3(-1e3f64..1e3),
    ) {
        let q = UnitQuaternion::from_euler_angles(r1, r2, r3);
        let mut mesh = box_mesh([a, b, c], [0.0; 3]);
        for v in &mut mesh.vertices {
            let w = q * Vector3::from(*v) + Vector3::from(t);
            *v = [w.x, w.y, w.z];
        }
        let p = solid(&mesh, Amount::Mass(3.0));
        let r = q.to_rotation_matrix();
        let expected = r.matrix() * box_inertia(3.0, a, b, c) * r.matrix().transpose();
        // Rotating the vertices rounds them at ε·|t|; that perturbs the box by ε|t|/size.
        let size = a.min(b).min(c);
        let tol = 64.0 * EPS * (1.0 + 1e3 / size) * expected.norm();
        prop_assert!((p.inertia_c - expected).norm() <= tol, "{} vs {}", p.inertia_c, expected);
        prop_assert!((p.p_oc - Vector3::from(t)).norm() <= 64.0 * EPS * 1e3);
    }
}

#[test]
fn three_stacked_cubes_equal_one_1x3x1_box() {
    let mut mesh = TriangleMesh::default();
    for k in 0..3 {
        let cube = box_mesh([1.0, 1.0, 1.0], [0.5, 0.5 + f64::from(k), 0.5]);
        let base = mesh.vertices.len() as u32;
        mesh.vertices.extend(cube.vertices);
        mesh.triangles
            .extend(cube.triangles.iter().map(|t| [t[0] + base, t[1] + base, t[2] + base]));
    }
    let p = solid(&mesh, Amount::Density(1.0));
    assert!((p.mass - 3.0).abs() <= 16.0 * EPS);
    assert!((p.p_oc - Vector3::new(0.5, 1.5, 0.5)).norm() <= 16.0 * EPS);
    let expected = box_inertia(3.0, 1.0, 3.0, 1.0);
    assert!((p.inertia_c - expected).norm() <= 32.0 * EPS * expected.norm());
}

/// Relative error of the inertia (Frobenius) of a mesh against a closed form.
fn inertia_error(mesh: &TriangleMesh, exact: &MassProperties) -> f64 {
    let p = solid(mesh, Amount::Density(1.0));
    // Compare at equal density: the volume error is part of the discretisation error.
    (p.inertia_c - exact.inertia_c).norm() / exact.inertia_c.norm()
}

#[test]
fn tessellated_sphere_and_torus_converge_at_second_order() {
    let sphere = primitives::sphere(1.5, Amount::Density(1.0)).expect("ok");
    let torus = primitives::torus(2.0, 0.5, Amount::Density(1.0)).expect("ok");
    for n in [16u32, 32, 64] {
        // Inscribed polygons lose O(h²) of the volume: halving h divides the error by 4.
        let e1 = inertia_error(&uv_sphere(1.5, n, 2 * n), &sphere);
        let e2 = inertia_error(&uv_sphere(1.5, 2 * n, 4 * n), &sphere);
        let ratio = e1 / e2;
        assert!((3.6..4.4).contains(&ratio), "sphere n={n}: {e1} / {e2} = {ratio}");
        let e1 = inertia_error(&torus_mesh(2.0, 0.5, 4 * n, n), &torus);
        let e2 = inertia_error(&torus_mesh(2.0, 0.5, 8 * n, 2 * n), &torus);
        let ratio = e1 / e2;
        assert!((3.6..4.4).contains(&ratio), "torus n={n}: {e1} / {e2} = {ratio}");
    }
    // The symmetric mesh has its centre at the origin to rounding.
    let p = solid(&uv_sphere(1.5, 64, 128), Amount::Density(1.0));
    assert!(p.p_oc.norm() <= 1e-14);
}

#[test]
fn inside_out_mesh_is_flipped_or_rejected() {
    let mut mesh = box_mesh([1.0, 2.0, 3.0], [5.0, 0.0, 0.0]);
    let good = solid(&mesh, Amount::Mass(1.0));
    for t in &mut mesh.triangles {
        t.swap(1, 2);
    }
    let r = mesh
        .mass_properties(Amount::Mass(1.0), &MeshOptions::default())
        .expect("flipped");
    assert!(r.diagnostics.flipped);
    assert_eq!(r.properties, good);
    let reject = MeshOptions {
        inside_out: InsideOutPolicy::Reject,
        ..MeshOptions::default()
    };
    assert!(matches!(
        mesh.mass_properties(Amount::Mass(1.0), &reject),
        Err(MassError::InsideOut { volume }) if (volume + 6.0).abs() < 1e-12
    ));
}

#[test]
fn open_mesh_is_reported_with_its_boundary_or_taken_as_a_shell() {
    let mut mesh = box_mesh([1.0, 1.0, 1.0], [0.0; 3]);
    mesh.triangles.pop();
    assert_eq!(
        mesh.mass_properties(Amount::Density(1.0), &MeshOptions::default()),
        Err(MassError::OpenMesh {
            boundary_edges: 3,
            non_manifold_edges: 0
        })
    );
    let shell = MeshOptions {
        open_mesh: OpenMeshPolicy::Shell,
        ..MeshOptions::default()
    };
    let r = mesh.mass_properties(Amount::Density(1.0), &shell).expect("shell");
    assert_eq!(r.model, MeshModel::Shell);
    assert_eq!(r.diagnostics.topology.boundary_edges, 3);
    assert!((r.measure - 5.5).abs() <= 8.0 * EPS);
}

#[test]
fn closed_cube_shell_matches_5_18_m_a_squared() {
    // Hollow cube with thin walls: I = 5/18 m a² about every axis through the centre.
    let a = 2.0;
    let mesh = box_mesh([a, a, a], [1e6, 0.0, -1e6]);
    let options = MeshOptions {
        model: MeshModel::Shell,
        ..MeshOptions::default()
    };
    let r = mesh.mass_properties(Amount::Mass(6.0), &options).expect("shell");
    assert!((r.measure - 6.0 * a * a).abs() <= 16.0 * EPS * 24.0);
    let expected = Matrix3::identity() * (5.0 / 18.0 * 6.0 * a * a);
    assert!((r.properties.inertia_c - expected).norm() <= 32.0 * EPS * expected.norm());
    assert!((r.properties.p_oc - Vector3::new(1e6, 0.0, -1e6)).norm() <= 1e6 * 4.0 * EPS);
}

#[test]
fn misoriented_and_non_manifold_meshes_are_named() {
    let mut mesh = box_mesh([1.0, 1.0, 1.0], [0.0; 3]);
    mesh.triangles[0].swap(1, 2);
    assert_eq!(
        mesh.mass_properties(Amount::Density(1.0), &MeshOptions::default()),
        Err(MassError::InconsistentOrientation { misoriented_edges: 3 })
    );
    // A fin: one extra triangle on an existing edge makes it non-manifold and adds 2 boundary edges.
    let mut mesh = box_mesh([1.0, 1.0, 1.0], [0.0; 3]);
    mesh.vertices.push([3.0, 3.0, 3.0]);
    mesh.triangles.push([0, 2, 8]);
    assert_eq!(
        mesh.mass_properties(Amount::Density(1.0), &MeshOptions::default()),
        Err(MassError::OpenMesh {
            boundary_edges: 2,
            non_manifold_edges: 1
        })
    );
}

#[test]
fn bad_input_is_named() {
    let mesh = box_mesh([1.0, 1.0, 1.0], [0.0; 3]);
    let opts = MeshOptions::default();
    let mut nan = mesh.clone();
    nan.vertices[5][1] = f64::NAN;
    assert!(matches!(
        nan.mass_properties(Amount::Density(1.0), &opts),
        Err(MassError::NonFiniteVertex { vertex: 5, value }) if value.is_nan()
    ));
    let mut range = mesh.clone();
    range.triangles[7][2] = 8;
    assert_eq!(
        range.mass_properties(Amount::Density(1.0), &opts),
        Err(MassError::IndexOutOfRange {
            triangle: 7,
            corner: 2,
            index: 8,
            vertex_count: 8
        })
    );
    assert_eq!(
        mesh.mass_properties(Amount::Density(0.0), &opts),
        Err(MassError::NonPositiveDensity(0.0))
    );
    assert_eq!(
        mesh.mass_properties(Amount::Density(-2.0), &opts),
        Err(MassError::NonPositiveDensity(-2.0))
    );
    assert_eq!(
        TriangleMesh::default().mass_properties(Amount::Density(1.0), &opts),
        Err(MassError::EmptyMesh)
    );
    // Degenerate triangles: a repeated index and a zero-area sliver on collinear points.
    let mut degenerate = mesh.clone();
    degenerate.triangles.push([3, 3, 5]);
    degenerate.vertices.push([0.5, 0.5, 0.5]);
    degenerate.vertices.push([0.25, 0.25, 0.25]);
    degenerate.triangles.push([7, 9, 8]);
    degenerate.triangles.push([7, 8, 9]);
    let r = degenerate
        .mass_properties(Amount::Density(1.0), &opts)
        .expect("skipped");
    assert_eq!(r.diagnostics.degenerate_triangles, 3);
    assert_eq!(r.properties, solid(&mesh, Amount::Density(1.0)));
    let reject = MeshOptions {
        degenerate: DegeneratePolicy::Reject,
        ..opts
    };
    assert_eq!(
        degenerate.mass_properties(Amount::Density(1.0), &reject),
        Err(MassError::DegenerateTriangles { count: 3, first: 12 })
    );
    // A closed two-sided triangle encloses no volume.
    let flat = TriangleMesh {
        vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        triangles: vec![[0, 1, 2], [0, 2, 1]],
    };
    assert!(matches!(
        flat.mass_properties(Amount::Density(1.0), &opts),
        Err(MassError::ZeroVolume { .. })
    ));
}

#[test]
fn large_meshes_give_the_same_bits_whatever_the_block_scheduling() {
    // Above 16 blocks the integration runs on several threads; the block sums are reduced in
    // order, so the result must equal a second run bit for bit and approximate the torus.
    let mesh = torus_mesh(2.0, 0.5, 1024, 128);
    let a = solid(&mesh, Amount::Density(1.0));
    let b = solid(&mesh, Amount::Density(1.0));
    assert_eq!(a, b);
    let exact = primitives::torus(2.0, 0.5, Amount::Density(1.0)).expect("ok");
    assert!((a.inertia_c - exact.inertia_c).norm() / exact.inertia_c.norm() < 1e-3);
}

#[cfg(feature = "io")]
mod files {
    use super::*;
    use mechanica_mass::io::{read_obj, read_stl};

    fn expected() -> MassProperties {
        solid(&box_mesh([1.0, 2.0, 3.0], [0.0; 3]), Amount::Density(1.0))
    }

    fn close(p: &MassProperties, q: &MassProperties) -> bool {
        // The STL path rounds coordinates to f32; these are exact in f32.
        (p.mass - q.mass).abs() <= 1e-14 && (p.inertia_c - q.inertia_c).norm() <= 1e-14
    }

    #[test]
    fn ascii_and_binary_stl_load_as_closed_meshes() {
        let mesh = box_mesh([1.0, 2.0, 3.0], [0.0; 3]);
        let mut ascii = String::from("solid box\n");
        for t in &mesh.triangles {
            ascii.push_str("facet normal 0 0 0\nouter loop\n");
            for &i in t {
                let v = mesh.vertices[i as usize];
                ascii.push_str(&format!("vertex {} {} {}\n", v[0], v[1], v[2]));
            }
            ascii.push_str("endloop\nendfacet\n");
        }
        ascii.push_str("endsolid box\n");
        let loaded = read_stl(&mut std::io::Cursor::new(ascii.into_bytes())).expect("ascii stl");
        assert_eq!(loaded.vertices.len(), 8);
        assert!(close(&solid(&loaded, Amount::Density(1.0)), &expected()));

        let triangles: Vec<stl_io::Triangle> = mesh
            .triangles
            .iter()
            .map(|t| stl_io::Triangle {
                normal: stl_io::Normal::new([0.0; 3]),
                vertices: t.map(|i| {
                    let v = mesh.vertices[i as usize];
                    stl_io::Vertex::new([v[0] as f32, v[1] as f32, v[2] as f32])
                }),
            })
            .collect();
        let mut bytes = Vec::new();
        stl_io::write_stl(&mut bytes, triangles.iter()).expect("write");
        let loaded = read_stl(&mut std::io::Cursor::new(bytes)).expect("binary stl");
        assert!(close(&solid(&loaded, Amount::Density(1.0)), &expected()));
        assert!(matches!(
            read_stl(&mut std::io::Cursor::new(b"solid x\nfacet nonsense".to_vec())),
            Err(MassError::Parse(_))
        ));
    }

    #[test]
    fn obj_quads_in_two_groups_are_triangulated_and_merged() {
        let obj = "v -0.5 -1 -1.5\nv 0.5 -1 -1.5\nv -0.5 1 -1.5\nv 0.5 1 -1.5\n\
                   v -0.5 -1 1.5\nv 0.5 -1 1.5\nv -0.5 1 1.5\nv 0.5 1 1.5\n\
                   o first\nf 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\n\
                   o second\nv 0.5 1 1.5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
        let loaded = read_obj(&mut std::io::Cursor::new(obj.as_bytes())).expect("obj");
        assert_eq!(loaded.triangles.len(), 12);
        assert!(close(&solid(&loaded, Amount::Density(1.0)), &expected()));
        assert!(matches!(
            mechanica_mass::io::load_mesh("/nonexistent/file.stl"),
            Err(MassError::Io(_))
        ));
    }
}

/// A deforming body: the topology of the first call, passed back as known, gives bitwise the
/// same result as a fresh check on every later shape; a bad index is still refused, an
/// inside-out shape still flipped, and a known-open topology still refused as a solid.
#[test]
fn known_topology_skips_the_edge_check_and_nothing_else() {
    use mechanica_mass::mesh::{MeshTopology, TopologySource};
    let mut mesh = torus_mesh(2.0, 0.5, 60, 40);
    let first = mesh
        .mass_properties(Amount::Density(1.0), &MeshOptions::default())
        .expect("closed torus");
    let known = MeshOptions {
        topology: TopologySource::Known(first.diagnostics.topology),
        ..MeshOptions::default()
    };
    for step in 1..4 {
        let squash = 1.0 + 0.1 * f64::from(step);
        for v in &mut mesh.vertices {
            v[2] /= squash;
            v[0] *= squash;
        }
        let checked = mesh
            .mass_properties(Amount::Density(1.0), &MeshOptions::default())
            .expect("closed");
        let reused = mesh.mass_properties(Amount::Density(1.0), &known).expect("closed");
        assert_eq!(checked, reused);
    }
    let mut inverted = mesh.clone();
    for t in &mut inverted.triangles {
        t.swap(1, 2);
    }
    let flipped = inverted.mass_properties(Amount::Density(1.0), &known).expect("flipped");
    assert!(flipped.diagnostics.flipped);
    let mut bad = mesh.clone();
    bad.triangles[7][1] = bad.vertices.len() as u32;
    assert!(matches!(
        bad.mass_properties(Amount::Density(1.0), &known),
        Err(MassError::IndexOutOfRange {
            triangle: 7,
            corner: 1,
            ..
        })
    ));
    let open = MeshOptions {
        topology: TopologySource::Known(MeshTopology {
            boundary_edges: 3,
            ..MeshTopology::default()
        }),
        ..MeshOptions::default()
    };
    assert!(matches!(
        mesh.mass_properties(Amount::Density(1.0), &open),
        Err(MassError::OpenMesh { boundary_edges: 3, .. })
    ));
}
