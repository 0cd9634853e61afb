//! Constrained integration by projection (Hairer, Lubich & Wanner, *Geometric Numerical
//! Integration*, IV.4, "standard projection"), for every method but RATTLE (M.19): each step
//! integrates the index-1 equations of motion, whose q̈ solves the multiplier equations (M.18),
//! and its end point is projected back onto the constraints:
//!
//! - q ← the Gauss–Newton projection onto f(q) = 0 in the metric of the mass matrix (the
//!   correction of least kinetic metric), to the rounding level of f
//!   ([`mechanica_dynamics::ConstrainedDynamics::project_positions`]);
//! - q̇ ← the A-orthogonal projection onto J(q) q̇ = 0
//!   ([`mechanica_dynamics::ConstrainedDynamics::project_velocities`]).
//!
//! The projection moves the state by the local error of the step, so the method keeps its
//! order, and the drift ‖f‖, ‖J q̇‖ stays at rounding level instead of growing with time.

use crate::error::StepFailure;
use crate::system::System;
use mechanica_dynamics::ProjectionOptions;

/// Projects (q, q̇) onto f(q) = 0 and J(q) q̇ = 0 in place (module docs); nothing without
/// constraints.
pub(crate) fn project(system: &mut System, q: &mut [f64], v: &mut [f64]) -> Result<(), StepFailure> {
    if !system.is_constrained() {
        return Ok(());
    }
    let constraints = system.constraints_mut();
    let positions = constraints.project_positions(q, &ProjectionOptions::default())?;
    q.copy_from_slice(&positions.q);
    let velocities = constraints.project_velocities(q, v)?;
    v.copy_from_slice(&velocities.q_dot);
    crate::error::check_finite(q, "projected q")?;
    crate::error::check_finite(v, "projected q̇")
}
