//! Welding of near-coincident mesh vertices: closing the hairline cracks that CAD exporters
//! leave where two patches meet (the same corner written as 0 on one side and 1e-18 on the
//! other), so that a solid's mesh comes out closed for [`crate::mesh::mesh_topology`].
//!
//! The rule (leader clustering in index order). The tolerance is relative: two positions are
//! near when they are at most t = `relative_tolerance` × (the diagonal of the vertex bounding
//! box) apart (Euclidean distance). Bit-identical positions are merged first. Then the
//! vertices are visited in index order; a vertex not yet claimed becomes a *leader* and claims
//! every unclaimed vertex within t of itself; every claimed vertex takes its leader's position.
//! Consequences:
//! - the result does not depend on hashing or thread order: the same mesh gives the same bits;
//! - every vertex moves by at most t (to its leader), reported as
//!   [`WeldReport::max_displacement`];
//! - chains do not propagate: of three points a, b, c with |ab|, |bc| ≤ t < |ac|, the first leader
//!   claims its neighbours only, so a chain of near points never collapses a stretch longer than
//!   t (unlike a transitive union of all near pairs);
//! - copies of one position, each within t/2 of it (so pairwise within t), are welded into one
//!   vertex whenever no other vertex lies within 3t/2 of that position.
//!
//! The near pairs are found in a hashed grid of cubes of side t (each vertex is compared with
//! the vertices of its own and the 26 neighbouring cubes), O(n) expected time. A tolerance so
//! coarse that more than [`MAX_POSITIONS_PER_CELL`] distinct positions share one cube would
//! collapse the tessellation itself and is refused ([`MassError::WeldTooCoarse`]); this also
//! bounds the work by 27 × [`MAX_POSITIONS_PER_CELL`] comparisons per vertex.
//!
//! Triangles whose corners coincide after welding are dropped and counted
//! ([`WeldReport::triangles_dropped`]); triangles that already repeated a vertex are kept for
//! the mass routine to count as degenerate. Vertices no triangle uses after welding are removed.

use crate::MassError;
use crate::mesh::TriangleMesh;
use std::collections::HashMap;

/// The default relative weld tolerance: 1e-8 of the bounding-box diagonal. It is below the
/// resolution of single-precision (STL) coordinates, 2⁻²⁴ ≈ 6e-8 of their magnitude, so it
/// merges only positions that a file format could not tell apart at the mesh's scale.
pub const DEFAULT_WELD_TOLERANCE: f64 = 1e-8;

/// Most distinct positions allowed in one grid cube of side t (see the module docs).
pub const MAX_POSITIONS_PER_CELL: usize = 64;

/// What [`weld_vertices`] did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WeldReport {
    /// The relative tolerance asked for.
    pub relative_tolerance: f64,
    /// The absolute tolerance applied, relative tolerance × bounding-box diagonal (m).
    pub tolerance: f64,
    /// Vertices before welding.
    pub vertices_before: usize,
    /// Vertices merged into another one (bit-identical or near); vertices no triangle uses
    /// are not counted here but are removed as well.
    pub vertices_welded: usize,
    /// Triangles dropped because welding made two of their corners one vertex.
    pub triangles_dropped: usize,
    /// The largest distance any vertex moved (m), at most `tolerance`.
    pub max_displacement: f64,
}

