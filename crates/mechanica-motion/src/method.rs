//! The integration methods and their parameters.

use crate::error::MotionError;

/// How the equations of motion are integrated. Every method re-centres rotation-vector charts
/// before each step ([`crate::chart`]). For a mechanism with holonomic constraints
/// ([`crate::Simulation::constrained`]), [`Method::Rattle`] keeps them by multipliers (M.17);
/// every other method integrates the index-1 equations (M.18) and projects each step's end
/// point back onto f(q) = 0 and J q̇ = 0 (M.19).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Method {
    /// The classical explicit Runge–Kutta method of order 4 (M.3) with steps of at most
    /// `step` seconds (each output interval is divided into equal steps).
    Rk4 {
        /// The largest step, s (> 0, finite).
        step: f64,
    },
    /// The Dormand–Prince 5(4) pair (M.4) with PI step control (M.6) on the weighted error
    /// of the embedded fourth-order solution, and its continuous extension (M.7) for output.
    DormandPrince {
        /// Relative tolerance (> 0, finite, at least 1e-14).
        rtol: f64,
        /// Absolute tolerance (> 0, finite), in the units of each component of (q, q̇).
        atol: f64,
    },
    /// Störmer–Verlet (generalized leapfrog) in (q, p = A(q) q̇) (M.8), order 2, symplectic
    /// for conservative systems with steps of at most `step` seconds.
    StormerVerlet {
        /// The largest step, s (> 0, finite).
        step: f64,
    },
    /// The implicit midpoint rule (M.10), order 2, A-stable and symplectic, for stiff
    /// springs, with steps of at most `step` seconds.
    ImplicitMidpoint {
        /// The largest step, s (> 0, finite).
        step: f64,
    },
    /// RATTLE (M.17): Störmer–Verlet with the constraints' multipliers solved so that
    /// f(q₁) = 0 to the rounding level of f and J(q₁) q̇₁ = 0, order 2, symplectic for
    /// conservative constrained systems, with steps of at most `step` seconds. Without
    /// constraints it is [`Method::StormerVerlet`].
    Rattle {
        /// The largest step, s (> 0, finite).
        step: f64,
    },
}

/// The smallest relative tolerance accepted by [`Method::DormandPrince`]: tighter than this
/// the steps' rounding dominates the error they control.
pub const MIN_RTOL: f64 = 1e-14;

fn positive(value: f64, what: &'static str) -> Result<(), MotionError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(MotionError::OutOfRange {
            what,
            requirement: "> 0 and finite",
            value,
        })
    }
}

impl Method {
    /// Checks the parameters: steps and tolerances positive and finite, rtol ≥ [`MIN_RTOL`].
    pub fn validate(&self) -> Result<(), MotionError> {
        match *self {
            Method::Rk4 { step }
            | Method::StormerVerlet { step }
            | Method::ImplicitMidpoint { step }
            | Method::Rattle { step } => positive(step, "step"),
            Method::DormandPrince { rtol, atol } => {
                positive(rtol, "rtol")?;
                positive(atol, "atol")?;
                if rtol < MIN_RTOL {
                    return Err(MotionError::OutOfRange {
                        what: "rtol",
                        requirement: "≥ 1e-14",
                        value: rtol,
                    });
                }
                Ok(())
            }
        }
    }

    /// The order p of the method's global error.
    pub fn order(&self) -> u32 {
        match self {
            Method::Rk4 { .. } => 4,
            Method::DormandPrince { .. } => 5,
            Method::StormerVerlet { .. } | Method::ImplicitMidpoint { .. } | Method::Rattle { .. } => 2,
        }
    }

    /// The companion of the global error estimate (M.12): half the step, or both tolerances
    /// divided by 32 (rtol kept at least [`MIN_RTOL`]).
    pub fn companion(&self) -> Method {
        match *self {
            Method::Rk4 { step } => Method::Rk4 { step: step / 2.0 },
            Method::StormerVerlet { step } => Method::StormerVerlet { step: step / 2.0 },
            Method::ImplicitMidpoint { step } => Method::ImplicitMidpoint { step: step / 2.0 },
            Method::Rattle { step } => Method::Rattle { step: step / 2.0 },
            Method::DormandPrince { rtol, atol } => Method::DormandPrince {
                rtol: (rtol / 32.0).max(MIN_RTOL),
                atol: atol / 32.0,
            },
        }
    }

    /// ρ of (M.13): the assumed bound on the companion's error relative to the method's,
    /// 1/2 for every method. A fixed step halved gives 2⁻ᵖ ≤ 1/4 asymptotically (p ≥ 2), and
    /// exact tolerance proportionality 1/32; the difference to 1/2 is the margin for the
    /// higher-order terms that make the asymptotic ratio an estimate, not a bound.
    pub(crate) fn companion_ratio(&self) -> f64 {
        0.5
    }
}
