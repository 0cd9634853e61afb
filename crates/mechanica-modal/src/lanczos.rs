//! The k lowest modes of a large sparse pencil (A, B) by shift-invert Lanczos (issue part 5).
//!
//! - **Operator.** With a shift σ below the lowest mode, K = B − σA is positive definite and
//!   factored once by faer's sparse Cholesky (AMD ordering; solved by this crate's
//!   supernodal block solve, `supernodal_solve`, 1.35–1.7× faster than faer's on a 2-D grid).
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
//!   [`SparseOptions::max_runs`] runs without agreement the solve fails with
//!   [`ModalError::LanczosNoConvergence`] (found vs. counted below τ).
//! - **Repeated eigenvalues at the cut.** Exactly k modes are returned; when the k-th and
//!   (k+1)-th are equal, [`SparseReport::kth_group_multiplicity`] gives the full multiplicity of
//!   the k-th mode's eigenvalue (all its copies lie below τ and were computed).
//! - **Bounds.** For a pair with θ = 1/(ω² − σ) the residual s = Ax − θKx gives
//!   δ = ‖s‖_{K⁻¹}/‖x‖_K (one solve with K): the pencil (A, K) has an eigenvalue within δ of θ
//!   (Parlett, "The Symmetric Eigenvalue Problem", Thm 15.9.1), and within δ²/gap (Kato–Temple)
//!   when the gap to the rest of the spectrum is known, which the inertia count makes rigorous
//!   (nothing else lies below τ). Mapped to ω²: |Δω²| ≤ e/(θ(θ − e)) with e the θ bound, plus the
//!   rounding of the Rayleigh quotient.

use crate::dd::{self, Dd};
use crate::sparse_inertia::{SparseInertia, inertia_with, symbolic_supernodal};
use crate::sparse_pencil::{Csc, SparsePencil, abs_quadratic, frobenius, mul};
use crate::spectrum::{Mode, ModeGroup, classify, group_modes};
use crate::supernodal_solve::SupernodalSolver;
use crate::{ModalError, PencilProblem, Refinement, Selection, SolveOptions, solve};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::{Conj, Mat, MatMut, MatRef, Par, Side};
use std::time::{Duration, Instant};

/// Options of [`solve_sparse`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SparseOptions {
    /// Number k of lowest modes wanted (1 ≤ k < n).
    pub count: usize,
    /// Shift σ (rad²/s²) below the lowest mode; None: automatic (see the module documentation).
    pub shift: Option<f64>,
    /// Convergence: Ritz residual ≤ tolerance·θ for each of the k wanted pairs (the buffer
    /// pairs computed above them, only to locate a gap, converge to max(tolerance, 1e-8)).
    pub tolerance: f64,
    /// Maximal number of thick restarts per Lanczos run.
    pub max_restarts: usize,
    /// Seed of the pseudo-random start vectors.
    pub seed: u64,
    /// Block size b of the block Lanczos iteration (≥ 1): b vectors share each pass over the
    /// Cholesky factor, and an eigenvalue of multiplicity ≤ b is seen in one run.
    pub block_size: usize,
    /// Maximal number of Lanczos runs: the first one plus deflated reruns for modes that the
    /// inertia count shows missing (0 is taken as 1). When exhausted the solve fails with
    /// [`ModalError::LanczosNoConvergence`] instead of returning an uncertified result.
    pub max_runs: usize,
}

impl Default for SparseOptions {
    fn default() -> Self {
        Self {
            count: 10,
            shift: None,
            tolerance: 1e-12,
            max_restarts: 300,
            seed: 1,
            block_size: 2,
            max_runs: 6,
        }
    }
}

/// Wall time of each stage of a sparse solve.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SparseTimings {
    /// Symbolic analysis and Cholesky factorization of B − σA (all shifts tried).
    pub factor: Duration,
    /// Lanczos iterations (all rounds).
    pub lanczos: Duration,
    /// Rayleigh–Ritz refinement, residuals and bounds.
    pub refine: Duration,
    /// Inertia (Sturm) checks, on their own thread: this time overlaps `lanczos` or `refine`
    /// unless faer's global parallelism is sequential.
    pub inertia: Duration,
    /// Of lanczos + refine: the triangular solves with the factor of B − σA.
    pub solves: Duration,
}

/// How the sparse result was obtained and how accurate it is.
#[derive(Debug, Clone, PartialEq)]
pub struct SparseReport {
    /// The shift σ of the factored operator (every mode lies above it).
    pub shift: f64,
    /// Cholesky factorizations tried to find a positive definite B − σA.
    pub shift_attempts: usize,
    /// Stored entries of the Cholesky factor L of B − σA (0 on the dense path): the memory of
    /// the solve is O(this + n·basis size).
    pub factor_nnz: usize,
    /// ‖A‖_F and ‖B‖_F.
    pub norm_a: f64,
    /// ‖B‖_F.
    pub norm_b: f64,
    /// Thick restarts over all Lanczos runs.
    pub restarts: usize,
    /// Applications of K⁻¹A.
    pub operator_applications: usize,
    /// Lanczos runs (1 + deflated reruns for missed modes); 0 on the dense path.
    pub lanczos_runs: usize,
    /// Multiplicity of the k-th (highest returned) mode's eigenvalue among all modes computed
    /// below the inertia shift τ, which is the whole eigenspace when `consistent` (τ lies in a
    /// real gap above the k-th mode). It exceeds the last returned group's multiplicity when
    /// the count k cuts through a repeated eigenvalue.
    pub kth_group_multiplicity: usize,
    /// Largest backward error η of the returned pairs.
    pub max_backward_error: f64,
    /// max |(XᵀAX − I)_ij| of the returned vectors.
    pub orthogonality_error: f64,
    /// The inertia check: B − τA at τ in a gap above the k-th mode.
    pub inertia: Option<SparseInertia>,
    /// How many computed modes lie below τ.
    pub computed_below: usize,
    /// Whether the inertia count equals computed_below (no mode below τ missed or invented).
    pub consistent: bool,
    /// True when the problem was small enough to be solved densely (n ≤ [`DENSE_LIMIT`]).
    pub dense_fallback: bool,
    /// Stage timings.
    pub timings: SparseTimings,
}

/// The k lowest modes of a sparse pencil.
#[derive(Debug, Clone)]
pub struct SparseModalSolution {
    /// The modes, ascending in ω² (error bounds and backward errors filled in).
    pub modes: Vec<Mode>,
    /// n × k A-orthonormal mode shapes.
    pub vectors: Mat<f64>,
    /// Groups of numerically equal frequencies (repeated modes).
    pub groups: Vec<ModeGroup>,
    /// Accuracy and cost.
    pub report: SparseReport,
}

/// At or below this order the sparse solver converts to dense and calls [`crate::solve()`].
pub const DENSE_LIMIT: usize = 400;

