//! Link mass properties: from `<inertial>`, or from a mesh when a link has none, checked for
//! physical validity (and repaired on request).

use crate::robot::{UrdfOptions, rotation};
use mechanica_kinematics::nalgebra::{Isometry3, Matrix3, Vector3};
use mechanica_mass::MassProperties;
use mechanica_mass::mesh::MeshOptions;
use mechanica_mass::primitives::Amount;
use mechanica_mass::validity::{ValidityTolerance, check, repair};
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
    options: UrdfOptions,
    notes: &mut Vec<String>,
) -> (Vec<MassProperties>, LinkProblems) {
    let mut problems = LinkProblems::default();
    let mut masses = Vec::with_capacity(links.len());
    for link in links {
        let mut props = match link_mass_properties(mesh_dir, link, notes) {
            Ok(props) => props,
            Err(problem) if options.allow_missing_mesh => {
                notes.push(format!("warning: {problem}; the link is massless"));
                massless()
            }
            Err(problem) => {
                problems.meshes.push(problem);
                massless()
            }
        };
        match checked_inertia(link, &props, options.repair_inertia, notes) {
            Ok(checked) => props = checked,
            Err(problem) => problems.inertias.push(problem),
        }
        masses.push(props);
    }
    (masses, problems)
}

/// `props` when it is physical (a finite mass ≥ 0 and, when massive, a valid tensor), or its
/// repair when `repair_inertia` is set (noted in `notes`); else the problem, naming the link.
fn checked_inertia(
    link: &urdf_rs::Link,
    props: &MassProperties,
    repair_inertia: bool,
    notes: &mut Vec<String>,
) -> Result<MassProperties, String> {
    if props.mass < 0.0 || !props.mass.is_finite() {
        return Err(format!(
            "link \"{}\": mass {} is not a physical mass",
            link.name, props.mass
        ));
    }
    if props.mass == 0.0 {
        return Ok(*props);
    }
    match check(props, &ValidityTolerance::default()) {
        Ok(_) => Ok(*props),
        Err(error) if repair_inertia => match repair(props, &ValidityTolerance::default()) {
            Ok((fixed, report)) => {
                notes.push(format!(
                    "link \"{}\": inertia repaired (relative change {:.2e}): {error}",
                    link.name, report.relative_change
                ));
                Ok(fixed)
            }
            Err(e) => Err(format!("link \"{}\": {e}", link.name)),
        },
        Err(error) => Err(format!("link \"{}\": {error}", link.name)),
    }
}

/// A link's mass properties in the link frame: from `<inertial>` (tensor rotated by its rpy),
/// or, for a massless one, from its mesh at [`MESH_DENSITY`] when it has one (noted in
/// `notes`). A mesh that cannot be used is an error naming the link and the mesh.
fn link_mass_properties(
    mesh_dir: &Path,
    link: &urdf_rs::Link,
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
    if props.mass != 0.0 {
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

/// Where a mesh file name is looked for: in `mesh_dir`, then as written (relative to the
/// working directory), `package://` and `file://` prefixes stripped.
fn mesh_candidates(mesh_dir: &Path, filename: &str) -> Vec<PathBuf> {
    let relative = filename.trim_start_matches("package://").trim_start_matches("file://");
    let mut candidates = vec![mesh_dir.join(relative)];
    if candidates[0] != Path::new(relative) {
        candidates.push(Path::new(relative).to_path_buf());
    }
    candidates
}

/// The mass properties of `mesh` at [`MESH_DENSITY`] in the link frame and the file they came
/// from, or what prevents them: the file is found nowhere, cannot be read, or has no volume.
fn mesh_mass(mesh_dir: &Path, mesh: &LinkMesh) -> Result<(MassProperties, String), String> {
    let candidates = mesh_candidates(mesh_dir, &mesh.filename);
    let Some(path) = candidates.iter().find(|p| p.is_file()) else {
        let looked: Vec<String> = candidates.iter().map(|p| p.display().to_string()).collect();
        return Err(format!("file not found (looked for {})", looked.join(" and ")));
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
