//! The k lowest modes of a large sparse pencil (A, B) by shift-invert Lanczos (issue part 5).
//!
//! - **Operator.** With a shift σ below the lowest mode, K = B − σA is positive definite and
//!   factored once by faer's sparse Cholesky (AMD ordering). T = K⁻¹A is self-adjoint in the
//!   A-inner product and has the eigenvalues θ = 1/(ω² − σ) > 0: the lowest ω² are the largest θ,
//!   well separated. A successful Cholesky factorization of K certifies that no mode lies below σ
//!   (Sylvester). The automatic σ is −√u·‖B‖_F/‖A‖_F, lowered by factors of 1000 while K is not
//!   positive definite (unstable modes).
//! - **Iteration.** Lanczos in the A-inner product with full (twice-applied, Gram–Schmidt)
//!   reorthogonalisation and thick restarts (Wu & Simon, SIMAX 22, 2000; in Krylov–Schur form,
//!   Stewart, SIMAX 23, 2001): the basis holds at most m = max(2·nev + 8, 20) vectors, so memory
//!   is O(nnz(L) + n·m).
//! - **Refinement.** The converged Ritz vectors are Rayleigh–Ritz-projected onto the original
//!   pencil (the dense solver on XᵀBX, XᵀAX), which makes them A-orthonormal and gives each ω²
//!   as a Rayleigh quotient.
//! - **Certification.** The inertia of B − τA ([`crate::count_below_sparse`]) at a shift τ in the
//!   widest gap above the k-th mode must equal the number of computed modes below τ. When it is
//!   larger, modes were missed (a single-vector Krylov space sees one vector per eigenspace of a
//!   repeated eigenvalue in exact arithmetic): Lanczos is rerun deflated against every found
//!   vector until the counts agree.
//! - **Bounds.** For a pair with θ = 1/(ω² − σ) the residual s = Ax − θKx gives
//!   δ = ‖s‖_{K⁻¹}/‖x‖_K (one solve with K): the pencil (A, K) has an eigenvalue within δ of θ
//!   (Parlett, "The Symmetric Eigenvalue Problem", Thm 15.9.1), and within δ²/gap (Kato–Temple)
//!   when the gap to the rest of the spectrum is known, which the inertia count makes rigorous
//!   (nothing else lies below τ). Mapped to ω²: |Δω²| ≤ e/(θ(θ − e)) with e the θ bound, plus the
//!   rounding of the Rayleigh quotient.

use crate::dd::{self, Dd};
use crate::solve::{Mode, ModeGroup, classify, group_modes};
use crate::sparse_inertia::{SparseInertia, inertia_with, symbolic_supernodal};
use crate::sparse_pencil::{Csc, SparsePencil, abs_quadratic, frobenius, mul};
use crate::{ModalError, PencilProblem, Refinement, Selection, SolveOptions, solve};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::LltError;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::{ColRef, Mat, MatMut, MatRef, Side};
use std::time::{Duration, Instant};

/// Options of [`solve_sparse`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SparseOptions {
    /// Number k of lowest modes wanted (1 ≤ k < n).
    pub count: usize,
    /// Shift σ (rad²/s²) below the lowest mode; None: automatic (see the module documentation).
    pub shift: Option<f64>,
    /// Convergence: Ritz residual ≤ tolerance·θ for every wanted pair.
    pub tolerance: f64,
    /// Maximal number of thick restarts per Lanczos run.
    pub max_restarts: usize,
    /// Seed of the pseudo-random start vectors.
    pub seed: u64,
}

