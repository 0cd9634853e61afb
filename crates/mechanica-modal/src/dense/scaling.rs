//! Power-of-two scaling of a pencil into the middle of the double range.
//!
//! (B, A) and (B/β, A/α) have the same modes, with ω² scaled by α/β and A-normalised shapes by
//! √α. With α and β powers of two the scaling is exact and commutes with every rounding, so a
//! pencil whose entries lie near 1e±308 (or are subnormal) is solved exactly as its scaled
//! copy: no norm, product or Rayleigh quotient overflows or loses its digits to underflow. The
//! results are mapped back, and a result outside the range of doubles is an
//! [`ModalError::OutOfRange`], never an infinity or a NaN.

use crate::dense::solution::ModalSolution;
use crate::error::ModalError;
use crate::linalg::powers_of_two::{exponent, times_power_of_two};
use crate::problem::PencilProblem;
use crate::spectrum::ModeKind;
use faer::{Mat, MatRef};

/// The largest binary exponent the scaled entries keep (so that sums of n² squares, Frobenius
/// norms, do not overflow).
const TOP_EXPONENT: i32 = 0;
/// A pencil whose largest entries of A and of B have binary exponents within ±SAFE_EXPONENT
/// (and no nonzero entry below 2^−900) is solved as stored: its ω², their squares in the
/// quadratic bounds and the double-double products all stay far inside the range.
const SAFE_EXPONENT: i32 = 100;
/// The smallest binary exponent a scaled nonzero entry may have: normal numbers only.
const BOTTOM_EXPONENT: i32 = f64::MIN_EXP;

/// The powers of two α = 2^`mass` (of A) and β = 2^`stiffness` (of B) by which a pencil is
/// divided, as binary exponents (2^±1024 and beyond are not doubles).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PencilScale {
    pub mass: i32,
    pub stiffness: i32,
}

impl PencilScale {
    /// The scale of `problem`: its largest entries brought to [1/2, 1), or, when that would
    /// take its smallest nonzero entry below the normal range, as high as the largest allows.
    /// None when no scaling is needed (see [`SAFE_EXPONENT`]).
    pub(crate) fn of(problem: &PencilProblem) -> Result<Option<Self>, ModalError> {
        let (mass, mass_needed) = exponent_for("A", problem.a())?;
        let (stiffness, stiffness_needed) = exponent_for("B", problem.b())?;
        Ok((mass_needed || stiffness_needed).then_some(Self { mass, stiffness }))
    }

    /// ω² of the scaled pencil → ω² of the stored one (a factor 2^(stiffness − mass)).
    pub(crate) fn to_stored(self, omega_sq: f64) -> f64 {
        times_power_of_two(omega_sq, self.stiffness - self.mass)
    }

    /// ω² of the stored pencil → ω² of the scaled one.
    pub(crate) fn to_scaled(self, omega_sq: f64) -> f64 {
        times_power_of_two(omega_sq, self.mass - self.stiffness)
    }

    /// (B/β, A/α).
    pub(crate) fn apply(&self, problem: &PencilProblem) -> Result<PencilProblem, ModalError> {
        let scaled =
            |m: MatRef<'_, f64>, e: i32| Mat::from_fn(m.nrows(), m.ncols(), |i, j| times_power_of_two(m[(i, j)], -e));
        PencilProblem::new(
            scaled(problem.a(), self.mass).as_ref(),
            scaled(problem.b(), self.stiffness).as_ref(),
        )
    }

    /// A bound of the scaled pencil → a bound of the stored one, never rounded below the
    /// rounding of an ω² of size `omega_sq` (stored units) to the double grid, which is coarse
    /// among subnormal numbers.
    fn bound_to_stored(&self, bound: f64, omega_sq: f64) -> f64 {
        let grid = if omega_sq.abs() < f64::MIN_POSITIVE {
            f64::from_bits(1)
        } else {
            0.0
        };
        let mapped = self.to_stored(bound);
        if bound > 0.0 {
            mapped.max(f64::from_bits(1)) + grid
        } else {
            mapped + grid
        }
    }

