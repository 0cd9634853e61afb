//! The a-priori error of an eigenvalue whose pair was never measured (values-only solves):
//! n·u·(‖B‖ + |ω²|‖A‖)·‖A⁻¹‖, with ‖A⁻¹‖₂ bounded from the Cholesky factor by Gaussian probes.

use crate::linalg::norms::vector_norm;
use faer::linalg::triangular_solve::{solve_lower_triangular_in_place, solve_upper_triangular_in_place};
use faer::{MatRef, Par};

/// Gaussian probes of [`a_inverse_norm_bound`]: with α = 10 the bound fails with probability
/// at most α^(−probes) = 1e-12 (the sketches' [`crate::certify::sketch::FAILURE_PROBABILITY`]).
const NORM_PROBES: usize = 12;

/// Powers of A⁻¹ applied to the probes. The bound overestimates ‖A⁻¹‖₂ by at most
/// (α√(2/π)·max‖ω_i‖)^(1/q): about 3.3 at n = 200 and 4.4 at n = 2000 when A's spectrum is flat
/// (A = I), less when it is graded; trace A⁻¹, the deterministic alternative, is n times
/// too large for A = I.
const NORM_POWER: usize = 4;

/// An upper bound of ‖A⁻¹‖₂ from the Cholesky factor L of A that holds with probability ≥ 1 − 1e-12
/// over the probes (for an A that does not depend on them; see [`probe_seed`]), and never below the
/// deterministic lower bounds 1/L_nn² and 1/min_i A_ii: for any matrix M and r independent standard
/// Gaussian vectors ω_i, ‖M‖ ≤ α√(2/π)·max_i ‖Mω_i‖ except with probability α^(−r) (Halko,
/// Martinsson & Tropp, "Finding structure with randomness", SIAM Review 53, 2011, Lemma 4.1, after
/// Dixon 1983), applied to M = (L⁻ᵀL⁻¹)^q = A^(−q), whose norm is ‖A⁻¹‖^q. Cost: 2q triangular
/// solves on r columns (2qrn² flops). Probes are renormalised after every power, so the bound is
/// infinite only when ‖A⁻¹‖ itself overflows. A diagonal L (lumped masses) gives the exact value
/// max_i 1/l_ii² instead, with no probability of failure.
pub(crate) fn a_inverse_norm_bound(l: MatRef<'_, f64>, par: Par) -> f64 {
    let n = l.nrows();
    if n == 0 {
        return 0.0;
    }
    if crate::linalg::reduce::is_diagonal(l) {
        return (0..n).map(|i| (l[(i, i)] * l[(i, i)]).recip()).fold(0.0, f64::max);
    }
    let mut v = crate::certify::sketch::gaussian(n, NORM_PROBES, probe_seed(l));
    // ln ‖A^(−k) ω_i‖ after k powers.
    let mut log_norms = [0.0_f64; NORM_PROBES];
    for _ in 0..NORM_POWER {
        solve_lower_triangular_in_place(l, v.as_mut(), par);
        solve_upper_triangular_in_place(l.transpose(), v.as_mut(), par);
        for (j, log_norm) in log_norms.iter_mut().enumerate() {
            let length = vector_norm(v.col(j));
            if !(length.is_finite() && length > 0.0) {
                return f64::INFINITY;
            }
            *log_norm += length.ln();
            v.col_mut(j).iter_mut().for_each(|e| *e /= length);
        }
    }
    let alpha = 10.0_f64;
    let largest = log_norms.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let probed = (((alpha * (2.0 / std::f64::consts::PI).sqrt()).ln() + largest) / NORM_POWER as f64).exp();
    // Deterministic lower bounds of ‖A⁻¹‖₂, which no choice of probes can miss:
    // (A⁻¹)_nn = 1/L_nn² and 1/λ_min ≥ 1/A_ii ≥ 1/Σ_k L_ik² for every i.
    let last = l[(n - 1, n - 1)];
    let mut diagonal_of_a = vec![0.0_f64; n];
    for k in 0..n {
        for (i, entry) in l.col(k).iter().enumerate().skip(k) {
            diagonal_of_a[i] += entry * entry;
        }
    }
    let smallest_diagonal = diagonal_of_a.iter().copied().fold(f64::INFINITY, f64::min);
    probed.max(1.0 / (last * last)).max(1.0 / smallest_diagonal)
}

