//! Mass properties of triangle meshes: exact volume integrals over closed meshes (divergence
//! theorem, polynomial integrals after Eberly, "Polyhedral Mass Properties (Revisited)", 2002,
//! and Mirtich, J. Graphics Tools 1(2), 1996), thin shells with surface density, and the
//! topology checks that keep either from being silently wrong.
//!
//! All integrals are taken relative to the centre of the vertex bounding box, not the world
//! origin, so a mesh far from the origin keeps full relative accuracy (a unit cube at 1e6 gives
//! ~1e-15). The per-triangle terms are summed in fixed blocks of [`BLOCK`] triangles and then
//! block by block, so the rounding error grows like (BLOCK + n/BLOCK)·ε instead of n·ε, and the
//! result is bitwise independent of the number of threads.

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
    /// Bound on the relative rounding error of `measure`, (BLOCK + n/BLOCK + 16)·ε·Σ|terms|/|measure|;
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

/// Checks the vertices and returns the centre of their bounding box and its diagonal length.
fn reference_point(vertices: &[[f64; 3]]) -> Result<([f64; 3], f64), MassError> {
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
    let centre = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])];
    let diag = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt();
    Ok((centre, diag))
}

fn check_indices(triangles: &[[u32; 3]], vertex_count: usize) -> Result<(), MassError> {
    let max = triangles.iter().flat_map(|t| t.iter().copied()).max().unwrap_or(0);
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

/// The edge topology of `triangles` (triangles with a repeated index are ignored), in O(n log d)
/// with an adjacency list per vertex (d = vertex degree). Indices must be in range and the
/// vertex count below 2³¹.
pub fn mesh_topology(vertex_count: usize, triangles: &[[u32; 3]]) -> MeshTopology {
    let mut start = vec![0u32; vertex_count + 1];
    let usable = |t: &[u32; 3]| t[0] != t[1] && t[1] != t[2] && t[2] != t[0];
    for t in triangles.iter().filter(|t| usable(t)) {
        for &a in t {
            start[a as usize + 1] += 1;
        }
    }
    for v in 0..vertex_count {
        start[v + 1] += start[v];
    }
    let mut fill = start.clone();
    let mut targets = vec![0u32; start[vertex_count] as usize];
    for t in triangles.iter().filter(|t| usable(t)) {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3]);
            targets[fill[a] as usize] = b;
            fill[a] += 1;
        }
    }
    drop(fill);
    for v in 0..vertex_count {
        targets[start[v] as usize..start[v + 1] as usize].sort_unstable();
    }
    let list = |v: usize| &targets[start[v] as usize..start[v + 1] as usize];
    let count_in = |v: usize, x: u32| {
        let l = list(v);
        l.partition_point(|&y| y <= x) - l.partition_point(|&y| y < x)
    };
    let mut topo = MeshTopology::default();
    for x in 0..vertex_count {
        let l = list(x);
        let mut i = 0;
        while i < l.len() {
            let y = l[i];
            let mut j = i + 1;
            while j < l.len() && l[j] == y {
                j += 1;
            }
            let forward = j - i;
            i = j;
            let backward = count_in(y as usize, x as u32);
            // Each undirected edge is classified once: from its smaller end, or from its only end.
            if (x as u32) > y && backward > 0 {
                continue;
            }
            match (forward + backward, forward, backward) {
                (1, _, _) => topo.boundary_edges += 1,
                (2, 1, 1) => {}
                (2, _, _) => topo.misoriented_edges += 1,
                _ => topo.non_manifold_edges += 1,
            }
        }
    }
    topo
}

/// Raw integrals over one block of triangles, relative to the reference point.
#[derive(Debug, Clone, Copy, Default)]
struct Sums {
    /// Solid: ∫1, ∫x, ∫y, ∫z, ∫x², ∫y², ∫z², ∫xy, ∫yz, ∫zx (unscaled Eberly sums).
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
    let degenerate = is_degenerate(&e1, &e2, &n);
    (p0, p1, p2, n, degenerate)
}

