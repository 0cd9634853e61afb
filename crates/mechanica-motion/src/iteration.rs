//! Convergence of the implicit equations of a step to rounding level.

use crate::error::StepFailure;

/// The most iterations an implicit solve may take.
pub(crate) const MAX_ITERATIONS: usize = 60;

/// Tracks the corrections ‖Δx‖∞ of an iteration and decides when it has converged: when a
/// correction is at the rounding level of the iterate, 4u‖x‖∞, or when corrections no
/// longer decrease while already below 1e3·u‖x‖∞ (rounding noise of the map itself).
#[derive(Debug, Clone)]
pub(crate) struct Convergence {
    what: &'static str,
    iterations: usize,
    previous: f64,
}

impl Convergence {
    pub(crate) fn new(what: &'static str) -> Self {
        Self {
            what,
            iterations: 0,
            previous: f64::INFINITY,
        }
    }

    /// Records one correction of size `correction` to an iterate of size `scale`; true when
    /// converged, an error when the correction is not finite or the iterations ran out.
    pub(crate) fn done(&mut self, correction: f64, scale: f64) -> Result<bool, StepFailure> {
        self.iterations += 1;
        if !correction.is_finite() {
            return Err(StepFailure::NonFinite { what: self.what });
        }
        let floor = f64::EPSILON * scale.max(f64::MIN_POSITIVE);
        let converged = correction <= 4.0 * floor || (correction >= self.previous && correction <= 1e3 * floor);
        if converged {
            return Ok(true);
        }
        if self.iterations >= MAX_ITERATIONS {
            return Err(StepFailure::NotConverged {
                what: self.what,
                iterations: self.iterations,
                correction,
            });
        }
        self.previous = correction;
        Ok(false)
    }
}

/// ‖a − b‖∞.
pub(crate) fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0, |m, (x, y)| m.max((x - y).abs()))
}

/// ‖a‖∞.
pub(crate) fn norm(a: &[f64]) -> f64 {
    a.iter().fold(0.0, |m, x| m.max(x.abs()))
}
