//! URDF import: a robot read by `mechanica::urdf` (links with mass properties, joints) becomes
//! a [`Scene`] and runs through the same pipeline as a scene file. The reading (inertials,
//! mesh fallbacks at water density, validity checks and repairs, the joint mapping) is
//! documented in `mechanica_urdf`; this module adds the scene around it:
//!
//! - every link is a body with explicit mass properties; a link named `ground` (the scene's
//!   name for the world) is renamed `ground (URDF link)`, with a note;
//! - the root link hangs on the ground by a fixed joint; gravity is −9.81 m/s² along z;
//! - a limited joint whose range excludes 0 starts at the middle of its limits;
//! - the analyses are: mass properties, a search for a stable equilibrium from q = 0 within
//!   the limits, and its modes.

use crate::scene::{Analyses, BodySpec, EquilibriumSpec, ExplicitMass, JointKind, JointSpec, ModesSpec, Scene};
use mechanica::mass::MassProperties;
pub use mechanica::urdf::UrdfOptions;
use mechanica::urdf::{JointKind as UrdfKind, UrdfDocument, UrdfError, UrdfJoint, UrdfRobot};
use std::path::Path;
use toml::Spanned;

fn spanned<T>(value: T) -> Spanned<T> {
    Spanned::new(0..0, value)
}

/// Loads `path` as a scene, with the notes and warnings for the report (see the module docs
/// and [`UrdfOptions`]); every link that cannot be used is named in one error.
pub fn load(path: &Path, options: UrdfOptions) -> Result<(Scene, Vec<String>), String> {
    let document = UrdfDocument::read(path).map_err(|e| located(path, e.to_string()))?;
    let mesh_dir = path.parent().unwrap_or(Path::new("."));
    let mut robot = document
        .robot(mesh_dir, options)
        .map_err(|e| located(path, cli_message(e)))?;
    rename_ground_link(&mut robot);
    let bodies = robot.links.iter().map(|l| explicit_body(&l.name, &l.mass)).collect();
    let mut joints = vec![JointSpec {
        name: "base (fixed to ground)".into(),
        kind: spanned(JointKind::Fixed),
        parent: spanned("ground".into()),
        child: spanned(robot.links[robot.root].name.clone()),
        axis: None,
        origin: [0.0; 3],
        rpy: [0.0; 3],
        q0: None,
        qd0: None,
        limits: None,
    }];
    joints.extend(robot.joints.iter().map(joint_spec));
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
        contacts: Vec::new(),
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
    Ok((scene, robot.notes))
}

/// Renames a link named `ground` (the scene's name for the world) to `ground (URDF link)`, or
/// `ground (URDF link k)` for the first k that names no other link, in the links and joints,
/// with a note.
fn rename_ground_link(robot: &mut UrdfRobot) {
    if !robot.links.iter().any(|l| l.name == "ground") {
        return;
    }
    let taken = |name: &str| robot.links.iter().any(|l| l.name == name);
    let new_name = (1..=robot.links.len() + 1)
        .map(|k| match k {
            1 => "ground (URDF link)".to_string(),
            k => format!("ground (URDF link {k})"),
        })
        .find(|name| !taken(name))
        .unwrap_or_default();
    for link in robot.links.iter_mut().filter(|l| l.name == "ground") {
        link.name.clone_from(&new_name);
    }
    for joint in &mut robot.joints {
        for end in [&mut joint.parent, &mut joint.child] {
            if end == "ground" {
                end.clone_from(&new_name);
            }
        }
    }
    robot.notes.push(format!(
        "link \"ground\" is called \"{new_name}\" here: \"ground\" names the world in scenes"
    ));
}

/// `what`, prefixed by the URDF file's path.
fn located(path: &Path, what: String) -> String {
    format!("{}: {what}", path.display())
}

/// The message of a reading error, with the command-line option that gets past it.
fn cli_message(error: UrdfError) -> String {
    match error {
        UrdfError::UnusableMeshes { problems } => format!(
            "links without <inertial> whose mesh cannot be used (run with --allow-missing-mesh to make them massless):\n  {}",
            problems.join("\n  ")
        ),
        UrdfError::InvalidInertias { problems } => format!(
            "invalid inertias (run with --repair-inertia to replace them by the nearest physical tensors):\n  {}",
            problems.join("\n  ")
        ),
        other => other.to_string(),
    }
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

/// The scene joint of a URDF joint; a limited joint whose range excludes 0 starts at the
/// middle of its limits.
fn joint_spec(joint: &UrdfJoint) -> JointSpec {
    let kind = match joint.kind {
        UrdfKind::Revolute => JointKind::Revolute,
        UrdfKind::Prismatic => JointKind::Prismatic,
        UrdfKind::Fixed => JointKind::Fixed,
        UrdfKind::Free => JointKind::Free,
        UrdfKind::Spherical => JointKind::Spherical,
        UrdfKind::Planar => JointKind::Planar,
    };
    let q0 = match joint.limits {
        Some([lower, upper]) if !(lower..=upper).contains(&0.0) => Some(spanned(vec![0.5 * (lower + upper)])),
        _ => None,
    };
    JointSpec {
        name: joint.name.clone(),
        kind: spanned(kind),
        parent: spanned(joint.parent.clone()),
        child: spanned(joint.child.clone()),
        axis: joint.axis.map(|a| spanned(a.into())),
        origin: joint.origin,
        rpy: joint.rpy,
        q0,
        qd0: None,
        limits: joint.limits.map(spanned),
    }
}
