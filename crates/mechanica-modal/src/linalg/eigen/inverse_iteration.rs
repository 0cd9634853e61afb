//! Eigenvectors of a symmetric tridiagonal matrix T for a few given eigenvalues, by inverse
//! iteration, and shifted solves (T − σI)v = w: what a values-only solve needs to certify the
//! handful of modes whose a-priori bound is too weak (see [`crate::values_only`]).
//!
//! Method (Wilkinson, "The Algebraic Eigenvalue Problem", §5.54–5.62; organised as LAPACK
//! `dstein`, Jessup & Ipsen, "Improving the accuracy of inverse iteration", SISSC 13, 1992):
//! T is scaled to unit 1-norm; for each eigenvalue θ the LU factorization of T − θI with
//! partial pivoting is formed once (zero pivots replaced by u·‖T‖, Wilkinson's perturbation),
//! and a pseudo-random start vector is solved with it until its growth shows that the residual
//! of the normalised iterate is at most √(10n)·n·u·‖T‖₁ (`dstein`'s test), plus one extra step.
//! Eigenvalues closer than 10⁻³‖T‖₁ form a cluster: each iterate is orthogonalised against
//! the cluster's earlier vectors (modified Gram–Schmidt), and equal eigenvalues are separated
//! by 10u|θ| so that the factorizations differ.

/// Unit roundoff 2⁻⁵³.
const EPS: f64 = f64::EPSILON / 2.0;
/// Eigenvalues closer than this fraction of ‖T‖₁ share a cluster (`dstein`'s ORTOL).
const CLUSTER_GAP: f64 = 1e-3;
/// Inverse-iteration steps allowed before convergence (`dstein`'s MAXITS).
const MAX_STEPS: usize = 5;
/// Back-substitution rescales the whole vector when an entry exceeds this (growth only says
/// that the shift is close to an eigenvalue; the direction is what is kept).
const RESCALE_ABOVE: f64 = 1e150;

/// LU factorization with partial pivoting of T − σI (T symmetric tridiagonal): unit lower
/// bidiagonal L with row interchanges, U with two superdiagonals (LAPACK `dgttrf`'s layout).
pub(crate) struct ShiftedTridiagonal {
    /// Multipliers of L.
    lower: Vec<f64>,
    /// U's diagonal, with zero and tiny pivots replaced by ±`tiny`.
    diag: Vec<f64>,
    /// U's first superdiagonal.
    upper: Vec<f64>,
    /// U's second superdiagonal (nonzero only after an interchange).
    upper2: Vec<f64>,
    /// Whether rows k and k + 1 were interchanged at step k.
    swapped: Vec<bool>,
}

impl ShiftedTridiagonal {
    /// Factors T − σI for T with diagonal `diag` and off-diagonal `offdiag`; pivots smaller
    /// in magnitude than `tiny` are replaced by ±`tiny`.
    pub(crate) fn new(diag: &[f64], offdiag: &[f64], sigma: f64, tiny: f64) -> Self {
        let n = diag.len();
        let mut d: Vec<f64> = diag.iter().map(|v| v - sigma).collect();
        let mut lower = offdiag.to_vec();
        let mut upper = offdiag.to_vec();
        let mut upper2 = vec![0.0; n.saturating_sub(2)];
        let mut swapped = vec![false; n.saturating_sub(1)];
        for k in 0..n.saturating_sub(1) {
            if d[k].abs() >= lower[k].abs() {
                let multiplier = if d[k] == 0.0 { 0.0 } else { lower[k] / d[k] };
                lower[k] = multiplier;
                d[k + 1] -= multiplier * upper[k];
            } else {
                let multiplier = d[k] / lower[k];
                d[k] = lower[k];
                lower[k] = multiplier;
                let above = upper[k];
                upper[k] = d[k + 1];
                d[k + 1] = above - multiplier * d[k + 1];
                if k + 2 < n {
                    upper2[k] = upper[k + 1];
                    upper[k + 1] *= -multiplier;
                }
                swapped[k] = true;
            }
        }
        for p in &mut d {
            if p.abs() < tiny {
                *p = if p.is_sign_negative() { -tiny } else { tiny };
            }
        }
        Self {
            lower,
            diag: d,
            upper,
            upper2,
            swapped,
        }
    }

