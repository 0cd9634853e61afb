//! Mass properties of triangle meshes: solids and shells, the policies for open, inside-out
//! and degenerate meshes, and the report of what was found.

use super::mech_mass_properties_t;
use super::primitives::{amount_of, mech_amount_t};
use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::c_enum::{c_enum, enum_value};
use crate::ffi::status::*;
use crate::ffi::validate::*;
use mechanica_mass::mesh::{
    DegeneratePolicy, InsideOutPolicy, MeshModel, MeshOptions, MeshTopology, OpenMeshPolicy, TopologySource,
    TriangleMesh,
};
use mechanica_mass::weld::{WeldReport, weld_vertices};

/// The mass model of a mesh.
pub type mech_mesh_model_t = i32;
/// A closed surface bounding a solid of uniform volume density.
pub const MECH_MESH_SOLID: mech_mesh_model_t = 0;
/// A thin shell with uniform surface density (kg/m²).
pub const MECH_MESH_SHELL: mech_mesh_model_t = 1;

/// What to do with an open mesh under MECH_MESH_SOLID.
pub type mech_open_mesh_t = i32;
/// Fail with MECH_STATUS_INVALID_ARGUMENT (the message gives the boundary-edge count).
pub const MECH_OPEN_MESH_REJECT: mech_open_mesh_t = 0;
/// Fall back to the shell model; a density amount is then read as kg/m².
pub const MECH_OPEN_MESH_SHELL: mech_open_mesh_t = 1;

/// What to do with an inside-out closed mesh (negative signed volume).
pub type mech_inside_out_t = i32;
/// Reverse the orientation and report `flipped` = 1.
pub const MECH_INSIDE_OUT_FLIP: mech_inside_out_t = 0;
/// Fail with MECH_STATUS_INVALID_ARGUMENT.
pub const MECH_INSIDE_OUT_REJECT: mech_inside_out_t = 1;

/// What to do with degenerate triangles (repeated indices or zero area).
pub type mech_degenerate_t = i32;
/// Count them in the report and leave them out of the integrals.
pub const MECH_DEGENERATE_SKIP: mech_degenerate_t = 0;
/// Fail with MECH_STATUS_INVALID_ARGUMENT.
pub const MECH_DEGENERATE_REJECT: mech_degenerate_t = 1;

c_enum!(MeshModel, MECH_MESH_SOLID => MeshModel::Solid, MECH_MESH_SHELL => MeshModel::Shell);
c_enum!(OpenMeshPolicy,
    MECH_OPEN_MESH_REJECT => OpenMeshPolicy::Reject,
    MECH_OPEN_MESH_SHELL => OpenMeshPolicy::Shell,
);
c_enum!(InsideOutPolicy,
    MECH_INSIDE_OUT_FLIP => InsideOutPolicy::Flip,
    MECH_INSIDE_OUT_REJECT => InsideOutPolicy::Reject,
);
c_enum!(DegeneratePolicy,
    MECH_DEGENERATE_SKIP => DegeneratePolicy::Skip,
    MECH_DEGENERATE_REJECT => DegeneratePolicy::Reject,
);

/// Options of mech_mass_mesh and mech_mass_mesh_same_connectivity; a NULL options pointer
/// means the defaults, which mech_mesh_options_default writes: solid, reject open meshes, flip
/// inside-out meshes, skip degenerate triangles (all fields zero).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_mesh_options_t {
    /// A mech_mesh_model_t.
    pub model: mech_mesh_model_t,
    /// A mech_open_mesh_t.
    pub open_mesh: mech_open_mesh_t,
    /// A mech_inside_out_t.
    pub inside_out: mech_inside_out_t,
    /// A mech_degenerate_t.
    pub degenerate: mech_degenerate_t,
}