impl Default for SparseOptions {
    fn default() -> Self {
        Self {
            count: 10,
            shift: None,
            tolerance: 1e-12,
            max_restarts: 300,
            seed: 1,
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
    /// Inertia (Sturm) checks.
    pub inertia: Duration,
}

/// How the sparse result was obtained and how accurate it is.
#[derive(Debug, Clone, PartialEq)]
pub struct SparseReport {
    /// The shift σ of the factored operator (every mode lies above it).
    pub shift: f64,
    /// Cholesky factorizations tried to find a positive definite B − σA.
    pub shift_attempts: usize,
    /// ‖A‖_F and ‖B‖_F.
    pub norm_a: f64,
    /// ‖B‖_F.
    pub norm_b: f64,
    /// Thick restarts over all Lanczos runs.
    pub restarts: usize,
    /// Applications of K⁻¹A.
    pub operator_applications: usize,
    /// Lanczos runs (1 + deflated reruns for missed modes).
    pub lanczos_runs: usize,
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

/// At or below this order the sparse solver converts to dense and calls [`crate::solve`].
pub const DENSE_LIMIT: usize = 400;

/// Shift-invert operator x ↦ K⁻¹(Ax).
struct Operator<'a> {
    llt: Llt<usize, f64>,
    a: faer::sparse::SparseColMatRef<'a, usize, f64>,
    applications: usize,
}

impl Operator<'_> {
    fn apply(&mut self, x: &[f64], out: &mut [f64]) {
        mul(self.a, x, out);
        self.solve(out);
        self.applications += 1;
    }

    fn solve(&self, x: &mut [f64]) {
        let n = x.len();
        self.llt.solve_in_place(MatMut::from_column_major_slice_mut(x, n, 1));
    }
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

fn dot(x: &[f64], y: &[f64]) -> f64 {
    x.iter().zip(y).map(|(a, b)| a * b).sum()
}

/// A-orthogonalises `w` against the columns of `basis` (n × cols, column-major) and of
/// `locked`, twice (classical Gram–Schmidt with reorthogonalisation); returns the coefficients
/// against `basis` and ‖w‖_A² afterwards.
fn orthogonalise(
    a: faer::sparse::SparseColMatRef<'_, usize, f64>,
    basis: &[f64],
    cols: usize,
    locked: &[f64],
    locked_cols: usize,
    w: &mut [f64],
    scratch: &mut [f64],
) -> (Vec<f64>, f64) {
    let n = w.len();
    let mut total = vec![0.0; cols];
    for _ in 0..2 {
        mul(a, w, scratch);
        let z = ColRef::from_slice(scratch);
        if cols > 0 {
            let v = MatRef::from_column_major_slice(&basis[..n * cols], n, cols);
            let h = v.transpose() * z;
            let update = v * &h;
            for i in 0..n {
                w[i] -= update[i];
            }
            for (t, i) in total.iter_mut().zip(0..cols) {
                *t += h[i];
            }
        }
        if locked_cols > 0 {
            let x = MatRef::from_column_major_slice(&locked[..n * locked_cols], n, locked_cols);
            let h = x.transpose() * z;
            let update = x * &h;
            for i in 0..n {
                w[i] -= update[i];
            }
        }
    }
    mul(a, w, scratch);
    (total, dot(w, scratch))
}

/// One thick-restart Lanczos run for the `nev` largest θ of T restricted to the A-orthogonal
/// complement of `locked`. Returns (θ descending, n × nev Ritz vectors column-major, restarts).
#[allow(clippy::too_many_arguments)]
fn lanczos_run(
    op: &mut Operator<'_>,
    nev: usize,
    locked: &[f64],
    locked_cols: usize,
    tolerance: f64,
    max_restarts: usize,
    rng: &mut Lcg,
) -> Result<(Vec<f64>, Vec<f64>, usize), ModalError> {
    let a = op.a;
    let n = a.nrows();
    let room = n.saturating_sub(locked_cols);
    let m = (2 * nev + 8).max(20).min(room);
    let nev = nev.min(m.saturating_sub(1)).max(1);
    let mut basis = vec![0.0; n * (m + 1)];
    let mut h = Mat::<f64>::zeros(m + 1, m);
    let mut scratch = vec![0.0; n];
    let mut w = vec![0.0; n];
    // Start vector: random, A-orthogonal to the locked vectors, A-normalised.
    let mut start = |w: &mut [f64], basis: &[f64], cols: usize, scratch: &mut [f64]| -> Result<(), ModalError> {
        for attempt in 0..8 {
            for x in w.iter_mut() {
                *x = rng.next();
            }
            let (_, norm_sq) = orthogonalise(a, basis, cols, locked, locked_cols, w, scratch);
            if norm_sq < 0.0 {
                return Err(ModalError::MassNotSemidefinite { value: norm_sq });
            }
            if norm_sq > 0.0 {
                let s = norm_sq.sqrt().recip();
                w.iter_mut().for_each(|x| *x *= s);
                return Ok(());
            }
            let _ = attempt;
        }
        Err(ModalError::LanczosNoConvergence {
            converged: 0,
            wanted: nev,
            restarts: 0,
        })
    };
    start(&mut w, &basis, 0, &mut scratch)?;
    basis[..n].copy_from_slice(&w);
    let mut kept = 0usize;
    let mut restarts = 0usize;
    loop {
        for j in kept..m {
            let (done, rest) = basis.split_at_mut(n * (j + 1));
            let vj = &done[n * j..n * (j + 1)];
            op.apply(vj, &mut w);
            let (coefficients, norm_sq) = orthogonalise(a, done, j + 1, locked, locked_cols, &mut w, &mut scratch);
            for (i, c) in coefficients.iter().enumerate() {
                h[(i, j)] = *c;
            }
            // The coupling θ-scale: |h_jj| ~ θ; an A-norm below u·θ·‖v‖ means an invariant subspace.
            let scale = coefficients.iter().fold(0.0_f64, |s, c| s.max(c.abs()));
            if norm_sq < -(f64::EPSILON * scale).powi(2) * 1e4 {
                return Err(ModalError::MassNotSemidefinite { value: norm_sq });
            }
            let beta = norm_sq.max(0.0).sqrt();
            let next = &mut rest[..n];
            if beta > 1e3 * f64::EPSILON * scale {
                let s = beta.recip();
                for (x, y) in next.iter_mut().zip(&w) {
                    *x = y * s;
                }
                h[(j + 1, j)] = beta;
            } else {
                // Invariant subspace found: continue with a fresh direction, coupling 0.
                start(&mut w, done, j + 1, &mut scratch)?;
                next.copy_from_slice(&w);
                h[(j + 1, j)] = 0.0;
            }
        }
        // Ritz pairs of the symmetrised projected matrix.
        let hm = Mat::from_fn(m, m, |i, j| 0.5 * (h[(i, j)] + h[(j, i)]));
        let eig = hm
            .self_adjoint_eigen(Side::Lower)
            .map_err(|_| ModalError::NoConvergence { n: m })?;
        let theta: Vec<f64> = (0..m).map(|i| eig.S()[i]).collect();
        let y = eig.U();
        // Wanted: the nev largest θ (last columns). Residual |c·y| with c the coupling row m.
        let residual = |col: usize| -> f64 { (0..m).map(|i| h[(m, i)] * y[(i, col)]).sum::<f64>().abs() };
        let wanted: Vec<usize> = (0..nev).map(|r| m - 1 - r).collect();
        let converged = wanted
            .iter()
            .filter(|&&c| residual(c) <= tolerance * theta[c].abs())
            .count();
        let v = MatRef::from_column_major_slice(&basis[..n * m], n, m);
        if converged == nev {
            let ys = Mat::from_fn(m, nev, |i, r| y[(i, wanted[r])]);
            let x = v * &ys;
            let mut out = vec![0.0; n * nev];
            for r in 0..nev {
                for i in 0..n {
                    out[i + n * r] = x[(i, r)];
                }
            }
            return Ok((wanted.iter().map(|&c| theta[c]).collect(), out, restarts));
        }
        if restarts >= max_restarts {
            return Err(ModalError::LanczosNoConvergence {
                converged,
                wanted: nev,
                restarts,
            });
        }
        restarts += 1;
        // Thick restart: keep the p largest Ritz vectors and the residual direction.
        let p = (nev + (m - nev) / 2).min(m - 1).max(nev);
        let keep: Vec<usize> = (0..p).map(|r| m - 1 - r).collect();
        let ys = Mat::from_fn(m, p, |i, r| y[(i, keep[r])]);
        let x = v * &ys;
        let coupling: Vec<f64> = keep.iter().map(|&c| (0..m).map(|i| h[(m, i)] * y[(i, c)]).sum()).collect();
        let residual_vector: Vec<f64> = basis[n * m..n * (m + 1)].to_vec();
        for r in 0..p {
            for i in 0..n {
                basis[i + n * r] = x[(i, r)];
            }
        }
        basis[n * p..n * (p + 1)].copy_from_slice(&residual_vector);
        h.fill(0.0);
        for r in 0..p {
            h[(r, r)] = theta[keep[r]];
            h[(p, r)] = coupling[r];
        }
        kept = p;
    }
}

/// Solves for the `options.count` lowest modes of the sparse pencil. See the module documentation.
pub fn solve_sparse(pencil: &SparsePencil, options: &SparseOptions) -> Result<SparseModalSolution, ModalError> {
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
    let symbolic = SymbolicLlt::try_new(pattern.to_faer().symbolic(), Side::Lower).map_err(|e| {
        ModalError::Factorization {
            what: "B − σA (symbolic)",
            detail: format!("{e:?}"),
        }
    })?;
    let ratio = if norm_a > 0.0 { norm_b / norm_a } else { 1.0 };
    let mut sigma = options.shift.unwrap_or(-f64::EPSILON.sqrt() * ratio.max(f64::MIN_POSITIVE));
    let mut attempts = 0;
    let (llt, sigma) = loop {
        attempts += 1;
        let kmat = Csc::combine(1.0, &cb, -sigma, &ca).to_faer();
        match Llt::try_new_with_symbolic(symbolic.clone(), kmat.as_ref(), Side::Lower) {
            Ok(llt) => break (llt, sigma),
            Err(LltError::Numeric(e)) => {
                let pivot = match e {
                    faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index } => index,
                };
                if options.shift.is_some() || attempts >= 6 {
                    return Err(ModalError::NoDefiniteShift {
                        lowest_shift: sigma,
                        pivot,
                    });
                }
                sigma *= 1e3;
            }
            Err(LltError::Generic(e)) => {
                return Err(ModalError::Factorization {
                    what: "B − σA",
                    detail: format!("{e:?}"),
                });
            }
        }
    };
    timings.factor = clock.elapsed();
    let mut op = Operator {
        llt,
        a,
        applications: 0,
    };
    let mut rng = Lcg(options.seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ 0x5851_f42d_4c95_7f2d);
    // First run: k plus a buffer, so that a gap above the k-th mode is seen.
    let buffer = (k / 4).clamp(2, 10);
    let clock = Instant::now();
    let (_, mut found, mut restarts) = lanczos_run(
        &mut op,
        (k + buffer).min(n - 1),
        &[],
        0,
        options.tolerance,
        options.max_restarts,
        &mut rng,
    )?;
    timings.lanczos += clock.elapsed();
    let mut runs = 1;
    let inertia_symbolic = symbolic_supernodal(&pattern)?;
    loop {
        let clock = Instant::now();
        let cols = found.len() / n;
        let refined = rayleigh_ritz(pencil, &found, cols)?;
        timings.refine += clock.elapsed();
        let omega = &refined.omega_sq;
        // τ in the widest gap between the k-th mode and the last one found.
        let last = cols - 1;
        let kth = (k - 1).min(last);
        let tau = if kth < last {
            let j = (kth..last)
                .max_by(|&i, &j| gap(omega, i).total_cmp(&gap(omega, j)))
                .unwrap_or(kth);
            0.5 * (omega[j] + omega[j + 1])
        } else {
            omega[last] + 0.5 * (omega[last] - sigma).abs()
        };
        let below = omega.partition_point(|&w| w < tau);
        let clock = Instant::now();
        let kmat = Csc::combine(1.0, &cb, -tau, &ca);
        let inertia = inertia_with(&inertia_symbolic, &kmat, tau)?;
        timings.inertia += clock.elapsed();
        let missing = inertia.count.below.saturating_sub(below);
        if missing == 0 || runs >= 6 {
            let clock = Instant::now();
            let solution = finish(
                pencil,
                &mut op,
                refined,
                k,
                sigma,
                tau,
                inertia,
                below,
                (norm_a, norm_b),
            )?;
            timings.refine += clock.elapsed();
            let mut solution = solution;
            solution.report.shift_attempts = attempts;
            solution.report.restarts = restarts;
            solution.report.lanczos_runs = runs;
            solution.report.timings = timings;
            return Ok(solution);
        }
        // Missed modes (repeated eigenvalues): rerun deflated against everything found.
        let clock = Instant::now();
        let (_, more, r) = lanczos_run(
            &mut op,
            (missing + 1).min(n - cols - 1).max(1),
            &refined.vectors,
            cols,
            options.tolerance,
            options.max_restarts,
            &mut rng,
        )?;
        timings.lanczos += clock.elapsed();
        restarts += r;
        runs += 1;
        found = refined.vectors;
        found.extend_from_slice(&more);
    }
}

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

fn rayleigh_ritz(pencil: &SparsePencil, x: &[f64], cols: usize) -> Result<Refined, ModalError> {
    let n = pencil.dim();
    let (a, b) = (pencil.a(), pencil.b());
    let mut ax = vec![0.0; n * cols];
    let mut bx = vec![0.0; n * cols];
    for c in 0..cols {
        mul(a, &x[n * c..n * (c + 1)], &mut ax[n * c..n * (c + 1)]);
        mul(b, &x[n * c..n * (c + 1)], &mut bx[n * c..n * (c + 1)]);
    }
    let xm = MatRef::from_column_major_slice(x, n, cols);
    let pa = xm.transpose() * MatRef::from_column_major_slice(&ax, n, cols);
    let pb = xm.transpose() * MatRef::from_column_major_slice(&bx, n, cols);
    let sym = |m: &Mat<f64>| Mat::from_fn(cols, cols, |i, j| 0.5 * (m[(i, j)] + m[(j, i)]));
    let projected = PencilProblem::new(sym(&pa).as_ref(), sym(&pb).as_ref())?;
    let sol = solve(
        &projected,
        &SolveOptions {
            selection: Selection::All,
            vectors: true,
            refinement: Refinement::Off,
        },
    )?;
    let y = sol.vectors.ok_or(ModalError::NoConvergence { n: cols })?;
    let finite = sol.modes.iter().take_while(|m| m.omega_sq.is_finite()).count();
    let z = xm * y.subcols(0, finite);
    let mut vectors = vec![0.0; n * finite];
    for c in 0..finite {
        for i in 0..n {
            vectors[i + n * c] = z[(i, c)];
        }
    }
    Ok(Refined {
        omega_sq: sol.modes[..finite].iter().map(|m| m.omega_sq).collect(),
        vectors,
    })
}

/// Bounds, backward errors, classification and the report for the lowest k refined modes.
#[allow(clippy::too_many_arguments)]
fn finish(
    pencil: &SparsePencil,
    op: &mut Operator<'_>,
    refined: Refined,
    k: usize,
    sigma: f64,
    tau: f64,
    inertia: SparseInertia,
    below: usize,
    (norm_a, norm_b): (f64, f64),
) -> Result<SparseModalSolution, ModalError> {
    let n = pencil.dim();
    let (a, b) = (pencil.a(), pencil.b());
    let cols = refined.omega_sq.len();
    let max_row = row_lengths(a).max(row_lengths(b)) as f64;
    // θ and the first-order θ bound δ of every refined pair.
    let mut theta = vec![0.0; cols];
    let mut delta = vec![0.0; cols];
    let mut eta = vec![0.0; cols];
    let mut rounding = vec![0.0; cols];
    let mut omega_sq = refined.omega_sq.clone();
    for c in 0..cols {
        let x = &refined.vectors[n * c..n * (c + 1)];
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
        // s = Ax − θ(Bx − σAx); ‖s‖²_{K⁻¹} = sᵀK⁻¹s; ‖x‖²_K = xᵀBx − σxᵀAx.
        let (td, sd) = (Dd::of(t), Dd::of(sigma));
        let s: Vec<f64> = (0..n)
            .map(|i| ax_dd[i].minus(td.times(bx_dd[i].minus(sd.times(ax_dd[i])))).to_f64())
            .collect();
        let mut ks = s.clone();
        op.solve(&mut ks);
        let xkx = xbx.minus(sd.times(xax)).to_f64();
        delta[c] = (dot(&s, &ks).max(0.0) / xkx.max(f64::MIN_POSITIVE)).sqrt();
        let wd = Dd::of(w);
        let r: Vec<f64> = (0..n).map(|i| bx_dd[i].minus(wd.times(ax_dd[i])).to_f64()).collect();
        let xn = dot(x, x).sqrt();
        eta[c] = dot(&r, &r).sqrt() / ((norm_b + w.abs() * norm_a) * xn).max(f64::MIN_POSITIVE);
        let xax = xax.to_f64().max(f64::MIN_POSITIVE);
        // Rounding of the double-double quotient and its final rounding to double.
        rounding[c] = 2.0 * f64::EPSILON * w.abs()
            + max_row * f64::EPSILON * f64::EPSILON * (abs_quadratic(b, x) + w.abs() * abs_quadratic(a, x)) / xax;
    }
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
    let mut modes: Vec<Mode> = (0..take)
        .map(|c| Mode {
            lambda: -omega_sq[c],
            omega_sq: omega_sq[c],
            kind: classify(omega_sq[c], bounds[c]),
            error_bound: bounds[c],
            backward_error: Some(eta[c]),
            group: 0,
        })
        .collect();
    let groups = group_modes(&mut modes);
    let vectors = Mat::from_fn(n, take, |i, c| refined.vectors[i + n * c]);
    let orthogonality_error = orthogonality(a, &vectors);
    Ok(SparseModalSolution {
        report: SparseReport {
            shift: sigma,
            shift_attempts: 0,
            norm_a,
            norm_b,
            restarts: 0,
            operator_applications: op.applications,
            lanczos_runs: 0,
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
    })
}

/// Largest number of stored entries in a column (= row, symmetric).
fn row_lengths(m: faer::sparse::SparseColMatRef<'_, usize, f64>) -> usize {
    (0..m.ncols()).map(|j| m.symbolic().col_range(j).len()).max().unwrap_or(0)
}

/// max |(XᵀAX − I)_ij|.
fn orthogonality(a: faer::sparse::SparseColMatRef<'_, usize, f64>, x: &Mat<f64>) -> f64 {
    let (n, c) = (x.nrows(), x.ncols());
    let mut ax = Mat::<f64>::zeros(n, c);
    let mut col = vec![0.0; n];
    let mut out = vec![0.0; n];
    for j in 0..c {
        for i in 0..n {
            col[i] = x[(i, j)];
        }
        mul(a, &col, &mut out);
        for i in 0..n {
            ax[(i, j)] = out[i];
        }
    }
    let g = x.transpose() * &ax;
    let mut worst = 0.0_f64;
    for j in 0..c {
        for i in 0..c {
            let target = if i == j { 1.0 } else { 0.0 };
            worst = worst.max((g[(i, j)] - target).abs());
        }
    }
    worst
}

/// Small problems: the dense solver, with its report mapped onto the sparse one.
fn dense_fallback(pencil: &SparsePencil, k: usize, norm_a: f64, norm_b: f64) -> Result<SparseModalSolution, ModalError> {
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
    let sol = solve(
        &problem,
        &SolveOptions {
            selection: Selection::Lowest(k),
            vectors: true,
            refinement: Refinement::Auto,
        },
    )?;
    let vectors = sol.vectors.clone().unwrap_or_else(|| Mat::zeros(n, 0));
    let check = sol.accuracy.inertia_check;
    Ok(SparseModalSolution {
        report: SparseReport {
            shift: f64::NEG_INFINITY,
            shift_attempts: 0,
            norm_a,
            norm_b,
            restarts: 0,
            operator_applications: 0,
            lanczos_runs: 0,
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
        modes: sol.modes,
        vectors,
        groups: sol.groups,
    })
}