/// Eberly's subexpressions for one coordinate: f1, f2, f3, g0, g1, g2.
#[inline(always)]
fn subexpressions(w0: f64, w1: f64, w2: f64) -> (f64, f64, f64, f64, f64, f64) {
    let t0 = w0 + w1;
    let f1 = t0 + w2;
    let t1 = w0 * w0;
    let t2 = t1 + w1 * t0;
    let f2 = t2 + w2 * f1;
    let f3 = w0 * t1 + w1 * t2 + w2 * f2;
    (
        f1,
        f2,
        f3,
        f2 + w0 * (f1 + w0),
        f2 + w1 * (f1 + w1),
        f2 + w2 * (f1 + w2),
    )
}

fn solid_block(vertices: &[[f64; 3]], triangles: &[[u32; 3]], r: &[f64; 3], offset: usize) -> Sums {
    let mut s = Sums::default();
    for (i, t) in triangles.iter().enumerate() {
        let (p0, p1, p2, n, degenerate) = corners(vertices, t, r);
        if degenerate {
            s.degenerate += 1;
            s.first_degenerate.get_or_insert(offset + i);
            continue;
        }
        let (f1x, f2x, f3x, g0x, g1x, g2x) = subexpressions(p0[0], p1[0], p2[0]);
        let (_, f2y, f3y, g0y, g1y, g2y) = subexpressions(p0[1], p1[1], p2[1]);
        let (_, f2z, f3z, g0z, g1z, g2z) = subexpressions(p0[2], p1[2], p2[2]);
        let vol = n[0] * f1x;
        s.v[0] += vol;
        s.abs_measure += vol.abs();
        s.v[1] += n[0] * f2x;
        s.v[2] += n[1] * f2y;
        s.v[3] += n[2] * f2z;
        s.v[4] += n[0] * f3x;
        s.v[5] += n[1] * f3y;
        s.v[6] += n[2] * f3z;
        s.v[7] += n[0] * (p0[1] * g0x + p1[1] * g1x + p2[1] * g2x);
        s.v[8] += n[1] * (p0[2] * g0y + p1[2] * g1y + p2[2] * g2y);
        s.v[9] += n[2] * (p0[0] * g0z + p1[0] * g1z + p2[0] * g2z);
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
    let blocks: Vec<&[[u32; 3]]> = triangles.chunks(BLOCK).collect();
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(blocks.len() / 16)
        .max(1);
    let mut partial = vec![Sums::default(); blocks.len()];
    if threads == 1 {
        for (b, (out, tris)) in partial.iter_mut().zip(&blocks).enumerate() {
            *out = block(vertices, tris, r, b * BLOCK);
        }
    } else {
        let per = blocks.len().div_ceil(threads);
        std::thread::scope(|scope| {
            for (chunk_index, (outs, tris)) in partial.chunks_mut(per).zip(blocks.chunks(per)).enumerate() {
                scope.spawn(move || {
                    for (k, (out, t)) in outs.iter_mut().zip(tris).enumerate() {
                        *out = block(vertices, t, r, (chunk_index * per + k) * BLOCK);
                    }
                });
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
/// of 1, x, x², xy over each triangle's cone (Eberly 2002); shells integrate over the triangles
/// directly. The inertia is J = tr(S)·I − S from the central second moments S = ∫ρ y yᵀ
/// (3.17–3.18).
///
/// Errors: [`MassError::EmptyMesh`], [`MassError::NonFiniteVertex`],
/// [`MassError::IndexOutOfRange`], [`MassError::TooManyVertices`],
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
    if vertices.len() > (1usize << 31) {
        return Err(MassError::TooManyVertices(vertices.len()));
    }
    let (r, diag) = reference_point(vertices)?;
    check_indices(triangles, vertices.len())?;
    let topology = mesh_topology(vertices.len(), triangles);
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
        let scale = [6.0, 24.0, 24.0, 24.0, 60.0, 60.0, 60.0, 120.0, 120.0, 120.0];
        for k in 0..10 {
            sums.v[k] /= scale[k];
        }
        sums.abs_measure /= 6.0;
    }
    let n = triangles.len() as f64;
    let relative_error_bound =
        |measure: f64| (BLOCK as f64 + n / BLOCK as f64 + 16.0) * f64::EPSILON * sums.abs_measure / measure.abs();
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