/// Shift-invert operator x ↦ K⁻¹(Ax) with the Cholesky factor of K = B − σA.
struct Operator<'a> {
    symbolic: &'a SymbolicCholesky<usize>,
    values: Vec<f64>,
    a: Mass<'a>,
    applications: usize,
    solve_time: Duration,
    /// Row-interleaved copy of the block being solved (kept: no page faults per solve).
    work: Vec<f64>,
}

impl Operator<'_> {
    /// x ← K⁻¹x for an n × b column-major block, counted and timed.
    fn solve_block(&mut self, x: &mut [f64], b: usize) {
        let clock = Instant::now();
        solve_with(self.symbolic, &self.values, x, b, &mut self.work);
        self.applications += b;
        self.solve_time += clock.elapsed();
    }
}

/// x ← K⁻¹x for an n × b column-major block (one pass over the factor for all columns) with
/// the factor (`symbolic`, `values`) of K and the scratch `work`: [`SupernodalSolver`] for a
/// supernodal factor, faer's solve for a simplicial one. Sequential: on a shared machine
/// threaded triangular solves contend badly.
fn solve_with(symbolic: &SymbolicCholesky<usize>, values: &[f64], x: &mut [f64], b: usize, work: &mut Vec<f64>) {
    match symbolic.raw() {
        SymbolicCholeskyRaw::Supernodal(supernodal) => {
            let fwd = symbolic.perm().map(|p| p.arrays().0);
            SupernodalSolver::new(supernodal, values, fwd).solve_in_place(x, b, work);
        }
        SymbolicCholeskyRaw::Simplicial(_) => {
            let n = symbolic.nrows();
            let req = symbolic.solve_in_place_scratch::<f64>(b, Par::Seq);
            let mut mem = MemBuffer::new(req);
            LltRef::new(symbolic, values).solve_in_place_with_conj(
                Conj::No,
                MatMut::from_column_major_slice_mut(x, n, b),
                Par::Seq,
                MemStack::new(&mut mem),
            );
        }
    }
}

/// Factors K = B − σA (lower triangle read) with a symbolic analysis of its pattern; on a
/// non-positive pivot returns its index.
fn factor_llt(symbolic: &SymbolicCholesky<usize>, k: &Csc) -> Result<Result<Vec<f64>, usize>, ModalError> {
    let m = k.to_faer();
    // Sequential: faster than two threads on this 2-D grid (125 against 140 ms), and no
    // contention on a shared machine.
    let par = Par::Seq;
    let req = symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default());
    let mut mem = MemBuffer::try_new(req).map_err(|_| ModalError::Factorization {
        what: "B − σA",
        detail: "out of memory for the factorization workspace".into(),
    })?;
    let mut values = vec![0.0; symbolic.len_val()];
    let result = symbolic.factorize_numeric_llt(
        &mut values,
        m.as_ref(),
        Side::Lower,
        Default::default(),
        par,
        MemStack::new(&mut mem),
        Default::default(),
    );
    Ok(match result {
        Ok(_) => Ok(values),
        Err(faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index }) => Err(index),
    })
}

/// Pseudo-random numbers in [−1, 1).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        2.0 * ((self.0 >> 11) as f64 / (1u64 << 53) as f64) - 1.0
    }
}

/// lhs · rhs, sequential (faer's threaded kernels contend on a shared machine at these sizes).
fn product(lhs: MatRef<'_, f64>, rhs: MatRef<'_, f64>) -> Mat<f64> {
    let mut out = Mat::<f64>::zeros(lhs.nrows(), rhs.ncols());
    product_to(out.as_mut(), lhs, rhs);
    out
}

/// out ← lhs · rhs, with `out` the column-major storage of the product (sequential).
fn product_into(out: &mut [f64], lhs: MatRef<'_, f64>, rhs: MatRef<'_, f64>) {
    product_to(
        MatMut::from_column_major_slice_mut(out, lhs.nrows(), rhs.ncols()),
        lhs,
        rhs,
    );
}

/// target ← lhs · rhs, sequential.
fn product_to(target: MatMut<'_, f64>, lhs: MatRef<'_, f64>, rhs: MatRef<'_, f64>) {
    faer::linalg::matmul::matmul(target, faer::Accum::Replace, lhs, rhs, 1.0, Par::Seq);
}

fn dot(x: &[f64], y: &[f64]) -> f64 {
    x.iter().zip(y).map(|(a, b)| a * b).sum()
}

