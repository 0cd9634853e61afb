//! A robot as a kinematic tree: one body per link, with the names of links, joints and
//! coordinates and the joint limits per coordinate.

use crate::error::UrdfError;
use crate::robot::{UrdfJoint, UrdfRobot};
use mechanica_kinematics::nalgebra::Isometry3;
use mechanica_kinematics::tree::{Joint, KinematicTree, TreeBuilder};
use mechanica_mass::MassProperties;
use std::collections::HashMap;

/// A robot's kinematic tree with names. Body b is link b of the robot (file order); the root
/// link hangs on the base frame by a fixed joint at the identity, every other link by its
/// URDF joint.
#[derive(Debug, Clone)]
pub struct UrdfTree {
    /// The tree.
    pub tree: KinematicTree,
    /// Per body: the link's name.
    pub link_names: Vec<String>,
    /// Per body: the name of the joint to its parent (empty for the root link).
    pub joint_names: Vec<String>,
    /// Per coordinate: its name, the joint's name for a one-coordinate joint and
    /// `joint[i]` (i = 0, 1, …) for the coordinates of a joint with several.
    pub coordinate_names: Vec<String>,
    /// Per body: the link's mass properties in its frame.
    pub masses: Vec<MassProperties>,
    /// Per coordinate: `[lower, upper]` when its joint has limits.
    pub limits: Vec<Option<[f64; 2]>>,
}

impl UrdfRobot {
    /// The kinematic tree of the robot (see [`UrdfTree`]). Errors: a joint's parent or child
    /// names no link, two links share a name, a link is the child of two joints, a joint origin
    /// is not finite, or the joints form a cycle.
    pub fn tree(&self) -> Result<UrdfTree, UrdfError> {
        let index = link_index(self)?;
        let mut joint_of: Vec<Option<&UrdfJoint>> = vec![None; self.links.len()];
        let mut parent_of = vec![None; self.links.len()];
        for joint in &self.joints {
            let child = linked(&index, joint, "child", &joint.child)?;
            let parent = linked(&index, joint, "parent", &joint.parent)?;
            if joint_of[child].replace(joint).is_some() {
                return Err(UrdfError::Structure {
                    link: joint.child.clone(),
                    problem: "is the child of two joints",
                });
            }
            check_origin(joint)?;
            parent_of[child] = Some(parent);
        }
        let mut builder = TreeBuilder::new();
        for (body, joint) in joint_of.iter().enumerate() {
            match joint {
                Some(joint) => builder.add_body(parent_of[body], joint.joint(), joint.placement()),
                None => builder.add_body(None, Joint::Fixed, Isometry3::identity()),
            };
        }
        let tree = builder.build()?;
        let (coordinate_names, limits) = coordinates(&tree, &joint_of);
        Ok(UrdfTree {
            tree,
            link_names: self.links.iter().map(|l| l.name.clone()).collect(),
            joint_names: joint_of
                .iter()
                .map(|j| j.map_or(String::new(), |j| j.name.clone()))
                .collect(),
            coordinate_names,
            masses: self.links.iter().map(|l| l.mass).collect(),
            limits,
        })
    }
}

/// Link name → index; two links with one name are an error.
fn link_index(robot: &UrdfRobot) -> Result<HashMap<&str, usize>, UrdfError> {
    let mut index = HashMap::with_capacity(robot.links.len());
    for (i, link) in robot.links.iter().enumerate() {
        if index.insert(link.name.as_str(), i).is_some() {
            return Err(UrdfError::Structure {
                link: link.name.clone(),
                problem: "two links have this name",
            });
        }
    }
    Ok(index)
}

/// The index of the link `name` given in `joint`'s `field`.
fn linked(
    index: &HashMap<&str, usize>,
    joint: &UrdfJoint,
    field: &'static str,
    name: &str,
) -> Result<usize, UrdfError> {
    index.get(name).copied().ok_or_else(|| UrdfError::UnknownLink {
        joint: joint.name.clone(),
        field,
        link: name.to_string(),
    })
}

/// Fails unless the joint's `<origin xyz rpy>` is finite.
fn check_origin(joint: &UrdfJoint) -> Result<(), UrdfError> {
    let finite = |v: &[f64; 3]| v.iter().all(|x| x.is_finite());
    if finite(&joint.origin) && finite(&joint.rpy) {
        return Ok(());
    }
    Err(UrdfError::NonFiniteOrigin {
        joint: joint.name.clone(),
    })
}

/// Per coordinate: its name and its joint's limits.
fn coordinates(tree: &KinematicTree, joint_of: &[Option<&UrdfJoint>]) -> (Vec<String>, Vec<Option<[f64; 2]>>) {
    let mut names = vec![String::new(); tree.dof()];
    let mut limits = vec![None; tree.dof()];
    for (body, joint) in joint_of.iter().enumerate() {
        let Some(joint) = joint else { continue };
        let range = tree.dof_range(body);
        let several = range.len() > 1;
        for (i, k) in range.enumerate() {
            names[k] = if several {
                format!("{}[{i}]", joint.name)
            } else {
                joint.name.clone()
            };
            limits[k] = joint.limits;
        }
    }
    (names, limits)
}
