//! The dense solver of det(λA + B) = 0 (8.89): Cholesky reduction to a standard symmetric
//! problem, its eigen-decomposition ([`crate::linalg::eigen`]), back-transformation, an accuracy report, mode
//! classification, grouping of repeated frequencies, static condensation of massless
//! coordinates, and refinement of the low modes of stiff problems.
//!
//! Sign convention: the syllabus writes det(λA + B) = 0, so an oscillatory mode has λ = −ω² < 0
//! (8.90). Internally and in every ordering the solver uses ω² = −λ, ascending: unstable modes
//! (ω² < 0) first, then rigid-body modes, then oscillatory modes, then infinite ones.
use crate::certify::a_priori::APrioriModel;
use crate::certify::idle_certificate::BottomCertificate;
use crate::certify::products::{PairProducts, Residuals};
use crate::certify::report::AccuracyReport;
use crate::certify::residual_bounds::{ModeBasis, RefinedResidual, residual_bounds, split_refined_clusters};
use crate::certify::resolution::zero_resolution;
use crate::certify::sketch::SketchRows;
use crate::certify::sturm::inertia_check;
use crate::condense::Condensation;
use crate::dd::Operand;
use crate::linalg::eigen::{
    OnTridiagonal, TridiagonalForm, symmetric_eigen_returning_input, symmetric_values_keeping_form,
};
use crate::linalg::norms::frobenius_norm;
use crate::linalg::reduce::{Cholesky, back_transform_into, cholesky_owned, lower_entry, reduce_owned};
use crate::refine::{
    Metric, ReducedCorrection, ReducedSpectrum, RefinedCluster, RefinedPair, SparseShifts, polish_simple_mode,
    refine_cluster, refine_simple_modes,
};
use crate::runtime::fork_join::{join, map_items};
use crate::runtime::idle_task::IdleTask;
use crate::spectrum::{Mode, ModeGroup, ModeKind, classify, clusters, group_modes, refinable};
use crate::{ModalError, PencilProblem};
use faer::{Mat, MatRef, Par};
use std::ops::Range;
use std::time::{Duration, Instant};

/// Which eigenpairs to return.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Selection {
    /// Every finite mode, plus the infinite (massless) ones when A is singular.
    All,
    /// The k finite modes of lowest ω² (unstable modes count as lowest).
    Lowest(usize),
    /// The finite modes with lower ≤ ω² ≤ upper (rad²/s²).
    Interval {
        /// Lower end of ω².
        lower: f64,
        /// Upper end of ω².
        upper: f64,
    },
}

/// Whether to refine low modes with extended-precision residuals (module `refine`). Clusters of
/// nearly equal ω² (up to [`MAX_REFINED_CLUSTER`] modes) are refined as blocks; a semidefinite A
/// is refined when it is diagonal with exactly zero massless entries (the condensation is then
/// exact), and otherwise keeps its first-order bounds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refinement {
    /// Refine every selected, simple, finite mode whose first-order error bound from the
    /// reduction exceeds [`AUTO_REFINE_RELATIVE_BOUND`]·|ω²| (stiff and graded problems).
    Auto,
    /// Never refine (the plain reduction; its bounds can then be large on stiff problems).
    Off,
    /// Refine every selected simple finite mode.
    Always,
}

/// Dense problems smaller than this are solved on one thread.
pub const SEQUENTIAL_BELOW: usize = 192;

/// From this order an all-modes solve puts work off its critical path on idle core time (module
/// `idle_task`: the norms, the sketch's rows, the bottom certificate): from the first order
/// solved on two threads. Measured (rotated chain, sketched report, medians of 15 solves in two
/// alternations, against the earlier threshold of 640): n = 250 18.4 / 17.6 → 14.8 / 13.6 ms,
/// n = 350 29.8 / 31.7 → 28.7 / 26.3 ms, n = 500 (threshold 300) 57.5 / 55.8 / 54.0 → 51.3 /
/// 50.2 / 50.0 ms; below the factorization's own threshold one core is idle while the other
/// factors A.
const IDLE_TIME_FROM: usize = SEQUENTIAL_BELOW;

