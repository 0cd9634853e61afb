//! Link mass properties: from `<inertial>`, or from a mesh when a link has none, checked for
//! physical validity (and repaired on request). A declared `<inertial>` is followed even with a
//! zero mass (a massless link, as the file says).

use crate::robot::{UrdfOptions, rotation};
use mechanica_kinematics::nalgebra::{Isometry3, Matrix3, Vector3};
use mechanica_mass::MassProperties;
use mechanica_mass::mesh::MeshOptions;
use mechanica_mass::primitives::Amount;
use mechanica_mass::validity::{ValidityTolerance, check, repair};
use std::collections::HashSet;
use std::path::{Path, PathBuf};

/// Density used for mesh-only links (kg/m³).
pub const MESH_DENSITY: f64 = 1000.0;

/// No mass anywhere: a frame.
pub(crate) fn massless() -> MassProperties {
    MassProperties::ZERO
}

/// What went wrong with the links, one line per link, in two groups.
#[derive(Default)]
pub(crate) struct LinkProblems {
    /// Links without `<inertial>` whose mesh cannot be used.
    pub meshes: Vec<String>,
    /// Links whose mass properties are not physical.
    pub inertias: Vec<String>,
}

/// Each link's mass properties in the link frame (see the crate docs); mesh fallbacks, repairs
/// and warnings are added to `notes`, problems to the returned [`LinkProblems`].
pub(crate) fn link_masses(
    mesh_dir: &Path,
    links: &[urdf_rs::Link],
    links_with_inertial: &HashSet<String>,
    options: UrdfOptions,
    notes: &mut Vec<String>,
) -> (Vec<MassProperties>, LinkProblems) {
    let mut problems = LinkProblems::default();
    let mut masses = Vec::with_capacity(links.len());
    for link in links {
        let declared = links_with_inertial.contains(&link.name);
        masses.push(match link_mass_properties(mesh_dir, link, declared, notes) {
            Ok(props) => props,
            Err(problem) if options.allow_missing_mesh => {
                notes.push(format!("warning: {problem}; the link is massless"));
                massless()
            }
            Err(problem) => {
                problems.meshes.push(problem);
                massless()
            }
        });
    }
    let rounding = ROBOT_ROUNDING * robot_inertia_scale(&masses);
    for (link, props) in links.iter().zip(&mut masses) {
        match checked_inertia(link, props, options.repair_inertia, rounding, notes) {
            Ok(checked) => *props = checked,
            Err(problem) => problems.inertias.push(problem),
        }
    }
    (masses, problems)
}

/// A link tensor whose nearest physical tensor is within this fraction of the robot's largest
/// link inertia ([`robot_inertia_scale`]) is taken as physical up to the file's rounding, and
/// replaced by that tensor with a note: exporters write zero moments as ±1e-20 and the like
/// (a point mass of 0.27 kg with ixz = 1.4e-20), below what the robot's mass matrix, assembled
/// with rounding of about n·u (1e-14 for tens of joints) of that scale, resolves.
const ROBOT_ROUNDING: f64 = 1e-14;

/// The largest trace of a physical link's inertia tensor about its frame origin,
/// tr J_c + 2m|c|² (0 for a robot without one): invalid tensors do not set the scale their
/// own errors are measured by, and point masses off the origin count.
fn robot_inertia_scale(masses: &[MassProperties]) -> f64 {
    masses
        .iter()
        .filter(|p| p.mass > 0.0 && check(p, &ValidityTolerance::default()).is_ok())
        .map(|p| p.inertia_c.trace() + 2.0 * p.mass * p.p_oc.norm_squared())
        .filter(|s| s.is_finite())
        .fold(0.0, f64::max)
}

