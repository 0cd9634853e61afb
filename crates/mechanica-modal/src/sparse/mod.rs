//! The k lowest modes of a large sparse pencil (A, B) by shift-invert Lanczos ([`solve_sparse`]),
//! certified by the inertia of B − τA ([`count_below_sparse`]).
//!
//! Files: the options ([`SparseSolveOptions`]) and the result ([`SparseModalSolution`],
//! [`SparseAccuracyReport`]); the pencil ([`SparsePencil`], `pencil`) and Matrix Market input
//! ([`matrix_market`]); the factored operator (`operator`, with the supernodal block solve of
//! `supernodal`); the Lanczos iteration (`lanczos`); Rayleigh–Ritz (`rayleigh_ritz`); the bounds
//! (`bounds`); the Sturm check (`sturm`, with the inertia count of `inertia`); small pencils
//! solved densely (`fallback`); the driver [`solve_sparse`] here.
//!
//! - **Operator.** With a shift σ below the lowest mode, K = B − σA is positive definite and
//!   factored once by faer's sparse Cholesky (AMD ordering; solved by this crate's supernodal
//!   block solve, module `supernodal`, which is faster than faer's on 2-D grids).
//!   T = K⁻¹A is self-adjoint in the A-inner product and has the eigenvalues θ = 1/(ω² − σ) > 0:
//!   the lowest ω² are the largest θ, well separated. A successful Cholesky factorization of K
//!   certifies that no mode lies below σ (Sylvester). The automatic σ is −√u·‖B‖_F/‖A‖_F,
//!   lowered by factors of 1000 while K is not positive definite (unstable modes).
//! - **Iteration.** Block Lanczos in the A-inner product with full reorthogonalisation (block
//!   Gram–Schmidt, repeated when a column loses more than 1 − 1/√2 of its A-norm) and thick
//!   restarts (Wu & Simon, SIMAX 22, 2000; in Krylov–Schur form, Stewart, SIMAX 23, 2001): the
//!   basis holds about m = max(2·nev + 4b, 24) vectors (a multiple of the block size b), so
//!   memory is O(nnz(L) + n·m).
//! - **Refinement.** The converged Ritz vectors are Rayleigh–Ritz-projected onto the original
//!   pencil (the dense solver on XᵀBX, XᵀAX), which makes them A-orthonormal and gives each ω²
//!   as a Rayleigh quotient.
//! - **Certification.** The inertia of B − τA ([`crate::count_below_sparse`]) at a shift τ in the
//!   widest gap above the k-th mode must equal the number of computed modes below τ. The
//!   count runs on a second thread (unless faer's global parallelism is sequential): started
//!   once the first run's Ritz values have converged to 1e-6, and kept when its τ still lies in
//!   the middle half of a real gap of the refined modes; otherwise recounted beside the
//!   residual computation. Only the k wanted modes converge to `tolerance`; the buffer above
//!   them, which only has to show the gap, to 1e-8. Only gaps
//!   wider than max(√u, 100·tolerance) relative count, so τ never falls inside a numerically
//!   repeated eigenvalue (where the count could split the group); when the modes found above
//!   the k-th have no such gap, τ goes above the last one. When the count is larger, modes were
//!   missed (a block Krylov space of block size b holds at most b directions of each
//!   eigenspace in exact arithmetic; further copies appear only from rounding, if at all):
//!   Lanczos is rerun deflated against every found vector, with a block of as many vectors as
//!   are missing (at most 32), so one rerun sees every missing copy of an eigenvalue. After
//!   [`SparseSolveOptions::max_runs`] runs without agreement the solve fails with
//!   [`ModalError::LanczosNoConvergence`] (found vs. counted below τ).
//! - **Repeated eigenvalues at the cut.** Exactly k modes are returned; when the k-th and (k+1)-th
//!   are equal, [`SparseAccuracyReport::kth_group_multiplicity`] gives the full multiplicity of the
//!   k-th mode's eigenvalue (all its copies lie below τ and were computed).
//! - **Bounds.** For a pair with θ = 1/(ω² − σ) the residual s = Ax − θKx gives
//!   δ = ‖s‖_{K⁻¹}/‖x‖_K (one solve with K): the pencil (A, K) has an eigenvalue within δ of θ
//!   (Parlett, "The Symmetric Eigenvalue Problem", Thm 15.9.1), and within δ²/gap (Kato–Temple)
//!   when the gap to the rest of the spectrum is known, which the inertia count makes rigorous
//!   (nothing else lies below τ). Mapped to ω²: |Δω²| ≤ e/(θ(θ − e)) with e the θ bound, plus the
//!   rounding of the Rayleigh quotient.

