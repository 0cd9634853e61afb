//! Linear and torsional springs acting on one joint coordinate.

use super::{Potential, PotentialSum};
use crate::{Configuration, MechanismError};
use mechanica_kinematics::tree::KinematicTree;

/// U = ½ k (q_i − q_rest)² on coordinate i: a torsional spring on a revolute or planar angle
/// (k in N·m/rad), a linear spring on a prismatic or planar translation (k in N/m).
///
/// Rotation-vector coordinates of spherical and free joints are rejected: they are re-centred
/// by [`crate::Mechanism::rebase`], so a rest value in them would silently change meaning.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointSpring {
    /// The coordinate index.
    pub coordinate: usize,
    /// Stiffness k ≥ 0.
    pub stiffness: f64,
    /// Rest value q_rest.
    pub rest: f64,
}

impl Potential for JointSpring {
    fn name(&self) -> String {
        format!("joint spring on q{}", self.coordinate)
    }

    fn validate(&self, tree: &KinematicTree) -> Result<(), MechanismError> {
        let k = crate::error::check_finite(self.stiffness, "joint spring stiffness")?;
        crate::error::check_finite(self.rest, "joint spring rest value")?;
        if k < 0.0 {
            return Err(MechanismError::OutOfRange {
                what: "joint spring stiffness",
                requirement: "≥ 0",
                value: k,
            });
        }
        let body = tree.dof_body(self.coordinate).ok_or(MechanismError::NoSuchCoordinate {
            what: "joint spring",
            index: self.coordinate,
            dof: tree.dof(),
        })?;
        if crate::mechanism::is_rotation_vector_coordinate(tree, body, self.coordinate) {
            return Err(MechanismError::Potential {
                name: self.name(),
                message: "springs on the rotation vector of a spherical or free joint are not supported; \
                          use point springs"
                    .into(),
            });
        }
        Ok(())
    }

    fn accumulate(&self, config: &Configuration<'_>, sum: &mut PotentialSum) -> Result<(), MechanismError> {
        let i = self.coordinate;
        let stretch = config.q[i] - self.rest;
        sum.value += 0.5 * self.stiffness * stretch * stretch;
        sum.gradient[i] += self.stiffness * stretch;
        if let Some(h) = sum.hessian.as_mut() {
            h[(i, i)] += self.stiffness;
        }
        Ok(())
    }
}