impl From<&MeshOptions> for mech_mesh_options_t {
    fn from(o: &MeshOptions) -> Self {
        Self {
            model: match o.model {
                MeshModel::Solid => MECH_MESH_SOLID,
                MeshModel::Shell => MECH_MESH_SHELL,
            },
            open_mesh: match o.open_mesh {
                OpenMeshPolicy::Reject => MECH_OPEN_MESH_REJECT,
                OpenMeshPolicy::Shell => MECH_OPEN_MESH_SHELL,
            },
            inside_out: match o.inside_out {
                InsideOutPolicy::Flip => MECH_INSIDE_OUT_FLIP,
                InsideOutPolicy::Reject => MECH_INSIDE_OUT_REJECT,
            },
            degenerate: match o.degenerate {
                DegeneratePolicy::Skip => MECH_DEGENERATE_SKIP,
                DegeneratePolicy::Reject => MECH_DEGENERATE_REJECT,
            },
        }
    }
}

/// Writes the default mesh options (those a NULL options pointer selects) to `options_out`.
///
/// Errors: none beyond the pointer checks.
///
/// # Safety
/// `options_out` must point to a writable mech_mesh_options_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mesh_options_default(options_out: *mut mech_mesh_options_t) -> mech_status_t {
    boundary(|| {
        let out = Out::new(options_out, "options_out")?;
        // SAFETY: caller's contract.
        unsafe { out.write((&MeshOptions::default()).into()) };
        Ok(())
    })
}

/// What mech_mass_mesh found and how accurate its integrals are.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_mesh_report_t {
    /// The model used (a mech_mesh_model_t; an open solid may fall back to a shell).
    pub model: mech_mesh_model_t,
    /// 1 when an inside-out mesh was reversed, else 0.
    pub flipped: i32,
    /// Volume (m³) for a solid, area (m²) for a shell.
    pub measure: f64,
    /// Bound on the relative rounding error of `measure`.
    pub relative_error_bound: f64,
    /// Number of triangles given.
    pub triangles: usize,
    /// Triangles skipped as degenerate.
    pub degenerate_triangles: usize,
    /// Edges used by one triangle only.
    pub boundary_edges: usize,
    /// Edges used by more than two triangles.
    pub non_manifold_edges: usize,
    /// Edges used twice in the same direction.
    pub misoriented_edges: usize,
}

/// Mass properties of the triangle mesh with `vertex_count` vertices (x, y, z interleaved:
/// 3·vertex_count doubles, metres, in the frame of the result) and `triangle_count` triangles
/// (3·triangle_count vertex indices, counter-clockwise seen from outside), with `amount` read
/// as a mass or a density per `amount_kind` (a mech_amount_t), written to `out`. Closed solids
/// use exact polynomial volume integrals relative to a point near the mesh, so far-from-origin
/// meshes keep full accuracy. `options` may be NULL for the defaults (see
/// mech_mesh_options_default); `report_out` (may be NULL) receives what was found and the
/// relative error bound of the volume or area.
///
/// Errors: MECH_STATUS_BAD_DIMENSION (0 triangles, sizes overflowing); MECH_STATUS_BAD_ENUM
/// (`amount_kind` or an options field); MECH_STATUS_NON_FINITE (a vertex; the message names
/// it); MECH_STATUS_INVALID_ARGUMENT (index out of range, open, misoriented, inside-out or
/// degenerate meshes under rejecting policies, zero volume, non-positive density or mass; the
/// message says which and how many).
///
/// # Safety
/// `vertices` must point to 3·vertex_count readable doubles, `indices` to 3·triangle_count
/// readable uint32_t, `options` NULL or readable, `out` writable, `report_out` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mass_mesh(
    vertices: *const f64,
    vertex_count: usize,
    indices: *const u32,
    triangle_count: usize,
    amount_kind: mech_amount_t,
    amount: f64,
    options: *const mech_mesh_options_t,
    out: *mut mech_mass_properties_t,
    report_out: *mut mech_mesh_report_t,
) -> mech_status_t {
    let mesh = MeshInput {
        vertices,
        vertex_count,
        indices,
        triangle_count,
    };
    // SAFETY: the caller's contract is mesh_call's.
    unsafe { mesh_call(mesh, amount_kind, amount, options, None, out, report_out, None) }
}