/// Welds the vertices of `mesh` within `relative_tolerance` × its bounding-box diagonal by the
/// rule of the module docs and returns the welded mesh (each leader at its own position,
/// numbered in order of first use by the kept triangles, unused vertices removed, collapsed
/// triangles dropped) with what was done. A tolerance of 0 only
/// merges bit-identical positions (−0 and +0 count as identical).
///
/// Errors: [`MassError::InvalidWeldTolerance`] for a negative or non-finite tolerance;
/// [`MassError::TooManyVertices`] beyond 2³¹ vertices; [`MassError::NonFiniteVertex`];
/// [`MassError::IndexOutOfRange`];
/// [`MassError::WeldTooCoarse`] when more than [`MAX_POSITIONS_PER_CELL`] distinct positions
/// fall into one cube of side t.
pub fn weld_vertices(mesh: &TriangleMesh, relative_tolerance: f64) -> Result<(TriangleMesh, WeldReport), MassError> {
    if !(relative_tolerance.is_finite() && relative_tolerance >= 0.0) {
        return Err(MassError::InvalidWeldTolerance(relative_tolerance));
    }
    if mesh.vertices.len() > 1 << 31 {
        return Err(MassError::TooManyVertices(mesh.vertices.len()));
    }
    crate::topology::check_indices(&mesh.triangles, mesh.vertices.len())?;
    let (lo, diag) = bounding_box(&mesh.vertices)?;
    let tolerance = relative_tolerance * diag;
    let exact = exact_leaders(&mesh.vertices);
    let leader = if tolerance > 0.0 {
        near_leaders(&mesh.vertices, &exact, &lo, tolerance, diag)?
    } else {
        exact
    };
    let mut report = WeldReport {
        relative_tolerance,
        tolerance,
        vertices_before: mesh.vertices.len(),
        ..WeldReport::default()
    };
    for (i, &l) in leader.iter().enumerate() {
        if l as usize != i {
            report.vertices_welded += 1;
            let d = distance(&mesh.vertices[i], &mesh.vertices[l as usize]);
            report.max_displacement = report.max_displacement.max(d);
        }
    }
    let (welded, dropped) = rebuild(mesh, &leader);
    report.triangles_dropped = dropped;
    Ok((welded, report))
}

/// The lower corner and the diagonal length of the vertex bounding box; an error for a
/// non-finite vertex.
fn bounding_box(vertices: &[[f64; 3]]) -> Result<([f64; 3], f64), MassError> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for (i, v) in vertices.iter().enumerate() {
        for k in 0..3 {
            if !v[k].is_finite() {
                return Err(MassError::NonFiniteVertex { vertex: i, value: v[k] });
            }
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    if vertices.is_empty() {
        return Ok(([0.0; 3], 0.0));
    }
    let d = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
    Ok((lo, d[0].hypot(d[1]).hypot(d[2])))
}

fn distance(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1]).hypot(a[2] - b[2])
}

/// Per vertex, the first vertex with a bit-identical position (−0 read as +0).
fn exact_leaders(vertices: &[[f64; 3]]) -> Vec<u32> {
    let mut first: HashMap<[u64; 3], u32> = HashMap::with_capacity(vertices.len());
    let key = |v: &[f64; 3]| v.map(|x| (x + 0.0).to_bits());
    (0..vertices.len() as u32)
        .map(|i| *first.entry(key(&vertices[i as usize])).or_insert(i))
        .collect()
}

/// The grid cube of side `cell` holding `p` (coordinates relative to `lo`, so non-negative).
fn cell_of(p: &[f64; 3], lo: &[f64; 3], cell: f64) -> [i64; 3] {
    // The cast saturates; cell ≥ diag·2⁻⁶⁰ keeps the quotient far below i64::MAX.
    std::array::from_fn(|k| ((p[k] - lo[k]) / cell).floor() as i64)
}

