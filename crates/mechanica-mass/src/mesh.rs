//! Mass properties of triangle meshes: exact volume integrals over closed meshes (divergence
//! theorem: the signed tetrahedra between a reference point and each triangle, the same
//! polynomial integrals as Mirtich, J. Graphics Tools 1(2), 1996, and Eberly, "Polyhedral Mass
//! Properties (Revisited)", 2002), thin shells with surface density, and the topology checks
//! that keep either from being silently wrong.
//!
//! All integrals are taken relative to the centre of the vertex bounding box, not the world
//! origin, so a mesh far from the origin keeps full relative accuracy (a unit cube at 1e6 gives
//! ~1e-15). The per-triangle terms are summed in fixed blocks of [`BLOCK`] triangles and then
//! block by block, so the rounding error grows like (BLOCK + n/BLOCK)·ε instead of n·ε, and the
//! result is bitwise independent of the number of threads.
//!
//! Meshes of at least [`PARALLEL_MIN_TRIANGLES`] triangles use all available cores (scoped
//! standard threads) for both the edge-topology check and the integrals.

use crate::error::check_finite;
use crate::primitives::Amount;
use crate::{MassError, MassProperties};
use nalgebra::{Matrix3, Vector3};

/// Triangles per partial sum.
pub const BLOCK: usize = 4096;

/// How the mesh carries its mass.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshModel {
    /// A closed surface bounding a solid of uniform volume density (kg/m³).
    Solid,
    /// A thin shell: the surface itself carries a uniform surface density (kg/m²).
    Shell,
}

/// What to do with a mesh that is not closed when a solid was asked for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OpenMeshPolicy {
    /// Fail with [`MassError::OpenMesh`] (the default).
    Reject,
    /// Fall back to the thin-shell model; a density given in [`Amount::Density`] is then read
    /// as a surface density in kg/m². The result reports `model = Shell`.
    Shell,
}

/// What to do with a closed mesh whose triangles all face inwards (negative signed volume).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InsideOutPolicy {
    /// Reverse the orientation (the default); the result reports `flipped = true`.
    Flip,
    /// Fail with [`MassError::InsideOut`].
    Reject,
}

/// What to do with degenerate triangles (repeated vertex indices or zero area).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DegeneratePolicy {
    /// Count them in the diagnostics and leave them out of the integrals (the default).
    Skip,
    /// Fail with [`MassError::DegenerateTriangles`].
    Reject,
}

/// Options of [`mesh_mass_properties`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MeshOptions {
    /// Solid (volume density) or shell (surface density).
    pub model: MeshModel,
    /// Open meshes under the solid model.
    pub open_mesh: OpenMeshPolicy,
    /// Inside-out closed meshes under the solid model.
    pub inside_out: InsideOutPolicy,
    /// Degenerate triangles.
    pub degenerate: DegeneratePolicy,
}

impl Default for MeshOptions {
    fn default() -> Self {
        Self {
            model: MeshModel::Solid,
            open_mesh: OpenMeshPolicy::Reject,
            inside_out: InsideOutPolicy::Flip,
            degenerate: DegeneratePolicy::Skip,
        }
    }
}

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
}

/// What the mesh checks found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MeshDiagnostics {
    /// Triangles given.
    pub triangles: usize,
    /// Triangles skipped as degenerate (repeated indices or zero area).
    pub degenerate_triangles: usize,
    /// The edge topology (see [`MeshTopology`]).
    pub topology: MeshTopology,
    /// True when an inside-out closed mesh was reversed.
    pub flipped: bool,
}