/// As mech_mass_mesh, for a mesh whose vertices moved since an earlier call on the same
/// triangle array (a deforming body re-integrated every step): the edge-topology check, the
/// larger part of the work for a large mesh, is skipped and its result taken from `earlier`,
/// the report of that call (its `triangles` must equal `triangle_count`). The caller vouches
/// that the triangles are unchanged; indices are still checked and an inside-out mesh is still
/// flipped or refused.
///
/// Errors: as mech_mass_mesh; MECH_STATUS_NULL_POINTER when `earlier` is NULL;
/// MECH_STATUS_BAD_DIMENSION when its triangle count differs.
///
/// # Safety
/// As mech_mass_mesh; `earlier` must point to a readable mech_mesh_report_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mass_mesh_same_connectivity(
    vertices: *const f64,
    vertex_count: usize,
    indices: *const u32,
    triangle_count: usize,
    amount_kind: mech_amount_t,
    amount: f64,
    options: *const mech_mesh_options_t,
    earlier: *const mech_mesh_report_t,
    out: *mut mech_mass_properties_t,
    report_out: *mut mech_mesh_report_t,
) -> mech_status_t {
    let mesh = MeshInput {
        vertices,
        vertex_count,
        indices,
        triangle_count,
    };
    // SAFETY: the caller's contract is mesh_call's.
    unsafe { mesh_call(mesh, amount_kind, amount, options, Some(earlier), out, report_out, None) }
}

/// The relative weld tolerance that mech_mass_mesh_welded takes for "default": 1e-8 of the
/// bounding-box diagonal, the tolerance the mesh file loaders apply.
pub const MECH_DEFAULT_WELD_TOLERANCE: f64 = 1e-8;

/// What mech_mass_mesh_welded's welding did.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_weld_report_t {
    /// The relative tolerance asked for.
    pub relative_tolerance: f64,
    /// The absolute tolerance applied: relative tolerance × bounding-box diagonal (m).
    pub tolerance: f64,
    /// The largest distance any vertex moved (m), at most `tolerance`.
    pub max_displacement: f64,
    /// Vertices given.
    pub vertices_before: usize,
    /// Vertices after welding (unused vertices removed).
    pub vertices_after: usize,
    /// Vertices merged into another one (bit-identical or within the tolerance).
    pub vertices_welded: usize,
    /// Triangles dropped because welding joined two of their corners.
    pub triangles_dropped: usize,
}

/// As mech_mass_mesh, after welding the vertices within `weld_tolerance` × the diagonal of
/// their bounding box (MECH_DEFAULT_WELD_TOLERANCE = 1e-8 closes the hairline cracks CAD
/// exporters leave between patches; 0 merges bit-identical positions only). The rule: the
/// vertices are visited in index order and each one not yet merged claims every unmerged
/// vertex within the tolerance, which takes its position; so every vertex moves at most the
/// tolerance, chains of near points do not collapse, and the result is deterministic.
/// Triangles whose corners welding joins are dropped. `report_out` describes the welded mesh
/// (its `triangles` counts the triangles kept, so it is not an `earlier` report for
/// mech_mass_mesh_same_connectivity of the caller's arrays); `weld_out` (may be NULL)
/// receives what welding did.
///
/// Errors: as mech_mass_mesh; MECH_STATUS_INVALID_ARGUMENT for a negative or non-finite
/// `weld_tolerance` and for one so coarse that more than 64 distinct vertices lie in one cube
/// of its size.
///
/// # Safety
/// As mech_mass_mesh; `weld_out` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mass_mesh_welded(
    vertices: *const f64,
    vertex_count: usize,
    indices: *const u32,
    triangle_count: usize,
    weld_tolerance: f64,
    amount_kind: mech_amount_t,
    amount: f64,
    options: *const mech_mesh_options_t,
    out: *mut mech_mass_properties_t,
    report_out: *mut mech_mesh_report_t,
    weld_out: *mut mech_weld_report_t,
) -> mech_status_t {
    let mesh = MeshInput {
        vertices,
        vertex_count,
        indices,
        triangle_count,
    };
    let weld = Weld {
        tolerance: weld_tolerance,
        report_out: weld_out,
    };
    // SAFETY: the caller's contract is mesh_call's.
    unsafe { mesh_call(mesh, amount_kind, amount, options, None, out, report_out, Some(weld)) }
}

