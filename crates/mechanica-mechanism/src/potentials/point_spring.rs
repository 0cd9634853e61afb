//! Springs between two body points, or between a body point and the ground.

use super::{Anchor, Potential, PotentialSum};
use crate::{Configuration, MechanismError};
use mechanica_kinematics::tree::KinematicTree;
use nalgebra::{Matrix3, Vector3};

/// A linear spring between the points `a` and `b`: U = ½ k (|d| − L₀)², d = x_a − x_b.
/// ∂U/∂d = k (|d| − L₀) u and ∂²U/∂d² = k [u uᵀ + (1 − L₀/|d|)(1 − u uᵀ)] with u = d/|d|.
/// With L₀ = 0 (a zero-length spring) U = ½ k |d|² and the Hessian is k·1 everywhere; with
/// L₀ > 0 and |d| = 0 the direction is undefined and [`MechanismError::ZeroLengthSpring`] is
/// returned.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointSpring {
    /// First end.
    pub a: Anchor,
    /// Second end.
    pub b: Anchor,
    /// Stiffness k ≥ 0 (N/m).
    pub stiffness: f64,
    /// Rest length L₀ ≥ 0 (m).
    pub rest_length: f64,
}

impl Potential for PointSpring {
    fn name(&self) -> String {
        let end = |a: &Anchor| match a.body {
            Some(b) => format!("body {b}"),
            None => "ground".into(),
        };
        format!("spring {}–{}", end(&self.a), end(&self.b))
    }

    fn validate(&self, tree: &KinematicTree) -> Result<(), MechanismError> {
        self.a.validate(tree, "spring end a")?;
        self.b.validate(tree, "spring end b")?;
        for (value, what) in [
            (self.stiffness, "spring stiffness"),
            (self.rest_length, "spring rest length"),
        ] {
            if crate::error::check_finite(value, what)? < 0.0 {
                return Err(MechanismError::OutOfRange {
                    what,
                    requirement: "≥ 0",
                    value,
                });
            }
        }
        Ok(())
    }

    fn accumulate(&self, config: &Configuration<'_>, sum: &mut PotentialSum) -> Result<(), MechanismError> {
        let d = config.point(self.a.body, &self.a.point)? - config.point(self.b.body, &self.b.point)?;
        let length = d.norm();
        let k = self.stiffness;
        let (energy, force, stiffness) = if self.rest_length == 0.0 {
            (0.5 * k * length * length, d * k, Matrix3::identity() * k)
        } else {
            if length == 0.0 {
                return Err(MechanismError::ZeroLengthSpring { name: self.name() });
            }
            let u: Vector3<f64> = d / length;
            let stretch = length - self.rest_length;
            let along = u * u.transpose();
            let across = (Matrix3::identity() - along) * (stretch / length);
            (0.5 * k * stretch * stretch, u * (k * stretch), (along + across) * k)
        };
        sum.add_point_potential(config, &[(self.a, 1.0), (self.b, -1.0)], energy, &force, &stiffness)
    }
}