/// `props` when it is physical (a finite mass ≥ 0 and, when massive, a valid tensor), its
/// nearest physical tensor when that is within `rounding` (absolute, Frobenius) of it, or its
/// repair when `repair_inertia` is set (both noted in `notes`); else the problem, naming the
/// link.
fn checked_inertia(
    link: &urdf_rs::Link,
    props: &MassProperties,
    repair_inertia: bool,
    rounding: f64,
    notes: &mut Vec<String>,
) -> Result<MassProperties, String> {
    if props.mass < 0.0 || !props.mass.is_finite() {
        return Err(format!(
            "link \"{}\": mass {} is not a physical mass",
            link.name, props.mass
        ));
    }
    // A zero mass with a tensor is a rotor (kept as the peers keep it): its tensor is judged,
    // and set to the nearest physical one, as a massive link's would be.
    let zero_mass = props.mass == 0.0;
    let judged = if zero_mass {
        MassProperties { mass: 1.0, ..*props }
    } else {
        *props
    };
    let as_given = |p: MassProperties| {
        if zero_mass {
            MassProperties { mass: 0.0, ..p }
        } else {
            p
        }
    };
    let tolerance = ValidityTolerance::default();
    let Err(error) = check(&judged, &tolerance) else {
        return Ok(*props);
    };
    match repair(&judged, &tolerance).map(|(fixed, report)| (as_given(fixed), report)) {
        Ok((fixed, report)) if report.change_norm <= rounding => {
            notes.push(format!(
                "link \"{}\": inertia off by rounding ({:.1e} kg·m², below {ROBOT_ROUNDING:.0e} of the robot's \
                 largest link inertia) set to the nearest physical tensor",
                link.name, report.change_norm
            ));
            Ok(fixed)
        }
        Ok((fixed, report)) if repair_inertia => {
            notes.push(format!(
                "link \"{}\": inertia repaired (relative change {:.2e}): {error}",
                link.name, report.relative_change
            ));
            Ok(fixed)
        }
        Err(e) if repair_inertia => Err(format!("link \"{}\": {e}", link.name)),
        _ => Err(format!("link \"{}\": {error}", link.name)),
    }
}

/// A link's mass properties in the link frame: from its `<inertial>` (tensor rotated by its
/// rpy) when it `declared` one, even with a zero mass, or else from its mesh at
/// [`MESH_DENSITY`] when it has one (noted in `notes`). A mesh that cannot be used is an error
/// naming the link and the mesh.
fn link_mass_properties(
    mesh_dir: &Path,
    link: &urdf_rs::Link,
    declared: bool,
    notes: &mut Vec<String>,
) -> Result<MassProperties, String> {
    let inertial = &link.inertial;
    let r = rotation(inertial.origin.rpy.0);
    let i = &inertial.inertia;
    let tensor = Matrix3::new(i.ixx, i.ixy, i.ixz, i.ixy, i.iyy, i.iyz, i.ixz, i.iyz, i.izz);
    let props = MassProperties {
        mass: inertial.mass.value,
        p_oc: Vector3::from(inertial.origin.xyz.0),
        inertia_c: r.matrix() * tensor * r.matrix().transpose(),
    };
    if declared || props.mass != 0.0 {
        return Ok(props);
    }
    let Some(mesh) = first_mesh(link) else {
        return Ok(props);
    };
    let (mesh_props, file) = mesh_mass(mesh_dir, &mesh)
        .map_err(|problem| format!("link \"{}\": mesh \"{}\": {problem}", link.name, mesh.filename))?;
    notes.push(format!(
        "link \"{}\": no <inertial>; mass properties from mesh {file} at {MESH_DENSITY} kg/m³",
        link.name
    ));
    Ok(mesh_props)
}

/// A mesh geometry of a link: its file name as written, scale and pose in the link frame.
struct LinkMesh {
    filename: String,
    scale: [f64; 3],
    pose: Isometry3<f64>,
}

/// The link's first mesh geometry, collision before visual.
fn first_mesh(link: &urdf_rs::Link) -> Option<LinkMesh> {
    let geometries = link
        .collision
        .iter()
        .map(|c| (&c.geometry, &c.origin))
        .chain(link.visual.iter().map(|v| (&v.geometry, &v.origin)));
    geometries.into_iter().find_map(|(geometry, origin)| match geometry {
        urdf_rs::Geometry::Mesh { filename, scale } => Some(LinkMesh {
            filename: filename.clone(),
            scale: scale.map_or([1.0; 3], |s| s.0),
            pose: Isometry3::from_parts(Vector3::from(origin.xyz.0).into(), rotation(origin.rpy.0).into()),
        }),
        _ => None,
    })
}

