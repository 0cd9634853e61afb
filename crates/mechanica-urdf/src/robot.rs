//! Reading a URDF text: the parsed document, then the robot's links (with mass properties) and
//! joints.

use crate::MAX_URDF_BYTES;
use crate::error::UrdfError;
use crate::links::link_masses;
use mechanica_kinematics::nalgebra::{Isometry3, Rotation3, UnitQuaternion, Vector3};
use mechanica_kinematics::tree::Joint;
use mechanica_mass::MassProperties;
use std::collections::HashSet;
use std::path::Path;

/// R = R_z(yaw) R_y(pitch) R_x(roll) of a URDF `rpy`.
pub(crate) fn rotation(rpy: [f64; 3]) -> Rotation3<f64> {
    Rotation3::from_euler_angles(rpy[0], rpy[1], rpy[2])
}

/// How a URDF description is turned into links when they are not physical as written.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct UrdfOptions {
    /// Replace invalid link tensors by the nearest physical ones (noted in the notes) instead
    /// of refusing the description.
    pub repair_inertia: bool,
    /// Make a link without `<inertial>` whose mesh cannot be used massless (with a warning in
    /// the notes) instead of refusing the description.
    pub allow_missing_mesh: bool,
}

/// The kind of a URDF joint, as the trees of `mechanica-kinematics` know it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointKind {
    /// `revolute` and `continuous`.
    Revolute,
    /// `prismatic`.
    Prismatic,
    /// `fixed`.
    Fixed,
    /// `floating`.
    Free,
    /// `spherical`.
    Spherical,
    /// `planar` (normal along the joint frame's z axis).
    Planar,
}

/// A link: its name and mass properties in the link frame.
#[derive(Debug, Clone, PartialEq)]
pub struct UrdfLink {
    /// The link's `name`.
    pub name: String,
    /// Mass, centre of mass and central inertia in the link frame (zero for a massless frame).
    pub mass: MassProperties,
}

/// A joint of the robot; its child link's frame is the joint frame at q = 0.
#[derive(Debug, Clone, PartialEq)]
pub struct UrdfJoint {
    /// The joint's `name`.
    pub name: String,
    /// Its kind.
    pub kind: JointKind,
    /// `<parent link>`, as written.
    pub parent: String,
    /// `<child link>`, as written.
    pub child: String,
    /// The unit `<axis xyz>` (joint frame) of revolute, prismatic and planar joints.
    pub axis: Option<Vector3<f64>>,
    /// `<origin xyz>`: the joint frame's position in the parent link frame (m).
    pub origin: [f64; 3],
    /// `<origin rpy>`: its orientation, R = R_z(yaw) R_y(pitch) R_x(roll) (rad).
    pub rpy: [f64; 3],
    /// `[lower, upper]` of a revolute or prismatic joint whose limits are finite with
    /// lower < upper.
    pub limits: Option<[f64; 2]>,
}

impl UrdfJoint {
    /// The joint of a kinematic tree.
    pub fn joint(&self) -> Joint {
        let axis = self.axis.unwrap_or_else(Vector3::z);
        match self.kind {
            JointKind::Revolute => Joint::Revolute { axis },
            JointKind::Prismatic => Joint::Prismatic { axis },
            JointKind::Fixed => Joint::Fixed,
            JointKind::Free => Joint::Free,
            JointKind::Spherical => Joint::Spherical,
            JointKind::Planar => Joint::Planar,
        }
    }

    /// The joint frame in the parent link frame.
    pub fn placement(&self) -> Isometry3<f64> {
        Isometry3::from_parts(
            Vector3::from(self.origin).into(),
            UnitQuaternion::from_euler_angles(self.rpy[0], self.rpy[1], self.rpy[2]),
        )
    }
}

/// A robot read from URDF: links (in the file's order), joints, the root link, and notes
/// about mesh fallbacks, repairs and warnings.
#[derive(Debug, Clone, PartialEq)]
pub struct UrdfRobot {
    /// The robot's `name`.
    pub name: String,
    /// The links, in the file's order.
    pub links: Vec<UrdfLink>,
    /// The joints, in the file's order.
    pub joints: Vec<UrdfJoint>,
    /// The index in `links` of the one link that is no joint's child.
    pub root: usize,
    /// What was assumed or changed: mesh-derived mass properties, repairs, massless links.
    pub notes: Vec<String>,
}

/// A parsed URDF text, before its links and joints are checked.
pub struct UrdfDocument {
    robot: urdf_rs::Robot,
    links_with_inertial: HashSet<String>,
}

impl UrdfDocument {
    /// Parses `text` (at most [`MAX_URDF_BYTES`] bytes).
    pub fn parse(text: &str) -> Result<Self, UrdfError> {
        if text.len() > MAX_URDF_BYTES {
            return Err(UrdfError::TooLarge {
                bytes: text.len() as u64,
                limit: MAX_URDF_BYTES,
            });
        }
        let prepared = crate::xml_scan::prepared(text)?;
        let robot =
            urdf_rs::read_from_string(&prepared.text).map_err(|e| UrdfError::Parse { message: e.to_string() })?;
        Ok(Self {
            robot,
            links_with_inertial: prepared.links_with_inertial,
        })
    }

