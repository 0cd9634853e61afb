//! URDF robot descriptions (read through the `urdf-rs` crate) as link mass properties, joints
//! and kinematic trees.
//!
//! - **Links** get explicit mass properties from `<inertial>`: the centre of mass at the
//!   inertial origin and the tensor rotated by its `rpy` into the link frame. Every link's
//!   tensor is checked (mass crate validity: symmetry, semidefiniteness, triangle inequality);
//!   all invalid links are reported at once, and [`UrdfOptions::repair_inertia`] replaces each
//!   by the nearest physical tensor (documented in `mechanica_mass::validity::repair`). A
//!   tensor whose nearest physical tensor is within 1e-14 of the robot's largest link inertia
//!   (trace about the link's frame origin, over physical tensors) is off by the file's
//!   rounding (exporters write zero moments as ±1e-20): it is replaced by that tensor with a
//!   note, without the option.
//! - A link without `<inertial>` whose collision (or else visual) geometry is a mesh gets the
//!   mesh's mass properties at [`MESH_DENSITY`] (water; URDF gives no density); a declared
//!   `<inertial>` is followed even with a zero mass (as in Pinocchio, Drake and MuJoCo: a
//!   massless link, or, with a tensor, a rotor whose rotational inertia counts without mass;
//!   the tensor must be one a body could have); the file name, with `package://` and `file://` prefixes stripped, is resolved
//!   in the mesh directory (the URDF file's directory for [`read_file`]), then relative to the
//!   working directory; a `package://PKG/rest` URI also under each ancestor of the mesh
//!   directory named PKG and under `PKG` in each ancestor and each `ROS_PACKAGE_PATH` entry. A mesh that cannot be used (missing file, a format other than STL or
//!   OBJ such as `.dae`, a mesh without a volume) is an error naming the link and the mesh;
//!   with [`UrdfOptions::allow_missing_mesh`] the link is massless instead and a warning is
//!   added to the notes. A link with neither `<inertial>` nor a mesh is a massless frame.
//! - **Joints**: revolute and continuous → revolute, prismatic, fixed, floating → free,
//!   spherical, planar (normal along the joint's z only). Placements use the joint origin
//!   (xyz, rpy = R_z(yaw) R_y(pitch) R_x(roll)); the child link frame is the joint frame at
//!   q = 0. Finite revolute/prismatic limits with lower < upper become joint limits. Mimic
//!   joints are not followed (each joint is free).
//! - **Trees** ([`UrdfRobot::tree`]): one body per link in the file's order, the root link
//!   attached to the base frame by a fixed joint, every other link by its URDF joint.
//!
//! Before parsing, one linear pass over the text refuses elements nested deeper than
//! [`MAX_NESTING`] (the XML parsers underneath recurse per level) and drops `<texture>`
//! elements without a `filename` (some exporters write `<texture/>` in materials, which only
//! concern rendering).
//!
//! The text is at most [`MAX_URDF_BYTES`] long; every allocation is proportional to it.

mod error;
mod links;
mod robot;
mod tree;
mod xml_scan;

pub use error::UrdfError;
pub use links::MESH_DENSITY;
pub use robot::{JointKind, UrdfDocument, UrdfJoint, UrdfLink, UrdfOptions, UrdfRobot, read_file, read_str};
pub use tree::UrdfTree;
pub use xml_scan::MAX_NESTING;

/// The longest URDF text read (64 MiB): larger files and strings are refused before parsing.
pub const MAX_URDF_BYTES: usize = 64 << 20;