    /// Overwrites `b` with the solution of (T − σI)v = b (perturbed pivots included) and
    /// returns the factor by which the solution was scaled down on the way (1 when it was not).
    pub(crate) fn solve_in_place(&self, b: &mut [f64]) -> f64 {
        let n = self.diag.len();
        for k in 0..n.saturating_sub(1) {
            if self.swapped[k] {
                let top = b[k];
                b[k] = b[k + 1];
                b[k + 1] = top - self.lower[k] * b[k];
            } else {
                b[k + 1] -= self.lower[k] * b[k];
            }
        }
        let mut scaled = 1.0;
        for k in (0..n).rev() {
            let mut v = b[k];
            if k + 1 < n {
                v -= self.upper[k] * b[k + 1];
            }
            if k + 2 < n {
                v -= self.upper2[k] * b[k + 2];
            }
            v /= self.diag[k];
            if v.abs() > RESCALE_ABOVE {
                let factor = RESCALE_ABOVE / v.abs();
                b.iter_mut().for_each(|e| *e *= factor);
                v *= factor;
                scaled *= factor;
            }
            b[k] = v;
        }
        scaled
    }
}

/// ‖T‖₁ of the symmetric tridiagonal matrix (diagonal `diag`, off-diagonal `offdiag`).
pub(crate) fn one_norm(diag: &[f64], offdiag: &[f64]) -> f64 {
    let n = diag.len();
    (0..n)
        .map(|i| {
            let left = if i > 0 { offdiag[i - 1].abs() } else { 0.0 };
            let right = if i + 1 < n { offdiag[i].abs() } else { 0.0 };
            diag[i].abs() + left + right
        })
        .fold(0.0, f64::max)
}

/// Unit eigenvectors of T (diagonal `diag`, off-diagonal `offdiag`) for the ascending
/// eigenvalues `values` (computed, e.g., by [`crate::linalg::eigen::ql_values`]), one column-major
/// n-vector after another. Err(i) when the iteration for `values[i]` did not converge.
pub(crate) fn tridiagonal_eigenvectors(diag: &[f64], offdiag: &[f64], values: &[f64]) -> Result<Vec<f64>, usize> {
    let n = diag.len();
    let mut vectors = vec![0.0; n * values.len()];
    if n == 0 {
        return Ok(vectors);
    }
    // Scale T to unit 1-norm (eigenvectors unchanged): every quantity below is then O(1).
    let norm = one_norm(diag, offdiag);
    if norm == 0.0 || !norm.is_finite() {
        for (i, v) in vectors.chunks_exact_mut(n).enumerate() {
            v[i.min(n - 1)] = 1.0;
        }
        return if norm == 0.0 && values.len() <= n {
            Ok(vectors)
        } else {
            Err(0)
        };
    }
    let d: Vec<f64> = diag.iter().map(|v| v / norm).collect();
    let e: Vec<f64> = offdiag.iter().map(|v| v / norm).collect();
    // An iterate started at 1-norm n·u that grows to ∞-norm √(0.1/n) has, normalised, a
    // residual of at most √(10n)·n·u (`dstein`'s test).
    let converged_size = (0.1 / n as f64).sqrt();
    let mut cluster_start = 0;
    let mut previous_shift = f64::NEG_INFINITY;
    let mut random = StartVector::new();
    for (i, &value) in values.iter().enumerate() {
        let mut shift = value / norm;
        if i > 0 && shift - values[i - 1] / norm > CLUSTER_GAP {
            cluster_start = i;
        }
        // Separate equal eigenvalues, so that their factorizations (and iterates) differ.
        let separation = 10.0 * EPS * shift.abs().max(EPS);
        if i > cluster_start && shift <= previous_shift + separation {
            shift = previous_shift + separation;
        }
        previous_shift = shift;
        let lu = ShiftedTridiagonal::new(&d, &e, shift, EPS);
        let (done, rest) = vectors.split_at_mut(i * n);
        let x = &mut rest[..n];
        random.fill(x);
        let mut extra_steps = 1;
        let mut converged = false;
        for _ in 0..MAX_STEPS + 1 {
            // Start each step from a vector of 1-norm n·u‖T‖₁ (= n·u here), as `dstein`.
            let scale = n as f64 * EPS / x.iter().map(|v| v.abs()).sum::<f64>().max(f64::MIN_POSITIVE);
            x.iter_mut().for_each(|v| *v *= scale);
            let shrunk = lu.solve_in_place(x);
            orthogonalize(x, &done[cluster_start * n..]);
            let largest = x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            if !largest.is_finite() {
                return Err(i);
            }
            if converged {
                extra_steps -= 1;
                if extra_steps == 0 {
                    break;
                }
            } else if shrunk < 1.0 || largest >= converged_size {
                converged = true;
            }
        }
        if !converged {
            return Err(i);
        }
        let length = x.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(length > 0.0 && length.is_finite()) {
            return Err(i);
        }
        x.iter_mut().for_each(|v| *v /= length);
    }
    Ok(vectors)
}

