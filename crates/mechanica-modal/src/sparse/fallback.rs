//! Small sparse pencils solved densely, with the dense report mapped onto the sparse one.

use crate::certify::report::AccuracyReport;
use crate::dense::{ModalSolution, Refinement, Selection, SolveOptions, solve};
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
    let clock = Instant::now();
    let problem = PencilProblem::new(dense(pencil.a(), n).as_ref(), dense(pencil.b(), n).as_ref())?;
    let sol = lowest_through_kth_group(&problem, k, n)?;
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
    let timings = SparseSolveTimings {
        refine: clock.elapsed(),
        ..SparseSolveTimings::default()
    };
    Ok(SparseModalSolution {
        report: mapped_report(&sol.accuracy, (norm_a, norm_b), kth_group_multiplicity, timings),
        modes,
        vectors,
        groups,
    })
}

/// The sparse matrix `m` of order n stored densely.
fn dense(m: faer::sparse::SparseColMatRef<'_, usize, f64>, n: usize) -> Mat<f64> {
    let mut d = Mat::<f64>::zeros(n, n);
    let (symbolic, val) = m.parts();
    for j in 0..n {
        for p in symbolic.col_range(j) {
            d[(symbolic.row_idx()[p], j)] = val[p];
        }
    }
    d
}

/// The lowest modes of `problem` (order n) with vectors, more than k until the k-th mode's
/// group is seen to end, so that a count cutting through a repeated eigenvalue is reported.
fn lowest_through_kth_group(problem: &PencilProblem, k: usize, n: usize) -> Result<ModalSolution, ModalError> {
    let lowest = |count: usize| {
        solve(
            problem,
            &SolveOptions {
                selection: Selection::Lowest(count),
                vectors: true,
                refinement: Refinement::Auto,
                ..SolveOptions::default()
            },
        )
    };
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
    Ok(sol)
}

/// The dense solve's report `accuracy` mapped onto the sparse one (no shift, factor or
/// Lanczos runs; the inertia check's count without pivots).
fn mapped_report(
    accuracy: &AccuracyReport,
    (norm_a, norm_b): (f64, f64),
    kth_group_multiplicity: usize,
    timings: SparseSolveTimings,
) -> SparseAccuracyReport {
    let check = accuracy.inertia_check;
    SparseAccuracyReport {
        shift: f64::NEG_INFINITY,
        shift_attempts: 0,
        factor_nnz: 0,
        norm_a,
        norm_b,
        restarts: 0,
        operator_applications: 0,
        lanczos_runs: 0,
        kth_group_multiplicity,
        max_backward_error: accuracy.max_backward_error.unwrap_or(0.0),
        orthogonality_error: accuracy.orthogonality_error.unwrap_or(0.0),
        inertia: check.map(|c| SparseInertiaCount {
            count: c.count,
            min_pivot: 0.0,
            max_pivot: 0.0,
        }),
        computed_below: check.map_or(0, |c| c.computed_below),
        consistent: check.is_some_and(|c| c.consistent),
        dense_fallback: true,
        timings,
    }
}
