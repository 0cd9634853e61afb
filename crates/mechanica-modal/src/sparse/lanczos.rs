//! Block thick-restart Lanczos in the A-inner product for the largest eigenvalues θ of
//! T = K⁻¹A, with full reorthogonalisation (block Gram–Schmidt, repeated when a column loses
//! more than 1 − 1/√2 of its A-norm) and thick restarts (Wu & Simon, SIMAX 22, 2000; in
//! Krylov–Schur form, Stewart, SIMAX 23, 2001).

use crate::error::ModalError;
use crate::sparse::operator::{Mass, Operator, dot, product, product_into};
use crate::tuning::Tuning;
use faer::{Mat, MatMut, MatRef, Par, Side};

/// Pseudo-random numbers in [−1, 1).
pub(crate) struct Lcg(pub(crate) u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        2.0 * ((self.0 >> 11) as f64 / (1u64 << 53) as f64) - 1.0
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
/// [`Tuning::buffer_tolerance`]. `rough`, when given, is called once with the nev θ
/// (descending) as soon as all of them have converged to [`Tuning::rough_tolerance`] (not when
/// they converge fully at the first check). Convergence is checked after every block step, not
/// only when the basis is full: the projected problem is tiny (at most m columns), and a run
/// then stops at the first block at which every wanted pair has converged instead of finishing
/// the cycle. Returns (θ descending, n × nev Ritz vectors, restarts).
#[allow(clippy::too_many_arguments)]
pub(crate) fn lanczos_run(
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
    let locked = Locked {
        vectors: locked,
        cols: locked_cols,
    };
    let mut krylov = Krylov::start(op.a, nev, block, locked, rng, start)?;
    loop {
        krylov.expand(op, locked, rng)?;
        if krylov.cols < nev + krylov.b {
            continue;
        }
        let ritz = RitzPairs::of(&krylov.h, krylov.cols, krylov.b)?;
        let wanted: Vec<usize> = (0..nev).map(|r| krylov.cols - 1 - r).collect();
        let converged = converged_count(&ritz, &wanted, strict, tolerance);
        if converged < nev
            && wanted
                .iter()
                .all(|&c| ritz.residual(c) <= Tuning::DEFAULT.rough_tolerance * ritz.theta[c].abs())
            && let Some(hook) = rough.take()
        {
            hook(&wanted.iter().map(|&c| ritz.theta[c]).collect::<Vec<_>>());
        }
        if converged == nev {
            let vectors = krylov.ritz_vectors(&ritz, &wanted);
            return Ok((
                wanted.iter().map(|&c| ritz.theta[c]).collect(),
                vectors,
                krylov.restarts,
            ));
        }
        if krylov.cols < krylov.m {
            continue;
        }
        if krylov.restarts >= max_restarts {
            return Err(ModalError::LanczosNoConvergence {
                converged,
                wanted: nev,
                restarts: krylov.restarts,
            });
        }
        krylov.restart(&ritz);
    }
}

/// The vectors a run stays A-orthogonal to (n × `cols`, column-major).
#[derive(Clone, Copy)]
struct Locked<'a> {
    vectors: &'a [f64],
    cols: usize,
}

/// How many of the `wanted` Ritz pairs have converged: the first `strict` to `tolerance`, the
/// rest to the larger of it and [`Tuning::buffer_tolerance`], relative to θ.
fn converged_count(ritz: &RitzPairs, wanted: &[usize], strict: usize, tolerance: f64) -> usize {
    wanted
        .iter()
        .enumerate()
        .filter(|&(r, &c)| {
            let limit = if r < strict {
                tolerance
            } else {
                tolerance.max(Tuning::DEFAULT.buffer_tolerance)
            };
            ritz.residual(c) <= limit * ritz.theta[c].abs()
        })
        .count()
}

/// The Krylov basis of a run: m columns (a multiple of the block size b) plus one residual
/// block, the projected matrix H, and the work blocks of an expansion.
struct Krylov<'a> {
    a: Mass<'a>,
    n: usize,
    /// The number of wanted values.
    nev: usize,
    b: usize,
    m: usize,
    basis: Vec<f64>,
    /// Second basis buffer for the restarts (allocated at the first).
    spare: Vec<f64>,
    h: Mat<f64>,
    scratch: Vec<f64>,
    w: Vec<f64>,
    /// Columns of the basis filled.
    cols: usize,
    /// Columns kept by the last restart (0 before the first).
    kept: usize,
    restarts: usize,
}