mod bounds;
mod fallback;
mod inertia;
mod lanczos;
pub mod matrix_market;
mod operator;
mod options;
mod pencil;
mod rayleigh_ritz;
mod solution;
mod sturm;
mod supernodal;

pub use inertia::{SparseInertiaCount, count_below_sparse};
pub use matrix_market::{MatrixMarket, parse_matrix_market, read_matrix_market};
pub use options::SparseSolveOptions;
pub use pencil::{SparsePencil, check_every_coordinate_used};
pub use solution::{SparseAccuracyReport, SparseModalSolution, SparseSolveTimings};

use crate::error::ModalError;
use crate::sparse::bounds::{PairResiduals, finish, pair_residuals};
use crate::sparse::fallback::dense_fallback;
use crate::sparse::lanczos::{Lcg, lanczos_run};
use crate::sparse::operator::{Mass, Operator, ShiftedFactor, factor_below_spectrum};
use crate::sparse::pencil::frobenius;
use crate::sparse::rayleigh_ritz::{Refined, rayleigh_ritz};
use crate::sparse::sturm::{Counted, InertiaCounter, TauChoice, joined};
use crate::tuning::Tuning;
use faer::Par;
use std::time::{Duration, Instant};

/// Solves for the `options.count` lowest modes of the sparse pencil. See the module documentation.
///
/// Exactly k = `options.count` modes are returned, ascending. When the k-th and (k+1)-th ω² are
/// equal (k cuts through a repeated eigenvalue), the last returned group is an A-orthonormal basis
/// of only part of that eigenspace; [`SparseAccuracyReport::kth_group_multiplicity`] then exceeds
/// the last group's multiplicity and says how many modes the whole eigenspace has.
///
/// Errors: [`ModalError::TooManyModes`] for k = 0 or k > n (or when the deflated reruns would need
/// more vectors than the pencil has), [`ModalError::BadShift`], [`ModalError::NoDefiniteShift`],
/// [`ModalError::MassNotSemidefinite`], and [`ModalError::LanczosNoConvergence`] when a run does
/// not converge within `max_restarts`, or when after `max_runs` Lanczos runs the inertia count
/// still shows modes missing below the check shift τ (then `converged` = modes found below τ,
/// `wanted` = the inertia count below τ, `restarts` = restarts over all runs). Up to order
/// [`Tuning::dense_rescue_limit`] a pencil on which a run exhausts `max_restarts` (typically a
/// graded one, whose shifted factor cannot be applied to the accuracy asked) is solved densely
/// instead, with the dense solver's
/// certified low modes; [`SparseAccuracyReport`] then says `dense_fallback`.
pub fn solve_sparse(pencil: &SparsePencil, options: &SparseSolveOptions) -> Result<SparseModalSolution, ModalError> {
    match solve_sparse_from(pencil, options, None) {
        Err(ModalError::LanczosNoConvergence { restarts, .. })
            if restarts >= options.max_restarts && pencil.dim() <= Tuning::DEFAULT.dense_rescue_limit =>
        {
            options.check(pencil.dim())?;
            dense_fallback(pencil, options.count, frobenius(pencil.a()), frobenius(pencil.b()))
        }
        other => other,
    }
}

