//! The computed spectrum as every solver reports it: the modes ([`Mode`], ω² ascending), what
//! each is physically ([`ModeKind`], [`classify`]), groups of repeated frequencies
//! ([`ModeGroup`]), and the clusters of modes whose error bounds overlap, which refinement
//! treats as one block.
//!
//! Sign convention: the syllabus writes det(λA + B) = 0, so an oscillatory mode has λ = −ω² < 0
//! (8.90, see docs/theory.md). Every ordering uses ω² = −λ, ascending: unstable modes (ω² < 0)
//! first, then rigid-body modes, then oscillatory modes, then infinite ones.

use crate::tuning::Tuning;
use std::ops::Range;

/// What a mode is physically (§8g: δ(t) ∝ x e^{±iωt} for λ = −ω² < 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ModeKind {
    /// λ < 0 beyond its error bound: δ(t) = x (a cos ωt + b sin ωt), ω = √(−λ) rad/s.
    Oscillatory {
        /// Angular frequency ω (rad/s).
        omega: f64,
    },
    /// |λ| within the data's resolution: a rigid-body (zero-frequency) mode, δ(t) = x (a + b t).
    Zero,
    /// λ > 0 beyond its error bound: the equilibrium is unstable, δ(t) ∝ x e^{±γt}.
    Unstable {
        /// Growth rate γ = √λ (1/s).
        growth_rate: f64,
    },
    /// A massless direction (A x = 0, A semidefinite): λ = −∞, infinite frequency.
    Infinite,
    /// The interval ω² ± error bound contains zero and is far wider than the data's resolution:
    /// the computation cannot decide whether the mode is oscillatory, rigid-body or unstable
    /// (an unrefined stiff mode). Its interval is [`Mode::omega_sq`] ± [`Mode::error_bound`].
    Undecided,
}

/// One eigenpair's scalar data.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mode {
    /// λ of det(λA + B) = 0 (= −ω²); −∞ for an infinite mode.
    pub lambda: f64,
    /// ω² = −λ (rad²/s²); +∞ for an infinite mode.
    pub omega_sq: f64,
    /// Classification.
    pub kind: ModeKind,
    /// Bound on |ω²_computed − ω²_exact| (first-order condition bound or residual bound, see
    /// [`crate::AccuracyReport::bound_kinds`]); 0 for infinite modes, which are exact by
    /// construction.
    pub error_bound: f64,
    /// Backward error η of the pair (None when values only were computed or the mode is infinite).
    pub backward_error: Option<f64>,
    /// Index of this mode's group of (numerically) equal frequencies in
    /// [`crate::ModalSolution::groups`].
    pub group: usize,
}

impl Mode {
    /// Classifies the mode oscillatory because its exact ω² is proven positive by an argument
    /// beyond its own bound (an inertia count, a definiteness proof of the stiffness):
    /// ω = √ω², or 0 where the computed ω² is not positive. The bound is left as it is.
    pub fn set_proven_oscillatory(&mut self) {
        self.kind = ModeKind::Oscillatory {
            omega: self.omega_sq.max(0.0).sqrt(),
        };
    }
}

/// A set of modes whose ω² cannot be told apart within their error bounds.
#[derive(Debug, Clone, PartialEq)]
pub struct ModeGroup {
    /// Index of the first mode of the group in [`crate::ModalSolution::modes`].
    pub first: usize,
    /// Multiplicity (number of modes in the group).
    pub multiplicity: usize,
    /// Mean ω² of the group.
    pub omega_sq: f64,
}

/// How far a mode's error bound may exceed its data resolution and the mode still be called zero
/// when its interval contains zero: within three orders the computation's uncertainty is that of
/// the data themselves, which no double-precision solve improves on.
pub const UNDECIDED_RATIO: f64 = 1e3;

/// The classification of a mode with value `omega_sq`, error bound `bound` (the interval
/// ω² ± bound contains the exact ω² of the stored pencil) and data `resolution` (how far
/// rounding A and B entrywise can move it, [`crate::certify::resolution::data_resolution`]):
/// - infinite ω²: [`ModeKind::Infinite`];
/// - an interval that excludes zero, with |ω²| above the resolution: oscillatory or unstable
///   by its sign;
/// - otherwise (|ω²| within the resolution, or an interval that contains zero):
///   [`ModeKind::Zero`] when the bound is within [`UNDECIDED_RATIO`] of the resolution (the
///   exact value is then proven within that distance of zero, where the data cannot tell it
///   from zero), else [`ModeKind::Undecided`]: neither the sign nor the size is known. A value
///   near zero with a wide bound is never called zero.
pub fn classify(omega_sq: f64, bound: f64, resolution: f64) -> ModeKind {
    if omega_sq.is_infinite() {
        ModeKind::Infinite
    } else if omega_sq.abs() > bound && omega_sq.abs() > resolution {
        if omega_sq > 0.0 {
            ModeKind::Oscillatory { omega: omega_sq.sqrt() }
        } else {
            ModeKind::Unstable {
                growth_rate: (-omega_sq).sqrt(),
            }
        }
    } else if bound <= UNDECIDED_RATIO * resolution {
        ModeKind::Zero
    } else {
        ModeKind::Undecided
    }
}