/// Per vertex, its leader under the rule of the module docs, given the bit-identical leaders
/// `exact`; only exact leaders take part in the grid.
fn near_leaders(
    vertices: &[[f64; 3]],
    exact: &[u32],
    lo: &[f64; 3],
    tolerance: f64,
    diag: f64,
) -> Result<Vec<u32>, MassError> {
    // A cube at least as wide as t finds every pair within t among the 27 around a vertex.
    let cell = tolerance.max(diag * 2f64.powi(-60));
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    for (i, v) in vertices.iter().enumerate() {
        if exact[i] as usize == i {
            let members = grid.entry(cell_of(v, lo, cell)).or_default();
            members.push(i as u32);
            if members.len() > MAX_POSITIONS_PER_CELL {
                return Err(MassError::WeldTooCoarse {
                    tolerance,
                    positions: members.len(),
                });
            }
        }
    }
    let mut leader: Vec<u32> = exact.to_vec();
    let mut claimed = vec![false; vertices.len()];
    for i in 0..vertices.len() {
        if exact[i] as usize != i || claimed[i] {
            continue;
        }
        claimed[i] = true;
        let c = cell_of(&vertices[i], lo, cell);
        for offset in NEIGHBOURS {
            let key = [c[0] + offset[0], c[1] + offset[1], c[2] + offset[2]];
            for &j in grid.get(&key).map_or(&[][..], Vec::as_slice) {
                let j = j as usize;
                if !claimed[j] && distance(&vertices[i], &vertices[j]) <= tolerance {
                    claimed[j] = true;
                    leader[j] = i as u32;
                }
            }
        }
    }
    // Bit-identical copies follow their position's leader.
    for i in 0..vertices.len() {
        leader[i] = leader[exact[i] as usize];
    }
    Ok(leader)
}

/// The 27 cube offsets around a cube.
const NEIGHBOURS: [[i64; 3]; 27] = {
    let mut all = [[0i64; 3]; 27];
    let mut k = 0;
    while k < 27 {
        all[k] = [(k % 3) as i64 - 1, ((k / 3) % 3) as i64 - 1, (k / 9) as i64 - 1];
        k += 1;
    }
    all
};

/// The mesh with every vertex replaced by its leader, the triangles that welding collapsed
/// dropped (their count returned) and the unused vertices removed, leaders in index order.
fn rebuild(mesh: &TriangleMesh, leader: &[u32]) -> (TriangleMesh, usize) {
    let collapsed = |t: &[u32; 3]| t[0] == t[1] || t[1] == t[2] || t[2] == t[0];
    let mut kept = Vec::with_capacity(mesh.triangles.len());
    let mut dropped = 0;
    for t in &mesh.triangles {
        let w = t.map(|i| leader[i as usize]);
        if collapsed(&w) && !collapsed(t) {
            dropped += 1;
        } else {
            kept.push(w);
        }
    }
    let mut new_index = vec![u32::MAX; mesh.vertices.len()];
    let mut vertices = Vec::new();
    for t in &mut kept {
        for i in t.iter_mut() {
            let slot = &mut new_index[*i as usize];
            if *slot == u32::MAX {
                *slot = vertices.len() as u32;
                vertices.push(mesh.vertices[*i as usize]);
            }
            *i = *slot;
        }
    }
    (
        TriangleMesh {
            vertices,
            triangles: kept,
        },
        dropped,
    )
}

