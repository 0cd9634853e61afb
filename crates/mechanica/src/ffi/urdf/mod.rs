//! C entry points of the URDF reader: kinematic trees and mechanisms from a URDF file or text,
//! and the names of their links, joints and coordinates.

mod names;
mod read;

pub use names::*;
pub use read::*;

pub(crate) use names::UrdfNames;
