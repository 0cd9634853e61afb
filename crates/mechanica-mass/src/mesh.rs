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

use crate::error::{check_finite, check_result};
use crate::primitives::Amount;
use crate::{MassError, MassProperties};
use nalgebra::{Matrix3, Vector3};

pub use crate::mesh_integrals::BLOCK;
use crate::mesh_integrals::{Integrand, SOLID_DIVISORS, Sums, integrate};
pub use crate::parallel::PARALLEL_MIN_TRIANGLES;
use crate::topology::check_indices;
pub use crate::topology::{MeshTopology, mesh_topology};

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
    /// Where the edge topology comes from.
    pub topology: TopologySource,
}

impl Default for MeshOptions {
    fn default() -> Self {
        Self {
            model: MeshModel::Solid,
            open_mesh: OpenMeshPolicy::Reject,
            inside_out: InsideOutPolicy::Flip,
            degenerate: DegeneratePolicy::Skip,
            topology: TopologySource::Check,
        }
    }
}

/// Where [`mesh_mass_properties`] takes the edge topology from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TopologySource {
    /// Classify every edge (the default). On large meshes the edge check takes more time than
    /// the integrals (see docs/benchmarks.md).
    Check,
    /// The topology an earlier call found for the same triangle array, for meshes whose
    /// vertices move while their connectivity stays (a deforming body re-integrated every step):
    /// the caller vouches that the triangles are unchanged, and the edge check is skipped. Vertex
    /// indices are still checked, and an inside-out mesh is still found from its signed volume.
    Known(MeshTopology),
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

/// Checks the vertices and returns the centre of their bounding box and its diagonal length.
fn reference_point(vertices: &[[f64; 3]]) -> Result<([f64; 3], f64), MassError> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut finite = true;
    // Plain comparisons (not f64::min/max, whose NaN rules block vectorisation); NaN is
    // caught by the finiteness flag.
    for v in vertices {
        for k in 0..3 {
            finite &= v[k].is_finite();
            lo[k] = if v[k] < lo[k] { v[k] } else { lo[k] };
            hi[k] = if v[k] > hi[k] { v[k] } else { hi[k] };
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

/// Mass properties of the triangle mesh (`vertices`, `triangles`) with the given amount of
/// material and options, in the frame of the vertices (m, kg, kg·m²). Closed solids use the
/// divergence theorem on the polynomial integrals of 1, x, x², xy over each triangle's cone
/// (the signed tetrahedra between a reference point and each triangle); shells integrate over
/// the triangles directly. The inertia is J = tr(S)·I − S from the central second moments
/// S = ∫ρ y yᵀ (3.17–3.18). The integrals are exact up to rounding, bounded by
/// [`MeshMassProperties::relative_error_bound`].
///
/// Errors: [`MassError::EmptyMesh`], [`MassError::NonFiniteVertex`],
/// [`MassError::IndexOutOfRange`], [`MassError::TooManyVertices`], [`MassError::TooManyTriangles`],
/// [`MassError::DegenerateTriangles`] (policy Reject), [`MassError::OpenMesh`] (policy Reject),
/// [`MassError::InconsistentOrientation`], [`MassError::InsideOut`] (policy Reject),
/// [`MassError::ZeroVolume`], the density/mass errors of [`Amount::mass_for`] (including
/// [`MassError::MassUnderflow`]), and [`MassError::NonFiniteResult`] when an integral or a
/// result overflows (vertex coordinates of extreme magnitude).
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
    let topology = match options.topology {
        TopologySource::Check => mesh_topology(vertices.len(), triangles)?,
        TopologySource::Known(known) => {
            check_indices(triangles, vertices.len())?;
            known
        }
    };
    let model = model_for_topology(options, &topology)?;
    let mut sums = scaled_sums(vertices, triangles, &r, model, options.degenerate)?;
    let flipped = check_measure(&mut sums, model, triangles.len(), diag, options.inside_out)?;
    let measure = sums.v[0];
    let properties = properties_from_sums(&sums, &r, amount)?;
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
        relative_error_bound: relative_error_bound(triangles.len(), sums.abs_measure, measure),
    })
}