/// [`solve_sparse`] with an optional first start block (n × block size, column-major): lets tests
/// start the first run exactly A-orthogonal to an eigenvector, which no rounding can then reach.
fn solve_sparse_from(
    pencil: &SparsePencil,
    options: &SparseSolveOptions,
    start: Option<&[f64]>,
) -> Result<SparseModalSolution, ModalError> {
    let n = pencil.dim();
    let k = options.count;
    options.check(n)?;
    let (a, b) = (pencil.a(), pencil.b());
    let norm_a = frobenius(a);
    let norm_b = frobenius(b);
    for (what, norm) in [("‖A‖_F", norm_a), ("‖B‖_F", norm_b)] {
        if !norm.is_finite() {
            return Err(ModalError::OutOfRange {
                what: what.to_string(),
                detail: "it exceeds the largest double; scale the pencil".to_string(),
            });
        }
    }
    if n <= Tuning::DEFAULT.dense_limit {
        return dense_fallback(pencil, k, norm_a, norm_b);
    }
    let mut timings = SparseSolveTimings::default();
    let (ca, cb) = (pencil.csc_a(), pencil.csc_b());
    let clock = Instant::now();
    let ratio = if norm_a > 0.0 { norm_b / norm_a } else { 1.0 };
    let (factor, values) = factor_below_spectrum(&ca, &cb, ratio, options.shift)?;
    timings.factor = clock.elapsed();
    let sigma = factor.sigma;
    let mut op = Operator {
        symbolic: &factor.symbolic,
        values,
        a: Mass::of(a),
        applications: 0,
        solve_time: Duration::ZERO,
        work: Vec::new(),
    };
    let mut rng = Lcg(options.seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ 0x5851_f42d_4c95_7f2d);
    let solve = LanczosSolve {
        pencil,
        options,
        sigma,
        norms: (norm_a, norm_b),
        // Independent work runs on two threads unless faer's global parallelism is sequential.
        concurrent: !matches!(faer::get_global_parallelism(), Par::Seq),
        tau: TauChoice::new(k, sigma, options.tolerance, ratio),
        counter: InertiaCounter::new(&factor.symbolic, &factor.pattern, &ca, &cb)?,
    };
    let clock = Instant::now();
    let (first, mut early) = solve.first_run(&mut op, &mut rng, start);
    let (_, mut found, mut restarts) = first?;
    timings.lanczos += clock.elapsed();
    let mut runs = 1;
    let max_runs = options.max_runs.max(1);
    loop {
        let clock = Instant::now();
        let cols = found.len() / n;
        let refined = rayleigh_ritz(op.a, b, &found, cols)?;
        timings.refine += clock.elapsed();
        let omega = &refined.omega_sq;
        if omega.is_empty() {
            return Err(ModalError::LanczosNoConvergence {
                converged: 0,
                wanted: k,
                restarts,
            });
        }
        let cols = omega.len();
        let (tau, (inertia, inertia_time), (residuals, residual_time)) = solve.check(&mut op, &refined, early.take());
        let below = omega.partition_point(|&w| w < tau);
        timings.inertia += inertia_time;
        timings.refine += residual_time;
        let inertia = inertia?;
        let missing = inertia.count.below.saturating_sub(below);
        if missing == 0 {
            let clock = Instant::now();
            let mut solution = finish(
                op.a,
                &refined,
                residuals,
                k,
                (sigma, tau),
                inertia,
                below,
                (norm_a, norm_b),
            );
            timings.refine += clock.elapsed();
            record_costs(&mut solution.report, &factor, &op, (restarts, runs), timings);
            return Ok(solution);
        }
        if runs >= max_runs {
            return Err(ModalError::LanczosNoConvergence {
                converged: below,
                wanted: inertia.count.below,
                restarts,
            });
        }
        let clock = Instant::now();
        let (_, more, r) = solve.rerun(&mut op, &mut rng, missing, &refined.vectors, cols)?;
        timings.lanczos += clock.elapsed();
        restarts += r;
        runs += 1;
        found = refined.vectors;
        found.extend_from_slice(&more);
    }
}

/// Writes what the solve cost into its report: the shift attempts and the factor's size, the
/// operator applications and solve time, the (restarts, runs) of Lanczos, and the stage times.
fn record_costs(
    report: &mut SparseAccuracyReport,
    factor: &ShiftedFactor,
    op: &Operator<'_>,
    (restarts, runs): (usize, usize),
    timings: SparseSolveTimings,
) {
    report.shift_attempts = factor.attempts;
    report.factor_nnz = factor.symbolic.len_val();
    report.operator_applications = op.applications;
    report.restarts = restarts;
    report.lanczos_runs = runs;
    report.timings = timings;
    report.timings.solves = op.solve_time;
}

/// The first run's result, and the inertia count it started early at the τ given.
type FirstRun = (Result<(Vec<f64>, Vec<f64>, usize), ModalError>, Option<(f64, Counted)>);

/// What the Lanczos runs and Sturm checks of one sparse solve share.
struct LanczosSolve<'a> {
    pencil: &'a SparsePencil,
    options: &'a SparseSolveOptions,
    /// The operator's shift σ (every mode lies above it).
    sigma: f64,
    /// (‖A‖_F, ‖B‖_F).
    norms: (f64, f64),
    /// Whether independent work runs on two threads.
    concurrent: bool,
    tau: TauChoice,
    counter: InertiaCounter<'a>,
}