    /// Reads and parses the file at `path` (at most [`MAX_URDF_BYTES`] bytes).
    pub fn read(path: &Path) -> Result<Self, UrdfError> {
        let io = |e: std::io::Error| UrdfError::Io { message: e.to_string() };
        let bytes = std::fs::metadata(path).map_err(io)?.len();
        if bytes > MAX_URDF_BYTES as u64 {
            return Err(UrdfError::TooLarge {
                bytes,
                limit: MAX_URDF_BYTES,
            });
        }
        Self::parse(&std::fs::read_to_string(path).map_err(io)?)
    }

    /// The link names, in the file's order.
    pub fn link_names(&self) -> impl Iterator<Item = &str> {
        self.robot.links.iter().map(|l| l.name.as_str())
    }

    /// The robot: link mass properties (meshes looked for in `mesh_dir`, then relative to the
    /// working directory), the root link and the joints (see the crate docs). Every link that
    /// cannot be used is named in one error: unusable meshes first, then invalid inertias.
    pub fn robot(&self, mesh_dir: &Path, options: UrdfOptions) -> Result<UrdfRobot, UrdfError> {
        let robot = &self.robot;
        let mut notes = Vec::new();
        let (masses, problems) = link_masses(mesh_dir, &robot.links, &self.links_with_inertial, options, &mut notes);
        if !problems.meshes.is_empty() {
            return Err(UrdfError::UnusableMeshes {
                problems: problems.meshes,
            });
        }
        if !problems.inertias.is_empty() {
            return Err(UrdfError::InvalidInertias {
                problems: problems.inertias,
            });
        }
        let root = root_link(robot)?;
        let joints = robot.joints.iter().map(urdf_joint).collect::<Result<Vec<_>, _>>()?;
        let links = robot
            .links
            .iter()
            .zip(masses)
            .map(|(link, mass)| UrdfLink {
                name: link.name.clone(),
                mass,
            })
            .collect();
        Ok(UrdfRobot {
            name: robot.name.clone(),
            links,
            joints,
            root,
            notes,
        })
    }
}

/// Reads the URDF file at `path`; meshes are looked for next to it (see
/// [`UrdfDocument::robot`]).
pub fn read_file(path: &Path, options: UrdfOptions) -> Result<UrdfRobot, UrdfError> {
    let mesh_dir = path.parent().unwrap_or(Path::new("."));
    UrdfDocument::read(path)?.robot(mesh_dir, options)
}

/// Reads a URDF text; meshes are looked for in `mesh_dir` (see [`UrdfDocument::robot`]).
pub fn read_str(text: &str, mesh_dir: &Path, options: UrdfOptions) -> Result<UrdfRobot, UrdfError> {
    UrdfDocument::parse(text)?.robot(mesh_dir, options)
}

/// The index of the one link that is no joint's child; an error when there is not exactly one.
fn root_link(robot: &urdf_rs::Robot) -> Result<usize, UrdfError> {
    let children: std::collections::HashSet<&str> = robot.joints.iter().map(|j| j.child.link.as_str()).collect();
    let roots: Vec<usize> = (0..robot.links.len())
        .filter(|&i| !children.contains(robot.links[i].name.as_str()))
        .collect();
    match roots.as_slice() {
        [root] => Ok(*root),
        _ => Err(UrdfError::RootCount {
            roots: roots.iter().map(|&i| robot.links[i].name.clone()).collect(),
        }),
    }
}

/// The joint of a URDF joint (see the crate docs for the mapping); an error for a revolute or
/// prismatic joint without a usable axis or a planar joint whose normal is not z.
fn urdf_joint(joint: &urdf_rs::Joint) -> Result<UrdfJoint, UrdfError> {
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
        return Err(UrdfError::BadAxis {
            joint: joint.name.clone(),
        });
    }
    if kind == JointKind::Planar && (axis / norm - Vector3::z()).norm() > 1e-12 {
        return Err(UrdfError::PlanarNormal {
            joint: joint.name.clone(),
        });
    }
    let limited = matches!(joint.joint_type, T::Revolute | T::Prismatic)
        && joint.limit.lower.is_finite()
        && joint.limit.upper.is_finite()
        && joint.limit.lower < joint.limit.upper;
    Ok(UrdfJoint {
        name: joint.name.clone(),
        kind,
        parent: joint.parent.link.clone(),
        child: joint.child.link.clone(),
        axis: matches!(kind, JointKind::Revolute | JointKind::Prismatic | JointKind::Planar).then(|| axis / norm),
        origin: joint.origin.xyz.0,
        rpy: joint.origin.rpy.0,
        limits: limited.then_some([joint.limit.lower, joint.limit.upper]),
    })
}
