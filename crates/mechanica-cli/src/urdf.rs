//! URDF import (through the `urdf-rs` crate): a robot description becomes a [`Scene`] and
//! runs through the same pipeline as a scene file.
//!
//! - **Links** become bodies with explicit mass properties from `<inertial>`: the centre of
//!   mass at the inertial origin and the tensor rotated by its `rpy` into the link frame.
//!   Every link's tensor is checked (mass crate validity: symmetry, semidefiniteness, triangle
//!   inequality); all invalid links are reported at once, and `--repair-inertia` replaces each
//!   by the nearest physical tensor (documented in `mechanica_mass::validity::repair`).
//! - A link without `<inertial>` (or with a zero mass there) whose collision (or else visual)
//!   geometry is a mesh gets the mesh's mass properties at 1000 kg/m³ (water; URDF gives no
//!   density); the file name is resolved relative to the URDF (then to the working directory),
//!   `package://` and `file://` prefixes stripped. A mesh that cannot be used (missing file, a format other
//!   than STL or OBJ such as `.dae`, a mesh without a volume) is an error naming the link and
//!   the mesh; with [`UrdfOptions::allow_missing_mesh`] the link is massless instead and the
//!   report carries a warning. A link with neither `<inertial>` nor a mesh is a massless frame.
//! - **Joints**: revolute and continuous → revolute, prismatic, fixed, floating → free,
//!   spherical, planar (normal along the joint's z only). Placements use the joint origin
//!   (xyz, rpy = R_z(yaw) R_y(pitch) R_x(roll)); the child link frame is the joint frame at
//!   q = 0, as in our trees. Finite revolute/prismatic limits become joint limits. Mimic
//!   joints are not followed (each joint is free).
//! - The root link hangs on the ground by a fixed joint; gravity is −9.81 m/s² along z.
//!   The analyses are: mass properties, a search for a stable equilibrium from q = 0 within
//!   the limits, and its modes.

use crate::scene::{Analyses, BodySpec, EquilibriumSpec, ExplicitMass, JointKind, JointSpec, ModesSpec, Scene};
use mechanica::kinematics::nalgebra::{Isometry3, Matrix3, Rotation3, Vector3};
use mechanica::mass::MassProperties;
use mechanica::mass::mesh::MeshOptions;
use mechanica::mass::primitives::Amount;
use mechanica::mass::validity::{ValidityTolerance, check, repair};
use std::path::Path;
use toml::Spanned;

/// Density used for mesh-only links (kg/m³).
pub const MESH_DENSITY: f64 = 1000.0;

fn spanned<T>(value: T) -> Spanned<T> {
    Spanned::new(0..0, value)
}

/// No mass anywhere: a frame.
fn massless() -> MassProperties {
    MassProperties {
        mass: 0.0,
        p_oc: Vector3::zeros(),
        inertia_c: Matrix3::zeros(),
    }
}

fn rotation(rpy: [f64; 3]) -> Rotation3<f64> {
    Rotation3::from_euler_angles(rpy[0], rpy[1], rpy[2])
}

/// How a URDF file is turned into a scene when its links are not physical as written.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct UrdfOptions {
    /// Replace invalid link tensors by the nearest physical ones (noted in the report) instead
    /// of refusing the file.
    pub repair_inertia: bool,
    /// Make a link without `<inertial>` whose mesh cannot be used massless (with a warning in
    /// the report) instead of refusing the file.
    pub allow_missing_mesh: bool,
}