/// Mass properties of a mesh with the diagnostics and the accuracy of the integrals.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshMassProperties {
    /// Mass, centre of mass and central inertia, in the frame of the vertices.
    pub properties: MassProperties,
    /// The model actually used (a solid request on an open mesh may fall back to a shell).
    pub model: MeshModel,
    /// Enclosed volume (m³) for a solid, surface area (m²) for a shell.
    pub measure: f64,
    /// What the checks found.
    pub diagnostics: MeshDiagnostics,
    /// Bound on the relative rounding error of `measure`,
    /// (min(n, BLOCK) + ⌈n/BLOCK⌉ + 16)·ε·Σ|terms|/|measure|;
    /// the first and second moments have errors of the same order relative to their scale.
    pub relative_error_bound: f64,
}

/// An indexed triangle mesh: vertex positions and counter-clockwise (outward-facing) triangles.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TriangleMesh {
    /// Vertex positions, m.
    pub vertices: Vec<[f64; 3]>,
    /// Vertex indices of each triangle.
    pub triangles: Vec<[u32; 3]>,
}

impl TriangleMesh {
    /// Mass properties of this mesh, see [`mesh_mass_properties`].
    pub fn mass_properties(&self, amount: Amount, options: &MeshOptions) -> Result<MeshMassProperties, MassError> {
        mesh_mass_properties(&self.vertices, &self.triangles, amount, options)
    }
}

/// Meshes with fewer triangles than this are handled on the calling thread only (starting
/// threads costs tens of microseconds).
pub const PARALLEL_MIN_TRIANGLES: usize = 1 << 16;

/// The number of threads for a mesh of `triangles` triangles: 1 below
/// [`PARALLEL_MIN_TRIANGLES`], else the available parallelism, with at least half of
/// [`PARALLEL_MIN_TRIANGLES`] triangles per thread.
fn worker_count(triangles: usize) -> usize {
    static AVAILABLE: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    if triangles < PARALLEL_MIN_TRIANGLES {
        return 1;
    }
    let available = *AVAILABLE.get_or_init(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    available.min(triangles / (PARALLEL_MIN_TRIANGLES / 2)).max(1)
}

/// Checks the vertices and returns the centre of their bounding box and its diagonal length.
fn reference_point(vertices: &[[f64; 3]]) -> Result<([f64; 3], f64), MassError> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut finite = true;
    for v in vertices {
        for k in 0..3 {
            finite &= v[k].is_finite();
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    if !finite {
        for (i, v) in vertices.iter().enumerate() {
            if let Some(&value) = v.iter().find(|x| !x.is_finite()) {
                return Err(MassError::NonFiniteVertex { vertex: i, value });
            }
        }
    }
    let centre = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])];
    let diag = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt();
    Ok((centre, diag))
}

/// Fails unless every index is below `vertex_count` (a vectorisable maximum first, the
/// offending triangle only on failure).
fn check_indices(triangles: &[[u32; 3]], vertex_count: usize) -> Result<(), MassError> {
    let max = triangles.as_flattened().iter().copied().max().unwrap_or(0);
    if (max as usize) < vertex_count {
        return Ok(());
    }
    for (triangle, t) in triangles.iter().enumerate() {
        for (corner, &index) in t.iter().enumerate() {
            if index as usize >= vertex_count {
                return Err(MassError::IndexOutOfRange {
                    triangle,
                    corner,
                    index: index.into(),
                    vertex_count,
                });
            }
        }
    }
    Ok(())
}

