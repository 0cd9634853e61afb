//! The invariance oracle of the mesh parsers: the mass properties of a parsed mesh do not
//! depend on where the mesh is. After the rigid motion x ↦ R x + t of every vertex, the
//! measure (volume or area) is unchanged, the centre of mass moves to R c + t and the central
//! tensor becomes R J Rᵀ — up to the rounding the library states (its relative error bound)
//! plus the rounding of moving the vertices.

use crate::input::{Input, mat_vec, rotate_tensor, rotation_of};
use mechanica::mass::mesh::{MeshModel, OpenMeshPolicy};
use mechanica::mass::{Amount, MeshMassProperties, MeshOptions, TriangleMesh};

/// Meshes larger than this are only parsed: the oracle is quadratic in nothing, but a large
/// mesh costs executions per second for no new coverage.
const MAX_TRIANGLES: usize = 4096;

/// Checks the oracle on `mesh` with a rigid motion drawn from `motion`. Meshes the library
/// refuses (open, degenerate, zero volume, …) only have to be refused without a panic.
pub fn check_rigid_motion_invariance(mesh: &TriangleMesh, motion: &mut Input) {
    if mesh.triangles.is_empty() || mesh.triangles.len() > MAX_TRIANGLES {
        return;
    }
    let options = MeshOptions {
        open_mesh: OpenMeshPolicy::Shell,
        ..MeshOptions::default()
    };
    let Ok(before) = mesh.mass_properties(Amount::Density(1.0), &options) else {
        return;
    };
    let rotation = rotation_of(motion.unit_quaternion());
    let translation = motion.vec3_moderate(1e3);
    let moved = TriangleMesh {
        vertices: mesh
            .vertices
            .iter()
            .map(|&v| {
                let r = mat_vec(&rotation, v);
                [r[0] + translation[0], r[1] + translation[1], r[2] + translation[2]]
            })
            .collect(),
        triangles: mesh.triangles.clone(),
    };
    // The moved mesh may cross a threshold (a triangle of zero area, a zero volume) that the
    // original did not: only two successes are compared.
    let Ok(after) = moved.mass_properties(Amount::Density(1.0), &options) else {
        return;
    };
    compare(mesh, &moved, &before, &after, &rotation, translation);
}

/// Largest coordinate magnitude and bounding-box diagonal of a mesh's used vertices.
fn extent(mesh: &TriangleMesh) -> (f64, f64) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut largest: f64 = 0.0;
    for v in &mesh.vertices {
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
            largest = largest.max(v[k].abs());
        }
    }
    let diag = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    (largest, diag)
}

fn compare(
    mesh: &TriangleMesh,
    moved: &TriangleMesh,
    before: &MeshMassProperties,
    after: &MeshMassProperties,
    rotation: &[f64; 9],
    translation: [f64; 3],
) {
    assert_eq!(before.model, after.model, "the model changed under a rigid motion");
    let (largest, diag) = extent(mesh);
    let (largest_moved, diag_moved) = extent(moved);
    let diag = diag.max(diag_moved);
    let measure = before.measure.abs().max(after.measure.abs());
    // Rounding of R v + t: a few ulps of the largest coordinate involved.
    let vertex_error = 8.0 * f64::EPSILON * (largest + largest_moved);
    // How far that moves the measure, per triangle: area × displacement (solid) or
    // perimeter × displacement (shell), with diag bounding every triangle's size.
    let size_power = if before.model == MeshModel::Solid { 2 } else { 1 };
    let n = mesh.triangles.len() as f64;
    let perturbation = 32.0 * vertex_error * n * diag.powi(size_power) / measure;
    let rho = 64.0 * (before.relative_error_bound + after.relative_error_bound) + perturbation;
    if !rho.is_finite() || rho > 1e-2 {
        return; // too ill-conditioned for the bound to say anything
    }
    let (p, q) = (&before.properties, &after.properties);
    assert!(
        (before.measure - after.measure).abs() <= rho * measure,
        "measure {} became {} under a rigid motion (allowed relative change {rho:e})",
        before.measure,
        after.measure
    );
    let c = [p.p_oc.x, p.p_oc.y, p.p_oc.z];
    let expected = mat_vec(rotation, c);
    let com_after = [q.p_oc.x, q.p_oc.y, q.p_oc.z];
    for k in 0..3 {
        let want = expected[k] + translation[k];
        assert!(
            (com_after[k] - want).abs() <= rho * diag + 4.0 * vertex_error,
            "centre of mass {c:?} moved to {com_after:?}, expected component {k} = {want}"
        );
    }
    let j: [f64; 9] = p.inertia_c.as_slice().try_into().expect("3×3");
    let j_after: [f64; 9] = q.inertia_c.as_slice().try_into().expect("3×3");
    let want = rotate_tensor(rotation, &j);
    let scale = p.mass.abs().max(q.mass.abs()) * diag * diag;
    for k in 0..9 {
        assert!(
            (j_after[k] - want[k]).abs() <= rho * scale,
            "central inertia entry {k}: {} after the motion, R J Rᵀ = {} (scale {scale:e}, rho {rho:e})",
            j_after[k],
            want[k]
        );
    }
}
