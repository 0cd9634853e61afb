//! `mechanica mass FILE`: the inertia calculator for triangle-mesh files (STL binary or ASCII,
//! OBJ). It reports what a URDF `<inertial>` or a simulator's body definition needs: the mass,
//! the centre of mass, the inertia tensor about the centre of mass, the principal moments and
//! axes, and what the mesh checks found (degenerate triangles skipped, boundary and
//! non-manifold edges, an inside-out mesh that was flipped).
//!
//! The amount of material is either `--density ρ` or `--mass m` (exclusive). Without either,
//! a solid has the density of water, 1000 kg/m³, and a shell (`--shell`) 1 kg/m². `--scale s`
//! multiplies every vertex coordinate first (0.001 for a file in millimetres). A solid needs a
//! closed mesh: an open one is rejected with its boundary-edge count unless `--shell` asks for
//! the thin-shell (surface-density) model.

pub(crate) mod records;

use crate::report::{Command, Report, timed_step};
use mechanica::mass::crack::crack_width;
use mechanica::mass::io::load_mesh_welded;
use mechanica::mass::mesh::{MeshMassProperties, MeshModel, MeshOptions, TriangleMesh};
use mechanica::mass::{Amount, DEFAULT_WELD_TOLERANCE, MassError, WeldReport};
use records::{InertiaSix, MeshDiagnosticsRecord, MeshLoadRecord, MeshMassRecord, MeshModelName, WeldRecord};

/// Density of a solid when neither `--density` nor `--mass` is given (water), kg/m³.
pub const DEFAULT_SOLID_DENSITY: f64 = 1000.0;
/// Surface density of a shell when neither `--density` nor `--mass` is given, kg/m².
pub const DEFAULT_SHELL_DENSITY: f64 = 1.0;

/// Arguments of `mechanica mass`.
#[derive(Debug, clap::Args)]
pub struct MassArgs {
    /// The mesh file (STL binary or ASCII, or OBJ; chosen by the extension).
    pub file: std::path::PathBuf,
    /// Uniform density: kg/m³ for a solid, kg/m² with --shell. Default 1000 kg/m³ (water) for
    /// a solid, 1 kg/m² for a shell.
    #[arg(long, value_name = "RHO", conflicts_with = "mass", allow_negative_numbers = true)]
    pub density: Option<f64>,
    /// Total mass in kg, spread uniformly over the volume (or the surface with --shell).
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    pub mass: Option<f64>,
    /// Thin-shell model: the surface carries the mass (surface density). Accepts open meshes.
    #[arg(long)]
    pub shell: bool,
    /// Multiplies every vertex coordinate before the computation, e.g. 0.001 for a file in
    /// millimetres (the results are then in metres).
    #[arg(long, value_name = "S", default_value_t = 1.0, allow_negative_numbers = true)]
    pub scale: f64,
    /// Welds vertices closer than TOL × the bounding-box diagonal (closes hairline cracks
    /// between CAD patches); 0 merges identical positions only.
    #[arg(long, value_name = "TOL", default_value_t = DEFAULT_WELD_TOLERANCE, allow_negative_numbers = true)]
    pub weld: f64,
}

impl MassArgs {
    /// The amount of material the arguments ask for.
    fn amount(&self) -> Amount {
        match (self.density, self.mass) {
            (_, Some(m)) => Amount::Mass(m),
            (Some(rho), None) => Amount::Density(rho),
            (None, None) if self.shell => Amount::Density(DEFAULT_SHELL_DENSITY),
            (None, None) => Amount::Density(DEFAULT_SOLID_DENSITY),
        }
    }
}

/// Explains a mesh error with the file name and, where it helps, the option that accepts it;
/// `mesh` (when loaded) tells cracks, which a larger weld tolerance closes, from an open
/// surface, which only the shell model accepts.
fn explain(file: &std::path::Path, error: &MassError, mesh: Option<&TriangleMesh>) -> String {
    let hint = match error {
        MassError::OpenMesh { boundary_edges: 0, .. } => " (no edge is open, but some are shared by more than two \
            triangles: the file may hold its surface twice, or parts that touch along edges; --shell accepts it as a \
            thin shell)"
            .into(),
        MassError::OpenMesh { .. } => open_mesh_hint(mesh),
        MassError::InconsistentOrientation { .. } => " (repair the mesh's triangle orientation first)".into(),
        _ => String::new(),
    };
    format!("{}: {error}{hint}", file.display())
}

/// The advice for an open mesh: `--weld` with a tolerance above the crack width when the
/// boundary is hairline cracks, `--shell` otherwise.
fn open_mesh_hint(mesh: Option<&TriangleMesh>) -> String {
    match mesh.and_then(crack_width) {
        Some(width) => {
            // The next power of ten at least twice the width, so that every crack end pairs.
            let suggested = 10f64.powf((2.0 * width).max(f64::MIN_POSITIVE).log10().ceil());
            format!(
                " (its boundary edges pair up across cracks up to {width:.1e} of the mesh size wide: \
                 try --weld {suggested:e} to close them; --shell only for a thin shell)"
            )
        }
        None => " (a large open boundary: use --shell for a thin-shell model with surface density)".into(),
    }
}