/// The weld step of mech_mass_mesh_welded: the relative tolerance and where its report goes.
struct Weld {
    tolerance: f64,
    report_out: *mut mech_weld_report_t,
}

impl From<(&WeldReport, usize)> for mech_weld_report_t {
    fn from((r, vertices_after): (&WeldReport, usize)) -> Self {
        Self {
            relative_tolerance: r.relative_tolerance,
            tolerance: r.tolerance,
            max_displacement: r.max_displacement,
            vertices_before: r.vertices_before,
            vertices_after,
            vertices_welded: r.vertices_welded,
            triangles_dropped: r.triangles_dropped,
        }
    }
}

/// The caller's vertex and index arrays.
struct MeshInput {
    vertices: *const f64,
    vertex_count: usize,
    indices: *const u32,
    triangle_count: usize,
}

/// The body of mech_mass_mesh, mech_mass_mesh_same_connectivity and mech_mass_mesh_welded;
/// `earlier` is the report whose topology is reused, if any, `weld` the weld step, if any.
///
/// # Safety
/// As mech_mass_mesh; `earlier`, when given, readable; the weld report pointer NULL or
/// writable.
unsafe fn mesh_call(
    mesh: MeshInput,
    amount_kind: mech_amount_t,
    amount: f64,
    options: *const mech_mesh_options_t,
    earlier: Option<*const mech_mesh_report_t>,
    out: *mut mech_mass_properties_t,
    report_out: *mut mech_mesh_report_t,
    weld: Option<Weld>,
) -> mech_status_t {
    boundary(|| {
        let triangle_count = mesh.triangle_count;
        if triangle_count == 0 {
            return Err(FfiError::new(MECH_STATUS_BAD_DIMENSION, "triangle_count is 0"));
        }
        let vertex_len = product(3, mesh.vertex_count, "vertex_count")?;
        // SAFETY: caller's contract.
        let flat_v = unsafe { read_slice(mesh.vertices, vertex_len, "vertices") }?;
        let index_len = product(3, triangle_count, "triangle_count")?;
        // SAFETY: caller's contract.
        let flat_i = unsafe { read_slice(mesh.indices, index_len, "indices") }?;
        let opts = if options.is_null() {
            mech_mesh_options_t::default()
        } else {
            // SAFETY: caller's contract.
            unsafe { read(options, "options") }?
        };
        let out = Out::new(out, "out")?;
        let report = Out::optional(report_out, "report_out")?;
        let topology = match earlier {
            None => TopologySource::Check,
            // SAFETY: caller's contract.
            Some(ptr) => unsafe { known_topology(ptr, triangle_count) }?,
        };
        let options = MeshOptions {
            model: enum_value(opts.model, "options.model")?,
            open_mesh: enum_value(opts.open_mesh, "options.open_mesh")?,
            inside_out: enum_value(opts.inside_out, "options.inside_out")?,
            degenerate: enum_value(opts.degenerate, "options.degenerate")?,
            topology,
        };
        let amount = amount_of(amount_kind, amount)?;
        let (verts, _) = flat_v.as_chunks::<3>();
        let (tris, _) = flat_i.as_chunks::<3>();
        let r = match weld {
            None => mechanica_mass::mesh_mass_properties(verts, tris, amount, &options)?,
            // SAFETY: caller's contract.
            Some(weld) => unsafe { welded_mass_properties(verts, tris, weld, amount, &options) }?,
        };
        let rep = report_to_c(&r);
        // SAFETY: caller's contract.
        unsafe {
            out.write(r.properties.into());
            if let Some(o) = report {
                o.write(rep);
            }
        }
        Ok(())
    })
}