impl TriangleMesh {
    /// This mesh welded within `relative_tolerance` × its bounding-box diagonal, see
    /// [`weld_vertices`].
    pub fn welded(&self, relative_tolerance: f64) -> Result<(TriangleMesh, WeldReport), MassError> {
        weld_vertices(self, relative_tolerance)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tessellation::uv_sphere;

    /// Two far corners that make the bounding-box diagonal exactly 10 (a 6-8-0 box).
    const FAR: [[f64; 3]; 2] = [[6.0, 8.0, 0.0], [0.0, 0.0, 0.0]];

    fn mesh(points: &[[f64; 3]], triangles: &[[u32; 3]]) -> TriangleMesh {
        let mut vertices = FAR.to_vec();
        vertices.extend_from_slice(points);
        TriangleMesh {
            vertices,
            triangles: triangles.to_vec(),
        }
    }

    #[test]
    fn invalid_tolerances_are_refused_and_zero_merges_identical_positions_only() {
        let m = mesh(
            &[[1.0, 1.0, 0.0], [1.0, 1.0, 1e-12], [1.0, 1.0, -0.0]],
            &[[0, 1, 2], [0, 1, 3], [0, 1, 4]],
        );
        for bad in [-1e-9, f64::NAN, f64::INFINITY] {
            assert!(matches!(
                weld_vertices(&m, bad),
                Err(MassError::InvalidWeldTolerance(_))
            ));
        }
        let (w, r) = weld_vertices(&m, 0.0).expect("valid");
        // +0 and −0 are one position; 1e-12 is another.
        assert_eq!((w.vertices.len(), r.vertices_welded, r.max_displacement), (4, 1, 0.0));
        let (w, r) = weld_vertices(&m, 1e-12).expect("valid");
        // t = 1e-11 ≥ 1e-12: all three copies are one vertex; two triangles became the first.
        assert_eq!((w.vertices.len(), r.vertices_welded, r.max_displacement), (3, 2, 1e-12));
        assert_eq!(w.triangles, vec![[0, 1, 2]; 3]);
        assert!((r.tolerance - 1e-11).abs() <= 1e-26);
    }

    #[test]
    fn chains_do_not_propagate_beyond_the_tolerance() {
        // a, b, c on a line 0.6 t apart (t = 1e-6 × 10): a claims b; c, 1.2 t from a, stays.
        let t = 1e-5;
        let pts = [[1.0, 1.0, 0.0], [1.0 + 0.6 * t, 1.0, 0.0], [1.0 + 1.2 * t, 1.0, 0.0]];
        let m = mesh(&pts, &[[0, 1, 2], [0, 1, 3], [0, 1, 4]]);
        let (w, r) = weld_vertices(&m, 1e-6).expect("valid");
        assert!((r.tolerance - t).abs() <= 1e-20);
        assert_eq!(w.vertices.len(), 4);
        assert_eq!(w.vertices[2], pts[0]);
        assert_eq!(w.vertices[3], pts[2]);
        assert_eq!(r.vertices_welded, 1);
        assert!((r.max_displacement - 0.6 * t).abs() <= 1e-15);
        // In the reverse order c claims b, and a stays: the result follows the vertex order.
        let m = mesh(&[pts[2], pts[1], pts[0]], &[[0, 1, 2], [0, 1, 3], [0, 1, 4]]);
        let (w, _) = weld_vertices(&m, 1e-6).expect("valid");
        assert_eq!((w.vertices[2], w.vertices[3]), (pts[2], pts[0]));
    }

    #[test]
    fn triangles_collapsed_by_welding_are_dropped_and_counted() {
        // A sliver whose two corners are 1e-9 apart, next to a proper triangle; a triangle that
        // repeated an index before welding is kept for the mass routine to count.
        let m = mesh(
            &[[1.0, 1.0, 0.0], [1.0, 1.0, 1e-9], [2.0, 1.0, 0.0]],
            &[[2, 3, 4], [0, 2, 4], [0, 0, 1]],
        );
        let (w, r) = weld_vertices(&m, 1e-8).expect("valid");
        assert_eq!(r.triangles_dropped, 1);
        assert_eq!(w.triangles.len(), 2);
        assert_eq!(w.triangles, vec![[0, 1, 2], [0, 0, 3]]);
    }

    #[test]
    fn a_tolerance_at_the_scale_of_the_tessellation_is_refused() {
        let sphere = uv_sphere(1.0, 24, 24);
        assert!(weld_vertices(&sphere, 1e-8).is_ok());
        assert!(matches!(
            weld_vertices(&sphere, 0.5),
            Err(MassError::WeldTooCoarse { positions, .. }) if positions == MAX_POSITIONS_PER_CELL + 1
        ));
    }

    #[test]
    fn bad_vertices_and_indices_are_errors() {
        let m = mesh(&[[f64::NAN, 0.0, 0.0]], &[[0, 1, 2]]);
        assert!(matches!(
            weld_vertices(&m, 1e-8),
            Err(MassError::NonFiniteVertex { vertex: 2, .. })
        ));
        let m = mesh(&[], &[[0, 1, 2]]);
        assert!(matches!(
            weld_vertices(&m, 1e-8),
            Err(MassError::IndexOutOfRange { .. })
        ));
    }
}
