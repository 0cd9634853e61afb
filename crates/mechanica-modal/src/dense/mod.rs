//! The dense solver of det(λA + B) = 0 ((8.89), see docs/theory.md), [`solve`]: the Cholesky
//! reduction to a standard symmetric problem C = L⁻¹BL⁻ᵀ ([`crate::linalg`]), its
//! eigen-decomposition, the back-transformation X = L⁻ᵀY, an accuracy report, classification,
//! grouping of repeated frequencies, static condensation of massless coordinates, and
//! refinement of the low modes of stiff problems. Modes are ordered by ω² = −λ ascending
//! ([`crate::spectrum`]).
//!
//! Files: what is asked ([`SolveOptions`], `options`) and returned ([`ModalSolution`],
//! `solution`); the definite pencil's spectrum from L (`definite`); the condensation of a
//! semidefinite A (`condense`, a transform [`solve`] calls before the definite solve); the
//! report inputs formed on idle core time (`idle_inputs`); the common tail of every solve
//! (`finish`: report, Sturm check, classification) with its refinement stage (`refinement`) and
//! the values-only sharpening (`values_only`).

mod condense;
mod cut_cluster;
mod definite;
mod finish;
mod idle_inputs;
mod mass_factor;
mod options;
mod refinement;
mod reversed;
pub(crate) mod scaling;
mod solution;
mod values_only;

pub use options::{AUTO_REFINE_RELATIVE_BOUND, Refinement, Selection, SolveOptions};
pub use solution::{Method, ModalSolution, SolveTimings};

use crate::certify::a_priori::APrioriModel;
use crate::certify::idle_certificate;
use crate::certify::products::Residuals;
use crate::dense::condense::{MassSpectrum, condense};
use crate::dense::definite::{select, solve_definite, solve_definite_owned};
use crate::dense::finish::Finish;
use crate::dense::idle_inputs::{EarlyInputs, IdleResults};
use crate::dense::mass_factor::{MassFactor, mass_factor};
use crate::dense::options::{check_interval, weakly_bounded};
use crate::dense::reversed::{adopt_reversed_bottom, reversed_bottom_of};
use crate::dense::scaling::PencilScale;
use crate::dense::solution::empty_solution;
use crate::error::ModalError;
use crate::linalg::eigen::OnTridiagonal;
use crate::linalg::norms::frobenius_norm;
use crate::linalg::reduce::{cholesky_mass_owned, lower_entry};
use crate::problem::PencilProblem;
use crate::runtime::fork_join::join;
use crate::runtime::idle_task::IdleTask;
use crate::runtime::scratch;
use crate::tuning::Tuning;
use faer::{MatRef, Par};
use std::time::Instant;

/// Solves det(λA + B) = 0 (8.89) for the selected modes, with a full accuracy report.
///
/// A positive definite (proven, `mass_factor`): Cholesky reduction. A positive semidefinite: the
/// massless directions (null space of A, from its eigen-decomposition) are condensed out
/// statically and reported as infinite modes. A indefinite: [`ModalError::IndefiniteMass`], naming the failed pivot.
/// Entries near the ends of the double range (1e±308, subnormal) are first scaled by powers of
/// two (`scaling`), exactly; a result outside the range of doubles is
/// [`ModalError::OutOfRange`]. A `Lowest(k)` selection whose edge cuts a cluster, leaving a mode
/// undecided or weakly bounded or the Sturm check inconsistent, is solved again with the selection widened by
/// [`Tuning::max_refined_cluster`] modes so that the cluster is refined whole; its first k
/// modes are returned (`cut_cluster`).
pub fn solve(problem: &PencilProblem, options: &SolveOptions) -> Result<ModalSolution, ModalError> {
    let solution = solve_once(problem, options)?;
    let Some(wide) = cut_cluster::wider_selection(problem, options, &solution) else {
        return Ok(solution);
    };
    let Selection::Lowest(k) = options.selection else {
        return Ok(solution);
    };
    Ok(match cut_cluster::solve_wider(problem, options, k, wide, solve_once) {
        Some(wider) => cut_cluster::first_modes(wider, k, &solution.timings),
        None => solution,
    })
}