/// Auto refinement starts when the reduction guarantees fewer than 8 digits of a mode's ω².
pub const AUTO_REFINE_RELATIVE_BOUND: f64 = 1e-8;

/// Whether a mode's bound guarantees fewer digits than [`AUTO_REFINE_RELATIVE_BOUND`] asks for.
pub(crate) fn weakly_bounded(bound: f64, omega_sq: f64) -> bool {
    bound > AUTO_REFINE_RELATIVE_BOUND * omega_sq.abs()
}

/// A values-only solve with [`Refinement::Auto`] forms the vectors of its poorly bounded modes
/// one by one (inverse iteration, module `values_only`) when there are at most this many or
/// n/4 of them; beyond that it computes all vectors, which then costs less (the clustered
/// inverse iteration orthogonalises in O(k²n), and all vectors cost about n³ more than values).
pub const FLAGGED_VECTORS_UP_TO: usize = 32;

/// Options of [`solve`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveOptions {
    /// Which modes.
    pub selection: Selection,
    /// Whether to return mode shapes (eigenvectors). Values only is cheaper.
    pub vectors: bool,
    /// Low-mode refinement policy.
    pub refinement: Refinement,
    /// How the accuracy report measures residuals and orthogonality (exact by default).
    pub residuals: Residuals,
}

impl Default for SolveOptions {
    fn default() -> Self {
        Self {
            selection: Selection::All,
            vectors: true,
            refinement: Refinement::Auto,
            residuals: Residuals::Exact,
        }
    }
}

/// How the modes were computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Cholesky A = LLᵀ, C = L⁻¹BL⁻ᵀ, C = Y Λ Yᵀ ([`crate::linalg::eigen`]), X = L⁻ᵀY.
    CholeskyReduction,
    /// Massless coordinates condensed out first (A semidefinite), then the reduction.
    CondensedReduction {
        /// Number of massless directions (infinite modes).
        massless: usize,
    },
}

/// The result of [`solve`]: modes, shapes, groups and the accuracy report.
#[derive(Debug, Clone)]
pub struct ModalSolution {
    /// Selected modes, ascending in ω².
    pub modes: Vec<Mode>,
    /// n × modes.len() mode shapes (columns, A-orthonormal for finite modes; Euclidean unit
    /// vectors of the null space of A for infinite modes), or None for values only.
    pub vectors: Option<Mat<f64>>,
    /// Groups of equal frequencies; each group's columns in `vectors` form an A-orthonormal
    /// basis of its eigenspace.
    pub groups: Vec<ModeGroup>,
    /// How the accuracy of every number above is known.
    pub accuracy: AccuracyReport,
    /// Algorithm used.
    pub method: Method,
    /// Wall time of each stage.
    pub timings: DenseTimings,
}

/// Wall time of each stage of a dense [`solve`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DenseTimings {
    /// Cholesky of A (or the condensation of a semidefinite A) and the reduction C = L⁻¹BL⁻ᵀ.
    pub factor: Duration,
    /// Eigen-decomposition of C and back-transformation X = L⁻ᵀY.
    pub eigen: Duration,
    /// Accuracy report: residual products, per-mode bounds, orthogonality.
    pub accuracy: Duration,
    /// Refinement of poorly bounded modes (with their residual bounds).
    pub refine: Duration,
    /// Sturm (inertia) check.
    pub inertia: Duration,
}

/// Finite spectrum of a definite pencil: all ω² ascending, the selected index range, and
/// the selected eigenvectors (A-orthonormal) when asked for.
pub(crate) struct Definite {
    pub omega_sq: Vec<f64>,
    pub first: usize,
    pub end: usize,
    pub vectors: Option<Mat<f64>>,
    /// All n orthonormal eigenvectors Y of the reduced matrix C (when vectors were computed),
    /// for refinement without a new factorization ([`crate::refine::ReducedSpectrum`]).
    pub reduced: Option<Mat<f64>>,
    /// Values only: C's tridiagonal form, from which [`crate::values_only`] forms the vectors
    /// of the few modes whose a-priori bound is too weak.
    pub form: Option<TridiagonalForm>,
    /// Values only: the a-priori error model, when already computed.
    pub a_priori: Option<APrioriModel>,
    /// The reduction's time (as `factor`) and the eigensolver's (as `eigen`).
    pub timings: DenseTimings,
}