/// Loads `path` as a scene, with the notes and warnings for the report (see the module docs
/// and [`UrdfOptions`]); every link that cannot be used is named in one error.
pub fn load(path: &Path, options: UrdfOptions) -> Result<(Scene, Vec<String>), String> {
    let robot = urdf_rs::read_file(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut notes = Vec::new();
    let bodies = link_bodies(path, &robot.links, options, &mut notes)?;
    let root = root_link(path, &robot)?;
    let mut joints = vec![JointSpec {
        name: "base (fixed to ground)".into(),
        kind: spanned(JointKind::Fixed),
        parent: spanned("ground".into()),
        child: spanned(root.to_string()),
        axis: None,
        origin: [0.0; 3],
        rpy: [0.0; 3],
        q0: None,
        qd0: None,
        limits: None,
    }];
    for joint in &robot.joints {
        joints.push(joint_spec(path, joint)?);
    }
    let scene = Scene {
        title: format!("URDF robot \"{}\" ({})", robot.name, path.display()),
        gravity: Some([0.0, 0.0, -9.81]),
        bodies,
        joints,
        rotating_frame: None,
        joint_springs: Vec::new(),
        springs: Vec::new(),
        forces: Vec::new(),
        joint_dampers: Vec::new(),
        dampers: Vec::new(),
        constraints: Vec::new(),
        analyses: Analyses {
            mass_properties: true,
            equilibrium: Some(EquilibriumSpec {
                seek: Some(spanned("minimum".into())),
                starts: Vec::new(),
                max_iterations: Some(200),
            }),
            modes: Some(ModesSpec { lowest: None }),
            response: None,
            impact: None,
            dynamics: None,
            simulate: None,
        },
    };
    scene.check(path)?;
    Ok((scene, notes))
}

/// `what`, prefixed by the URDF file's path.
fn located(path: &Path, what: String) -> String {
    format!("{}: {what}", path.display())
}

/// One body per link, with explicit mass properties (see the module docs); mesh fallbacks,
/// repairs and warnings are added to `notes`, and every link that cannot be used is named in
/// one error.
fn link_bodies(
    path: &Path,
    links: &[urdf_rs::Link],
    options: UrdfOptions,
    notes: &mut Vec<String>,
) -> Result<Vec<BodySpec>, String> {
    let mut inertia_problems = Vec::new();
    let mut mesh_problems = Vec::new();
    let mut bodies = Vec::new();
    for link in links {
        if link.name == "ground" {
            return Err(located(
                path,
                "a link named \"ground\" clashes with the scene's name for the world".into(),
            ));
        }
        let mut props = match link_mass_properties(path, link, notes) {
            Ok(props) => props,
            Err(problem) if options.allow_missing_mesh => {
                notes.push(format!("warning: {problem}; the link is massless"));
                massless()
            }
            Err(problem) => {
                mesh_problems.push(problem);
                massless()
            }
        };
        match checked_inertia(link, &props, options.repair_inertia, notes) {
            Ok(checked) => props = checked,
            Err(problem) => inertia_problems.push(problem),
        }
        bodies.push(explicit_body(&link.name, &props));
    }
    if !mesh_problems.is_empty() {
        return Err(located(
            path,
            format!(
                "links without <inertial> whose mesh cannot be used (run with --allow-missing-mesh to make them massless):\n  {}",
                mesh_problems.join("\n  ")
            ),
        ));
    }
    if !inertia_problems.is_empty() {
        return Err(located(
            path,
            format!(
                "invalid inertias (run with --repair-inertia to replace them by the nearest physical tensors):\n  {}",
                inertia_problems.join("\n  ")
            ),
        ));
    }
    Ok(bodies)
}

/// `props` when it is physical (a finite mass ≥ 0 and, when massive, a valid tensor), or its
/// repair when `repair` is set (noted in `notes`); else the problem, naming the link.
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
fn link_mass_properties(path: &Path, link: &urdf_rs::Link, notes: &mut Vec<String>) -> Result<MassProperties, String> {
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
    let (mesh_props, file) = mesh_mass(path, &mesh)
        .map_err(|problem| format!("link \"{}\": mesh \"{}\": {problem}", link.name, mesh.filename))?;
    notes.push(format!(
        "link \"{}\": no <inertial>; mass properties from mesh {file} at {MESH_DENSITY} kg/m³",
        link.name
    ));
    Ok(mesh_props)
}

/// A scene body named `name` with the explicit mass properties `props` (central inertia).
fn explicit_body(name: &str, props: &MassProperties) -> BodySpec {
    let c = props.inertia_c;
    BodySpec {
        name: spanned(name.to_string()),
        mass_properties: Some(ExplicitMass {
            mass: props.mass,
            com: props.p_oc.into(),
            inertia: [c[(0, 0)], c[(1, 1)], c[(2, 2)], c[(0, 1)], c[(0, 2)], c[(1, 2)]],
        }),
        primitive: None,
        mesh: None,
        offset: [0.0; 3],
    }
}

/// The one link that is no joint's child; an error when there is not exactly one.
fn root_link<'r>(path: &Path, robot: &'r urdf_rs::Robot) -> Result<&'r str, String> {
    let children: Vec<&str> = robot.joints.iter().map(|j| j.child.link.as_str()).collect();
    let roots: Vec<&str> = robot
        .links
        .iter()
        .map(|l| l.name.as_str())
        .filter(|name| !children.contains(name))
        .collect();
    let [root] = roots.as_slice() else {
        return Err(located(path, format!("a URDF tree has one root link, found {roots:?}")));
    };
    Ok(root)
}