/// Where a mesh file name is looked for, in this order: in `mesh_dir`, then as written
/// (relative to the working directory), `package://` and `file://` prefixes stripped; then,
/// for `package://PKG/rest`, under the package's root: each ancestor of `mesh_dir` named PKG,
/// and `PKG` inside each ancestor and inside each directory of `ROS_PACKAGE_PATH`.
fn mesh_candidates(mesh_dir: &Path, filename: &str) -> Vec<PathBuf> {
    let relative = filename.trim_start_matches("package://").trim_start_matches("file://");
    let mut candidates = vec![mesh_dir.join(relative)];
    if candidates[0] != Path::new(relative) {
        candidates.push(Path::new(relative).to_path_buf());
    }
    if let Some(uri) = filename.strip_prefix("package://") {
        for candidate in package_candidates(mesh_dir, uri) {
            if !candidates.contains(&candidate) {
                candidates.push(candidate);
            }
        }
    }
    candidates
}

/// The paths a `package://` URI (without its scheme, `PKG/rest`) may name: `rest` under each
/// ancestor of `mesh_dir` named PKG, and `PKG/rest` under each ancestor and each directory of
/// `ROS_PACKAGE_PATH` (a directory named PKG there stands for the package itself).
fn package_candidates(mesh_dir: &Path, uri: &str) -> Vec<PathBuf> {
    let Some((package, rest)) = package_parts(uri) else {
        return Vec::new();
    };
    let search_path = std::env::var_os("ROS_PACKAGE_PATH").unwrap_or_default();
    // Ancestors of the absolute directory: `robot.urdf` alone has a mesh directory "".
    let base = if mesh_dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        mesh_dir
    };
    let absolute = std::path::absolute(base).unwrap_or_else(|_| base.to_path_buf());
    let roots = absolute
        .ancestors()
        .map(Path::to_path_buf)
        .chain(std::env::split_paths(&search_path));
    let mut candidates = Vec::new();
    for root in roots.filter(|r| !r.as_os_str().is_empty()) {
        if root.file_name().is_some_and(|name| name == package) {
            candidates.push(root.join(rest));
        }
        candidates.push(root.join(package).join(rest));
    }
    candidates
}

/// The package name and the path inside it of a `package://` URI without its scheme; None
/// for an empty, `.` or `..` package name or a path that is empty or absolute.
fn package_parts(uri: &str) -> Option<(&str, &str)> {
    let (package, rest) = uri.split_once('/')?;
    let usable = !matches!(package, "" | "." | "..") && !rest.is_empty() && !rest.starts_with('/');
    usable.then_some((package, rest))
}

/// The mass properties of `mesh` at [`MESH_DENSITY`] in the link frame and the file they came
/// from, or what prevents them: the file is found nowhere, cannot be read, or has no volume.
fn mesh_mass(mesh_dir: &Path, mesh: &LinkMesh) -> Result<(MassProperties, String), String> {
    let candidates = mesh_candidates(mesh_dir, &mesh.filename);
    let Some(path) = candidates.iter().find(|p| p.is_file()) else {
        let looked: Vec<String> = candidates.iter().take(2).map(|p| p.display().to_string()).collect();
        let package = match mesh.filename.strip_prefix("package://").and_then(package_parts) {
            Some((package, _)) => {
                format!(", and under package \"{package}\" among the mesh directory's ancestors and ROS_PACKAGE_PATH")
            }
            None => String::new(),
        };
        return Err(format!("file not found (looked for {}{package})", looked.join(" and ")));
    };
    let mut triangles = mechanica_mass::io::load_mesh(path).map_err(|e| e.to_string())?;
    for v in &mut triangles.vertices {
        for k in 0..3 {
            v[k] *= mesh.scale[k];
        }
    }
    let props = triangles
        .mass_properties(Amount::Density(MESH_DENSITY), &MeshOptions::default())
        .map_err(|e| format!("{}: {e}", path.display()))?;
    Ok((props.properties.transformed(&mesh.pose), path.display().to_string()))
}
