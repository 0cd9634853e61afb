//! A `Lowest(k)` selection whose edge cuts a cluster: the modes above the edge that the
//! cluster's bounds cannot tell apart from the selected ones are missing members of its block,
//! so refinement declines the block ([`crate::spectrum::refinable`]) and the Sturm check cannot
//! place a shift at the edge. Where that leaves a selected mode undecided or weakly bounded, or
//! the Sturm check inconsistent, the solve is repeated with the selection widened by
//! [`crate::Tuning::max_refined_cluster`] modes (or to every finite mode), and the first k modes
//! of that solve are returned: their bounds and classes hold whatever else was computed.

use crate::dense::options::{Refinement, Selection, SolveOptions, weakly_bounded};
use crate::dense::solution::{ModalSolution, SolveTimings};
use crate::error::ModalError;
use crate::problem::PencilProblem;
use crate::spectrum::{ModeKind, group_modes};
use crate::tuning::Tuning;

/// The wider selection to solve again with, when `solution` (of `options`) left a selected mode
/// undecided or weakly bounded, or its Sturm check inconsistent, under a `Lowest(k)` that is not
/// every mode.
pub(crate) fn wider_selection(
    problem: &PencilProblem,
    options: &SolveOptions,
    solution: &ModalSolution,
) -> Option<usize> {
    let Selection::Lowest(k) = options.selection else {
        return None;
    };
    let n = problem.dim();
    let doubtful = solution
        .modes
        .iter()
        .any(|m| m.kind == ModeKind::Undecided || weakly_bounded(m.error_bound, m.omega_sq))
        || solution.accuracy.inertia_check.is_some_and(|c| !c.consistent);
    (options.refinement != Refinement::Off && k < n && doubtful)
        .then(|| n.min(k.saturating_add(Tuning::DEFAULT.max_refined_cluster)))
}

/// The first `k` modes of `wide` (a solve of a wider `Lowest` selection), with their report
/// entries and shapes, regrouped; `first_try`'s stage times are added to the wide solve's. The
/// report's orthogonality error, largest backward error and Sturm check are those of the wide
/// solve, which contains the k modes.
pub(crate) fn first_modes(mut wide: ModalSolution, k: usize, first_try: &SolveTimings) -> ModalSolution {
    if wide.modes.len() > k {
        wide.modes.truncate(k);
        wide.vectors = wide.vectors.map(|x| x.subcols(0, k.min(x.ncols())).to_owned());
        wide.accuracy.truncate(k);
        wide.groups = group_modes(&mut wide.modes);
    }
    wide.timings += *first_try;
    wide
}

/// Solves `problem` again for the lowest `wide` modes with `options` otherwise unchanged; where
/// fewer finite modes exist, for all of them. None when that is not more than `k`, or fails.
pub(crate) fn solve_wider(
    problem: &PencilProblem,
    options: &SolveOptions,
    k: usize,
    wide: usize,
    solve_once: impl Fn(&PencilProblem, &SolveOptions) -> Result<ModalSolution, ModalError>,
) -> Option<ModalSolution> {
    let with = |count: usize| SolveOptions {
        selection: Selection::Lowest(count),
        ..*options
    };
    match solve_once(problem, &with(wide)) {
        Ok(solution) => Some(solution),
        Err(ModalError::TooManyModes { available, .. }) if available > k => solve_once(problem, &with(available)).ok(),
        Err(_) => None,
    }
}