/// The edge topology of `triangles` over `vertex_count` vertices (triangles with a repeated
/// index are ignored), in O(n) time and 4·(3n + V) bytes, by bucketing: every edge is filed
/// under its smaller end with the larger end and its direction, each bucket (a handful of
/// edges) is sorted, and the runs of equal edges are classified. For large meshes the vertex
/// range is split between threads, each scanning all triangles for its own buckets, so the
/// result does not depend on the thread count.
///
/// Errors: [`MassError::TooManyVertices`] (more than 2³¹), [`MassError::TooManyTriangles`]
/// (3n ≥ 2³²), [`MassError::IndexOutOfRange`].
pub fn mesh_topology(vertex_count: usize, triangles: &[[u32; 3]]) -> Result<MeshTopology, MassError> {
    if vertex_count > (1usize << 31) {
        return Err(MassError::TooManyVertices(vertex_count));
    }
    if triangles.len() >= (u32::MAX / 3) as usize {
        return Err(MassError::TooManyTriangles(triangles.len()));
    }
    check_indices(triangles, vertex_count)?;
    let threads = worker_count(triangles.len()).min(vertex_count.max(1));
    if threads == 1 {
        return Ok(topology_of_range(triangles, 0, vertex_count));
    }
    let per = vertex_count.div_ceil(threads);
    let parts: Vec<MeshTopology> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads)
            .map(|t| {
                let (lo, hi) = ((t * per).min(vertex_count), ((t + 1) * per).min(vertex_count));
                scope.spawn(move || topology_of_range(triangles, lo, hi))
            })
            .collect();
        // A worker cannot panic (indices are checked, buffers sized from the same counts); if
        // one did, that bug is re-raised here rather than hidden.
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    });
    let mut total = MeshTopology::default();
    for p in parts {
        total.boundary_edges += p.boundary_edges;
        total.non_manifold_edges += p.non_manifold_edges;
        total.misoriented_edges += p.misoriented_edges;
    }
    Ok(total)
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

/// The topology of the edges whose smaller end lies in `lo..hi` (indices checked in range).
fn topology_of_range(triangles: &[[u32; 3]], lo: usize, hi: usize) -> MeshTopology {
    let len = hi - lo;
    // end[v] counts, then (inclusive prefix sums) ends, then (after filing) starts of buckets.
    let mut end = vec![0u32; len + 1];
    let in_range = |m: u32| (m as usize).wrapping_sub(lo) < len;
    for t in triangles {
        if let Some(es) = edges(t) {
            for (a, b) in es {
                let m = a.min(b);
                if in_range(m) {
                    end[m as usize - lo] += 1;
                }
            }
        }
    }
    let mut sum = 0u32;
    for e in end.iter_mut().take(len) {
        sum += *e;
        *e = sum;
    }
    end[len] = sum;
    // Entry: the larger end shifted left, with bit 0 set when the edge runs from the smaller
    // end to the larger one (indices < 2³¹, so this fits in 32 bits).
    let mut bucket = vec![0u32; sum as usize];
    for t in triangles {
        if let Some(es) = edges(t) {
            for (a, b) in es {
                let (m, x) = if a < b { (a, (b << 1) | 1) } else { (b, a << 1) };
                if in_range(m) {
                    let slot = &mut end[m as usize - lo];
                    *slot -= 1;
                    bucket[*slot as usize] = x;
                }
            }
        }
    }
    let mut topo = MeshTopology::default();
    for v in 0..len {
        let list = &mut bucket[end[v] as usize..end[v + 1] as usize];
        list.sort_unstable();
        // The common case, a closed and consistently oriented neighbourhood: the sorted list
        // is pairs (2x, 2x + 1), each edge once in each direction (distinct x by sorting).
        let mut paired = list.len().is_multiple_of(2);
        for p in list.chunks_exact(2) {
            paired &= (p[0] & 1 == 0) & (p[1] == p[0] | 1);
        }
        if paired {
            continue;
        }
        let mut i = 0;
        while i < list.len() {
            let other = list[i] >> 1;
            let mut j = i + 1;
            while j < list.len() && list[j] >> 1 == other {
                j += 1;
            }
            let forward = list[i..j].iter().filter(|&&x| x & 1 == 1).count();
            match (j - i, forward) {
                (1, _) => topo.boundary_edges += 1,
                (2, 1) => {}
                (2, _) => topo.misoriented_edges += 1,
                _ => topo.non_manifold_edges += 1,
            }
            i = j;
        }
    }
    topo
}