/// The seed of [`a_inverse_norm_bound`]'s probes, hashed (FNV-1a) from L's diagonal: the
/// probability is over the probes for an A chosen independently of them, and with one fixed
/// seed every A built against its probes (a small eigenvector orthogonal to all twelve)
/// would defeat the bound.
fn probe_seed(l: MatRef<'_, f64>) -> u64 {
    (0..l.nrows()).fold(0xcbf2_9ce4_8422_2325_u64, |h, i| {
        (h ^ l[(i, i)].to_bits()).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The a-priori (values-only) error n·u·(‖B‖ + |ω²|‖A‖)·‖A⁻¹‖ of a value whose pair was never
/// measured: a backward error of n·u assumed, ‖A⁻¹‖₂ bounded as in [`a_inverse_norm_bound`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct APrioriModel {
    /// n·u·‖A⁻¹‖₂.
    scale: f64,
    norm_a: f64,
    norm_b: f64,
}

impl APrioriModel {
    pub(crate) fn new(l: MatRef<'_, f64>, norm_a: f64, norm_b: f64, par: Par) -> Self {
        let order = l.nrows();
        let scale = order as f64 * f64::EPSILON * a_inverse_norm_bound(l, par);
        Self { scale, norm_a, norm_b }
    }

    pub(crate) fn bound(&self, omega_sq: f64) -> f64 {
        self.scale * (self.norm_b + omega_sq.abs() * self.norm_a)
    }

    /// The bounds of the values `omega_sq`.
    pub(crate) fn bounds(&self, omega_sq: &[f64]) -> Vec<f64> {
        omega_sq.iter().map(|&w| self.bound(w)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::norms::vector_norm;
    use crate::linalg::reduce::{Cholesky, cholesky};
    use crate::testing;
    use faer::Mat;

    /// The probabilistic bound of ‖A⁻¹‖₂ lies above the true norm and within its worst-case
    /// overestimate (α√(2/π)·max‖ω_i‖)^(1/q) (reached by A = I), for a rotated mass matrix
    /// whose eigenvalues (and so ‖A⁻¹‖ = 1/λ_min) are known, from well to badly conditioned.
    #[test]
    fn a_inverse_bound_holds_and_is_tight() {
        let n = 200;
        let q = testing::random_orthogonal(n, 5);
        for decades in [0.0, 6.0, 12.0] {
            let lambda: Vec<f64> = (0..n)
                .map(|i| 10f64.powf(-decades * i as f64 / (n - 1) as f64))
                .collect();
            let d = Mat::from_fn(n, n, |i, j| if i == j { lambda[i] } else { 0.0 });
            let (a, _) = testing::rotate(&d, &d, &q);
            let Cholesky::Factor(l) = cholesky(a.as_ref(), Par::Seq) else {
                panic!("positive definite");
            };
            let exact = 1.0 / lambda[n - 1];
            let bound = a_inverse_norm_bound(l.as_ref(), Par::Seq);
            let probes = crate::certify::sketch::gaussian(n, NORM_PROBES, probe_seed(l.as_ref()));
            let longest = (0..NORM_PROBES).map(|j| vector_norm(probes.col(j))).fold(0.0, f64::max);
            let worst =
                (10.0 * (2.0 / std::f64::consts::PI).sqrt() * longest).powf(1.0 / NORM_POWER as f64) * (1.0 + 1e-9);
            assert!(
                bound >= exact && bound <= worst * exact,
                "{decades} decades: {bound:e} vs {exact:e}"
            );
        }
        // One small eigenvalue ε along a dense direction u: the diagonal of A stays near 1,
        // so only the probes can see ‖A⁻¹‖ = 1/ε.
        let u = q.col(0);
        for eps in [1e-2, 1e-4, 1e-8] {
            let a = Mat::from_fn(n, n, |i, j| if i == j { 1.0 } else { 0.0 } - (1.0 - eps) * u[i] * u[j]);
            let Cholesky::Factor(l) = cholesky(a.as_ref(), Par::Seq) else {
                panic!("positive definite");
            };
            let bound = a_inverse_norm_bound(l.as_ref(), Par::Seq);
            assert!(bound >= 1.0 / eps && bound <= 10.0 / eps, "ε = {eps:e}: {bound:e}");
        }
        // A diagonal A: exactly 1/min a_ii (to the rounding of l_ii² = a_ii), probes or not.
        let masses: Vec<f64> = (0..n)
            .map(|i| 10f64.powf(6.0 - 12.0 * ((i * 37) % n) as f64 / n as f64))
            .collect();
        let a = Mat::from_fn(n, n, |i, j| if i == j { masses[i] } else { 0.0 });
        let Cholesky::Factor(l) = cholesky(a.as_ref(), Par::Seq) else {
            panic!("positive definite");
        };
        let exact = 1.0 / masses.iter().copied().fold(f64::INFINITY, f64::min);
        let bound = a_inverse_norm_bound(l.as_ref(), Par::Seq);
        assert!(
            (bound - exact).abs() <= 4.0 * f64::EPSILON * exact,
            "{bound:e} vs {exact:e}"
        );
    }
}
