//! The Sturm check attached to every dense solve: the inertia of B − sA at a shift s against the
//! number of computed ω² below s, so that no mode below s was missed or invented.

use crate::certify::idle_certificate::{BottomCertificate, IdleCertificate, Outcome};
use crate::certify::inertia::{InertiaCount, all_above, count_below};
use crate::error::ModalError;
use crate::problem::PencilProblem;
use faer::Par;

/// The Sturm check attached to a solve: no mode below the shift was missed or invented.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InertiaCheck {
    /// The inertia of B − sA at the chosen shift, in modes: for a condensed pencil (semidefinite
    /// A) the negative eigenvalues of the massless directions' stiffness B₀₀ are taken out of
    /// `below` (Haynsworth: In(B − sA) = In(B₀₀) + In(S − sA₁)), and the infinite modes are
    /// `above`.
    pub count: InertiaCount,
    /// How many computed ω² lie below the shift.
    pub computed_below: usize,
    /// Whether the two counts agree (and s is not numerically an eigenvalue).
    pub consistent: bool,
}

/// The Sturm check of a solve (`spare`: an unused matrix whose storage it may take). With every
/// mode selected it first tries the cheap certificate
/// that B − sA is positive definite for s just below the lowest computed ω² (by half its size or
/// twice its bound): nothing was missed at the bottom of the spectrum, where stability is
/// decided (the idle-time certificate's decision, when it has one at that shift). Otherwise, or
/// when that Cholesky fails, it places a shift in the first real gap
/// (wider than twice the largest bound) at or beyond the selection's edge, so never inside a
/// cluster the selection cut, or in the widest gap of the whole spectrum, and compares the LBLᵀ
/// inertia count with the number of computed ω² below it.
pub(crate) fn inertia_check(
    problem: &PencilProblem,
    omega_all: &[f64],
    (first, end): (usize, usize),
    bounds: &[f64],
    condensed_stiffness_negatives: Option<usize>,
    bottom: Option<BottomCertificate>,
    par: Par,
) -> Result<Option<InertiaCheck>, ModalError> {
    if omega_all.is_empty() {
        return Ok(None);
    }
    let n = omega_all.len();
    // A condensed pencil: the count of the full B − sA includes B₀₀'s negative eigenvalues.
    let offset = condensed_stiffness_negatives.unwrap_or(0);
    if first == 0 && end == n && !bounds.is_empty() && offset == 0 {
        // Every mode selected: certify the bottom of the spectrum (no mode, and so no
        // instability, below the lowest computed ω²) with a Cholesky factorization.
        let lowest = omega_all[0];
        let rule = lowest - (0.5 * lowest.abs()).max(2.0 * bounds[0]);
        // Half of T's lowest eigenvalue (the shift the idle thread factors at) is taken when it
        // is the rule's to 8 digits, or higher and still below the lowest ω² by more than twice
        // its bound: then the certified shift does not depend on whether the thread finished.
        let usable = |s: f64| s >= rule - 1e-8 * rule.abs() && s < lowest - 2.0 * bounds[0];
        let (shift, idle) = match bottom {
            Some(b) if usable(b.shift) => (b.shift, b.idle),
            _ => (rule, None),
        };
        // A factor the thread had begun is finished here on every thread.
        let from_idle = match idle.and_then(IdleCertificate::collect) {
            Some(Outcome::Decided { positive: true }) => Some(shift),
            Some(Outcome::Partial(partial)) => partial.finish(par).then_some(shift),
            _ => None,
        };
        let certified = from_idle.or_else(|| (shift < lowest && all_above(problem, shift, par)).then_some(shift));
        if let Some(shift) = certified {
            return Ok(Some(InertiaCheck {
                count: InertiaCount {
                    shift,
                    below: 0,
                    zero: 0,
                    above: problem.dim(),
                },
                computed_below: 0,
                consistent: true,
            }));
        }
    }
    let margin = bounds.iter().copied().fold(0.0, f64::max);
    // A gap between i − 1 and i that is real (wider than the bounds), so that the shift does
    // not fall inside a cluster the selection cut (its count would split the cluster).
    let real_gap = |i: &usize| omega_all[*i] - omega_all[*i - 1] > 2.0 * margin;
    let midpoint = |i: usize| 0.5 * (omega_all[i - 1] + omega_all[i]);
    let shift = if end < n && end > 0 {
        midpoint((end..n).find(real_gap).unwrap_or(end))
    } else if first > 0 && first < n {
        midpoint((1..=first).rev().find(real_gap).unwrap_or(first))
    } else {
        // All modes selected: the widest gap, or above the top of the spectrum.
        let widest =
            (1..n).max_by(|&i, &j| (omega_all[i] - omega_all[i - 1]).total_cmp(&(omega_all[j] - omega_all[j - 1])));
        match widest {
            Some(i) if omega_all[i] - omega_all[i - 1] > 2.0 * margin => 0.5 * (omega_all[i] + omega_all[i - 1]),
            _ => omega_all[n - 1] + omega_all[n - 1].abs().max(1.0),
        }
    };
    let raw = count_below(problem, shift)?;
    // In modes: B₀₀'s negative eigenvalues leave `below`; its positive ones are the infinite
    // modes, above every shift, as `above` already counts them.
    let count = InertiaCount {
        below: raw.below.saturating_sub(offset),
        above: raw.above + offset.min(raw.below),
        ..raw
    };
    let expected = omega_all.partition_point(|&w| w < shift);
    Ok(Some(InertiaCheck {
        count,
        computed_below: expected,
        consistent: raw.below == expected + offset && raw.zero == 0,
    }))
}