/// The scene joint of a URDF joint (see the module docs for the mapping); an error for a
/// revolute or prismatic joint without a usable axis or a planar joint whose normal is not z.
fn joint_spec(path: &Path, joint: &urdf_rs::Joint) -> Result<JointSpec, String> {
    use urdf_rs::JointType as T;
    let kind = match joint.joint_type {
        T::Revolute | T::Continuous => JointKind::Revolute,
        T::Prismatic => JointKind::Prismatic,
        T::Fixed => JointKind::Fixed,
        T::Floating => JointKind::Free,
        T::Spherical => JointKind::Spherical,
        T::Planar => JointKind::Planar,
    };
    let axis = Vector3::from(joint.axis.xyz.0);
    let norm = axis.norm();
    if matches!(kind, JointKind::Revolute | JointKind::Prismatic) && !(norm > 0.0 && norm.is_finite()) {
        return Err(located(
            path,
            format!("joint \"{}\": zero or non-finite axis", joint.name),
        ));
    }
    if kind == JointKind::Planar && (axis / norm - Vector3::z()).norm() > 1e-12 {
        return Err(located(
            path,
            format!(
                "joint \"{}\": planar joints are supported with their normal along the joint's z axis only",
                joint.name
            ),
        ));
    }
    let limited = matches!(joint.joint_type, T::Revolute | T::Prismatic)
        && joint.limit.lower.is_finite()
        && joint.limit.upper.is_finite()
        && joint.limit.lower < joint.limit.upper;
    let q0 = if limited && !(joint.limit.lower..=joint.limit.upper).contains(&0.0) {
        Some(spanned(vec![0.5 * (joint.limit.lower + joint.limit.upper)]))
    } else {
        None
    };
    Ok(JointSpec {
        name: joint.name.clone(),
        kind: spanned(kind),
        parent: spanned(joint.parent.link.clone()),
        child: spanned(joint.child.link.clone()),
        axis: matches!(kind, JointKind::Revolute | JointKind::Prismatic | JointKind::Planar)
            .then(|| spanned((axis / norm).into())),
        origin: joint.origin.xyz.0,
        rpy: joint.origin.rpy.0,
        q0,
        qd0: None,
        limits: limited.then(|| spanned([joint.limit.lower, joint.limit.upper])),
    })
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

/// The mass properties of `mesh` at [`MESH_DENSITY`] in the link frame and the file they came
/// from, or what prevents them: the file is found nowhere, cannot be read, or has no volume.
fn mesh_mass(urdf: &Path, mesh: &LinkMesh) -> Result<(MassProperties, String), String> {
    let relative = mesh
        .filename
        .trim_start_matches("package://")
        .trim_start_matches("file://");
    let base = urdf.parent().unwrap_or(Path::new("."));
    let mut candidates = vec![base.join(relative)];
    if candidates[0] != Path::new(relative) {
        candidates.push(Path::new(relative).to_path_buf());
    }
    let Some(path) = candidates.iter().find(|p| p.is_file()) else {
        let looked: Vec<String> = candidates.iter().map(|p| p.display().to_string()).collect();
        return Err(format!("file not found (looked for {})", looked.join(" and ")));
    };
    let mut triangles = mechanica::mass::io::load_mesh(path).map_err(|e| e.to_string())?;
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