/// Groups consecutive modes whose ω² differ by at most the sum of their bounds, or that are
/// both zero (the rigid-body modes form one group), and stores each mode's group index.
pub(crate) fn group_modes(modes: &mut [Mode]) -> Vec<ModeGroup> {
    let mut groups: Vec<ModeGroup> = Vec::new();
    for i in 0..modes.len() {
        let joins = i > 0 && {
            let (p, q) = (&modes[i - 1], &modes[i]);
            (p.omega_sq.is_infinite() && q.omega_sq.is_infinite())
                || (p.kind == ModeKind::Zero && q.kind == ModeKind::Zero)
                || (q.omega_sq - p.omega_sq).abs() <= p.error_bound + q.error_bound
        };
        if joins && let Some(g) = groups.last_mut() {
            g.multiplicity += 1;
        } else {
            groups.push(ModeGroup {
                first: i,
                multiplicity: 1,
                omega_sq: 0.0,
            });
        }
        modes[i].group = groups.len() - 1;
    }
    for g in &mut groups {
        let sum: f64 = modes[g.first..g.first + g.multiplicity]
            .iter()
            .map(|m| m.omega_sq)
            .sum();
        g.omega_sq = sum / g.multiplicity as f64;
    }
    groups
}

/// Whether the bound intervals of two modes overlap (with a factor 2 of margin): refinement
/// cannot tell them apart, so it treats them as one cluster.
fn overlapping(omega_i: f64, bound_i: f64, omega_j: f64, bound_j: f64) -> bool {
    (omega_i - omega_j).abs() <= 2.0 * (bound_i + bound_j)
}

/// The selected modes split into clusters: maximal runs of consecutive modes whose bound
/// intervals overlap, chained (a simple mode is a cluster of one). Refinement treats each
/// cluster as one block ([`crate::refine::refine_cluster_projected`]).
pub(crate) fn clusters(omega: &[f64], bounds: &[f64]) -> Vec<Range<usize>> {
    let mut out: Vec<Range<usize>> = Vec::new();
    for i in 0..omega.len() {
        match out.last_mut() {
            Some(g) if overlapping(omega[i - 1], bounds[i - 1], omega[i], bounds[i]) => g.end = i + 1,
            _ => out.push(i..i + 1),
        }
    }
    out
}

/// Whether the cluster `g` of the selection (entries `first..` of the ascending spectrum
/// `omega_all`) can be refined: at most [`crate::Tuning::max_refined_cluster`] modes, and not cut
/// by the selection (an unselected mode within its bounds would be a missing member of the block,
/// which makes the correction singular).
pub(crate) fn refinable(g: &Range<usize>, omega: &[f64], bounds: &[f64], omega_all: &[f64], first: usize) -> bool {
    let cut_below = g.start == 0 && first > 0 && overlapping(omega[0], bounds[0], omega_all[first - 1], bounds[0]);
    let last = g.end - 1;
    let cut_above = g.end == omega.len()
        && first + omega.len() < omega_all.len()
        && overlapping(omega[last], bounds[last], omega_all[first + omega.len()], bounds[last]);
    g.len() <= Tuning::DEFAULT.max_refined_cluster && !cut_below && !cut_above
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classification_follows_the_interval_and_the_resolution() {
        // Resolved values: by sign.
        assert_eq!(classify(4.0, 1e-3, 1e-12), ModeKind::Oscillatory { omega: 2.0 });
        assert_eq!(classify(-4.0, 1e-3, 1e-12), ModeKind::Unstable { growth_rate: 2.0 });
        // Within the data's resolution and with a bound to match: zero.
        assert_eq!(classify(1e-13, 1e-20, 1e-12), ModeKind::Zero);
        // Within the resolution, but with a bound that reaches far beyond it: undecided (the
        // exact value may be anywhere in the interval).
        assert_eq!(classify(0.0, 8e4, 1e-4), ModeKind::Undecided);
        assert_eq!(classify(1e-13, 1e-8, 1e-12), ModeKind::Undecided);
        // An interval containing zero, within three orders of the resolution: zero.
        assert_eq!(classify(1e-11, 1e-10, 1e-12), ModeKind::Zero);
        // An interval containing zero, far wider than the resolution: undecided.
        assert_eq!(classify(1e-3, 1e2, 1e-12), ModeKind::Undecided);
        assert_eq!(classify(-1e-3, 1e2, 1e-12), ModeKind::Undecided);
        assert_eq!(classify(f64::INFINITY, 0.0, 0.0), ModeKind::Infinite);
    }
}
