//! The applied generalized forces τ of the equations of motion A q̈ + h = τ (7.60).

use crate::error::{MotionError, StepFailure, check_vector};
use std::sync::Arc;

/// τ(t, q, q̇) written into the last argument (one entry per coordinate).
pub type ForceFunction = dyn Fn(f64, &[f64], &[f64], &mut [f64]) + Send + Sync;

/// The applied generalized forces τ, N or N·m per coordinate, on top of the loads the dynamics
/// already holds (gravity, potentials, dampers, velocity potentials).
#[derive(Clone, Default)]
pub enum Forcing {
    /// τ = 0.
    #[default]
    None,
    /// A constant τ. It has the potential −τ·q, which the energy monitor includes.
    Constant(Vec<f64>),
    /// τ(t, q, q̇) from a callback (Rust only). It is not a potential: the energy monitor
    /// measures the work it does as drift.
    Function(Arc<ForceFunction>),
}

impl std::fmt::Debug for Forcing {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Forcing::None => f.write_str("None"),
            Forcing::Constant(tau) => f.debug_tuple("Constant").field(tau).finish(),
            Forcing::Function(_) => f.write_str("Function"),
        }
    }
}

impl Forcing {
    /// Checks a constant τ against the number of coordinates.
    pub(crate) fn validate(&self, dof: usize) -> Result<(), MotionError> {
        match self {
            Forcing::Constant(tau) => check_vector(tau, dof, "tau"),
            _ => Ok(()),
        }
    }

    /// Writes τ(t, q, q̇) to `out`; fails on a non-finite entry from a callback.
    pub(crate) fn evaluate(&self, t: f64, q: &[f64], q_dot: &[f64], out: &mut [f64]) -> Result<(), StepFailure> {
        match self {
            Forcing::None => out.fill(0.0),
            Forcing::Constant(tau) => out.copy_from_slice(tau),
            Forcing::Function(f) => {
                out.fill(0.0);
                f(t, q, q_dot, out);
                if let Some((index, &value)) = out.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                    return Err(StepFailure::NonFiniteForce { index, value });
                }
            }
        }
        Ok(())
    }

    /// The potential −τ·q of a constant τ, zero otherwise.
    pub(crate) fn potential(&self, q: &[f64]) -> f64 {
        match self {
            Forcing::Constant(tau) => -tau.iter().zip(q).map(|(t, x)| t * x).sum::<f64>(),
            _ => 0.0,
        }
    }
}
