//! Constant (dead) loads: a force of fixed world direction at a body point, and a constant
//! generalized force on one coordinate.

use super::{Anchor, Potential, PotentialSum};
use crate::{Configuration, MechanismError};
use mechanica_kinematics::tree::KinematicTree;
use nalgebra::{Matrix3, Vector3};

/// A constant world force F at a body point: U = −F·x, ∂U/∂q = −J_xᵀ F, and the Hessian is the
/// geometric term −F·∂²x/∂q∂q (a dead load stiffens or softens a mechanism).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConstantForce {
    /// The body and its point (body coordinates).
    pub body: usize,
    /// Point of application, body coordinates.
    pub point: Vector3<f64>,
    /// The force, world components (N).
    pub force: Vector3<f64>,
}

impl Potential for ConstantForce {
    fn name(&self) -> String {
        format!("constant force on body {}", self.body)
    }

    fn validate(&self, tree: &KinematicTree) -> Result<(), MechanismError> {
        crate::error::check_all_finite(self.force.iter(), "constant force")?;
        Anchor {
            body: Some(self.body),
            point: self.point,
        }
        .validate(tree, "constant force")
    }

    fn accumulate(&self, config: &Configuration<'_>, sum: &mut PotentialSum) -> Result<(), MechanismError> {
        let anchor = Anchor {
            body: Some(self.body),
            point: self.point,
        };
        let x = config.point(anchor.body, &anchor.point)?;
        sum.add_point_potential(
            config,
            &[(anchor, 1.0)],
            -self.force.dot(&x),
            &-self.force,
            &Matrix3::zeros(),
        )
    }
}

/// A constant generalized force Q on coordinate i: U = −Q q_i.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeneralizedForce {
    /// The coordinate index.
    pub coordinate: usize,
    /// Q (N or N·m).
    pub value: f64,
}

impl Potential for GeneralizedForce {
    fn name(&self) -> String {
        format!("generalized force on q{}", self.coordinate)
    }

    fn validate(&self, tree: &KinematicTree) -> Result<(), MechanismError> {
        crate::error::check_finite(self.value, "generalized force")?;
        if self.coordinate >= tree.dof() {
            return Err(MechanismError::NoSuchCoordinate {
                what: "generalized force",
                index: self.coordinate,
                dof: tree.dof(),
            });
        }
        Ok(())
    }

    fn accumulate(&self, config: &Configuration<'_>, sum: &mut PotentialSum) -> Result<(), MechanismError> {
        sum.value -= self.value * config.q[self.coordinate];
        sum.gradient[self.coordinate] -= self.value;
        Ok(())
    }
}