/// [`solve`] with the selection as given.
fn solve_once(problem: &PencilProblem, options: &SolveOptions) -> Result<ModalSolution, ModalError> {
    check_interval(options.selection)?;
    let solution = match PencilScale::of(problem)? {
        None => solve_in_range(problem, options)?,
        Some(scale) => {
            let selection = match options.selection {
                Selection::Interval { lower, upper } => Selection::Interval {
                    lower: scale.to_scaled(lower),
                    upper: scale.to_scaled(upper),
                },
                other => other,
            };
            let scaled_options = SolveOptions { selection, ..*options };
            scale.restore(solve_in_range(&scale.apply(problem)?, &scaled_options)?)?
        }
    };
    check_finite(&solution)?;
    Ok(solution)
}

/// Every finite mode's ω² and bound are numbers: a NaN or an overflow anywhere in the solve is
/// a typed error, never a reported value.
fn check_finite(solution: &ModalSolution) -> Result<(), ModalError> {
    let bad = solution.modes.iter().enumerate().find(|(_, m)| {
        m.kind != crate::spectrum::ModeKind::Infinite && !(m.omega_sq.is_finite() && m.error_bound.is_finite())
    });
    match bad {
        Some((k, mode)) => Err(ModalError::OutOfRange {
            what: format!("mode {k}"),
            detail: format!("ω² {} with error bound {}", mode.omega_sq, mode.error_bound),
        }),
        None => Ok(()),
    }
}

/// [`solve`] of a pencil whose entries need no scaling.
fn solve_in_range(problem: &PencilProblem, options: &SolveOptions) -> Result<ModalSolution, ModalError> {
    let (a, b) = (problem.a(), problem.b());
    let n = problem.dim();
    // Below a few hundred unknowns thread start-up costs more than it saves (mechanisms).
    let par = if n < Tuning::DEFAULT.sequential_below {
        Par::Seq
    } else {
        faer::get_global_parallelism()
    };
    if n == 0 {
        return select(&[], options.selection).map(|_| empty_solution());
    }
    // The refinement and the residual bounds need the vectors even when the caller does not.
    let want_vectors = options.vectors || options.refinement == Refinement::Always;
    // All modes of a large pencil: work off the critical path goes to idle core time.
    let idle_time =
        matches!(options.selection, Selection::All) && n >= Tuning::DEFAULT.idle_time_from && par.degree() > 1;
    let early_inputs = idle_time
        .then(|| EarlyInputs::start(problem, want_vectors && options.residuals == Residuals::Sketched))
        .flatten();
    let clock = Instant::now();
    // The copies of A (factored in place) and B (reduced in place) take kept working storage
    // (`crate::runtime::scratch`) and are written on two threads: the first write of fresh
    // memory faults every page, and faults on two cores proceed in parallel. Only the lower
    // triangles are read (the factorization and the reduction use no other entry); the upper
    // ones are zeroed, as L's must be.
    let (mut a_copy, mut b_copy) = (scratch::empty(n, n), scratch::empty(n, n));
    join(
        || a_copy.resize_with(n, n, |i, j| lower_entry(a, i, j)),
        || b_copy.resize_with(n, n, |i, j| lower_entry(b, i, j)),
        par,
    );
    match mass_factor(a, cholesky_mass_owned(a_copy, par), par)? {
        MassFactor::Definite(l) => {
            let cholesky_time = clock.elapsed();
            // The bottom certificate is factored on idle time once T is known.
            let mut certificate = None;
            let mut start_certificate =
                |diag: &[f64], subdiag: &[f64]| certificate = idle_certificate::start(problem, diag, subdiag);
            let hook: Option<OnTridiagonal<'_>> = if idle_time { Some(&mut start_certificate) } else { None };
            let mut def = solve_definite_owned(l.as_ref(), b_copy, options.selection, want_vectors, par, hook)?;
            let clock = Instant::now();
            let bottom = (options.refinement != Refinement::Off)
                .then(|| reversed_bottom_of(&def.omega_sq, a, b, par))
                .flatten();
            def.timings.factor += clock.elapsed();
            if let Some(bottom) = bottom {
                if !want_vectors {
                    // The reversed modes are refined from their shapes, so the solve needs all of them.
                    let first_try = def.timings;
                    def = solve_definite(l.as_ref(), b, options.selection, true, par)?;
                    def.timings += first_try;
                }
                adopt_reversed_bottom(&mut def, &bottom, l.as_ref(), par);
            }
            let early = early_inputs.and_then(IdleTask::finished);
            let (norm_a, norm_b) = match &early {
                Some(inputs) => inputs.norms,
                None => (frobenius_norm(a), frobenius_norm(b)),
            };
            if def.vectors.is_none() && options.refinement == Refinement::Auto {
                // Values only: the modes whose a-priori bound is too weak get their vectors
                // (crate::values_only), unless they are so many that all vectors cost less.
                let clock = Instant::now();
                let selected = &def.omega_sq[def.first..def.end];
                let model = APrioriModel::new(l.as_ref(), norm_a, norm_b, par);
                def.timings.accuracy = clock.elapsed();
                let flagged = selected.iter().filter(|&&w| weakly_bounded(model.bound(w), w)).count();
                if flagged > Tuning::DEFAULT.flagged_vectors_up_to.max(n / 4) {
                    let first_try = def.timings;
                    def = solve_definite(l.as_ref(), b, options.selection, true, par)?;
                    def.timings += first_try;
                } else {
                    def.a_priori = Some(model);
                }
            }
            def.timings.factor += cholesky_time;
            let finish = Finish {
                problem,
                l: l.as_ref(),
                norm_a,
                norm_b,
                options,
                par,
                condensed_stiffness_negatives: None,
                condensation: None,
            };
            let idle = IdleResults {
                certificate,
                sketch_rows: early.and_then(|inputs| inputs.sketch_rows),
            };
            let solution = finish.run(def, Vec::new(), None, Method::CholeskyReduction, idle);
            scratch::give_back(l);
            solution
        }
        MassFactor::Massless(spectrum) => {
            let (norm_a, norm_b) = (frobenius_norm(a), frobenius_norm(b));
            solve_semidefinite(problem, spectrum, options, (norm_a, norm_b), par)
        }
    }
}