/// Raw integrals over one block of triangles, relative to the reference point.
#[derive(Debug, Clone, Copy, Default)]
struct Sums {
    /// Solid: Σ D, Σ D sₖ, Σ D (Σᵢ pᵢⱼpᵢₖ + sⱼsₖ) for jk = xx, yy, zz, xy, yz, zx (unscaled
    /// tetrahedron sums, see [`solid_block`]).
    /// Shell: area, first moments, second moments (already scaled).
    v: [f64; 10],
    /// Σ |measure term|, for the error bound.
    abs_measure: f64,
    degenerate: usize,
    first_degenerate: Option<usize>,
}

impl Sums {
    fn add(&mut self, o: &Sums) {
        for k in 0..10 {
            self.v[k] += o.v[k];
        }
        self.abs_measure += o.abs_measure;
        self.degenerate += o.degenerate;
        self.first_degenerate = self.first_degenerate.or(o.first_degenerate);
    }
}

#[inline(always)]
fn sub(v: &[f64; 3], r: &[f64; 3]) -> [f64; 3] {
    [v[0] - r[0], v[1] - r[1], v[2] - r[2]]
}

/// Zero-area test: |n|² ≤ (8ε)²|e₁|²|e₂|² (the cross product is at rounding level).
#[inline(always)]
fn is_degenerate(e1: &[f64; 3], e2: &[f64; 3], n: &[f64; 3]) -> bool {
    let l1 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
    let l2 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
    let nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    const T: f64 = 64.0 * f64::EPSILON * f64::EPSILON;
    nn <= T * l1 * l2
}

/// The corners relative to `r`, the normal n = (p₁ − p₀) × (p₂ − p₀), and whether the
/// triangle is degenerate.
#[inline(always)]
fn corners(vertices: &[[f64; 3]], t: &[u32; 3], r: &[f64; 3]) -> ([f64; 3], [f64; 3], [f64; 3], [f64; 3], bool) {
    let p0 = sub(&vertices[t[0] as usize], r);
    let p1 = sub(&vertices[t[1] as usize], r);
    let p2 = sub(&vertices[t[2] as usize], r);
    let e1 = [p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]];
    let e2 = [p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]];
    let n = [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ];
    // A repeated index gives n = 0 exactly, which the area test catches.
    let degenerate = is_degenerate(&e1, &e2, &n);
    (p0, p1, p2, n, degenerate)
}

/// The solid integrals by the divergence theorem in its simplest form: the closed surface
/// bounds the signed union of the tetrahedra (r, p₀, p₁, p₂), each with D = p₀·((p₁ − p₀) ×
/// (p₂ − p₀)) = 6·volume, ∫x dV = D s/24 and ∫x xᵀ dV = D (Σᵢ pᵢpᵢᵀ + s sᵀ)/120 with
/// s = p₀ + p₁ + p₂ (coordinates relative to r; the second moment of a simplex with vertices
/// vᵢ is V/20 (Σ vᵢvᵢᵀ + (Σ vᵢ)(Σ vᵢ)ᵀ), here with one vertex at r). These are the same
/// polynomial integrals as in Eberly's form, in fewer operations.
fn solid_block(vertices: &[[f64; 3]], triangles: &[[u32; 3]], r: &[f64; 3], offset: usize) -> Sums {
    let mut s = Sums::default();
    for (i, t) in triangles.iter().enumerate() {
        let (p0, p1, p2, n, degenerate) = corners(vertices, t, r);
        if degenerate {
            s.degenerate += 1;
            s.first_degenerate.get_or_insert(offset + i);
            continue;
        }
        let d = p0[0] * n[0] + p0[1] * n[1] + p0[2] * n[2];
        let c = [p0[0] + p1[0] + p2[0], p0[1] + p1[1] + p2[1], p0[2] + p1[2] + p2[2]];
        let second = |j: usize, k: usize| p0[j] * p0[k] + p1[j] * p1[k] + p2[j] * p2[k] + c[j] * c[k];
        s.v[0] += d;
        s.abs_measure += d.abs();
        s.v[1] += d * c[0];
        s.v[2] += d * c[1];
        s.v[3] += d * c[2];
        s.v[4] += d * second(0, 0);
        s.v[5] += d * second(1, 1);
        s.v[6] += d * second(2, 2);
        s.v[7] += d * second(0, 1);
        s.v[8] += d * second(1, 2);
        s.v[9] += d * second(2, 0);
    }
    s
}

