//! How far a state is from the constraints: f(q), J(q) q̇, their 2-norms, and the rounding
//! level of f, for integrators that must meet f = 0 and for monitors of constraint drift.
//!
//! The rounding level is 64·m·u·max_r s_r, with s_r the magnitude of the terms f_r is computed
//! from (the world positions of its points, the rod length, the prescribed value) and u the
//! unit roundoff: a ‖f‖₂ below it is as close to f = 0 as f can be evaluated. It is the
//! default tolerance of [`super::ConstrainedDynamics::project_positions`].

use super::ConstrainedDynamics;
use super::evaluate::Evaluated;
use super::forward::norm2;
use crate::error::DynamicsError;

/// The constraint residuals at one state (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct ConstraintDrift {
    /// f(q), one entry per equation.
    pub values: Vec<f64>,
    /// J(q) q̇, one entry per equation.
    pub velocities: Vec<f64>,
    /// ‖f(q)‖₂ (mixed units when the equations mix lengths and angles).
    pub position: f64,
    /// ‖J(q) q̇‖₂.
    pub velocity: f64,
    /// The rounding level of ‖f‖₂ at q (module docs).
    pub rounding_level: f64,
}

/// 64·m·u·max_r s_r for the evaluated constraints (module docs).
pub(crate) fn rounding_level(evaluated: &Evaluated) -> f64 {
    let scale = evaluated.value_scale.iter().fold(0.0f64, |m, s| m.max(*s));
    64.0 * evaluated.equations() as f64 * f64::EPSILON * scale
}

impl ConstrainedDynamics {
    /// f(q), J q̇, their 2-norms and the rounding level of f at (q, q̇) (module docs). Errors:
    /// wrong lengths or non-finite inputs, points of a rod constraint that coincide.
    pub fn drift(&mut self, q: &[f64], q_dot: &[f64]) -> Result<ConstraintDrift, DynamicsError> {
        let evaluated = self.evaluate(q, q_dot)?;
        Ok(ConstraintDrift {
            position: norm2(&evaluated.value),
            velocity: norm2(&evaluated.velocity),
            rounding_level: rounding_level(&evaluated),
            values: evaluated.value,
            velocities: evaluated.velocity,
        })
    }
}