/// x ← (I − V Vᵀ)² x for the orthonormal columns V stored one after another in `basis`:
/// classical Gram–Schmidt applied twice, which orthogonalises to working precision ("twice is
/// enough", Giraud, Langou & Rozložník, Comput. Math. Appl. 50, 2005) with matrix-vector
/// products instead of one dot product per column.
fn orthogonalize(x: &mut [f64], basis: &[f64]) {
    let n = x.len();
    if basis.is_empty() {
        return;
    }
    let v = faer::MatRef::from_column_major_slice(basis, n, basis.len() / n);
    let mut overlap = faer::Mat::<f64>::zeros(v.ncols(), 1);
    for _ in 0..2 {
        let mut x_mat = faer::MatMut::from_column_major_slice_mut(&mut *x, n, 1);
        faer::linalg::matmul::matmul(
            overlap.as_mut(),
            faer::Accum::Replace,
            v.transpose(),
            x_mat.as_ref(),
            1.0,
            faer::Par::Seq,
        );
        faer::linalg::matmul::matmul(
            x_mat.as_mut(),
            faer::Accum::Add,
            v,
            overlap.as_ref(),
            -1.0,
            faer::Par::Seq,
        );
    }
}

/// Deterministic uniform(−1, 1) start vectors (a 64-bit linear congruential generator; the
/// start only has to have a component along the wanted eigenvector).
struct StartVector {
    state: u64,
}

impl StartVector {
    fn new() -> Self {
        Self {
            state: 0x853c_49e6_748f_ea9b,
        }
    }

