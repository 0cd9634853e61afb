//! The edge topology of a triangle mesh: boundary, non-manifold and misoriented edges, in O(n)
//! time by a parallel counting sort of the edges.
//!
//! Every edge is filed under its smaller end, with the larger end and its direction; each
//! vertex's bucket (a handful of edges) is then sorted and its runs of equal edges classified.
//! The triangles are split between threads for counting and filing (each thread writes its
//! own, precomputed slots of every bucket), the vertices for classifying; the result is a
//! count, so it does not depend on the number of threads.

use crate::MassError;
use crate::parallel::{map_in_parallel, worker_count};
use std::sync::atomic::{AtomicU32, Ordering};

/// Edge-based topology of a triangle mesh: every undirected edge of a closed, consistently
/// oriented surface is used exactly twice, once in each direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MeshTopology {
    /// Edges used by exactly one triangle.
    pub boundary_edges: usize,
    /// Edges used by more than two triangles.
    pub non_manifold_edges: usize,
    /// Edges used by two triangles in the same direction (inconsistent orientation).
    pub misoriented_edges: usize,
}

impl MeshTopology {
    /// True when no edge is a boundary or non-manifold edge.
    pub fn is_closed(&self) -> bool {
        self.boundary_edges == 0 && self.non_manifold_edges == 0
    }

    fn add(&mut self, other: &MeshTopology) {
        self.boundary_edges += other.boundary_edges;
        self.non_manifold_edges += other.non_manifold_edges;
        self.misoriented_edges += other.misoriented_edges;
    }
}

/// The edge topology of `triangles` over `vertex_count` vertices (triangles with a repeated
/// index are ignored), in O(n + V) time and 4·(3n + (threads + 1)·V) bytes; large meshes use
/// all available cores.
///
/// Errors: [`MassError::TooManyVertices`] (more than 2³¹), [`MassError::TooManyTriangles`]
/// (3n ≥ 2³²), [`MassError::IndexOutOfRange`] (naming the first offending corner).
pub fn mesh_topology(vertex_count: usize, triangles: &[[u32; 3]]) -> Result<MeshTopology, MassError> {
    topology_on(worker_count(triangles.len()), vertex_count, triangles)
}

/// [`mesh_topology`] on `threads` threads.
pub(crate) fn topology_on(
    threads: usize,
    vertex_count: usize,
    triangles: &[[u32; 3]],
) -> Result<MeshTopology, MassError> {
    if vertex_count > (1usize << 31) {
        return Err(MassError::TooManyVertices(vertex_count));
    }
    if triangles.len() >= (u32::MAX / 3) as usize {
        return Err(MassError::TooManyTriangles(triangles.len()));
    }
    if triangles.is_empty() {
        return Ok(MeshTopology::default());
    }
    let per = triangles.len().div_ceil(threads.clamp(1, triangles.len()));
    let chunks: Vec<&[[u32; 3]]> = triangles.chunks(per).collect();
    // Pass 1: per chunk, the number of edges filed under each vertex.
    let counted = map_in_parallel(chunks.clone(), |chunk| count_edges(chunk, vertex_count));
    let Some(mut cursors) = counted.into_iter().collect::<Option<Vec<Vec<u32>>>>() else {
        return Err(first_index_error(triangles, vertex_count));
    };
    // Bucket v spans start[v]..start[v + 1]; chunk c files its edges of v from cursors[c][v] on.
    // The total is 3n < 2³² by the check above.
    let mut start = Vec::with_capacity(vertex_count + 1);
    let mut total = 0u32;
    for v in 0..vertex_count {
        start.push(total);
        for chunk_cursors in &mut cursors {
            let count = chunk_cursors[v];
            chunk_cursors[v] = total;
            total += count;
        }
    }
    start.push(total);
    // Pass 2: filing. The slots of different chunks are disjoint, so relaxed stores suffice.
    let shared: Vec<AtomicU32> = (0..total).map(|_| AtomicU32::new(0)).collect();
    map_in_parallel(chunks.into_iter().zip(cursors).collect(), |(chunk, cursors)| {
        file_edges(chunk, cursors, &shared)
    });
    let mut bucket: Vec<u32> = shared.into_iter().map(AtomicU32::into_inner).collect();
    // Pass 3: classification, the vertex range split between threads.
    let vertex_share = vertex_count.div_ceil(threads.clamp(1, vertex_count.max(1))).max(1);
    let mut pieces = Vec::new();
    let mut rest: &mut [u32] = &mut bucket;
    for lo in (0..vertex_count).step_by(vertex_share) {
        let bounds = &start[lo..=(lo + vertex_share).min(vertex_count)];
        let len = (bounds[bounds.len() - 1] - bounds[0]) as usize;
        let (piece, tail) = rest.split_at_mut(len);
        pieces.push((piece, bounds));
        rest = tail;
    }
    let mut topology = MeshTopology::default();
    for part in map_in_parallel(pieces, |(piece, bounds)| classify_buckets(piece, bounds)) {
        topology.add(&part);
    }
    Ok(topology)
}