/// Solves a pencil whose mass matrix has massless directions (its `spectrum`): they are
/// condensed out ([`condense`]), the definite pencil (S, A₁) is solved, and its modes are
/// lifted back, with the infinite modes appended.
fn solve_semidefinite(
    problem: &PencilProblem,
    spectrum: MassSpectrum,
    options: &SolveOptions,
    (norm_a, norm_b): (f64, f64),
    par: Par,
) -> Result<ModalSolution, ModalError> {
    let clock = Instant::now();
    let mut condensed = condense(problem, spectrum, norm_b)?;
    // Always with vectors: an a-priori bound would measure the condensed pencil (S, A₁), not
    // the stored one, and forming S = B₁₁ − B₁₀B₀₀⁻¹B₀₁ can cancel far beyond it; only the
    // residuals of the lifted vectors in (A, B) see that error. Values only drops them at the end.
    let want_vectors = true;
    let condensation_time = clock.elapsed();
    let l1 = condensed.condensation.l1.as_ref();
    let mut def = solve_definite(l1, condensed.stiffness.as_ref(), options.selection, want_vectors, par)?;
    def.timings.factor += condensation_time;
    let infinite = std::mem::take(&mut condensed.infinite);
    let condensed = &condensed;
    let lift = |z: MatRef<'_, f64>| condensed.lift(z);
    let condensation = &condensed.condensation;
    let finish = Finish {
        problem,
        l: condensation.l1.as_ref(),
        norm_a,
        norm_b,
        options,
        par,
        condensed_stiffness_negatives: Some(condensed.stiffness_negatives),
        condensation: condensation.refinable.then_some(condensation),
    };
    finish.run(
        def,
        infinite,
        Some(&lift),
        Method::CondensedReduction {
            massless: condensed.massless,
        },
        IdleResults::default(),
    )
}