/// The mass matrix A as the iteration applies it (a dozen products per block step): a diagonal
/// A (lumped masses, the common case) elementwise, which vectorises; any other by columns.
#[derive(Clone, Copy)]
enum Mass<'a> {
    /// The diagonal entries, in order.
    Diagonal(&'a [f64]),
    Sparse(faer::sparse::SparseColMatRef<'a, usize, f64>),
}

impl<'a> Mass<'a> {
    fn of(a: faer::sparse::SparseColMatRef<'a, usize, f64>) -> Self {
        let (symbolic, val) = a.parts();
        let n = a.ncols();
        let diagonal = val.len() == n
            && symbolic.col_ptr().iter().enumerate().all(|(j, &p)| p == j)
            && symbolic.row_idx().iter().enumerate().all(|(k, &i)| i == k);
        if diagonal { Mass::Diagonal(val) } else { Mass::Sparse(a) }
    }

    fn nrows(&self) -> usize {
        match self {
            Mass::Diagonal(d) => d.len(),
            Mass::Sparse(a) => a.nrows(),
        }
    }

    /// y = A x.
    fn apply(&self, x: &[f64], y: &mut [f64]) {
        match self {
            Mass::Diagonal(d) => {
                for ((y, x), d) in y.iter_mut().zip(x).zip(*d) {
                    *y = d * x;
                }
            }
            Mass::Sparse(a) => mul(*a, x, y),
        }
    }

    /// Y = A X for n × b column-major blocks.
    fn apply_block(&self, x: &[f64], y: &mut [f64]) {
        let n = self.nrows();
        for (xc, yc) in x.chunks_exact(n).zip(y.chunks_exact_mut(n)) {
            self.apply(xc, yc);
        }
    }
}

/// A-orthogonalises the n × b block `w` against the first `cols` columns of `basis` and all of
/// `locked` by block classical Gram–Schmidt, repeated once when a column lost more than
/// 1 − 1/√2 of its A-norm ("twice is enough": Daniel, Gragg, Kaufman & Stewart, Math. Comp. 30,
/// 1976; Giraud, Langou & Rozložník, Comput. Math. Appl. 50, 2005); returns the accumulated
/// cols × b coefficients.
///
/// When only the columns from `coupled_from` on carry w's large components (the blocks the
/// Lanczos recurrence couples it to), a first pass against those alone removes them; one pass
/// against everything then usually keeps 1/√2 of what is left, so the whole basis is read
/// twice per block step instead of four times.
#[allow(clippy::too_many_arguments)]
fn orthogonalise_block(
    a: Mass<'_>,
    basis: &[f64],
    cols: usize,
    coupled_from: usize,
    locked: &[f64],
    locked_cols: usize,
    w: &mut [f64],
    scratch: &mut [f64],
) -> Mat<f64> {
    let n = a.nrows();
    let b = w.len() / n;
    let mut total = Mat::<f64>::zeros(cols, b);
    if coupled_from > 0 && coupled_from < cols {
        a.apply_block(w, scratch);
        let h = project_out(&basis[n * coupled_from..n * cols], scratch, w, n);
        total
            .as_mut()
            .subrows_mut(coupled_from, cols - coupled_from)
            .copy_from(&h);
    }
    let a_norms = |w: &[f64], aw: &[f64]| -> Vec<f64> {
        w.chunks_exact(n)
            .zip(aw.chunks_exact(n))
            .map(|(x, y)| dot(x, y).max(0.0).sqrt())
            .collect()
    };
    let mut before: Option<Vec<f64>> = None;
    for _ in 0..2 {
        a.apply_block(w, scratch);
        let norms = a_norms(w, scratch);
        if let Some(previous) = &before
            && norms
                .iter()
                .zip(previous)
                .all(|(now, then)| *now >= std::f64::consts::FRAC_1_SQRT_2 * then)
        {
            break;
        }
        before = Some(norms);
        for (part, count, accumulate) in [(basis, cols, true), (locked, locked_cols, false)] {
            if count == 0 {
                continue;
            }
            let h = project_out(&part[..n * count], scratch, w, n);
            if accumulate {
                total += &h;
            }
        }
    }
    total
}

/// One classical Gram–Schmidt projection: W ← W − V H with H = Vᵀz (returned), for the n × count
/// columns `v`, the n × b block `w` and z = A·W (all column-major, n > 0).
fn project_out(v: &[f64], z: &[f64], w: &mut [f64], n: usize) -> Mat<f64> {
    let b = w.len() / n;
    let v = MatRef::from_column_major_slice(v, n, v.len() / n);
    let h = product(v.transpose(), MatRef::from_column_major_slice(z, n, b));
    faer::linalg::matmul::matmul(
        MatMut::from_column_major_slice_mut(w, n, b),
        faer::Accum::Add,
        v,
        h.as_ref(),
        -1.0,
        Par::Seq,
    );
    h
}

/// A-orthonormalises the columns of the block `w` among themselves (modified Gram–Schmidt, each
/// column against the earlier ones, twice); returns the b × b upper triangular R with
/// W_old = W_new R. A column that vanishes (invariant subspace) is replaced by a random vector
/// orthogonal to everything, with a zero column in R. Errors if A gives a negative norm.
/// `aw` (length n) is scratch.
#[allow(clippy::too_many_arguments)]
fn normalise_block(
    a: Mass<'_>,
    basis: &[f64],
    cols: usize,
    locked: &[f64],
    locked_cols: usize,
    w: &mut [f64],
    scale: f64,
    rng: &mut Lcg,
    aw: &mut [f64],
) -> Result<Mat<f64>, ModalError> {
    let n = a.nrows();
    let b = w.len() / n;
    let mut r = Mat::<f64>::zeros(b, b);
    for c in 0..b {
        let (done, rest) = w.split_at_mut(n * c);
        let wc = &mut rest[..n];
        // (The first column has nothing earlier to be orthogonalised against.)
        for _ in 0..if c == 0 { 0 } else { 2 } {
            a.apply(wc, aw);
            for d in 0..c {
                let wd = &done[n * d..n * (d + 1)];
                let h = dot(wd, aw);
                r[(d, c)] += h;
                for (x, y) in wc.iter_mut().zip(wd) {
                    *x -= h * y;
                }
            }
        }
        a.apply(wc, aw);
        let norm_sq = dot(wc, aw);
        if norm_sq < -1e4 * (f64::EPSILON * scale).powi(2) {
            return Err(ModalError::MassNotSemidefinite { value: norm_sq });
        }
        let norm = norm_sq.max(0.0).sqrt();
        if norm > 1e3 * f64::EPSILON * scale.max(f64::MIN_POSITIVE) {
            r[(c, c)] = norm;
            wc.iter_mut().for_each(|x| *x /= norm);
            continue;
        }
        // Deflated direction: a fresh random vector, A-orthogonal to everything so far.
        let mut replaced = false;
        let mut scratch = vec![0.0; n];
        for _ in 0..8 {
            wc.iter_mut().for_each(|x| *x = rng.next());
            let mut all = basis[..n * cols].to_vec();
            all.extend_from_slice(done);
            let _ = orthogonalise_block(a, &all, cols + c, 0, locked, locked_cols, wc, &mut scratch);
            a.apply(wc, aw);
            let fresh = dot(wc, aw);
            if fresh > 0.0 {
                let s = fresh.sqrt();
                wc.iter_mut().for_each(|x| *x /= s);
                replaced = true;
                break;
            }
        }
        if !replaced {
            return Err(ModalError::LanczosNoConvergence {
                converged: 0,
                wanted: b,
                restarts: 0,
            });
        }
    }
    Ok(r)
}

/// Called once with roughly converged θ (see [`lanczos_run`]).
type RoughHook<'a> = &'a mut dyn FnMut(&[f64]);

/// One block thick-restart Lanczos run for the `nev` largest θ of T restricted to the
/// A-orthogonal complement of `locked`, from the n × b column-major `start` block when given
/// with that size (tests), else from a pseudo-random block. The first `strict` of them converge
/// to `tolerance`, the rest (a buffer that only has to show where the spectrum has a gap) to
/// [`BUFFER_TOLERANCE`]. `rough`, when given, is called once with the nev θ (descending) as
/// soon as all of them have converged to [`ROUGH_TOLERANCE`] (not when they converge fully at
/// the first check). Returns (θ descending, n × nev Ritz vectors, restarts).
#[allow(clippy::too_many_arguments)]
fn lanczos_run(
    op: &mut Operator<'_>,
    nev: usize,
    strict: usize,
    block: usize,
    locked: &[f64],
    locked_cols: usize,
    tolerance: f64,
    max_restarts: usize,
    rng: &mut Lcg,
    start: Option<&[f64]>,
    mut rough: Option<RoughHook<'_>>,
) -> Result<(Vec<f64>, Vec<f64>, usize), ModalError> {
    let a = op.a;
    let n = a.nrows();
    let room = n.saturating_sub(locked_cols);
    let b = block.clamp(1, (room / 4).max(1));
    // m basis columns (a multiple of b) plus one residual block.
    // 2·nev + 4b: with convergence checked after every block step, a larger basis saves no
    // operator application on the 300×300 grid (k = 10, b = 2: 72 for every m from 32 to 56),
    // only orthogonalisation work; 2·nev + 2b needed more.
    let wanted_m = (2 * nev + 4 * b).max(24);
    let m = (wanted_m.div_ceil(b) * b).min((room.saturating_sub(b) / b) * b);
    if m < 2 * b || nev >= m {
        return Err(ModalError::TooManyModes {
            requested: nev + locked_cols,
            available: n,
        });
    }
    let mut basis = vec![0.0; n * (m + b)];
    // Second basis buffer for the restarts (allocated at the first).
    let mut spare = Vec::new();
    let mut h = Mat::<f64>::zeros(m + b, m);
    let mut scratch = vec![0.0; n * b];
    let mut w = vec![0.0; n * b];
    // Start block: given or random, A-orthonormal, A-orthogonal to the locked vectors.
    match start {
        Some(given) if given.len() == w.len() => w.copy_from_slice(given),
        _ => w.iter_mut().for_each(|x| *x = rng.next()),
    }
    let _ = orthogonalise_block(a, &[], 0, 0, locked, locked_cols, &mut w, &mut scratch);
    normalise_block(a, &[], 0, locked, locked_cols, &mut w, 1.0, rng, &mut scratch[..n])?;
    basis[..n * b].copy_from_slice(&w);
    let mut cols = 0usize;
    // Columns kept by the last restart (0 before the first).
    let mut kept = 0usize;
    let mut restarts = 0usize;
    loop {
        // Expand by one block.
        let current = &basis[n * cols..n * (cols + b)];
        a.apply_block(current, &mut w);
        op.solve_block(&mut w, b);
        // The recurrence couples the block to the previous one, or after a restart (and at the
        // start) to every kept Ritz vector.
        let coupled_from = if cols == kept { 0 } else { cols - b };
        let coefficients = orthogonalise_block(
            a,
            &basis,
            cols + b,
            coupled_from,
            locked,
            locked_cols,
            &mut w,
            &mut scratch,
        );
        let scale = (0..cols + b)
            .flat_map(|i| (0..b).map(move |c| (i, c)))
            .fold(0.0_f64, |s, (i, c)| s.max(coefficients[(i, c)].abs()));
        let r = normalise_block(
            a,
            &basis,
            cols + b,
            locked,
            locked_cols,
            &mut w,
            scale,
            rng,
            &mut scratch[..n],
        )?;
        for c in 0..b {
            for i in 0..cols + b {
                h[(i, cols + c)] = coefficients[(i, c)];
            }
            for i in 0..b {
                h[(cols + b + i, cols + c)] = r[(i, c)];
            }
        }
        basis[n * (cols + b)..n * (cols + 2 * b)].copy_from_slice(&w);
        cols += b;
        // Convergence is checked after every block step, not only when the basis is full: the
        // projected problem is tiny (cols ≤ m), and a run then stops at the first block at which
        // every wanted pair has converged instead of finishing the cycle.
        if cols < nev + b {
            continue;
        }
        let ritz = RitzPairs::of(&h, cols, b)?;
        let wanted: Vec<usize> = (0..nev).map(|r| cols - 1 - r).collect();
        let converged = wanted
            .iter()
            .enumerate()
            .filter(|&(r, &c)| {
                let goal = if r < strict {
                    tolerance
                } else {
                    tolerance.max(BUFFER_TOLERANCE)
                };
                ritz.residual(c) <= goal * ritz.theta[c].abs()
            })
            .count();
        if converged < nev
            && wanted
                .iter()
                .all(|&c| ritz.residual(c) <= ROUGH_TOLERANCE * ritz.theta[c].abs())
            && let Some(hook) = rough.take()
        {
            hook(&wanted.iter().map(|&c| ritz.theta[c]).collect::<Vec<_>>());
        }
        let v = MatRef::from_column_major_slice(&basis[..n * cols], n, cols);
        if converged == nev {
            let ys = Mat::from_fn(cols, nev, |i, r| ritz.y[(i, wanted[r])]);
            let mut out = vec![0.0; n * nev];
            product_into(&mut out, v, ys.as_ref());
            return Ok((wanted.iter().map(|&c| ritz.theta[c]).collect(), out, restarts));
        }
        if cols < m {
            continue;
        }
        if restarts >= max_restarts {
            return Err(ModalError::LanczosNoConvergence {
                converged,
                wanted: nev,
                restarts,
            });
        }
        restarts += 1;
        // Thick restart: keep the p largest Ritz vectors and the residual block.
        // p ≡ m (mod b), so that the expansions fill the basis exactly.
        let p_wanted = (nev + (m - nev) / 2).min(m - b).max(nev);
        let p = m - (m - p_wanted).div_ceil(b) * b;
        let keep: Vec<usize> = (0..p).map(|r| m - 1 - r).collect();
        let ys = Mat::from_fn(m, p, |i, r| ritz.y[(i, keep[r])]);
        // The new basis is formed in the spare buffer, which then becomes the basis.
        spare.resize(basis.len(), 0.0);
        product_into(&mut spare[..n * p], v, ys.as_ref());
        spare[n * p..n * (p + b)].copy_from_slice(&basis[n * m..n * (m + b)]);
        std::mem::swap(&mut basis, &mut spare);
        h.fill(0.0);
        for r in 0..p {
            h[(r, r)] = ritz.theta[keep[r]];
            for i in 0..b {
                h[(p + i, r)] = ritz.coupling[(i, keep[r])];
            }
        }
        cols = p;
        kept = p;
    }
}

/// Ritz pairs of the projected matrix of a Lanczos basis with `cols` columns: θ ascending, the
/// eigenvectors Y of the symmetrised leading cols × cols block of H, and the coupling
/// H[cols..cols+b, ..cols]·Y, whose column norms are the Ritz residuals ‖K⁻¹A x − θx‖_A.
struct RitzPairs {
    theta: Vec<f64>,
    y: Mat<f64>,
    coupling: Mat<f64>,
}

impl RitzPairs {
    fn of(h: &Mat<f64>, cols: usize, b: usize) -> Result<Self, ModalError> {
        let hm = Mat::from_fn(cols, cols, |i, j| 0.5 * (h[(i, j)] + h[(j, i)]));
        let eig = hm
            .self_adjoint_eigen(Side::Lower)
            .map_err(|_| ModalError::NoConvergence { n: cols })?;
        let y = eig.U().to_owned();
        let coupling = product(h.as_ref().submatrix(cols, 0, b, cols), y.as_ref());
        Ok(Self {
            theta: (0..cols).map(|i| eig.S()[i]).collect(),
            y,
            coupling,
        })
    }

    /// Ritz residual of pair `col`.
    fn residual(&self, col: usize) -> f64 {
        (0..self.coupling.nrows())
            .map(|i| self.coupling[(i, col)].powi(2))
            .sum::<f64>()
            .sqrt()
    }
}

/// Solves for the `options.count` lowest modes of the sparse pencil. See the module documentation.
///
/// Exactly k = `options.count` modes are returned, ascending. When the k-th and (k+1)-th ω² are
/// equal (k cuts through a repeated eigenvalue), the last returned group is an A-orthonormal basis
/// of only part of that eigenspace; [`SparseReport::kth_group_multiplicity`] then exceeds the
/// last group's multiplicity and says how many modes the whole eigenspace has.
///
/// Errors: [`ModalError::TooManyModes`] for k = 0 or k > n (or when the deflated reruns would
/// need more vectors than the pencil has), [`ModalError::BadShift`], [`ModalError::NoDefiniteShift`],
/// [`ModalError::MassNotSemidefinite`], and [`ModalError::LanczosNoConvergence`] when a run does not
/// converge within `max_restarts`, or when after `max_runs` Lanczos runs the inertia count still
/// shows modes missing below the check shift τ (then `converged` = modes found below τ, `wanted` =
/// the inertia count below τ, `restarts` = restarts over all runs).
pub fn solve_sparse(pencil: &SparsePencil, options: &SparseOptions) -> Result<SparseModalSolution, ModalError> {
    solve_sparse_from(pencil, options, None)
}

/// [`solve_sparse`] with an optional first start block (n × block size, column-major): lets tests
/// start the first run exactly A-orthogonal to an eigenvector, which no rounding can then reach.
fn solve_sparse_from(
    pencil: &SparsePencil,
    options: &SparseOptions,
    start: Option<&[f64]>,
) -> Result<SparseModalSolution, ModalError> {
    let n = pencil.dim();
    let k = options.count;
    if k == 0 || k > n {
        return Err(ModalError::TooManyModes {
            requested: k,
            available: n,
        });
    }
    if let Some(s) = options.shift
        && !s.is_finite()
    {
        return Err(ModalError::BadShift(s));
    }
    if !(options.tolerance > 0.0 && options.tolerance < 1.0) {
        return Err(ModalError::BadTolerance(options.tolerance));
    }
    let (a, b) = (pencil.a(), pencil.b());
    let norm_a = frobenius(a);
    let norm_b = frobenius(b);
    if n <= DENSE_LIMIT {
        return dense_fallback(pencil, k, norm_a, norm_b);
    }
    let mut timings = SparseTimings::default();
    let (ca, cb) = (pencil.csc_a(), pencil.csc_b());
    // Factor K = B − σA at a shift below the spectrum.
    let clock = Instant::now();
    let pattern = Csc::combine(1.0, &cb, 1.0, &ca);
    let symbolic = factorize_symbolic_cholesky(
        pattern.to_faer().symbolic(),
        Side::Lower,
        SymmetricOrdering::Amd,
        // faer's own choice (supernodal here): a simplicial factor has cheaper solves but on the
        // 300×300 grid its slower factorization cost more than that saved (idle: 1.63 s against
        // 1.89 s in all at block size 2).
        CholeskySymbolicParams::default(),
    )
    .map_err(|e| ModalError::Factorization {
        what: "B − σA (symbolic)",
        detail: format!("{e:?}"),
    })?;
    let ratio = if norm_a > 0.0 { norm_b / norm_a } else { 1.0 };
    let mut sigma = options
        .shift
        .unwrap_or(-f64::EPSILON.sqrt() * ratio.max(f64::MIN_POSITIVE));
    let mut attempts = 0;
    let values = loop {
        attempts += 1;
        match factor_llt(&symbolic, &Csc::combine(1.0, &cb, -sigma, &ca))? {
            Ok(values) => break values,
            Err(pivot) => {
                if options.shift.is_some() || attempts >= 6 {
                    return Err(ModalError::NoDefiniteShift {
                        lowest_shift: sigma,
                        pivot,
                    });
                }
                sigma *= 1e3;
            }
        }
    };
    timings.factor = clock.elapsed();
    // Independent work runs on two threads unless faer's global parallelism is sequential.
    let concurrent = !matches!(faer::get_global_parallelism(), Par::Seq);
    let mut op = Operator {
        symbolic: &symbolic,
        values,
        a: Mass::of(a),
        applications: 0,
        solve_time: Duration::ZERO,
        work: Vec::new(),
    };
    let mut rng = Lcg(options.seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ 0x5851_f42d_4c95_7f2d);
    // Gaps narrower than this (relative, plus an absolute floor at the rounding level of ω²
    // near zero, e.g. rigid-body modes) may lie inside a numerically repeated eigenvalue: an
    // inertia shift there could split the group, so τ is never placed in one.
    let min_gap = f64::EPSILON.sqrt().max(100.0 * options.tolerance);
    let floor = 100.0 * f64::EPSILON * ratio;
    let is_real_gap = |below: f64, above: f64| above - below > min_gap * below.abs().max(above.abs()) + floor;
    let real_gap = |omega: &[f64], j: usize| is_real_gap(omega[j], omega[j + 1]);
    // τ in the widest real gap between the k-th mode and the last one found (ω² ascending);
    // above the last one when every gap there is within a cluster.
    let choose_tau = |omega: &[f64]| -> f64 {
        let last = omega.len() - 1;
        let kth = (k - 1).min(last);
        match (kth..last)
            .filter(|&j| real_gap(omega, j))
            .max_by(|&i, &j| gap(omega, i).total_cmp(&gap(omega, j)))
        {
            Some(j) => 0.5 * (omega[j] + omega[j + 1]),
            None => omega[last] + 0.5 * (omega[last] - sigma).abs(),
        }
    };
    // A τ chosen from rough Ritz values still serves for the final ones when it lies above the
    // k-th of them and in the middle half of a real gap (or, above the last, a real gap away).
    let tau_is_clear = |omega: &[f64], tau: f64| -> bool {
        let j = omega.partition_point(|&w| w < tau);
        if j < k.min(omega.len()) || j == 0 {
            return false;
        }
        match omega.get(j) {
            Some(&above) => {
                let below = omega[j - 1];
                let quarter = 0.25 * (above - below);
                real_gap(omega, j - 1) && tau - below >= quarter && above - tau >= quarter
            }
            None => is_real_gap(omega[j - 1], tau),
        }
    };
    // The inertia count needs a supernodal analysis of the same pattern: the Cholesky one when
    // faer chose supernodal (as on large problems), else a forced one.
    let forced_supernodal = match symbolic.raw() {
        SymbolicCholeskyRaw::Supernodal(_) => None,
        SymbolicCholeskyRaw::Simplicial(_) => Some(symbolic_supernodal(&pattern)?),
    };
    let inertia_symbolic = forced_supernodal.as_ref().unwrap_or(&symbolic);
    let count_at = |tau: f64| {
        let clock = Instant::now();
        let kmat = Csc::combine(1.0, &cb, -tau, &ca);
        (inertia_with(inertia_symbolic, &kmat, tau), clock.elapsed())
    };
    let joined = |counted: std::thread::Result<(Result<SparseInertia, ModalError>, Duration)>| {
        counted.unwrap_or_else(|_| {
            let failure = ModalError::Factorization {
                what: "B − τA",
                detail: "the inertia count failed".into(),
            };
            (Err(failure), Duration::ZERO)
        })
    };
    // First run: k plus a buffer, so that a gap above the k-th mode is seen. Once its θ are
    // roughly converged the inertia count at a τ chosen from them starts on a second thread.
    let buffer = (k / 4).clamp(2, 10);
    let clock = Instant::now();
    let (first, mut early) = std::thread::scope(|scope| {
        let mut pending = None;
        let mut start_count = |theta: &[f64]| {
            let omega: Vec<f64> = theta.iter().map(|t| sigma + 1.0 / t).collect();
            let tau = choose_tau(&omega);
            // (Should no thread be creatable, the count is done after the run instead.)
            let counting = std::thread::Builder::new().spawn_scoped(scope, move || count_at(tau));
            pending = counting.ok().map(|handle| (tau, handle));
        };
        let run = lanczos_run(
            &mut op,
            (k + buffer).min(n - 1),
            k,
            options.block_size,
            &[],
            0,
            options.tolerance,
            options.max_restarts,
            &mut rng,
            start,
            if concurrent { Some(&mut start_count) } else { None },
        );
        let early = pending.map(|(tau, handle)| (tau, joined(handle.join())));
        (run, early)
    });
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
        let residuals = |op: &mut Operator<'_>, two_threads: bool| {
            let clock = Instant::now();
            (
                pair_residuals(pencil, op, &refined, sigma, (norm_a, norm_b), two_threads),
                clock.elapsed(),
            )
        };
        // The early count when its τ still fits the refined modes; else a count now, beside the
        // residuals of the refined pairs.
        let (tau, (inertia, inertia_time), (residuals, residual_time)) =
            match early.take().filter(|(tau, _)| tau_is_clear(omega, *tau)) {
                Some((tau, counted)) => (tau, counted, residuals(&mut op, concurrent)),
                None => {
                    let tau = choose_tau(omega);
                    if concurrent {
                        std::thread::scope(|scope| {
                            match std::thread::Builder::new().spawn_scoped(scope, || count_at(tau)) {
                                Ok(counting) => {
                                    let residuals = residuals(&mut op, false);
                                    (tau, joined(counting.join()), residuals)
                                }
                                Err(_) => (tau, count_at(tau), residuals(&mut op, false)),
                            }
                        })
                    } else {
                        (tau, count_at(tau), residuals(&mut op, false))
                    }
                }
            };
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
            solution.report.shift_attempts = attempts;
            solution.report.factor_nnz = symbolic.len_val();
            solution.report.operator_applications = op.applications;
            solution.report.restarts = restarts;
            solution.report.lanczos_runs = runs;
            solution.report.timings = timings;
            solution.report.timings.solves = op.solve_time;
            return Ok(solution);
        }
        if runs >= max_runs {
            return Err(ModalError::LanczosNoConvergence {
                converged: below,
                wanted: inertia.count.below,
                restarts,
            });
        }
        // Missed modes (repeated eigenvalues): rerun deflated against everything found. A block
        // of `missing` vectors (≤ MAX_RERUN_BLOCK) sees every missing copy of an eigenvalue in one
        // run, whatever its multiplicity.
        let clock = Instant::now();
        let rerun_nev = (missing + 1).min(n.saturating_sub(cols + 1)).max(1);
        let (_, more, r) = lanczos_run(
            &mut op,
            rerun_nev,
            rerun_nev,
            options.block_size.max(missing.min(MAX_RERUN_BLOCK)),
            &refined.vectors,
            cols,
            options.tolerance,
            options.max_restarts,
            &mut rng,
            None,
            None,
        )?;
        timings.lanczos += clock.elapsed();
        restarts += r;
        runs += 1;
        found = refined.vectors;
        found.extend_from_slice(&more);
    }
}