/// The directed edges (a, b) of a triangle with distinct corners, or none.
#[inline(always)]
fn edges(t: &[u32; 3]) -> Option<[(u32, u32); 3]> {
    if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
        None
    } else {
        Some([(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
    }
}

/// Per vertex, the number of edges of `chunk` filed under it (its smaller end); `None` when a
/// corner is out of range.
fn count_edges(chunk: &[[u32; 3]], vertex_count: usize) -> Option<Vec<u32>> {
    let mut counts = vec![0u32; vertex_count];
    for t in chunk {
        if t[0].max(t[1]).max(t[2]) as usize >= vertex_count {
            return None;
        }
        if let Some(es) = edges(t) {
            for (a, b) in es {
                counts[a.min(b) as usize] += 1;
            }
        }
    }
    Some(counts)
}

/// Files every edge of `chunk` into its bucket slot: the larger end shifted left, with bit 0
/// set when the edge runs from the smaller end to the larger one (indices < 2³¹, so this fits
/// in 32 bits). `cursors[v]` is this chunk's next slot for vertex v.
fn file_edges(chunk: &[[u32; 3]], mut cursors: Vec<u32>, bucket: &[AtomicU32]) {
    for t in chunk {
        if let Some(es) = edges(t) {
            for (a, b) in es {
                let (m, x) = if a < b { (a, (b << 1) | 1) } else { (b, a << 1) };
                let slot = &mut cursors[m as usize];
                bucket[*slot as usize].store(x, Ordering::Relaxed);
                *slot += 1;
            }
        }
    }
}

/// The topology of the buckets in `piece`, whose boundaries (offsets into the whole bucket
/// array) are `bounds`.
fn classify_buckets(piece: &mut [u32], bounds: &[u32]) -> MeshTopology {
    let base = bounds[0];
    let mut topology = MeshTopology::default();
    for w in bounds.windows(2) {
        let list = &mut piece[(w[0] - base) as usize..(w[1] - base) as usize];
        list.sort_unstable();
        // The common case, a closed and consistently oriented neighbourhood: the sorted list
        // is pairs (2x, 2x + 1), each edge once in each direction (distinct x by sorting).
        let mut paired = list.len().is_multiple_of(2);
        for p in list.chunks_exact(2) {
            paired &= (p[0] & 1 == 0) & (p[1] == p[0] | 1);
        }
        if !paired {
            classify_runs(list, &mut topology);
        }
    }
    topology
}

/// Adds the classification of every run of equal edges in the sorted `list`.
fn classify_runs(list: &[u32], topology: &mut MeshTopology) {
    let mut i = 0;
    while i < list.len() {
        let other = list[i] >> 1;
        let mut j = i + 1;
        while j < list.len() && list[j] >> 1 == other {
            j += 1;
        }
        let forward = list[i..j].iter().filter(|&&x| x & 1 == 1).count();
        match (j - i, forward) {
            (1, _) => topology.boundary_edges += 1,
            (2, 1) => {}
            (2, _) => topology.misoriented_edges += 1,
            _ => topology.non_manifold_edges += 1,
        }
        i = j;
    }
}

/// Fails with [`MassError::IndexOutOfRange`] (naming the first offending corner) unless every
/// index is below `vertex_count`; a vectorisable maximum first, the search only on failure.
pub(crate) fn check_indices(triangles: &[[u32; 3]], vertex_count: usize) -> Result<(), MassError> {
    let max = triangles.as_flattened().iter().copied().max().unwrap_or(0);
    if (max as usize) < vertex_count {
        Ok(())
    } else {
        Err(first_index_error(triangles, vertex_count))
    }
}

/// The error for the first corner of `triangles` that is not below `vertex_count`.
fn first_index_error(triangles: &[[u32; 3]], vertex_count: usize) -> MassError {
    for (triangle, t) in triangles.iter().enumerate() {
        for (corner, &index) in t.iter().enumerate() {
            if index as usize >= vertex_count {
                return MassError::IndexOutOfRange {
                    triangle,
                    corner,
                    index: index.into(),
                    vertex_count,
                };
            }
        }
    }
    // Unreachable when called after a failed count; name the mesh size rather than panic.
    MassError::TooManyTriangles(triangles.len())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parallel::PARALLEL_MIN_TRIANGLES;
    use crate::tessellation::torus_mesh;
    use proptest::prelude::*;
    use std::collections::HashMap;

    /// The edge classification by brute force: a map from undirected edge to the number of
    /// traversals in each direction.
    fn reference_topology(triangles: &[[u32; 3]]) -> MeshTopology {
        let mut uses: HashMap<(u32, u32), (usize, usize)> = HashMap::new();
        for t in triangles
            .iter()
            .filter(|t| t[0] != t[1] && t[1] != t[2] && t[2] != t[0])
        {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let entry = uses.entry((a.min(b), a.max(b))).or_default();
                if a < b {
                    entry.0 += 1;
                } else {
                    entry.1 += 1;
                }
            }
        }
        let mut topo = MeshTopology::default();
        for (forward, backward) in uses.into_values() {
            match (forward + backward, forward) {
                (1, _) => topo.boundary_edges += 1,
                (2, 1) => {}
                (2, _) => topo.misoriented_edges += 1,
                _ => topo.non_manifold_edges += 1,
            }
        }
        topo
    }

    proptest! {
        /// Random triangle soups over few vertices (so that edges repeat, flip and pile up)
        /// are classified as the brute-force reference does, on any number of threads (the
        /// triangles and vertices are then split at different points).
        #[test]
        fn bucketed_topology_equals_brute_force(
            triangles in proptest::collection::vec(proptest::array::uniform3(0u32..12), 1..60),
            threads in 1usize..14,
        ) {
            let expected = reference_topology(&triangles);
            prop_assert_eq!(topology_on(threads, 12, &triangles).expect("in range"), expected);
        }
    }

    #[test]
    fn topology_of_a_large_closed_mesh_is_clean_on_any_number_of_threads() {
        let mesh = torus_mesh(2.0, 0.5, 300, 250);
        assert!(mesh.triangles.len() >= PARALLEL_MIN_TRIANGLES);
        let v = mesh.vertices.len();
        assert_eq!(mesh_topology(v, &mesh.triangles).expect("ok"), MeshTopology::default());
        for threads in [1, 2, 3, 7] {
            assert_eq!(
                topology_on(threads, v, &mesh.triangles).expect("ok"),
                MeshTopology::default()
            );
            // Dropping one triangle opens three edges.
            assert_eq!(
                topology_on(threads, v, &mesh.triangles[1..])
                    .expect("ok")
                    .boundary_edges,
                3
            );
        }
    }

    #[test]
    fn an_out_of_range_corner_is_named_even_in_a_degenerate_triangle() {
        for threads in [1, 2] {
            assert!(matches!(
                topology_on(threads, 3, &[[0, 1, 2], [0, 1, 3]]),
                Err(MassError::IndexOutOfRange {
                    triangle: 1,
                    corner: 2,
                    index: 3,
                    vertex_count: 3
                })
            ));
            assert!(matches!(
                topology_on(threads, 3, &[[0, 1, 2], [5, 5, 5]]),
                Err(MassError::IndexOutOfRange {
                    triangle: 1,
                    corner: 0,
                    index: 5,
                    vertex_count: 3
                })
            ));
        }
    }
}