/// The mass properties of the mesh (`verts`, `tris`) welded by `weld`, whose report is written
/// (when its pointer is not NULL) once the welding succeeded.
///
/// # Safety
/// `weld.report_out` NULL or writable.
unsafe fn welded_mass_properties(
    verts: &[[f64; 3]],
    tris: &[[u32; 3]],
    weld: Weld,
    amount: mechanica_mass::Amount,
    options: &MeshOptions,
) -> Result<mechanica_mass::mesh::MeshMassProperties, FfiError> {
    let weld_out = Out::optional(weld.report_out, "weld_out")?;
    let given = TriangleMesh {
        vertices: verts.to_vec(),
        triangles: tris.to_vec(),
    };
    let (welded, report) = weld_vertices(&given, weld.tolerance)?;
    if let Some(o) = weld_out {
        // SAFETY: caller's contract.
        unsafe { o.write((&report, welded.vertices.len()).into()) };
    }
    Ok(welded.mass_properties(amount, options)?)
}

/// The edge topology recorded in the report `earlier` of a mesh with `triangle_count`
/// triangles (BAD_DIMENSION for a report of another size).
///
/// # Safety
/// A non-NULL, aligned `earlier` must point to a readable mech_mesh_report_t.
unsafe fn known_topology(
    earlier: *const mech_mesh_report_t,
    triangle_count: usize,
) -> Result<TopologySource, FfiError> {
    // SAFETY: caller's contract.
    let e = unsafe { read(earlier, "earlier") }?;
    if e.triangles != triangle_count {
        return Err(FfiError::new(
            MECH_STATUS_BAD_DIMENSION,
            format!(
                "earlier report is for {} triangles, this call has {triangle_count}",
                e.triangles
            ),
        ));
    }
    Ok(TopologySource::Known(MeshTopology {
        boundary_edges: e.boundary_edges,
        non_manifold_edges: e.non_manifold_edges,
        misoriented_edges: e.misoriented_edges,
    }))
}

/// The C report of a mesh integration.
fn report_to_c(r: &mechanica_mass::mesh::MeshMassProperties) -> mech_mesh_report_t {
    let d = &r.diagnostics;
    mech_mesh_report_t {
        model: match r.model {
            MeshModel::Solid => MECH_MESH_SOLID,
            MeshModel::Shell => MECH_MESH_SHELL,
        },
        flipped: i32::from(d.flipped),
        measure: r.measure,
        relative_error_bound: r.relative_error_bound,
        triangles: d.triangles,
        degenerate_triangles: d.degenerate_triangles,
        boundary_edges: d.topology.boundary_edges,
        non_manifold_edges: d.topology.non_manifold_edges,
        misoriented_edges: d.topology.misoriented_edges,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_options_are_all_zeros() {
        let mut written = mech_mesh_options_t {
            model: -1,
            open_mesh: -1,
            inside_out: -1,
            degenerate: -1,
        };
        // SAFETY: `written` is a writable mech_mesh_options_t.
        assert_eq!(unsafe { mech_mesh_options_default(&mut written) }, MECH_STATUS_OK);
        assert_eq!(written, mech_mesh_options_t::default());
    }

    #[test]
    fn the_c_default_weld_tolerance_is_the_loaders() {
        assert_eq!(
            MECH_DEFAULT_WELD_TOLERANCE,
            mechanica_mass::weld::DEFAULT_WELD_TOLERANCE
        );
    }
}