fn select(omega_sq: &[f64], selection: Selection) -> Result<(usize, usize), ModalError> {
    let n = omega_sq.len();
    match selection {
        Selection::All => Ok((0, n)),
        Selection::Lowest(k) if k <= n => Ok((0, k)),
        Selection::Lowest(k) => Err(ModalError::TooManyModes {
            requested: k,
            available: n,
        }),
        Selection::Interval { lower, upper } => {
            let first = omega_sq.partition_point(|&w| w < lower);
            let end = omega_sq.partition_point(|&w| w <= upper);
            Ok((first, end.max(first)))
        }
    }
}

/// Solves the definite pencil with Cholesky factor `l` of A.
pub(crate) fn solve_definite(
    l: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    selection: Selection,
    vectors: bool,
    par: Par,
) -> Result<Definite, ModalError> {
    solve_definite_owned(l, b.to_owned(), selection, vectors, par, None)
}

/// [`solve_definite`] on a copy of B that the caller no longer needs (reduced in place).
fn solve_definite_owned(
    l: MatRef<'_, f64>,
    b: Mat<f64>,
    selection: Selection,
    vectors: bool,
    par: Par,
    on_tridiagonal: Option<OnTridiagonal<'_>>,
) -> Result<Definite, ModalError> {
    let n = b.nrows();
    if n == 0 {
        // faer's eigensolvers underflow a size computation at n = 0; never call them there.
        let (first, end) = select(&[], selection)?;
        return Ok(Definite {
            omega_sq: Vec::new(),
            first,
            end,
            vectors: vectors.then(|| Mat::zeros(0, 0)),
            reduced: None,
            form: None,
            a_priori: None,
            timings: DenseTimings::default(),
        });
    }
    let clock = Instant::now();
    let c = reduce_owned(l, b, par);
    let mut timings = DenseTimings {
        factor: clock.elapsed(),
        ..DenseTimings::default()
    };
    let clock = Instant::now();
    if !vectors {
        let (omega_sq, form) = symmetric_values_keeping_form(c, par, on_tridiagonal)?;
        let (first, end) = select(&omega_sq, selection)?;
        timings.eigen = clock.elapsed();
        return Ok(Definite {
            omega_sq,
            first,
            end,
            vectors: None,
            reduced: None,
            form: Some(form),
            a_priori: None,
            timings,
        });
    }
    let (eigen, mut spent) = symmetric_eigen_returning_input(c, true, par, on_tridiagonal)?;
    let omega_sq = eigen.values;
    let (first, end) = select(&omega_sq, selection)?;
    let (x, y) = match eigen.vectors {
        Some(y) => {
            // X = L⁻ᵀ Y(:, first..end), written into the reduced matrix's spent storage (copy and
            // solve per thread: stage median 19.1 against 20.4 ms at n = 1000, 36 solves
            // alternating with a copy on one thread before the solve).
            spent.truncate(n, end - first);
            back_transform_into(l, y.subcols(first, end - first), spent.as_mut(), par);
            (spent, y)
        }
        None => return Err(ModalError::NoConvergence { n }),
    };
    timings.eigen = clock.elapsed();
    Ok(Definite {
        omega_sq,
        first,
        end,
        vectors: Some(x),
        reduced: Some(y),
        form: None,
        a_priori: None,
        timings,
    })
}

fn check_interval(selection: Selection) -> Result<(), ModalError> {
    if let Selection::Interval { lower, upper } = selection
        && !(lower.is_finite() && upper.is_finite() && lower <= upper)
    {
        return Err(ModalError::BadInterval { lower, upper });
    }
    Ok(())
}