/// Relative Ritz residual to which the buffer modes above the k-th converge. They serve only to
/// place the inertia shift τ in a real gap (relative width ≥ √u); after Rayleigh–Ritz their ω²
/// err by about the square of this, far inside such a gap.
const BUFFER_TOLERANCE: f64 = 1e-8;

/// Relative Ritz residual at which the first run's θ are good enough to place the inertia shift
/// τ (their ω² then err by about 1e-12 relative): the inertia count starts on a second thread
/// while Lanczos converges the rest of the way.
const ROUGH_TOLERANCE: f64 = 1e-6;

/// Largest block size of a deflated rerun.
const MAX_RERUN_BLOCK: usize = 32;

/// ω²_{j+1} − ω²_j relative to max(|ω²_j|, |ω²_{j+1}|) (0 past the end).
fn gap(omega: &[f64], j: usize) -> f64 {
    if j + 1 >= omega.len() {
        return 0.0;
    }
    let scale = omega[j].abs().max(omega[j + 1].abs()).max(f64::MIN_POSITIVE);
    (omega[j + 1] - omega[j]) / scale
}

/// Rayleigh–Ritz on span(X) for the original pencil.
struct Refined {
    omega_sq: Vec<f64>,
    /// n × cols column-major, A-orthonormal.
    vectors: Vec<f64>,
}

