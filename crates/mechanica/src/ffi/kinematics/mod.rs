//! C entry points of the kinematics crate: rotations, Euler angles, rigid and relative motion,
//! and the kinematic tree handle. A result that overflows is MECH_STATUS_OUT_OF_RANGE.

use super::boundary::FfiError;
use super::status::*;
use mechanica_kinematics::KinematicsError;

mod euler;
mod jacobian;
mod motion;
mod rotation;
mod tree;
mod tree_state;

pub use euler::*;
pub use jacobian::*;
pub use motion::*;
pub use rotation::*;
pub use tree::*;
pub use tree_state::*;

impl From<KinematicsError> for FfiError {
    fn from(error: KinematicsError) -> Self {
        let status = match error {
            KinematicsError::NonFinite { .. } | KinematicsError::NonFiniteEntry { .. } => MECH_STATUS_NON_FINITE,
            KinematicsError::EulerRateSingular { .. } => MECH_STATUS_SINGULAR,
            KinematicsError::NonFiniteResult { .. } => MECH_STATUS_OUT_OF_RANGE,
            KinematicsError::WrongLength { .. } => MECH_STATUS_BAD_DIMENSION,
            KinematicsError::NotARotation { .. }
            | KinematicsError::NotAUnitQuaternion { .. }
            | KinematicsError::NotAUnitAxis { .. }
            | KinematicsError::JointAxisNotUnit { .. }
            | KinematicsError::EmptyTree
            | KinematicsError::ParentOutOfRange { .. }
            | KinematicsError::NoRoot
            | KinematicsError::MultipleRoots { .. }
            | KinematicsError::Cycle { .. }
            | KinematicsError::BodyOutOfRange { .. }
            | KinematicsError::WorkspaceNotReady { .. }
            | KinematicsError::RotationAngleUnresolved { .. } => MECH_STATUS_INVALID_ARGUMENT,
            // A variant added after this layer was written: its message still says what was wrong.
            _ => MECH_STATUS_INVALID_ARGUMENT,
        };
        FfiError::new(status, error.to_string())
    }
}
