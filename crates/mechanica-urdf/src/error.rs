//! The error type of URDF reading and tree building.

use mechanica_kinematics::KinematicsError;
use thiserror::Error;

/// Why a URDF description could not be used. Messages name the link or joint and the field.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum UrdfError {
    /// The file could not be read.
    #[error("{message}")]
    Io {
        /// What the operating system reported.
        message: String,
    },
    /// The text is longer than [`crate::MAX_URDF_BYTES`].
    #[error("the URDF text has {bytes} bytes, more than the limit of {limit}")]
    TooLarge {
        /// Its length in bytes.
        bytes: u64,
        /// The limit.
        limit: usize,
    },
    /// The text is not a URDF robot (XML syntax, missing or malformed elements).
    #[error("{message}")]
    Parse {
        /// The parser's message.
        message: String,
    },
    /// Links without `<inertial>` whose mesh cannot be used, one line per link.
    #[error("links without <inertial> whose mesh cannot be used:\n  {}", problems.join("\n  "))]
    UnusableMeshes {
        /// One problem per link, naming the link and the mesh.
        problems: Vec<String>,
    },
    /// Links whose `<inertial>` is not physical, one line per link.
    #[error("invalid inertias:\n  {}", problems.join("\n  "))]
    InvalidInertias {
        /// One problem per link, naming the link.
        problems: Vec<String>,
    },
    /// Not exactly one link is no joint's child.
    #[error("{}", root_count_message(roots))]
    RootCount {
        /// The links that are no joint's child.
        roots: Vec<String>,
    },
    /// A revolute or prismatic joint whose `<axis xyz>` is zero or not finite.
    #[error("joint \"{joint}\": zero or non-finite axis")]
    BadAxis {
        /// The joint.
        joint: String,
    },
    /// A planar joint whose `<axis xyz>` (the plane's normal) is not the joint frame's z axis.
    #[error("joint \"{joint}\": planar joints are supported with their normal along the joint's z axis only")]
    PlanarNormal {
        /// The joint.
        joint: String,
    },
    /// A joint's `<parent link>` or `<child link>` names no link.
    #[error("joint \"{joint}\": {field} link \"{link}\" is not a link of the robot")]
    UnknownLink {
        /// The joint.
        joint: String,
        /// `parent` or `child`.
        field: &'static str,
        /// The name given.
        link: String,
    },
    /// A joint's `<origin xyz>` or `<origin rpy>` holds a NaN or an infinity.
    #[error("joint \"{joint}\": origin: xyz and rpy must be finite")]
    NonFiniteOrigin {
        /// The joint.
        joint: String,
    },
    /// Two links share a name, or a link is the child of two joints.
    #[error("link \"{link}\": {problem}")]
    Structure {
        /// The link.
        link: String,
        /// What is wrong.
        problem: &'static str,
    },
    /// The joints do not form a tree (a cycle) or a placement is not a rigid motion.
    #[error(transparent)]
    Kinematics(#[from] KinematicsError),
}

/// The message of [`UrdfError::RootCount`].
fn root_count_message(roots: &[String]) -> String {
    if roots.is_empty() {
        "a URDF tree needs one root link (a link that is no joint's child): the robot has no links, or every link is \
         a joint's child"
            .to_string()
    } else {
        format!("a URDF tree has one root link (a link that is no joint's child), found {roots:?}")
    }
}