/// Rayleigh–Ritz on span(X) (n × cols, column-major) for the pencil (A, B): the finite Ritz
/// pairs of the projected pencil, ω² ascending, the vectors A-orthonormal.
fn rayleigh_ritz(
    a: Mass<'_>,
    b: faer::sparse::SparseColMatRef<'_, usize, f64>,
    x: &[f64],
    cols: usize,
) -> Result<Refined, ModalError> {
    let n = a.nrows();
    let mut ax = vec![0.0; n * cols];
    let mut bx = vec![0.0; n * cols];
    a.apply_block(&x[..n * cols], &mut ax);
    for c in 0..cols {
        mul(b, &x[n * c..n * (c + 1)], &mut bx[n * c..n * (c + 1)]);
    }
    let xm = MatRef::from_column_major_slice(x, n, cols);
    let pa = product(xm.transpose(), MatRef::from_column_major_slice(&ax, n, cols));
    let pb = product(xm.transpose(), MatRef::from_column_major_slice(&bx, n, cols));
    let sym = |m: &Mat<f64>| Mat::from_fn(cols, cols, |i, j| 0.5 * (m[(i, j)] + m[(j, i)]));
    let projected = PencilProblem::new(sym(&pa).as_ref(), sym(&pb).as_ref())?;
    let sol = solve(
        &projected,
        &SolveOptions {
            selection: Selection::All,
            vectors: true,
            refinement: Refinement::Off,
            ..SolveOptions::default()
        },
    )?;
    let y = sol.vectors.ok_or(ModalError::NoConvergence { n: cols })?;
    let finite = sol.modes.iter().take_while(|m| m.omega_sq.is_finite()).count();
    let mut vectors = vec![0.0; n * finite];
    product_into(&mut vectors, xm, y.subcols(0, finite));
    Ok(Refined {
        omega_sq: sol.modes[..finite].iter().map(|m| m.omega_sq).collect(),
        vectors,
    })
}