fn shell_block(vertices: &[[f64; 3]], triangles: &[[u32; 3]], r: &[f64; 3], offset: usize) -> Sums {
    let mut s = Sums::default();
    for (i, t) in triangles.iter().enumerate() {
        let (p0, p1, p2, n, degenerate) = corners(vertices, t, r);
        if degenerate {
            s.degenerate += 1;
            s.first_degenerate.get_or_insert(offset + i);
            continue;
        }
        let area = 0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        s.v[0] += area;
        s.abs_measure += area;
        let c = [p0[0] + p1[0] + p2[0], p0[1] + p1[1] + p2[1], p0[2] + p1[2] + p2[2]];
        for k in 0..3 {
            s.v[1 + k] += area * c[k] / 3.0;
        }
        // ∫ x_j x_k dA = A/12 (Σ_i p_ij p_ik + c_j c_k), c = Σ_i p_i.
        let second = |j: usize, k: usize| p0[j] * p0[k] + p1[j] * p1[k] + p2[j] * p2[k] + c[j] * c[k];
        let w = area / 12.0;
        s.v[4] += w * second(0, 0);
        s.v[5] += w * second(1, 1);
        s.v[6] += w * second(2, 2);
        s.v[7] += w * second(0, 1);
        s.v[8] += w * second(1, 2);
        s.v[9] += w * second(2, 0);
    }
    s
}

/// The integrand of one block: (vertices, triangles, reference point, index of the first triangle).
type BlockFn = fn(&[[f64; 3]], &[[u32; 3]], &[f64; 3], usize) -> Sums;

/// Sums `block` over all triangles in blocks of [`BLOCK`], in parallel for large meshes, and
/// reduces the block sums in order (deterministic for any thread count).
fn integrate(vertices: &[[f64; 3]], triangles: &[[u32; 3]], r: &[f64; 3], block: BlockFn) -> Sums {
    integrate_on(worker_count(triangles.len()), vertices, triangles, r, block)
}

/// [`integrate`] on `threads` threads.
fn integrate_on(threads: usize, vertices: &[[f64; 3]], triangles: &[[u32; 3]], r: &[f64; 3], block: BlockFn) -> Sums {
    let blocks = triangles.len().div_ceil(BLOCK);
    let mut partial = vec![Sums::default(); blocks];
    let threads = threads.clamp(1, blocks.max(1));
    let per = blocks.div_ceil(threads).max(1);
    let run = |first_block: usize, outs: &mut [Sums]| {
        for (k, out) in outs.iter_mut().enumerate() {
            let start = (first_block + k) * BLOCK;
            let end = (start + BLOCK).min(triangles.len());
            *out = block(vertices, &triangles[start..end], r, start);
        }
    };
    if threads == 1 {
        run(0, &mut partial);
    } else {
        std::thread::scope(|scope| {
            for (chunk, outs) in partial.chunks_mut(per).enumerate() {
                let run = &run;
                scope.spawn(move || run(chunk * per, outs));
            }
        });
    }
    let mut total = Sums::default();
    for p in &partial {
        total.add(p);
    }
    total
}