impl LanczosSolve<'_> {
    /// The first run: k plus a buffer, so that a gap above the k-th mode is seen. Once its θ
    /// are roughly converged the inertia count at a τ chosen from them starts on a second thread
    /// (when no thread can be created, the count is done after the run instead).
    fn first_run(&self, op: &mut Operator<'_>, rng: &mut Lcg, start: Option<&[f64]>) -> FirstRun {
        let (n, k) = (self.pencil.dim(), self.options.count);
        let buffer = (k / 4).clamp(2, 10);
        let counter = &self.counter;
        std::thread::scope(|scope| {
            let mut pending = None;
            let mut start_count = |theta: &[f64]| {
                let omega: Vec<f64> = theta.iter().map(|t| self.sigma + 1.0 / t).collect();
                let tau = self.tau.choose(&omega);
                let counting = std::thread::Builder::new().spawn_scoped(scope, move || counter.count_at(tau));
                pending = counting.ok().map(|handle| (tau, handle));
            };
            let run = lanczos_run(
                op,
                (k + buffer).min(n - 1),
                k,
                self.options.block_size,
                &[],
                0,
                self.options.tolerance,
                self.options.max_restarts,
                rng,
                start,
                if self.concurrent { Some(&mut start_count) } else { None },
            );
            let early = pending.map(|(tau, handle)| (tau, joined(handle.join())));
            (run, early)
        })
    }

    /// τ and the inertia count there, with the residuals of the `refined` pairs: the `early`
    /// count when its τ still fits the refined modes, else a count now, beside the residuals.
    fn check(
        &self,
        op: &mut Operator<'_>,
        refined: &Refined,
        early: Option<(f64, Counted)>,
    ) -> (f64, Counted, (PairResiduals, Duration)) {
        let omega = &refined.omega_sq;
        let residuals = |op: &mut Operator<'_>, two_threads: bool| {
            let clock = Instant::now();
            (
                pair_residuals(self.pencil, op, refined, self.sigma, self.norms, two_threads),
                clock.elapsed(),
            )
        };
        match early.filter(|(tau, _)| self.tau.is_clear(omega, *tau)) {
            Some((tau, counted)) => (tau, counted, residuals(op, self.concurrent)),
            None => {
                let tau = self.tau.choose(omega);
                if self.concurrent {
                    std::thread::scope(|scope| {
                        match std::thread::Builder::new().spawn_scoped(scope, || self.counter.count_at(tau)) {
                            Ok(counting) => {
                                let residuals = residuals(op, false);
                                (tau, joined(counting.join()), residuals)
                            }
                            Err(_) => (tau, self.counter.count_at(tau), residuals(op, false)),
                        }
                    })
                } else {
                    (tau, self.counter.count_at(tau), residuals(op, false))
                }
            }
        }
    }

    /// Missed modes (repeated eigenvalues): a run deflated against the `cols` vectors `found`.
    /// A block of `missing` vectors (at most [`Tuning::max_rerun_block`]) sees every missing
    /// copy of an eigenvalue in one run, whatever its multiplicity.
    fn rerun(
        &self,
        op: &mut Operator<'_>,
        rng: &mut Lcg,
        missing: usize,
        found: &[f64],
        cols: usize,
    ) -> Result<(Vec<f64>, Vec<f64>, usize), ModalError> {
        let n = self.pencil.dim();
        let rerun_nev = (missing + 1).min(n.saturating_sub(cols + 1)).max(1);
        lanczos_run(
            op,
            rerun_nev,
            rerun_nev,
            self.options
                .block_size
                .max(missing.min(Tuning::DEFAULT.max_rerun_block)),
            found,
            cols,
            self.options.tolerance,
            self.options.max_restarts,
            rng,
            None,
            None,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::Triplet;
    use std::f64::consts::PI;

    /// Two uncoupled consistent-mass chains of `len` nodes (A = tridiag(1, 4, 1),
    /// B = 6s·tridiag(−1, 2, −1), s = 1 for the first and 2 for the second):
    /// ω²_j = 12 s sin²(θ_j/2)/(2 + cos θ_j), θ_j = jπ/(len + 1).
    fn two_chains(len: usize) -> (SparsePencil, Vec<f64>) {
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for (c, s) in [(0, 1.0), (1, 2.0)] {
            for i in 0..len {
                let r = c * len + i;
                a.push(Triplet::new(r, r, 4.0));
                b.push(Triplet::new(r, r, 12.0 * s));
                if i + 1 < len {
                    for (p, q) in [(r, r + 1), (r + 1, r)] {
                        a.push(Triplet::new(p, q, 1.0));
                        b.push(Triplet::new(p, q, -6.0 * s));
                    }
                }
            }
        }
        let mut exact: Vec<f64> = [1.0, 2.0]
            .iter()
            .flat_map(|s| {
                (1..=len).map(move |j| {
                    let theta = j as f64 * PI / (len as f64 + 1.0);
                    let h = (0.5 * theta).sin();
                    12.0 * s * h * h / (2.0 + theta.cos())
                })
            })
            .collect();
        exact.sort_by(f64::total_cmp);
        let pencil = SparsePencil::from_triplets(2 * len, &a, &b).expect("valid");
        (pencil, exact)
    }
    /// Every returned ω² within its bound (plus 8u for the rounding of the closed form) of the
    /// closed form, and the certificate holds.
    fn assert_matches(sol: &SparseModalSolution, exact: &[f64]) {
        for (i, (m, w)) in sol.modes.iter().zip(exact).enumerate() {
            let err = (m.omega_sq - w).abs();
            assert!(
                err <= m.error_bound + 8.0 * f64::EPSILON * w,
                "mode {i}: {} vs {w} (bound {:e})",
                m.omega_sq,
                m.error_bound
            );
        }
        assert!(sol.report.consistent, "{:?}", sol.report);
        assert!(sol.report.orthogonality_error <= 1e3 * f64::EPSILON, "{:?}", sol.report);
    }
    /// A start vector that is exactly zero on the first chain: every Krylov vector stays exactly
    /// zero there (block-diagonal A and Cholesky factor, products with exact zeros), so the first
    /// run cannot see the lowest modes in any arithmetic. The inertia count must notice and the
    /// deflated rerun (random start) must find them.
    #[test]
    fn modes_invisible_from_the_start_block_are_recovered() {
        let len = 300;
        let (p, exact) = two_chains(len);
        let options = SparseSolveOptions {
            count: 6,
            block_size: 1,
            ..SparseSolveOptions::default()
        };
        let mut start = vec![0.0; 2 * len];
        for (i, x) in start[len..].iter_mut().enumerate() {
            *x = 1.0 + (i % 7) as f64;
        }
        let sol = solve_sparse_from(&p, &options, Some(&start)).expect("solve");
        assert!(sol.report.lanczos_runs >= 2, "{:?}", sol.report);
        assert_eq!(sol.modes.len(), 6);
        assert_matches(&sol, &exact);
        // With a single run allowed the missed modes are a typed error naming both counts.
        let single = SparseSolveOptions { max_runs: 1, ..options };
        match solve_sparse_from(&p, &single, Some(&start)) {
            Err(ModalError::LanczosNoConvergence { converged, wanted, .. }) => {
                assert!(converged < wanted, "{converged} of {wanted}");
            }
            other => panic!("expected a missed-mode error, got {other:?}"),
        }
    }
    /// A start vector nearly orthogonal (1e-13 relative) to the first chain: rounding-level
    /// components may or may not grow within the first run; either way the result is certified.
    #[test]
    fn nearly_invisible_modes_are_recovered() {
        let len = 300;
        let (p, exact) = two_chains(len);
        let mut start = vec![0.0; 2 * len];
        for (i, x) in start.iter_mut().enumerate() {
            let scale = if i < len { 1e-13 } else { 1.0 };
            *x = scale * (1.0 + (i % 5) as f64);
        }
        for block in [1, 2] {
            let options = SparseSolveOptions {
                count: 8,
                block_size: block,
                ..SparseSolveOptions::default()
            };
            let mut s = start.clone();
            if block == 2 {
                s.extend(start.iter().enumerate().map(|(i, x)| x * (1.0 + (i % 3) as f64)));
            }
            let sol = solve_sparse_from(&p, &options, Some(&s)).expect("solve");
            assert_eq!(sol.modes.len(), 8);
            assert_matches(&sol, &exact);
        }
    }
}