/// What the bounds of the refined pairs need: each Rayleigh quotient and its rounding, θ, the
/// first-order θ bound δ and the backward error η; and what the classification needs, the
/// data resolution of each ω² ([`crate::certify::resolution::data_resolution`]).
struct PairResiduals {
    omega_sq: Vec<f64>,
    theta: Vec<f64>,
    delta: Vec<f64>,
    eta: Vec<f64>,
    rounding: Vec<f64>,
    resolution: Vec<f64>,
}

/// The residuals of every refined pair: Rayleigh quotients and residuals in double-double, the
/// residual s = Ax − θKx solved with K (δ = ‖s‖_{K⁻¹}/‖x‖_K). With `two_threads` each thread
/// takes half of the pairs (about 60 ms of 130 on the 300×300 grid, k = 10).
fn pair_residuals(
    pencil: &SparsePencil,
    op: &mut Operator<'_>,
    refined: &Refined,
    sigma: f64,
    norms: (f64, f64),
    two_threads: bool,
) -> PairResiduals {
    let cols = refined.omega_sq.len();
    let (symbolic, values) = (op.symbolic, op.values.as_slice());
    let max_row = row_lengths(pencil.a()).max(row_lengths(pencil.b())) as f64;
    let shared = ResidualInputs {
        pencil,
        factor: (symbolic, values),
        refined,
        sigma,
        norms,
        max_row,
    };
    let (residuals, solve_time) = if two_threads && cols > 1 {
        let half = cols / 2;
        let work = &mut op.work;
        let (first, second) = std::thread::scope(|scope| {
            let second =
                std::thread::Builder::new().spawn_scoped(scope, || residuals_of(&shared, half..cols, &mut Vec::new()));
            let first = residuals_of(&shared, 0..half, work);
            (first, second.ok().and_then(|s| s.join().ok()))
        });
        // (No thread could be created, or it panicked, a bug: the pairs are then done here.)
        let second = second.unwrap_or_else(|| residuals_of(&shared, half..cols, work));
        let ((mut first, first_time), (second, second_time)) = (first, second);
        first.append(second);
        // The two halves' solves ran at the same time: the stage took the longer one.
        (first, first_time.max(second_time))
    } else {
        residuals_of(&shared, 0..cols, &mut op.work)
    };
    op.applications += cols;
    op.solve_time += solve_time;
    residuals
}

