//! What kind of opening an open mesh has: hairline cracks (every boundary edge has another
//! boundary edge a hair's breadth away, the two sides of a seam that were not joined; welding
//! closes them) or a real open boundary (a surface, a missing face; only the shell model fits).

use crate::mesh::TriangleMesh;
use std::collections::HashMap;

/// Widest crack, relative to the bounding-box diagonal, that [`crack_width`] recognises as
/// one: 1e-4 (0.1 mm on a 1 m part), far above exporter rounding, far below a modelled gap.
pub const MAX_CRACK_WIDTH: f64 = 1e-4;

/// Boundary edges compared per grid cube (an upper estimate of the width beyond that).
const MAX_COMPARED_PER_CELL: usize = 64;

/// The width of the cracks of an open mesh relative to its bounding-box diagonal. Every
/// boundary edge (an edge used by one non-degenerate triangle) is matched with the other
/// boundary edge whose ends are nearest its own ends, the distance of a match being the larger
/// of its two end-to-end distances (0 for a shared end); the width is the largest such distance
/// over all boundary edges, divided by the diagonal. `None` when the mesh has no boundary edge,
/// or some boundary edge has no match within [`MAX_CRACK_WIDTH`] of the diagonal (a real open
/// boundary). Welding with a relative tolerance at least this width merges the ends of every
/// matched pair whenever each end's copies lie within the width of one another (see
/// [`crate::weld`]). O(n) expected time (hashing); out-of-range triangles are ignored.
pub fn crack_width(mesh: &TriangleMesh) -> Option<f64> {
    let edges = boundary_edges(mesh);
    if edges.is_empty() {
        return None;
    }
    let vertices = &mesh.vertices;
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for v in vertices {
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    let diag = (hi[0] - lo[0]).hypot(hi[1] - lo[1]).hypot(hi[2] - lo[2]);
    let reach = MAX_CRACK_WIDTH * diag;
    if !(reach.is_finite() && reach > 0.0) {
        return None;
    }
    let midpoint = |(a, b): (u32, u32)| -> [f64; 3] {
        let (p, q) = (&vertices[a as usize], &vertices[b as usize]);
        std::array::from_fn(|k| 0.5 * (p[k] + q[k]))
    };
    let cell_of = |p: &[f64; 3]| -> [i64; 3] { std::array::from_fn(|k| ((p[k] - lo[k]) / reach).floor() as i64) };
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    for (i, &e) in edges.iter().enumerate() {
        grid.entry(cell_of(&midpoint(e))).or_default().push(i);
    }
    let gap = |a: u32, b: u32| distance(&vertices[a as usize], &vertices[b as usize]);
    let mut widest: f64 = 0.0;
    for (i, &(a, b)) in edges.iter().enumerate() {
        let c = cell_of(&midpoint((a, b)));
        let mut nearest = f64::INFINITY;
        for k in 0..27i64 {
            let key = [c[0] + k % 3 - 1, c[1] + (k / 3) % 3 - 1, c[2] + k / 9 - 1];
            for &j in grid
                .get(&key)
                .map_or(&[][..], Vec::as_slice)
                .iter()
                .take(MAX_COMPARED_PER_CELL)
            {
                if j != i {
                    let (p, q) = edges[j];
                    let straight = gap(a, p).max(gap(b, q));
                    let crossed = gap(a, q).max(gap(b, p));
                    nearest = nearest.min(straight.min(crossed));
                }
            }
        }
        if nearest > reach {
            return None;
        }
        widest = widest.max(nearest);
    }
    Some(widest / diag)
}

fn distance(p: &[f64; 3], q: &[f64; 3]) -> f64 {
    (p[0] - q[0]).hypot(p[1] - q[1]).hypot(p[2] - q[2])
}

/// The boundary edges (smaller end first), in ascending order.
fn boundary_edges(mesh: &TriangleMesh) -> Vec<(u32, u32)> {
    let n = mesh.vertices.len();
    let mut uses: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &mesh.triangles {
        if t.iter().any(|&i| i as usize >= n) || t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
            continue;
        }
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *uses.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let mut boundary: Vec<(u32, u32)> = uses.into_iter().filter(|&(_, n)| n == 1).map(|(e, _)| e).collect();
    boundary.sort_unstable();
    boundary
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tessellation::box_mesh;

    #[test]
    fn a_split_seam_is_a_crack_and_an_open_face_is_not() {
        let closed = box_mesh([1.0, 2.0, 3.0], [0.0; 3]);
        assert_eq!(crack_width(&closed), None);
        // Duplicate vertex 7 as vertex 8, 1e-9 away, used by the last triangle only: the two
        // triangles around the edge 1–7 of the x = + face no longer share it.
        let mut cracked = closed.clone();
        let v7 = cracked.vertices[7];
        cracked.vertices.push([v7[0], v7[1] + 1e-9, v7[2]]);
        cracked.triangles[11] = [1, 8, 5];
        let diag = 14f64.sqrt();
        let width = crack_width(&cracked).expect("a crack");
        assert!((width - 1e-9 / diag).abs() <= 1e-6 * width, "{width}");
        // Removing a face leaves a square hole whose corners are a box edge apart.
        let mut open = closed;
        open.triangles.truncate(10);
        assert_eq!(crack_width(&open), None);
    }
}