/// Mass properties of the triangle mesh (`vertices`, `triangles`) with the given amount of
/// material and options. Closed solids use the divergence theorem on the polynomial integrals
/// of 1, x, x², xy over each triangle's cone (see the tetrahedron sums in the module source); shells integrate over the triangles
/// directly. The inertia is J = tr(S)·I − S from the central second moments S = ∫ρ y yᵀ
/// (3.17–3.18).
///
/// Errors: [`MassError::EmptyMesh`], [`MassError::NonFiniteVertex`],
/// [`MassError::IndexOutOfRange`], [`MassError::TooManyVertices`], [`MassError::TooManyTriangles`],
/// [`MassError::DegenerateTriangles`] (policy Reject), [`MassError::OpenMesh`] (policy Reject),
/// [`MassError::InconsistentOrientation`], [`MassError::InsideOut`] (policy Reject),
/// [`MassError::ZeroVolume`], and the density/mass errors of [`Amount::mass_for`].
pub fn mesh_mass_properties(
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    amount: Amount,
    options: &MeshOptions,
) -> Result<MeshMassProperties, MassError> {
    match amount {
        Amount::Mass(m) | Amount::Density(m) => {
            check_finite(m, "mass or density")?;
        }
    }
    if triangles.is_empty() {
        return Err(MassError::EmptyMesh);
    }
    let (r, diag) = reference_point(vertices)?;
    let topology = mesh_topology(vertices.len(), triangles)?;
    let mut model = options.model;
    if model == MeshModel::Solid && !topology.is_closed() {
        match options.open_mesh {
            OpenMeshPolicy::Reject => {
                return Err(MassError::OpenMesh {
                    boundary_edges: topology.boundary_edges,
                    non_manifold_edges: topology.non_manifold_edges,
                });
            }
            OpenMeshPolicy::Shell => model = MeshModel::Shell,
        }
    }
    if model == MeshModel::Solid && topology.misoriented_edges > 0 {
        return Err(MassError::InconsistentOrientation {
            misoriented_edges: topology.misoriented_edges,
        });
    }
    let mut sums = match model {
        MeshModel::Solid => integrate(vertices, triangles, &r, solid_block),
        MeshModel::Shell => integrate(vertices, triangles, &r, shell_block),
    };
    if let (DegeneratePolicy::Reject, Some(first)) = (options.degenerate, sums.first_degenerate) {
        return Err(MassError::DegenerateTriangles {
            count: sums.degenerate,
            first,
        });
    }
    if sums.degenerate == triangles.len() {
        return Err(MassError::EmptyMesh);
    }
    if model == MeshModel::Solid {
        let scale = [6.0, 24.0, 24.0, 24.0, 120.0, 120.0, 120.0, 120.0, 120.0, 120.0];
        for k in 0..10 {
            sums.v[k] /= scale[k];
        }
        sums.abs_measure /= 6.0;
    }
    // Recursive summation within a block (at most min(n, BLOCK) terms), then over the blocks,
    // plus a few roundings per term.
    let n = triangles.len();
    let terms = (n.min(BLOCK) + n.div_ceil(BLOCK) + 16) as f64;
    let relative_error_bound = |measure: f64| terms * f64::EPSILON * sums.abs_measure / measure.abs();
    let mut flipped = false;
    if model == MeshModel::Solid {
        let volume = sums.v[0];
        let cube = diag * diag * diag;
        if volume.abs() <= 1e-12 * cube || volume.abs() <= 4.0 * relative_error_bound(1.0) {
            return Err(MassError::ZeroVolume { volume, scale: cube });
        }
        if volume < 0.0 {
            match options.inside_out {
                InsideOutPolicy::Reject => return Err(MassError::InsideOut { volume }),
                InsideOutPolicy::Flip => {
                    for v in &mut sums.v {
                        *v = -*v;
                    }
                    flipped = true;
                }
            }
        }
    } else if sums.v[0].is_nan() || sums.v[0] <= 0.0 {
        return Err(MassError::EmptyMesh);
    }
    let measure = sums.v[0];
    let mass = amount.mass_for(measure)?;
    let rho = mass / measure;
    let c = Vector3::new(sums.v[1], sums.v[2], sums.v[3]) / measure;
    let v = &sums.v;
    let second = Matrix3::new(v[4], v[7], v[9], v[7], v[5], v[8], v[9], v[8], v[6]) * rho;
    let central = second - mass * (c * c.transpose());
    let inertia = Matrix3::identity() * central.trace() - central;
    let properties = MassProperties {
        mass,
        p_oc: Vector3::new(r[0] + c.x, r[1] + c.y, r[2] + c.z),
        inertia_c: inertia,
    };
    if let Some(value) = properties
        .inertia_c
        .iter()
        .chain(properties.p_oc.iter())
        .copied()
        .find(|x| !x.is_finite())
    {
        return Err(MassError::NonFinite {
            what: "mesh integral (overflow)",
            value,
        });
    }
    Ok(MeshMassProperties {
        properties,
        model,
        measure,
        diagnostics: MeshDiagnostics {
            triangles: triangles.len(),
            degenerate_triangles: sums.degenerate,
            topology,
            flipped,
        },
        relative_error_bound: relative_error_bound(measure),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
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

    fn add(a: MeshTopology, b: MeshTopology) -> MeshTopology {
        MeshTopology {
            boundary_edges: a.boundary_edges + b.boundary_edges,
            non_manifold_edges: a.non_manifold_edges + b.non_manifold_edges,
            misoriented_edges: a.misoriented_edges + b.misoriented_edges,
        }
    }

    proptest! {
        /// Random triangle soups over few vertices (so that edges repeat, flip and pile up)
        /// are classified as the brute-force reference does, also when the vertex range is
        /// split between workers at any point.
        #[test]
        fn bucketed_topology_equals_brute_force(
            triangles in proptest::collection::vec(proptest::array::uniform3(0u32..12), 1..60),
            split in 0usize..13,
        ) {
            let expected = reference_topology(&triangles);
            prop_assert_eq!(mesh_topology(12, &triangles).expect("in range"), expected);
            let parts = add(topology_of_range(&triangles, 0, split.min(12)), topology_of_range(&triangles, split.min(12), 12));
            prop_assert_eq!(parts, expected);
        }
    }

    #[test]
    fn topology_of_a_large_closed_mesh_is_clean_on_any_number_of_workers() {
        let mesh = torus_mesh(2.0, 0.5, 300, 250);
        assert!(mesh.triangles.len() >= PARALLEL_MIN_TRIANGLES);
        let v = mesh.vertices.len();
        assert_eq!(mesh_topology(v, &mesh.triangles).expect("ok"), MeshTopology::default());
        let third = v / 3;
        let parts = add(
            add(
                topology_of_range(&mesh.triangles, 0, third),
                topology_of_range(&mesh.triangles, third, 2 * third),
            ),
            topology_of_range(&mesh.triangles, 2 * third, v),
        );
        assert_eq!(parts, MeshTopology::default());
        // Dropping one triangle opens three edges.
        assert_eq!(mesh_topology(v, &mesh.triangles[1..]).expect("ok").boundary_edges, 3);
        assert!(matches!(
            mesh_topology(3, &[[0, 1, 3]]),
            Err(MassError::IndexOutOfRange {
                triangle: 0,
                corner: 2,
                index: 3,
                vertex_count: 3
            })
        ));
    }

    #[test]
    fn integrals_are_bitwise_identical_on_one_two_and_three_threads() {
        let mesh = torus_mesh(2.0, 0.5, 200, 100);
        let (r, _) = reference_point(&mesh.vertices).expect("finite");
        for block in [solid_block as BlockFn, shell_block] {
            let one = integrate_on(1, &mesh.vertices, &mesh.triangles, &r, block);
            for threads in [2, 3, 7] {
                let many = integrate_on(threads, &mesh.vertices, &mesh.triangles, &r, block);
                assert_eq!(one.v, many.v);
                assert_eq!(one.abs_measure, many.abs_measure);
            }
        }
    }
}