/// What every range of [`residuals_of`] reads.
struct ResidualInputs<'a> {
    pencil: &'a SparsePencil,
    /// The symbolic and numeric Cholesky factor of K.
    factor: (&'a SymbolicCholesky<usize>, &'a [f64]),
    refined: &'a Refined,
    sigma: f64,
    /// (‖A‖_F, ‖B‖_F).
    norms: (f64, f64),
    /// The longest row of A or B (entries), for the rounding term.
    max_row: f64,
}

impl PairResiduals {
    /// Appends the pairs of `other` after those of `self`.
    fn append(&mut self, other: PairResiduals) {
        self.omega_sq.extend(other.omega_sq);
        self.theta.extend(other.theta);
        self.delta.extend(other.delta);
        self.eta.extend(other.eta);
        self.rounding.extend(other.rounding);
        self.resolution.extend(other.resolution);
    }
}

/// [`pair_residuals`] of the refined pairs in `range`, their residuals solved in one block with
/// the factor of K; also returns the wall time of that solve.
fn residuals_of(
    inputs: &ResidualInputs<'_>,
    range: std::ops::Range<usize>,
    work: &mut Vec<f64>,
) -> (PairResiduals, Duration) {
    let ResidualInputs {
        pencil,
        factor: (symbolic, values),
        refined,
        sigma,
        norms: (norm_a, norm_b),
        max_row,
    } = *inputs;
    let n = pencil.dim();
    let (a, b) = (pencil.a(), pencil.b());
    let cols = range.len();
    let mut theta = vec![0.0; cols];
    let mut delta = vec![0.0; cols];
    let mut eta = vec![0.0; cols];
    let mut rounding = vec![0.0; cols];
    let mut resolution = vec![0.0; cols];
    let mut omega_sq = refined.omega_sq[range.clone()].to_vec();
    // Residuals s = Ax − θKx of every pair, solved with K in one block.
    let mut residuals = vec![0.0; n * cols];
    let mut xkx = vec![0.0; cols];
    let mut r = vec![0.0; n];
    for (c, pair) in range.enumerate() {
        let x = &refined.vectors[n * pair..n * (pair + 1)];
        // Rayleigh quotient and residuals in double-double: the bounds below then need no
        // first-order rounding term of size u·|x|ᵀ|B||x|.
        let bx_dd = dd::sparse_mat_vec(b, x);
        let ax_dd = dd::sparse_mat_vec(a, x);
        let xbx = dd::dot(x, &bx_dd);
        let xax = dd::dot(x, &ax_dd);
        let w = xbx.over(xax).to_f64();
        omega_sq[c] = w;
        let t = 1.0 / (w - sigma);
        theta[c] = t;
        // s = Ax − θ(Bx − σAx), r = Bx − ω²Ax; ‖x‖²_K = xᵀBx − σxᵀAx.
        dd::pencil_residuals(
            &ax_dd,
            &bx_dd,
            (w, t, sigma),
            &mut r,
            &mut residuals[n * c..n * (c + 1)],
        );
        xkx[c] = xbx.minus(Dd::of(sigma).times(xax)).to_f64();
        let xn = dot(x, x).sqrt();
        eta[c] = dot(&r, &r).sqrt() / ((norm_b + w.abs() * norm_a) * xn).max(f64::MIN_POSITIVE);
        let xax = xax.to_f64().max(f64::MIN_POSITIVE);
        // Rounding of the double-double quotient and its final rounding to double.
        let componentwise = (abs_quadratic(b, x) + w.abs() * abs_quadratic(a, x)) / xax;
        rounding[c] = 2.0 * f64::EPSILON * w.abs() + max_row * f64::EPSILON * f64::EPSILON * componentwise;
        resolution[c] = f64::EPSILON * componentwise;
    }
    let mut solved = residuals.clone();
    let clock = Instant::now();
    solve_with(symbolic, values, &mut solved, cols, work);
    let solve_time = clock.elapsed();
    for c in 0..cols {
        let sc = &residuals[n * c..n * (c + 1)];
        let kc = &solved[n * c..n * (c + 1)];
        delta[c] = (dot(sc, kc).max(0.0) / xkx[c].max(f64::MIN_POSITIVE)).sqrt();
    }
    let residuals = PairResiduals {
        omega_sq,
        theta,
        delta,
        eta,
        rounding,
        resolution,
    };
    (residuals, solve_time)
}

