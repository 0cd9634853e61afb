//! URDF import (through the `urdf-rs` crate): a robot description becomes a [`Scene`] and
//! runs through the same pipeline as a scene file.
//!
//! - **Links** become bodies with explicit mass properties from `<inertial>`: the centre of
//!   mass at the inertial origin and the tensor rotated by its `rpy` into the link frame.
//!   Every link's tensor is checked (mass crate validity: symmetry, semidefiniteness, triangle
//!   inequality); all invalid links are reported at once, and `--repair-inertia` replaces each
//!   by the nearest physical tensor (documented in `mechanica_mass::validity::repair`).
//! - A link without `<inertial>` whose collision (or else visual) geometry is a mesh file
//!   that exists gets the mesh's mass properties at 1000 kg/m³ (water; URDF gives no
//!   density) — the file name is resolved relative to the URDF, `package://` prefixes
//!   stripped. Otherwise it is massless.
//! - **Joints**: revolute and continuous → revolute, prismatic, fixed, floating → free,
//!   spherical, planar (normal along the joint's z only). Placements use the joint origin
//!   (xyz, rpy = R_z(yaw) R_y(pitch) R_x(roll)); the child link frame is the joint frame at
//!   q = 0, as in our trees. Finite revolute/prismatic limits become joint limits. Mimic
//!   joints are not followed (each joint is free).
//! - The root link hangs on the ground by a fixed joint; gravity is −9.81 m/s² along z.
//!   The analyses are: mass properties, a search for a stable equilibrium from q = 0 within
//!   the limits, and its modes.

use crate::scene::{Analyses, BodySpec, EquilibriumSpec, ExplicitMass, JointKind, JointSpec, ModesSpec, Scene};
use mechanica::kinematics::nalgebra::{Matrix3, Rotation3, Vector3};
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

fn rotation(rpy: [f64; 3]) -> Rotation3<f64> {
    Rotation3::from_euler_angles(rpy[0], rpy[1], rpy[2])
}

/// Loads `path` as a scene. With `repair_inertia`, invalid link tensors are repaired (and the
/// repairs listed in the returned notes); otherwise they are an error naming every such link.
pub fn load(path: &Path, repair_inertia: bool) -> Result<(Scene, Vec<String>), String> {
    let robot = urdf_rs::read_file(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut notes = Vec::new();
    let bodies = link_bodies(path, &robot.links, repair_inertia, &mut notes)?;
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
        },
    };
    scene.check(path)?;
    Ok((scene, notes))
}

/// `what`, prefixed by the URDF file's path.
fn located(path: &Path, what: String) -> String {
    format!("{}: {what}", path.display())
}

/// One body per link, with explicit mass properties (see the module docs); mesh fallbacks and
/// repairs are added to `notes`, and every invalid link is named in one error.
fn link_bodies(
    path: &Path,
    links: &[urdf_rs::Link],
    repair_inertia: bool,
    notes: &mut Vec<String>,
) -> Result<Vec<BodySpec>, String> {
    let mut problems = Vec::new();
    let mut bodies = Vec::new();
    for link in links {
        if link.name == "ground" {
            return Err(located(
                path,
                "a link named \"ground\" clashes with the scene's name for the world".into(),
            ));
        }
        let mut props = link_mass_properties(path, link, notes);
        if props.mass < 0.0 || !props.mass.is_finite() {
            problems.push(format!(
                "link \"{}\": mass {} is not a physical mass",
                link.name, props.mass
            ));
        } else if props.mass > 0.0 {
            match check(&props, &ValidityTolerance::default()) {
                Ok(_) => {}
                Err(error) if repair_inertia => match repair(&props, &ValidityTolerance::default()) {
                    Ok((fixed, report)) => {
                        notes.push(format!(
                            "link \"{}\": inertia repaired (relative change {:.2e}): {error}",
                            link.name, report.relative_change
                        ));
                        props = fixed;
                    }
                    Err(e) => problems.push(format!("link \"{}\": {e}", link.name)),
                },
                Err(error) => problems.push(format!("link \"{}\": {error}", link.name)),
            }
        }
        bodies.push(explicit_body(&link.name, &props));
    }
    if !problems.is_empty() {
        return Err(located(
            path,
            format!(
                "invalid inertias (run with --repair-inertia to replace them by the nearest physical tensors):\n  {}",
                problems.join("\n  ")
            ),
        ));
    }
    Ok(bodies)
}

/// A link's mass properties in the link frame: from `<inertial>` (tensor rotated by its rpy),
/// or, for a massless one, from its mesh at [`MESH_DENSITY`] when there is one (noted in `notes`).
fn link_mass_properties(path: &Path, link: &urdf_rs::Link, notes: &mut Vec<String>) -> MassProperties {
    let inertial = &link.inertial;
    let r = rotation(inertial.origin.rpy.0);
    let i = &inertial.inertia;
    let tensor = Matrix3::new(i.ixx, i.ixy, i.ixz, i.ixy, i.iyy, i.iyz, i.ixz, i.iyz, i.izz);
    let mut props = MassProperties {
        mass: inertial.mass.value,
        p_oc: Vector3::from(inertial.origin.xyz.0),
        inertia_c: r.matrix() * tensor * r.matrix().transpose(),
    };
    if props.mass == 0.0
        && let Some((mesh_props, file)) = mesh_mass(path, link)
    {
        notes.push(format!(
            "link \"{}\": no <inertial>; mass properties from mesh {file} at {MESH_DENSITY} kg/m³",
            link.name
        ));
        props = mesh_props;
    }
    props
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

/// The mass properties of a link's first mesh geometry (collision, else visual), when its
/// file exists.
fn mesh_mass(urdf: &Path, link: &urdf_rs::Link) -> Option<(MassProperties, String)> {
    let geometries = link
        .collision
        .iter()
        .map(|c| (&c.geometry, &c.origin))
        .chain(link.visual.iter().map(|v| (&v.geometry, &v.origin)));
    for (geometry, origin) in geometries {
        if let urdf_rs::Geometry::Mesh { filename, scale } = geometry {
            let relative = filename.trim_start_matches("package://").trim_start_matches("file://");
            let base = urdf.parent().unwrap_or(Path::new("."));
            let path = [base.join(relative), Path::new(relative).to_path_buf()]
                .into_iter()
                .find(|p| p.exists())?;
            let mut mesh = mechanica::mass::io::load_mesh(&path).ok()?;
            let s = scale.map_or([1.0; 3], |s| s.0);
            for v in &mut mesh.vertices {
                for k in 0..3 {
                    v[k] *= s[k];
                }
            }
            let props = mesh
                .mass_properties(Amount::Density(MESH_DENSITY), &MeshOptions::default())
                .ok()?;
            let pose = mechanica::kinematics::nalgebra::Isometry3::from_parts(
                Vector3::from(origin.xyz.0).into(),
                rotation(origin.rpy.0).into(),
            );
            return Some((props.properties.transformed(&pose), path.display().to_string()));
        }
    }
    None
}