/// The model to integrate: the requested one, or a shell for an open mesh under
/// [`OpenMeshPolicy::Shell`]; an error for an open (policy Reject) or misoriented solid.
fn model_for_topology(options: &MeshOptions, topology: &MeshTopology) -> Result<MeshModel, MassError> {
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
    Ok(model)
}

/// The integrals of 1, x, x², xy relative to `r` under `model`, scaled to volume moments for a
/// solid; an error when degenerate triangles are rejected or every triangle is degenerate.
fn scaled_sums(
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    r: &[f64; 3],
    model: MeshModel,
    degenerate: DegeneratePolicy,
) -> Result<Sums, MassError> {
    let mut sums = match model {
        MeshModel::Solid => integrate(vertices, triangles, r, Integrand::Solid),
        MeshModel::Shell => integrate(vertices, triangles, r, Integrand::Shell),
    };
    if let (DegeneratePolicy::Reject, Some(first)) = (degenerate, sums.first_degenerate) {
        return Err(MassError::DegenerateTriangles {
            count: sums.degenerate,
            first,
        });
    }
    if sums.degenerate == triangles.len() {
        return Err(MassError::EmptyMesh);
    }
    if model == MeshModel::Solid {
        for k in 0..10 {
            sums.v[k] /= SOLID_DIVISORS[k];
        }
        sums.abs_measure /= 6.0;
    }
    Ok(sums)
}

/// The bound (min(n, BLOCK) + ⌈n/BLOCK⌉ + 16)·ε·`abs_measure`/|`measure`| on the relative
/// rounding error of a measure summed over `n` triangles: recursive summation within a block
/// (at most min(n, BLOCK) terms), then over the blocks, plus a few roundings per term.
fn relative_error_bound(n: usize, abs_measure: f64, measure: f64) -> f64 {
    let terms = (n.min(BLOCK) + n.div_ceil(BLOCK) + 16) as f64;
    terms * f64::EPSILON * abs_measure / measure.abs()
}

/// Checks the measure: a solid's volume must exceed both 1e-12·`diag`³ and four times its
/// rounding bound, and a negative one is reversed (returning true) or rejected by
/// `inside_out`; a shell's area must be positive.
fn check_measure(
    sums: &mut Sums,
    model: MeshModel,
    n: usize,
    diag: f64,
    inside_out: InsideOutPolicy,
) -> Result<bool, MassError> {
    let mut flipped = false;
    check_result(sums.v.iter(), "mesh integrals (vertex coordinates too large)")?;
    if model == MeshModel::Solid {
        let volume = sums.v[0];
        let cube = diag * diag * diag;
        if volume.abs() <= 1e-12 * cube || volume.abs() <= 4.0 * relative_error_bound(n, sums.abs_measure, 1.0) {
            return Err(MassError::ZeroVolume { volume, scale: cube });
        }
        if volume < 0.0 {
            match inside_out {
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
    Ok(flipped)
}

/// Mass, centre of mass and central inertia J = tr(S)·I − S (3.17–3.18) from the checked sums
/// relative to `r`; an error when the amount does not fit the measure or a result overflows.
fn properties_from_sums(sums: &Sums, r: &[f64; 3], amount: Amount) -> Result<MassProperties, MassError> {
    let measure = sums.v[0];
    let mass = amount.mass_for(measure)?;
    let c = Vector3::new(sums.v[1], sums.v[2], sums.v[3]) / measure;
    let v = &sums.v;
    // The second moments per unit measure, then times the mass: the density mass/measure
    // itself may underflow (a light body of large measure) where the moments do not.
    let second = Matrix3::new(v[4], v[7], v[9], v[7], v[5], v[8], v[9], v[8], v[6]) / measure * mass;
    let central = second - mass * (c * c.transpose());
    let inertia = Matrix3::identity() * central.trace() - central;
    let properties = MassProperties {
        mass,
        p_oc: Vector3::new(r[0] + c.x, r[1] + c.y, r[2] + c.z),
        inertia_c: inertia,
    };
    check_result(properties.p_oc.iter(), "mesh centre of mass")?;
    check_result(properties.inertia_c.iter(), "mesh inertia tensor")?;
    Ok(properties)
}