/// Bounds, classification and the report for the lowest k refined modes, from their residuals
/// and the inertia count at τ (σ the operator's shift).
#[allow(clippy::too_many_arguments)]
fn finish(
    a: Mass<'_>,
    refined: &Refined,
    residuals: PairResiduals,
    k: usize,
    (sigma, tau): (f64, f64),
    inertia: SparseInertia,
    below: usize,
    (norm_a, norm_b): (f64, f64),
) -> SparseModalSolution {
    let n = a.nrows();
    let cols = refined.omega_sq.len();
    let PairResiduals {
        omega_sq,
        theta,
        delta,
        eta,
        rounding,
        resolution,
    } = residuals;
    // Clusters of θ whose δ-intervals overlap; Kato–Temple with the gap to other clusters and to
    // θ(τ) (no eigenvalue with ω² < τ is unaccounted for when the inertia check passed).
    let theta_tau = 1.0 / (tau - sigma);
    let consistent = inertia.count.below == below && inertia.count.zero == 0;
    let mut bounds = vec![0.0; cols];
    for c in 0..cols {
        let in_cluster = |d: usize| (theta[c] - theta[d]).abs() <= delta[c] + delta[d];
        let mut g = if consistent && omega_sq[c] < tau {
            theta[c] - theta_tau
        } else {
            0.0
        };
        // Quadratic residual bound for a Rayleigh–Ritz cluster (Mathias, SIMAX 19, 1998):
        // |Δθ| ≤ ‖R‖²/gap with ‖R‖² ≤ Σ δ_d² over the cluster.
        let mut cluster_sq = 0.0;
        for d in 0..cols {
            if in_cluster(d) {
                cluster_sq += delta[d] * delta[d];
            } else {
                g = g.min((theta[c] - theta[d]).abs() - delta[d]);
            }
        }
        let e = if g > 0.0 {
            delta[c].min(cluster_sq / g)
        } else {
            delta[c]
        };
        let t = theta[c];
        let omega_bound = if t > e { e / (t * (t - e)) } else { f64::INFINITY };
        bounds[c] = omega_bound + rounding[c];
    }
    let take = k.min(cols);
    let mut modes: Vec<Mode> = (0..cols)
        .map(|c| Mode {
            lambda: -omega_sq[c],
            omega_sq: omega_sq[c],
            kind: classify(omega_sq[c], bounds[c].max(resolution[c])),
            error_bound: bounds[c],
            backward_error: Some(eta[c]),
            group: 0,
        })
        .collect();
    let kth_group_multiplicity = kth_group_multiplicity(&mut modes, take);
    modes.truncate(take);
    let groups = group_modes(&mut modes);
    let vectors = Mat::from_fn(n, take, |i, c| refined.vectors[i + n * c]);
    let orthogonality_error = orthogonality(a, &vectors);
    SparseModalSolution {
        report: SparseReport {
            shift: sigma,
            shift_attempts: 0,
            factor_nnz: 0,
            norm_a,
            norm_b,
            restarts: 0,
            operator_applications: 0,
            lanczos_runs: 0,
            kth_group_multiplicity,
            max_backward_error: eta[..take].iter().copied().fold(0.0, f64::max),
            orthogonality_error,
            inertia: Some(inertia),
            computed_below: below,
            consistent,
            dense_fallback: false,
            timings: SparseTimings::default(),
        },
        modes,
        vectors,
        groups,
    }
}

/// The multiplicity, among all of `modes` (ascending), of the group of mode `k` − 1 (0 when
/// k = 0), grouped as the returned modes are (ω² within the sum of their bounds).
fn kth_group_multiplicity(modes: &mut [Mode], k: usize) -> usize {
    if k == 0 || k > modes.len() {
        return 0;
    }
    let groups = group_modes(modes);
    groups.get(modes[k - 1].group).map_or(0, |g| g.multiplicity)
}

/// Largest number of stored entries in a column (= row, symmetric).
fn row_lengths(m: faer::sparse::SparseColMatRef<'_, usize, f64>) -> usize {
    (0..m.ncols())
        .map(|j| m.symbolic().col_range(j).len())
        .max()
        .unwrap_or(0)
}

/// max |(XᵀAX − I)_ij|.
fn orthogonality(a: Mass<'_>, x: &Mat<f64>) -> f64 {
    let (n, c) = (x.nrows(), x.ncols());
    let mut ax = Mat::<f64>::zeros(n, c);
    for j in 0..c {
        let (Some(xj), Some(axj)) = (
            x.col(j).try_as_col_major().map(|col| col.as_slice()),
            ax.col_mut(j).try_as_col_major_mut().map(|col| col.as_slice_mut()),
        ) else {
            continue;
        };
        a.apply(xj, axj);
    }
    let g = product(x.transpose(), ax.as_ref());
    let mut worst = 0.0_f64;
    for j in 0..c {
        for i in 0..c {
            let target = if i == j { 1.0 } else { 0.0 };
            worst = worst.max((g[(i, j)] - target).abs());
        }
    }
    worst
}

/// Small problems: the dense solver, with its report mapped onto the sparse one. The dense solve
/// asks for more than k modes until the k-th mode's group is seen to end; its accuracy fields
/// (backward error, orthogonality, inertia check) cover that superset of the returned modes.
fn dense_fallback(
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
        report: SparseReport {
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
            inertia: check.map(|c| SparseInertia {
                count: c.count,
                min_pivot: 0.0,
                max_pivot: 0.0,
            }),
            computed_below: check.map_or(0, |c| c.computed_below),
            consistent: check.is_some_and(|c| c.consistent),
            dense_fallback: true,
            timings: SparseTimings {
                refine: clock.elapsed(),
                ..SparseTimings::default()
            },
        },
        modes,
        vectors,
        groups,
    })
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

    /// The diagonal fast path is taken exactly for diagonal matrices, and agrees with the
    /// general product; n stored entries that are not the diagonal (a column with two, another
    /// with none) are not mistaken for it.
    #[test]
    fn mass_applies_diagonal_and_general_matrices_alike() {
        use faer::sparse::{SparseColMat, Triplet};
        let matrix = |entries: &[(usize, usize, f64)]| {
            let triplets: Vec<_> = entries.iter().map(|&(i, j, v)| Triplet::new(i, j, v)).collect();
            SparseColMat::<usize, f64>::try_new_from_triplets(3, 3, &triplets).expect("valid")
        };
        let x = [1.5, -2.0, 0.25];
        let diagonal = matrix(&[(0, 0, 2.0), (1, 1, 3.0), (2, 2, 4.0)]);
        let mass = Mass::of(diagonal.as_ref());
        assert!(matches!(mass, Mass::Diagonal(_)));
        let mut y = [0.0; 3];
        mass.apply(&x, &mut y);
        assert_eq!(y, [3.0, -6.0, 1.0]);
        let shifted = matrix(&[(0, 0, 2.0), (1, 0, 3.0), (2, 2, 4.0)]);
        let mass = Mass::of(shifted.as_ref());
        assert!(matches!(mass, Mass::Sparse(_)));
        mass.apply(&x, &mut y);
        assert_eq!(y, [3.0, 4.5, 1.0]);
    }

    /// A start vector that is exactly zero on the first chain: every Krylov vector stays exactly
    /// zero there (block-diagonal A and Cholesky factor, products with exact zeros), so the first
    /// run cannot see the lowest modes in any arithmetic. The inertia count must notice and the
    /// deflated rerun (random start) must find them.
    #[test]
    fn modes_invisible_from_the_start_block_are_recovered() {
        let len = 300;
        let (p, exact) = two_chains(len);
        let options = SparseOptions {
            count: 6,
            block_size: 1,
            ..SparseOptions::default()
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
        let single = SparseOptions { max_runs: 1, ..options };
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
            let options = SparseOptions {
                count: 8,
                block_size: block,
                ..SparseOptions::default()
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
