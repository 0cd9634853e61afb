//! Small sparse pencils solved densely, with the dense report mapped onto the sparse one.

use crate::dense::{Refinement, Selection, SolveOptions, solve};
use crate::error::ModalError;
use crate::problem::PencilProblem;
use crate::sparse::inertia::SparseInertiaCount;
use crate::sparse::pencil::SparsePencil;
use crate::sparse::solution::{SparseAccuracyReport, SparseModalSolution, SparseSolveTimings};
use crate::spectrum::group_modes;
use faer::Mat;
use std::time::Instant;

/// Small problems: the dense solver, with its report mapped onto the sparse one. The dense solve
/// asks for more than k modes until the k-th mode's group is seen to end; its accuracy fields
/// (backward error, orthogonality, inertia check) cover that superset of the returned modes.
pub(crate) fn dense_fallback(
    pencil: &SparsePencil,
    k: usize,
    norm_a: f64,
    norm_b: f64,
) -> Result<SparseModalSolution, ModalError> {
    let n = pencil.dim();
    let dense = |m: faer::sparse::SparseColMatRef<'_, usize, f64>| {
        let mut d = Mat::<f64>::zeros(n, n);
        let (symbolic, val) = m.parts();
        for j in 0..n {
            for p in symbolic.col_range(j) {
                d[(symbolic.row_idx()[p], j)] = val[p];
            }
        }
        d
    };
    let clock = Instant::now();
    let problem = PencilProblem::new(dense(pencil.a()).as_ref(), dense(pencil.b()).as_ref())?;
    let lowest = |count: usize| {
        solve(
            &problem,
            &SolveOptions {
                selection: Selection::Lowest(count),
                vectors: true,
                refinement: Refinement::Auto,
                ..SolveOptions::default()
            },
        )
    };
    // Ask for more than k until the k-th mode's group is seen to end, so that a count cutting
    // through a repeated eigenvalue is reported (kth_group_multiplicity).
    let mut wanted = (k + 1).min(n);
    let mut sol = match lowest(wanted) {
        Ok(sol) => sol,
        Err(ModalError::TooManyModes { .. }) if wanted > k => {
            wanted = k;
            lowest(k)?
        }
        Err(e) => return Err(e),
    };
    while wanted > k && wanted < n && sol.modes.len() == wanted && sol.modes[wanted - 1].group == sol.modes[k - 1].group
    {
        wanted = (2 * wanted).min(n);
        match lowest(wanted) {
            Ok(more) => sol = more,
            Err(ModalError::TooManyModes { .. }) => break,
            Err(e) => return Err(e),
        }
    }
    let kth_group_multiplicity = sol
        .modes
        .get(k - 1)
        .and_then(|m| sol.groups.get(m.group))
        .map_or(0, |g| g.multiplicity);
    let mut modes = sol.modes;
    modes.truncate(k);
    let groups = group_modes(&mut modes);
    let vectors = match &sol.vectors {
        Some(v) => v.subcols(0, modes.len()).to_owned(),
        None => Mat::zeros(n, 0),
    };
    let check = sol.accuracy.inertia_check;
    Ok(SparseModalSolution {
        report: SparseAccuracyReport {
            shift: f64::NEG_INFINITY,
            shift_attempts: 0,
            factor_nnz: 0,
            norm_a,
            norm_b,
            restarts: 0,
            operator_applications: 0,
            lanczos_runs: 0,
            kth_group_multiplicity,
            max_backward_error: sol.accuracy.max_backward_error.unwrap_or(0.0),
            orthogonality_error: sol.accuracy.orthogonality_error.unwrap_or(0.0),
            inertia: check.map(|c| SparseInertiaCount {
                count: c.count,
                min_pivot: 0.0,
                max_pivot: 0.0,
            }),
            computed_below: check.map_or(0, |c| c.computed_below),
            consistent: check.is_some_and(|c| c.consistent),
            dense_fallback: true,
            timings: SparseSolveTimings {
                refine: clock.elapsed(),
                ..SparseSolveTimings::default()
            },
        },
        modes,
        vectors,
        groups,
    })
}