impl<'a> Krylov<'a> {
    /// The basis of a run for `nev` values with block size `block` (clamped to the room left
    /// beside the locked vectors): m = max(2·nev + 4b, [`Tuning::lanczos_min_basis`]) rounded
    /// up to a multiple of b, since a larger basis saves no operator application, only
    /// orthogonalisation work. Its first block is the start block (given or random),
    /// A-orthonormal and A-orthogonal to the locked vectors.
    fn start(
        a: Mass<'a>,
        nev: usize,
        block: usize,
        locked: Locked<'_>,
        rng: &mut Lcg,
        start: Option<&[f64]>,
    ) -> Result<Self, ModalError> {
        let n = a.nrows();
        let room = n.saturating_sub(locked.cols);
        let b = block.clamp(1, (room / 4).max(1));
        let wanted_m = (2 * nev + 4 * b).max(Tuning::DEFAULT.lanczos_min_basis);
        let m = (wanted_m.div_ceil(b) * b).min((room.saturating_sub(b) / b) * b);
        if m < 2 * b || nev >= m {
            return Err(ModalError::TooManyModes {
                requested: nev + locked.cols,
                available: n,
            });
        }
        let mut basis = vec![0.0; n * (m + b)];
        let h = Mat::<f64>::zeros(m + b, m);
        let mut scratch = vec![0.0; n * b];
        let mut w = vec![0.0; n * b];
        match start {
            Some(given) if given.len() == w.len() => w.copy_from_slice(given),
            _ => w.iter_mut().for_each(|x| *x = rng.next()),
        }
        let _ = orthogonalise_block(a, &[], 0, 0, locked.vectors, locked.cols, &mut w, &mut scratch);
        normalise_block(
            a,
            &[],
            0,
            locked.vectors,
            locked.cols,
            &mut w,
            1.0,
            rng,
            &mut scratch[..n],
        )?;
        basis[..n * b].copy_from_slice(&w);
        Ok(Self {
            a,
            n,
            nev,
            b,
            m,
            basis,
            spare: Vec::new(),
            h,
            scratch,
            w,
            cols: 0,
            kept: 0,
            restarts: 0,
        })
    }

    /// Expands the basis by one block: W = K⁻¹A V_last, A-orthogonalised against the basis and
    /// the locked vectors, A-orthonormalised, its coefficients written into H.
    fn expand(&mut self, op: &mut Operator<'_>, locked: Locked<'_>, rng: &mut Lcg) -> Result<(), ModalError> {
        let (a, n, b, cols) = (self.a, self.n, self.b, self.cols);
        let current = &self.basis[n * cols..n * (cols + b)];
        a.apply_block(current, &mut self.w);
        op.solve_block(&mut self.w, b);
        // The recurrence couples the block to the previous one, or after a restart (and at the
        // start) to every kept Ritz vector.
        let coupled_from = if cols == self.kept { 0 } else { cols - b };
        let coefficients = orthogonalise_block(
            a,
            &self.basis,
            cols + b,
            coupled_from,
            locked.vectors,
            locked.cols,
            &mut self.w,
            &mut self.scratch,
        );
        let scale = (0..cols + b)
            .flat_map(|i| (0..b).map(move |c| (i, c)))
            .fold(0.0_f64, |s, (i, c)| s.max(coefficients[(i, c)].abs()));
        let r = normalise_block(
            a,
            &self.basis,
            cols + b,
            locked.vectors,
            locked.cols,
            &mut self.w,
            scale,
            rng,
            &mut self.scratch[..n],
        )?;
        for c in 0..b {
            for i in 0..cols + b {
                self.h[(i, cols + c)] = coefficients[(i, c)];
            }
            for i in 0..b {
                self.h[(cols + b + i, cols + c)] = r[(i, c)];
            }
        }
        self.basis[n * (cols + b)..n * (cols + 2 * b)].copy_from_slice(&self.w);
        self.cols += b;
        Ok(())
    }

    /// The filled columns of the basis.
    fn filled(&self) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(&self.basis[..self.n * self.cols], self.n, self.cols)
    }

    /// The Ritz vectors V·Y of the `wanted` pairs (n × nev, column-major).
    fn ritz_vectors(&self, ritz: &RitzPairs, wanted: &[usize]) -> Vec<f64> {
        let ys = Mat::from_fn(self.cols, wanted.len(), |i, r| ritz.y[(i, wanted[r])]);
        let mut out = vec![0.0; self.n * wanted.len()];
        product_into(&mut out, self.filled(), ys.as_ref());
        out
    }

    /// Thick restart: keeps the p largest Ritz vectors and the residual block, with
    /// p ≡ m (mod b) so that the expansions fill the basis exactly. The new basis is formed in
    /// the spare buffer, which then becomes the basis.
    fn restart(&mut self, ritz: &RitzPairs) {
        let (n, b, m) = (self.n, self.b, self.m);
        self.restarts += 1;
        let nev = self.nev;
        let p_wanted = (nev + (m - nev) / 2).min(m - b).max(nev);
        let p = m - (m - p_wanted).div_ceil(b) * b;
        let keep: Vec<usize> = (0..p).map(|r| m - 1 - r).collect();
        let ys = Mat::from_fn(m, p, |i, r| ritz.y[(i, keep[r])]);
        let mut spare = std::mem::take(&mut self.spare);
        spare.resize(self.basis.len(), 0.0);
        product_into(&mut spare[..n * p], self.filled(), ys.as_ref());
        spare[n * p..n * (p + b)].copy_from_slice(&self.basis[n * m..n * (m + b)]);
        self.spare = std::mem::replace(&mut self.basis, spare);
        self.h.fill(0.0);
        for r in 0..p {
            self.h[(r, r)] = ritz.theta[keep[r]];
            for i in 0..b {
                self.h[(p + i, r)] = ritz.coupling[(i, keep[r])];
            }
        }
        self.cols = p;
        self.kept = p;
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