/// Solves det(λA + B) = 0 (8.89) for the selected modes, with a full accuracy report.
///
/// A positive definite: Cholesky reduction. A positive semidefinite: the massless directions
/// (null space of A, from its eigen-decomposition) are condensed out statically and reported as
/// infinite modes. A indefinite: [`ModalError::IndefiniteMass`], naming the failed pivot.
pub fn solve(problem: &PencilProblem, options: &SolveOptions) -> Result<ModalSolution, ModalError> {
    check_interval(options.selection)?;
    let (a, b) = (problem.a(), problem.b());
    let n = problem.dim();
    // Below a few hundred unknowns thread start-up costs more than it saves (mechanisms).
    let par = if n < SEQUENTIAL_BELOW {
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
    let idle_time = matches!(options.selection, Selection::All) && n >= IDLE_TIME_FROM && par.degree() > 1;
    let early_inputs = idle_time
        .then(|| EarlyInputs::start(problem, want_vectors && options.residuals == Residuals::Sketched))
        .flatten();
    let clock = Instant::now();
    // The copies of A (factored in place) and B (reduced in place) take kept working storage
    // (module `scratch`) and are written on two threads: the first write of fresh memory faults
    // every page, and faults on two cores proceed in parallel (6.5 ms per 8 MB on one core of
    // the Zen 3 host). Only the lower triangles are read (the factorization and the reduction
    // use no other entry); the upper ones are zeroed, as L's must be.
    let (mut a_copy, mut b_copy) = (
        crate::runtime::scratch::empty(n, n),
        crate::runtime::scratch::empty(n, n),
    );
    join(
        || a_copy.resize_with(n, n, |i, j| lower_entry(a, i, j)),
        || b_copy.resize_with(n, n, |i, j| lower_entry(b, i, j)),
        par,
    );
    match cholesky_owned(a_copy, par) {
        Cholesky::Factor(l) => {
            let cholesky_time = clock.elapsed();
            // The bottom certificate is factored on idle time once T is known.
            let mut certificate = None;
            let mut start_certificate = |diag: &[f64], subdiag: &[f64]| {
                certificate = crate::certify::idle_certificate::start(problem, diag, subdiag)
            };
            let hook: Option<OnTridiagonal<'_>> = if idle_time { Some(&mut start_certificate) } else { None };
            let mut def = solve_definite_owned(l.as_ref(), b_copy, options.selection, want_vectors, par, hook)?;
            let early = early_inputs.and_then(IdleTask::finished);
            let (norm_a, norm_b) = match &early {
                Some(inputs) => inputs.norms,
                None => (frobenius_norm(a), frobenius_norm(b)),
            };
            if !want_vectors && options.refinement == Refinement::Auto {
                // Values only: the modes whose a-priori bound is too weak get their vectors
                // (crate::values_only), unless they are so many that all vectors cost less.
                let clock = Instant::now();
                let selected = &def.omega_sq[def.first..def.end];
                let model = APrioriModel::new(l.as_ref(), norm_a, norm_b, par);
                def.timings.accuracy = clock.elapsed();
                let flagged = selected.iter().filter(|&&w| weakly_bounded(model.bound(w), w)).count();
                if flagged > FLAGGED_VECTORS_UP_TO.max(n / 4) {
                    let first_try = def.timings;
                    def = solve_definite(l.as_ref(), b, options.selection, true, par)?;
                    def.timings.factor += first_try.factor;
                    def.timings.eigen += first_try.eigen;
                    def.timings.accuracy += first_try.accuracy;
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
            crate::runtime::scratch::give_back(l);
            solution
        }
        Cholesky::Failed { pivot } => {
            let (norm_a, norm_b) = (frobenius_norm(a), frobenius_norm(b));
            crate::condense::solve_semidefinite(problem, pivot, options, norm_a, norm_b, par)
        }
    }
}

/// What an all-modes solve computes on idle core time from its start (module `idle_task`): the
/// Frobenius norms of A and B and, for a sketched report, the sketch's rows S·A and S·B.
struct EarlyInputs {
    norms: (f64, f64),
    sketch_rows: Option<SketchRows>,
}

impl EarlyInputs {
    /// Starts the task (None when no thread could be started).
    fn start(problem: &PencilProblem, sketched: bool) -> Option<IdleTask<Self>> {
        let problem = problem.clone();
        IdleTask::spawn("mechanica-idle-inputs", move |stop| {
            let (a, b) = (problem.a(), problem.b());
            let norms = (frobenius_norm(a), frobenius_norm(b));
            if stop.load(std::sync::atomic::Ordering::Acquire) {
                return None;
            }
            let sketch_rows = sketched.then(|| SketchRows::new(a, b));
            Some(Self { norms, sketch_rows })
        })
    }
}

/// What idle core time delivered to the report (each None when not started or not finished).
#[derive(Default)]
pub(crate) struct IdleResults {
    /// The bottom certificate's shift and its factorization begun on idle time, module
    /// `idle_certificate`.
    pub(crate) certificate: Option<BottomCertificate>,
    /// The sketch's S·A and S·B.
    pub(crate) sketch_rows: Option<SketchRows>,
}

fn empty_solution() -> ModalSolution {
    ModalSolution {
        modes: Vec::new(),
        vectors: None,
        groups: Vec::new(),
        accuracy: AccuracyReport::empty(),
        method: Method::CholeskyReduction,
        timings: DenseTimings::default(),
    }
}

/// Maps mode shapes of a condensed pencil back to the original coordinates.
pub(crate) type Lift<'a> = &'a dyn Fn(MatRef<'_, f64>) -> Mat<f64>;

/// The common tail of every solve: refinement, accuracy report, classification, groups.
pub(crate) struct Finish<'a> {
    pub problem: &'a PencilProblem,
    /// Cholesky factor of the (condensed) mass matrix used for A⁻¹-norms.
    pub l: MatRef<'a, f64>,
    pub norm_a: f64,
    pub norm_b: f64,
    pub options: &'a SolveOptions,
    pub par: Par,
    /// For a condensed pencil: the number of negative eigenvalues of the stiffness block B₀₀ of
    /// the massless directions, by which the inertia of B − sA exceeds the count of modes
    /// below s (Haynsworth: In(B − sA) = In(B₀₀) + In(S − sA₁), S the condensed stiffness).
    pub condensed_stiffness_negatives: Option<usize>,
    /// For a condensed pencil whose condensation is exact (diagonal A): what refinement needs
    /// to correct its modes and bound them in the condensed pencil.
    pub condensation: Option<&'a Condensation>,
}

impl Finish<'_> {
    /// The refined modes' residual bounds ([`crate::certify::residual_bounds::residual_bounds`]), in the definite
    /// pencil the residuals belong to: (B, A) itself, or the condensed (S, A₁) with the modes'
    /// rows at the coordinates with mass.
    fn residual_bounds(
        &self,
        report: &mut AccuracyReport,
        omega: &[f64],
        omega_all: &[f64],
        first: usize,
        residuals: &[RefinedResidual],
        x: MatRef<'_, f64>,
    ) {
        let all: Vec<usize> = (0..omega.len()).collect();
        let condensed = self.condensation.map(|c| (c.condensed_mass(), c.massed_rows(x)));
        let (basis_a, basis_x) = match &condensed {
            Some((a1, z)) => (a1.as_ref(), z.as_ref()),
            None => (self.problem.a(), x),
        };
        let basis = ModeBasis {
            a: basis_a,
            l: self.l,
            x: basis_x,
            modes: &all,
            unselected: None,
        };
        residual_bounds(report, omega, omega_all, first, residuals, &basis, self.par);
    }

    /// `def` holds the finite spectrum of the (possibly condensed) pencil; `lift` maps its
    /// vectors to the original coordinates (None: identity); `infinite` are unit null vectors
    /// of A appended as infinite modes.
    pub(crate) fn run(
        &self,
        def: Definite,
        infinite: Vec<Vec<f64>>,
        lift: Option<Lift<'_>>,
        method: Method,
        idle: IdleResults,
    ) -> Result<ModalSolution, ModalError> {
        let (a, b) = (self.problem.a(), self.problem.b());
        let n = self.problem.dim();
        let omega_all = def.omega_sq;
        let mut form = def.form;
        let mut omega: Vec<f64> = omega_all[def.first..def.end].to_vec();
        let mut x = match (def.vectors, lift) {
            (Some(v), Some(f)) => Some(f(v.as_ref())),
            (v, _) => v,
        };
        let m = omega.len();
        let mut timings = def.timings;
        let clock = Instant::now();
        let mut products = x
            .as_ref()
            .map(|x| PairProducts::new(a, b, x.as_ref(), self.options.residuals, idle.sketch_rows, self.par));
        // Values only: the a-priori error model (computed once, here or by `solve`).
        let mut a_priori = None;
        let mut report = match (&x, &products) {
            (Some(x), Some(p)) => AccuracyReport::from_products(p, x.as_ref(), &omega, self.norm_a, self.norm_b),
            _ => {
                let model = def
                    .a_priori
                    .unwrap_or_else(|| APrioriModel::new(self.l, self.norm_a, self.norm_b, self.par));
                a_priori = Some(model);
                AccuracyReport::a_priori(self.norm_a, self.norm_b, model.bounds(&omega))
            }
        };
        timings.accuracy += clock.elapsed();
        let clock = Instant::now();
        // Values only: the data resolution of the modes whose vectors were formed.
        let mut measured_resolution: Vec<(usize, f64)> = Vec::new();
        if let (Some(form), Some(model)) = (form.as_mut(), a_priori)
            && lift.is_none()
            && self.options.refinement == Refinement::Auto
        {
            let pencil = crate::values_only::Pencil {
                a,
                b,
                l: self.l,
                residuals: self.options.residuals,
                par: self.par,
            };
            measured_resolution =
                crate::values_only::sharpen(&pencil, model, form, &mut report, &mut omega, &omega_all, def.first);
        }
        // Refinement of poorly bounded modes (needs vectors in the original coordinates). A
        // condensed pencil is refined when its condensation is exact (diagonal A), in the metric
        // of the condensed pencil.
        let metric = match (lift.is_none(), self.condensation) {
            (true, _) => Some(Metric::Cholesky(crate::linalg::reduce::LowerFactor::new(self.l))),
            (false, Some(c)) => Some(Metric::Condensed(c)),
            (false, None) => None,
        };
        if let (Some(xm), Some(products), Some(metric)) = (x.as_mut(), products.as_mut(), metric)
            && self.options.refinement != Refinement::Off
        {
            let jobs: Vec<Range<usize>> = clusters(&omega, &report.error_bounds)
                .into_iter()
                .filter(|g| {
                    let wanted = self.options.refinement == Refinement::Always
                        || g.clone().any(|i| weakly_bounded(report.error_bounds[i], omega[i]));
                    wanted && refinable(g, &omega, &report.error_bounds, &omega_all, def.first)
                })
                .collect();
            let (mass, stiffness) = (Operand::new(a), Operand::new(b));
            let shifts = if jobs.is_empty() {
                None
            } else {
                SparseShifts::new(&mass, &stiffness)
            };
            // Clusters are independent: each is refined from its own columns of X, sequentially
            // inside, and the clusters are shared among the threads.
            let start = xm.as_ref();
            let refine_one = |g: &Range<usize>| {
                let x0 = start.subcols(g.start, g.len()).to_owned();
                let mut spectrum = def.reduced.as_ref().map(|y| ReducedSpectrum {
                    y: y.as_ref(),
                    omega_sq: &omega_all,
                    modes: def.first + g.start..def.first + g.end,
                });
                let correction = spectrum.as_mut().map(|s| s as &mut dyn ReducedCorrection);
                refine_cluster(
                    &mass,
                    &stiffness,
                    shifts.as_ref(),
                    metric,
                    correction,
                    x0.as_ref(),
                    omega[g.start],
                )
            };
            // Simple modes of a definite pencil are refined as one batch whose corrections are
            // block products ([`refine_simple_modes`]); a mode whose batch step fails, and
            // every cluster, takes its own path. A sparse pencil's simple modes take theirs at
            // once: a sparse bordered factorization per mode costs less than the batch's
            // products through Y (`refine::refine_pair_sparse`).
            let mut refined: Vec<Option<RefinedCluster>> = vec![None; jobs.len()];
            let mut pending: Vec<usize> = (0..jobs.len()).collect();
            if let (Metric::Cholesky(l), Some(y), None) = (metric, def.reduced.as_ref(), &shifts) {
                let singles: Vec<usize> = pending.iter().copied().filter(|&j| jobs[j].len() == 1).collect();
                if !singles.is_empty() {
                    let x0 = Mat::from_fn(n, singles.len(), |i, c| start[(i, jobs[singles[c]].start)]);
                    let modes: Vec<usize> = singles.iter().map(|&j| def.first + jobs[j].start).collect();
                    let pairs = refine_simple_modes(
                        &mass,
                        &stiffness,
                        l,
                        (y.as_ref(), &omega_all),
                        &modes,
                        x0.as_ref(),
                        self.par,
                    );
                    for (&j, pair) in singles.iter().zip(pairs) {
                        refined[j] = pair.map(RefinedCluster::single);
                    }
                    pending.retain(|&j| refined[j].is_none());
                }
            }
            let rest: Vec<Option<RefinedCluster>> = map_items(&pending, self.par, |&j| refine_one(&jobs[j]));
            for (&j, cluster) in pending.iter().zip(rest) {
                refined[j] = cluster;
            }
            let mut residuals: Vec<RefinedResidual> = Vec::new();
            let mut changed: Vec<usize> = Vec::new();
            for (g, cluster) in jobs.iter().zip(refined) {
                let Some(cluster) = cluster else { continue };
                for (i, p) in g.clone().zip(cluster.pairs) {
                    xm.col_as_slice_mut(i).copy_from_slice(&p.x);
                    omega[i] = p.omega_sq;
                    report.residual_norms_a_inv[i] = Some(p.residual_a_inv);
                    report.refinement_steps[i] = p.steps;
                    changed.push(i);
                    residuals.push(RefinedResidual {
                        mode: i,
                        cluster: g.clone(),
                        orthogonality: cluster.orthogonality,
                        residual: p.residual,
                    });
                }
            }
            products.update_columns(a, b, xm.as_ref(), &changed, self.par);
            for &i in &changed {
                report.set_pair_error(products, xm.as_ref(), i, omega[i]);
            }
            split_refined_clusters(&mut residuals, &omega, &report.residual_norms_a_inv);
            let first_order = (report.error_bounds.clone(), report.bound_kinds.clone());
            self.residual_bounds(&mut report, &omega, &omega_all, def.first, &residuals, xm.as_ref());
            // Simple modes refined in double (the batch, the projected step) whose bound is still
            // weak: their residual is limited by rounding the vector; more projected steps with
            // a double-double iterate, kept where they lower the residual, and the bounds again.
            if let (Metric::Cholesky(_), Some(y), None) = (metric, def.reduced.as_ref(), &shifts) {
                let weak: Vec<usize> = (0..residuals.len())
                    .filter(|&k| {
                        let i = residuals[k].mode;
                        residuals[k].cluster.len() == 1 && weakly_bounded(report.error_bounds[i], omega[i])
                    })
                    .collect();
                let polish = |&k: &usize| {
                    let i = residuals[k].mode;
                    let mut spectrum = ReducedSpectrum {
                        y: y.as_ref(),
                        omega_sq: &omega_all,
                        modes: def.first + i..def.first + i + 1,
                    };
                    let steps = report.refinement_steps[i];
                    polish_simple_mode(&mass, &stiffness, metric, &mut spectrum, xm.col_as_slice(i), steps)
                };
                let polished: Vec<Option<RefinedPair>> = map_items(&weak, self.par, polish);
                let mut improved: Vec<usize> = Vec::new();
                for (&k, pair) in weak.iter().zip(polished) {
                    let i = residuals[k].mode;
                    let Some(p) = pair.filter(|p| Some(p.residual_a_inv) < report.residual_norms_a_inv[i]) else {
                        continue;
                    };
                    xm.col_as_slice_mut(i).copy_from_slice(&p.x);
                    omega[i] = p.omega_sq;
                    report.residual_norms_a_inv[i] = Some(p.residual_a_inv);
                    report.refinement_steps[i] = p.steps;
                    residuals[k].residual = p.residual;
                    improved.push(i);
                }
                if !improved.is_empty() {
                    products.update_columns(a, b, xm.as_ref(), &improved, self.par);
                    (report.error_bounds, report.bound_kinds) = first_order;
                    for &i in &improved {
                        report.set_pair_error(products, xm.as_ref(), i, omega[i]);
                    }
                    self.residual_bounds(&mut report, &omega, &omega_all, def.first, &residuals, xm.as_ref());
                }
            }
        }
        timings.refine = clock.elapsed();
        let clock = Instant::now();
        if let (Some(x), Some(p)) = (&x, products.as_mut()) {
            report.finish(p, a, x.as_ref(), &omega, self.par);
        }
        timings.accuracy += clock.elapsed();
        let clock = Instant::now();
        // The reduced eigenvectors are no longer needed: their storage takes the certificate's
        // matrix (a fresh n×n allocation costs its page faults).
        if let Some(storage) = def.reduced.or_else(|| form.map(TridiagonalForm::into_storage)) {
            crate::runtime::scratch::give_back(storage);
        }
        report.inertia_check = inertia_check(
            self.problem,
            &omega_all,
            (def.first, def.end),
            &report.error_bounds,
            self.condensed_stiffness_negatives,
            idle.certificate,
            self.par,
        )?;
        timings.inertia = clock.elapsed();
        // What the data resolve: the zero classification allows for the rounding of A and B.
        let mut resolution: Vec<f64> = (0..m)
            .map(|i| match (&x, &a_priori) {
                (Some(x), _) => zero_resolution(a, b, x.col_as_slice(i), omega[i], (self.norm_a, self.norm_b)),
                (None, Some(model)) => model.data_resolution(omega[i]),
                (None, None) => 0.0,
            })
            .collect();
        for (i, value) in measured_resolution {
            resolution[i] = value;
        }
        if !self.options.vectors {
            x = None;
            report.backward_errors.iter_mut().for_each(|e| *e = None);
            report.orthogonality_error = None;
        }
        let mut modes: Vec<Mode> = (0..m)
            .map(|i| {
                let bound = report.error_bounds[i];
                Mode {
                    lambda: -omega[i],
                    omega_sq: omega[i],
                    kind: classify(omega[i], bound.max(resolution[i])),
                    error_bound: bound,
                    backward_error: report.backward_errors.get(i).copied().flatten(),
                    group: 0,
                }
            })
            .collect();
        let include_infinite = matches!(self.options.selection, Selection::All) && !infinite.is_empty();
        if include_infinite {
            for _ in &infinite {
                modes.push(Mode {
                    lambda: f64::NEG_INFINITY,
                    omega_sq: f64::INFINITY,
                    kind: ModeKind::Infinite,
                    error_bound: 0.0,
                    backward_error: None,
                    group: 0,
                });
            }
            if let Some(xf) = x.take() {
                let extra = infinite.len();
                x = Some(Mat::from_fn(n, m + extra, |r, c| {
                    if c < m { xf[(r, c)] } else { infinite[c - m][r] }
                }));
            }
        }
        let groups = group_modes(&mut modes);
        Ok(ModalSolution {
            modes,
            vectors: x,
            groups,
            accuracy: report,
            method,
            timings,
        })
    }
}
