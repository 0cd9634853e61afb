//! The global error estimate from a companion run (M.12)–(M.13).
//!
//! The companion integrates the same initial value problem with the same method at half the
//! step (tolerances divided by 32 for the adaptive pair). If its error is at most ρ times the
//! method's, e_c ≤ ρ e, then e ≤ ‖y − y_c‖ + e_c gives e ≤ ‖y − y_c‖ / (1 − ρ) (M.13). For a
//! fixed step h of a method of order p, the leading global error term is C(t) hᵖ, so the
//! ratio tends to 2⁻ᵖ and ‖y − y_c‖ / (1 − 2⁻ᵖ) is Richardson's estimate, which is
//! asymptotically exact and so falls short of the true error about half the time. The
//! estimate uses ρ = 1/2 for every method instead: the ratio of a first-order method, above
//! the 2⁻ᵖ ≤ 1/4 of a halved step of order p ≥ 2 and the 1/32 of the adaptive pair's
//! tolerance proportionality; the margin covers the higher-order terms. It overestimates by
//! about 2(1 − 2⁻ᵖ).
//! The argument holds for chaotic and growing errors as long as both runs follow the same
//! trajectory to first order, because it compares global errors, not sums of local ones.
//! Rounding adds 2u·√(N + 1)·‖y‖∞ after N steps, which the estimate includes as a floor.

use crate::integrator::Point;

/// Estimates of the global error of a reported state (∞-norms, in the reporting chart).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorEstimate {
    /// Of q (rad or m).
    pub q: f64,
    /// Of q̇ (rad/s or m/s).
    pub q_dot: f64,
}

fn component(main: &[f64], companion: &[f64], ratio: f64, steps: usize) -> f64 {
    let difference = crate::iteration::distance(main, companion);
    let size = crate::iteration::norm(main).max(crate::iteration::norm(companion));
    let rounding = 2.0 * f64::EPSILON * ((steps + 1) as f64).sqrt() * size;
    difference / (1.0 - ratio) + rounding
}

/// The estimate (M.13) for the main run's `main` from the companion's `companion` (both in the
/// reporting chart), with the companion ratio ρ and the main run's step count.
pub(crate) fn estimate(main: &Point, companion: &Point, ratio: f64, steps: usize) -> ErrorEstimate {
    ErrorEstimate {
        q: component(&main.q, &companion.q, ratio, steps),
        q_dot: component(&main.q_dot, &companion.q_dot, ratio, steps),
    }
}