fn scaled(mut mesh: TriangleMesh, scale: f64) -> Result<TriangleMesh, String> {
    if !(scale.is_finite() && scale > 0.0) {
        return Err(format!("--scale must be finite and positive, got {scale}"));
    }
    if scale != 1.0 {
        for v in &mut mesh.vertices {
            for x in v.iter_mut() {
                *x *= scale;
            }
        }
    }
    Ok(mesh)
}

/// What welding did, in the units of the scaled mesh.
fn weld_record(weld: &WeldReport, scale: f64) -> WeldRecord {
    WeldRecord {
        relative_tolerance: weld.relative_tolerance,
        tolerance: weld.tolerance * scale,
        vertices_welded: weld.vertices_welded,
        triangles_dropped: weld.triangles_dropped,
        max_displacement: weld.max_displacement * scale,
    }
}

/// The rows of a 3 × 3 matrix.
fn rows(m: &mechanica::kinematics::nalgebra::Matrix3<f64>) -> [[f64; 3]; 3] {
    [0, 1, 2].map(|r| [0, 1, 2].map(|c| m[(r, c)]))
}

/// The record of the mass-properties step.
fn properties_record(result: &MeshMassProperties) -> Result<MeshMassRecord, MassError> {
    let p = &result.properties;
    let j = &p.inertia_c;
    let principal = p.principal_axes()?;
    let axes = principal.r_fp.matrix();
    let j_origin = p.inertia_about(&mechanica::kinematics::nalgebra::Vector3::zeros());
    Ok(MeshMassRecord {
        model: match result.model {
            MeshModel::Solid => MeshModelName::Solid,
            MeshModel::Shell => MeshModelName::Shell,
        },
        mass: p.mass,
        measure: result.measure,
        density: p.mass / result.measure,
        centre_of_mass: p.p_oc.into(),
        inertia: rows(j),
        inertia_urdf: InertiaSix {
            ixx: j[(0, 0)],
            ixy: j[(0, 1)],
            ixz: j[(0, 2)],
            iyy: j[(1, 1)],
            iyz: j[(1, 2)],
            izz: j[(2, 2)],
        },
        inertia_about_origin: rows(&j_origin),
        principal_moments: principal.moments.into(),
        principal_axes: [0, 1, 2].map(|c| [0, 1, 2].map(|r| axes[(r, c)])),
        principal_relative_residual: principal.relative_residual,
        relative_error_bound: result.relative_error_bound,
    })
}

/// Runs the inertia calculator on one mesh file.
pub fn run(args: &MassArgs) -> Result<Report, String> {
    let file = &args.file;
    let mut mesh = None;
    let load = timed_step("load mesh", || -> Result<MeshLoadRecord, String> {
        let (m, weld) = load_mesh_welded(file, args.weld).map_err(|e| explain(file, &e, None))?;
        let m = scaled(m, args.scale)?;
        let record = MeshLoadRecord {
            vertices: m.vertices.len(),
            triangles: m.triangles.len(),
            scale: args.scale,
            weld: weld_record(&weld, args.scale),
        };
        mesh = Some(m);
        Ok(record)
    })?;
    let mesh = mesh.ok_or_else(|| format!("{}: no mesh was loaded", file.display()))?;
    let options = MeshOptions {
        model: if args.shell { MeshModel::Shell } else { MeshModel::Solid },
        ..MeshOptions::default()
    };
    let mut result = None;
    let analysis = if args.shell {
        "mass properties (thin shell, surface density)"
    } else {
        "mass properties (solid, volume density)"
    };
    let properties = timed_step(analysis, || -> Result<MeshMassRecord, String> {
        let r = mesh
            .mass_properties(args.amount(), &options)
            .map_err(|e| explain(file, &e, Some(&mesh)))?;
        let record = properties_record(&r).map_err(|e| explain(file, &e, Some(&mesh)))?;
        result = Some(r);
        Ok(record)
    })?;
    let result = result.ok_or_else(|| format!("{}: no mass properties were computed", file.display()))?;
    let d = &result.diagnostics;
    let diagnostics = timed_step("mesh diagnostics", || -> Result<MeshDiagnosticsRecord, String> {
        Ok(MeshDiagnosticsRecord {
            triangles: d.triangles,
            degenerate_triangles: d.degenerate_triangles,
            boundary_edges: d.topology.boundary_edges,
            non_manifold_edges: d.topology.non_manifold_edges,
            misoriented_edges: d.topology.misoriented_edges,
            flipped: d.flipped,
        })
    })?;
    Ok(Report::new(
        Command::Mass,
        format!("mass properties of {}", file.display()),
        vec![load, properties, diagnostics],
    ))
}