    /// The solution of the scaled pencil mapped back to the stored one.
    pub(crate) fn restore(&self, mut solution: ModalSolution) -> Result<ModalSolution, ModalError> {
        let in_range = |what: &str, value: f64| -> Result<f64, ModalError> {
            if value.is_finite() {
                return Ok(value);
            }
            Err(ModalError::OutOfRange {
                what: what.to_string(),
                detail: format!("it is {value:e} once scaled back by 2^{}", self.stiffness - self.mass),
            })
        };
        for (k, mode) in solution.modes.iter_mut().enumerate() {
            if mode.kind == ModeKind::Infinite {
                continue;
            }
            let scaled_omega_sq = mode.omega_sq;
            mode.omega_sq = in_range(&format!("ω² of mode {k}"), self.to_stored(scaled_omega_sq))?;
            mode.lambda = -mode.omega_sq;
            mode.error_bound = in_range(
                &format!("the error bound of mode {k}"),
                self.bound_to_stored(mode.error_bound, mode.omega_sq),
            )?;
            mode.kind = match mode.kind {
                // A mode certified oscillatory (or unstable) by the order or by Sylvester's law
                // may have a computed ω² of the other sign within its bound: its rate is then 0.
                ModeKind::Oscillatory { .. } => ModeKind::Oscillatory {
                    omega: mode.omega_sq.max(0.0).sqrt(),
                },
                ModeKind::Unstable { .. } => ModeKind::Unstable {
                    growth_rate: (-mode.omega_sq).max(0.0).sqrt(),
                },
                other => other,
            };
        }
        for group in &mut solution.groups {
            if group.omega_sq.is_finite() {
                group.omega_sq = self.to_stored(group.omega_sq);
            }
        }
        let finite_modes = solution.modes.iter().filter(|m| m.kind != ModeKind::Infinite).count();
        if let Some(x) = solution.vectors.as_mut() {
            // xᵀ(A/α)x = 1 → (x/√α)ᵀA(x/√α) = 1, √α = 2^(mass/2): an exact power of two, and
            // one division by √2 for an odd exponent.
            let even = self.mass.div_euclid(2);
            let odd = self.mass.rem_euclid(2) == 1;
            for c in 0..finite_modes.min(x.ncols()) {
                x.col_mut(c).iter_mut().for_each(|v| {
                    let halved = times_power_of_two(*v, -even);
                    *v = if odd { halved / std::f64::consts::SQRT_2 } else { halved };
                });
            }
        }
        let report = &mut solution.accuracy;
        // A norm beyond the largest double is reported as f64::MAX (documented on the field);
        // the backward errors were formed on the scaled pencil and hold as they are.
        report.norm_a = times_power_of_two(report.norm_a, self.mass).min(f64::MAX);
        report.norm_b = times_power_of_two(report.norm_b, self.stiffness).min(f64::MAX);
        for (i, bound) in report.error_bounds.iter_mut().enumerate() {
            let omega_sq = solution.modes.get(i).map_or(0.0, |m| m.omega_sq);
            *bound = self.bound_to_stored(*bound, omega_sq);
        }
        report
            .residual_norms_a_inv
            .iter_mut()
            .flatten()
            .for_each(|r| *r = self.to_stored(*r));
        if let Some(check) = report.inertia_check.as_mut() {
            check.count.shift = self.to_stored(check.count.shift);
        }
        Ok(solution)
    }
}

/// The exponent e to divide `m` by 2^e, and whether scaling is needed: e is the exponent of the
/// largest |entry| minus [`TOP_EXPONENT`], lowered when that would push the smallest nonzero
/// entry below [`BOTTOM_EXPONENT`] (as long as the largest stays below 2^1000).
fn exponent_for(what: &str, m: MatRef<'_, f64>) -> Result<(i32, bool), ModalError> {
    let (mut largest, mut smallest) = (0.0_f64, f64::INFINITY);
    for j in 0..m.ncols() {
        for &v in m.col(j).iter() {
            if v != 0.0 {
                largest = largest.max(v.abs());
                smallest = smallest.min(v.abs());
            }
        }
    }
    if largest == 0.0 {
        return Ok((0, false));
    }
    let (top, bottom) = (exponent(largest), exponent(smallest));
    let needed = !(-SAFE_EXPONENT..=SAFE_EXPONENT).contains(&top) || bottom < -900;
    let mut shift = top - TOP_EXPONENT;
    if bottom - shift < BOTTOM_EXPONENT {
        shift = bottom - BOTTOM_EXPONENT;
        if top - shift > 1000 {
            return Err(ModalError::OutOfRange {
                what: format!("the entries of {what}"),
                detail: format!("they span {largest:e} to {smallest:e}, more than double precision holds"),
            });
        }
    }
    Ok((shift, needed))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exponents_match_frexp_from_subnormal_to_the_largest_double() {
        for x in [
            f64::from_bits(1),
            1e-310,
            f64::MIN_POSITIVE,
            0.75,
            1.0,
            3.0,
            1e300,
            1e308,
            1.5e308,
            f64::MAX,
        ] {
            let e = exponent(x);
            assert!(
                times_power_of_two(x, -e) < 1.0 && times_power_of_two(x, -e) >= 0.5,
                "{x:e}: {e}"
            );
        }
    }

    /// A pencil at 1e308, 2 × 2, whose modes are 0.5 and 2.5: scaled, solved, restored.
    #[test]
    fn a_pencil_at_the_top_of_the_range_keeps_its_modes() {
        let a = Mat::from_fn(2, 2, |i, j| if i == j { 1e308 } else { 0.0 });
        let b = Mat::from_fn(2, 2, |i, j| if i == j { 1.5e308 } else { -1e308 });
        let problem = PencilProblem::new(a.as_ref(), b.as_ref()).expect("finite pencil");
        let solution = crate::solve(&problem, &crate::SolveOptions::default()).expect("solve");
        for (mode, exact) in solution.modes.iter().zip([0.5, 2.5]) {
            assert!((mode.omega_sq - exact).abs() <= mode.error_bound, "{mode:?}");
            assert!(mode.error_bound <= 1e-14, "{mode:?}");
        }
    }

    #[test]
    fn scaling_by_powers_of_two_is_exact_through_the_whole_range() {
        for (x, e) in [(1e308, -1024), (1e-310, 1060), (3.0, 0), (-5e-324, 1074)] {
            let y = times_power_of_two(x, e);
            assert_eq!(times_power_of_two(y, -e), x, "{x:e} by 2^{e}");
        }
    }
}