    fn fill(&mut self, x: &mut [f64]) {
        for v in x {
            self.state = self
                .state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            *v = (self.state >> 11) as f64 / (1u64 << 52) as f64 - 1.0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::eigen::ql_values::tridiagonal_eigenvalues;

    /// ‖T z − θ z‖₂ / ‖T‖₁ for a unit z (formed on T/‖T‖₁, so that squares cannot overflow).
    fn relative_residual(d: &[f64], e: &[f64], theta: f64, z: &[f64]) -> f64 {
        let n = d.len();
        let norm = one_norm(d, e);
        (0..n)
            .map(|i| {
                let mut r = (d[i] / norm - theta / norm) * z[i];
                if i > 0 {
                    r += e[i - 1] / norm * z[i - 1];
                }
                if i + 1 < n {
                    r += e[i] / norm * z[i + 1];
                }
                r * r
            })
            .sum::<f64>()
            .sqrt()
    }

    fn max_orthogonality_error(z: &[f64], n: usize) -> f64 {
        let cols: Vec<&[f64]> = z.chunks_exact(n).collect();
        let mut worst = 0.0_f64;
        for (i, p) in cols.iter().enumerate() {
            for (j, q) in cols.iter().enumerate() {
                let dot: f64 = p.iter().zip(q.iter()).map(|(a, b)| a * b).sum();
                worst = worst.max((dot - if i == j { 1.0 } else { 0.0 }).abs());
            }
        }
        worst
    }

    /// The second-difference matrix (2, −1): θ_k = 2 − 2cos(kπ/(n+1)) and
    /// z_k(j) ∝ sin(jkπ/(n+1)) in closed form.
    #[test]
    fn second_difference_vectors_match_the_closed_form() {
        let n = 500;
        let d = vec![2.0; n];
        let e = vec![-1.0; n - 1];
        let h = std::f64::consts::PI / (n + 1) as f64;
        let wanted = [0usize, 1, 2, 250, 499];
        let values: Vec<f64> = wanted.iter().map(|&k| 2.0 - 2.0 * ((k + 1) as f64 * h).cos()).collect();
        let z = tridiagonal_eigenvectors(&d, &e, &values).expect("converges");
        for (c, &k) in wanted.iter().enumerate() {
            let exact: Vec<f64> = (0..n).map(|j| ((j + 1) as f64 * (k + 1) as f64 * h).sin()).collect();
            let length = exact.iter().map(|v| v * v).sum::<f64>().sqrt();
            let col = &z[c * n..(c + 1) * n];
            let sign = if col.iter().zip(&exact).map(|(a, b)| a * b).sum::<f64>() < 0.0 {
                -1.0
            } else {
                1.0
            };
            let err = col
                .iter()
                .zip(&exact)
                .map(|(a, b)| (sign * a - b / length).abs())
                .fold(0.0, f64::max);
            // Eigenvector error ≤ residual / gap; the smallest gap here is about π²/n² ≈ 4e-5.
            assert!(err < 1e-10, "mode {k}: {err:e}");
        }
    }

    /// Wilkinson's W21+ has pairs of eigenvalues equal to 14 digits: the vectors of each pair
    /// must come out orthogonal, with residuals at rounding level.
    #[test]
    fn wilkinson_pairs_come_out_orthogonal() {
        let n = 21;
        let d: Vec<f64> = (0..n).map(|i| (10.0 - i as f64).abs()).collect();
        let e = vec![1.0; n - 1];
        let values = tridiagonal_eigenvalues(&d, &e).expect("converges");
        let top = &values[n - 6..];
        let z = tridiagonal_eigenvectors(&d, &e, top).expect("converges");
        for (c, &theta) in top.iter().enumerate() {
            let r = relative_residual(&d, &e, theta, &z[c * n..(c + 1) * n]);
            assert!(r <= 10.0 * n as f64 * f64::EPSILON, "{c}: {r:e}");
        }
        assert!(
            max_orthogonality_error(&z, n) < 1e-12,
            "{:e}",
            max_orthogonality_error(&z, n)
        );
    }

    /// A triple eigenvalue (a direct sum of three equal blocks): three orthonormal vectors.
    #[test]
    fn exactly_repeated_eigenvalues_give_an_orthonormal_basis() {
        let block = [(3.0, -1.0), (2.0, -1.0), (4.0, 0.0)];
        let d: Vec<f64> = (0..9).map(|i| block[i % 3].0).collect();
        let e: Vec<f64> = (0..8).map(|i| block[i % 3].1).collect();
        let values = tridiagonal_eigenvalues(&d, &e).expect("converges");
        let z = tridiagonal_eigenvectors(&d, &e, &values[..3]).expect("converges");
        for c in 0..3 {
            let r = relative_residual(&d, &e, values[c], &z[c * 9..(c + 1) * 9]);
            assert!(r < 4.0 * f64::EPSILON, "{c}: {r:e}");
        }
        assert!(max_orthogonality_error(&z, 9) < 1e-14);
    }

    /// Graded from 1e-150 to 1e150 and scaled towards the ends of the range: the scaling to unit
    /// norm keeps every step finite, and the residuals are small relative to ‖T‖.
    #[test]
    fn graded_and_extreme_scales_stay_finite() {
        let n = 40;
        for scale in [1e-150, 1.0, 1e150] {
            let d: Vec<f64> = (0..n)
                .map(|i| scale * 10f64.powf(-150.0 + 300.0 * i as f64 / (n - 1) as f64))
                .collect();
            let e: Vec<f64> = (0..n - 1).map(|i| 0.3 * d[i].sqrt() * d[i + 1].sqrt()).collect();
            let values = tridiagonal_eigenvalues(&d, &e).expect("values converge");
            let z = tridiagonal_eigenvectors(&d, &e, &values).expect("vectors converge");
            for (c, &theta) in values.iter().enumerate() {
                let r = relative_residual(&d, &e, theta, &z[c * n..(c + 1) * n]);
                assert!(r <= 10.0 * n as f64 * f64::EPSILON, "scale {scale:e}, {c}: {r:e}");
            }
        }
    }

    /// Glued Wilkinson matrices (W21+ blocks joined by off-diagonals 1e-12: tight clusters of
    /// up to eight eigenvalues, the classic hard case of inverse iteration) and near-degenerate
    /// random tridiagonals: every vector of the whole spectrum has a residual at rounding level
    /// and the basis is orthonormal.
    #[test]
    fn glued_and_clustered_spectra_give_orthonormal_vectors() {
        let mut cases: Vec<(Vec<f64>, Vec<f64>)> = Vec::new();
        let (blocks, m) = (8, 21);
        let n = blocks * m;
        let d: Vec<f64> = (0..n).map(|i| ((i % m) as f64 - 10.0).abs()).collect();
        let e: Vec<f64> = (0..n - 1).map(|i| if i % m == m - 1 { 1e-12 } else { 1.0 }).collect();
        cases.push((d, e));
        let mut random = StartVector::new();
        let mut noise = vec![0.0; 400];
        random.fill(&mut noise);
        let d: Vec<f64> = noise[..200].iter().map(|v| 1.0 + 1e-9 * v).collect();
        let e: Vec<f64> = noise[200..399].iter().map(|v| 1e-6 * v).collect();
        cases.push((d, e));
        for (d, e) in cases {
            let n = d.len();
            let values = tridiagonal_eigenvalues(&d, &e).expect("values converge");
            let z = tridiagonal_eigenvectors(&d, &e, &values).expect("vectors converge");
            for (c, &theta) in values.iter().enumerate() {
                let r = relative_residual(&d, &e, theta, &z[c * n..(c + 1) * n]);
                assert!(r <= 10.0 * n as f64 * f64::EPSILON, "{c}: {r:e}");
            }
            let orth = max_orthogonality_error(&z, n);
            assert!(orth <= 10.0 * n as f64 * f64::EPSILON, "{orth:e}");
        }
    }

    /// The shifted solve is exact on a system with a known solution, with and without
    /// row interchanges.
    #[test]
    fn shifted_solve_reproduces_a_known_solution() {
        let n = 30;
        let d: Vec<f64> = (0..n).map(|i| (i % 5) as f64 - 2.0).collect();
        let e: Vec<f64> = (0..n - 1).map(|i| 1.0 + (i % 3) as f64).collect();
        let sigma = 0.37;
        let v: Vec<f64> = (0..n).map(|i| ((i * 7) % 11) as f64 - 5.0).collect();
        let mut w: Vec<f64> = (0..n)
            .map(|i| {
                let mut r = (d[i] - sigma) * v[i];
                if i > 0 {
                    r += e[i - 1] * v[i - 1];
                }
                if i + 1 < n {
                    r += e[i] * v[i + 1];
                }
                r
            })
            .collect();
        let lu = ShiftedTridiagonal::new(&d, &e, sigma, 0.0);
        assert!(lu.swapped.iter().any(|&s| s) && lu.swapped.iter().any(|&s| !s));
        assert_eq!(lu.solve_in_place(&mut w), 1.0);
        let err = w.iter().zip(&v).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(err < 1e-11, "{err:e}");
    }
}
