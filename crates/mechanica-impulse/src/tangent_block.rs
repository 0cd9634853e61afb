//! The tangential block W_TT of a contact mobility: a symmetric positive semidefinite 2×2
//! matrix, factored by LDLᵀ with symmetric pivoting and a rank check, and the two solves the
//! impact process needs, each with a bound on its error:
//!
//! - the stick ratio t with W_TT t = −W_Tn (and the tangential impulse that stops a slip);
//! - the direction ŝ of slip that resumes from rest when sticking is impossible,
//!   (f W_TT + α I) ŝ = W_Tn with |ŝ| = 1 and α > 0.
//!
//! # Factorization and rank
//! With the larger diagonal entry as first pivot, M = L D Lᵀ, L = [1 0; l 1], |l| ≤ 1,
//! D = diag(d₁, d₂), d₂ = M₂₂ − l M₂₁ (one fused multiply-add). The block has rank 0 when
//! d₁ is at most the caller's zero threshold, rank 1 when d₂ ≤ [`BLOCK_RANK_RELATIVE`]·d₁ (its
//! condition number exceeds about 1e12: a contact that cannot move in one tangential
//! direction, as on a hinged body), rank 2 otherwise. A rank-deficient block is solved in the
//! minimum-norm sense M⁺ r; that is exact when the block is singular and the right side lies
//! in its range, which holds for the tangential block of any positive semidefinite W.
//!
//! # Error bounds (theory.md, "Error of the tangential solves")
//! A rank-2 solve is refined once with the residual r = M x − b evaluated in compensated
//! arithmetic ([`crate::compensated::dot2`]), so that x is accurate to a few ulps whatever the
//! condition of M (as long as κ(M)·u ≪ 1). Because x − x* = M⁻¹ r(x) exactly, the solve of the
//! final residual, δ = M⁻¹ r, is the error itself to first order; the reported bound is
//! 2|δ| + 4u|x| (the factor 2 covers the relative error κ(M)·u ≤ 1e-4 with which δ is
//! computed). For ŝ the residual of the bordered system is linearised the same way.

use crate::compensated::{UNIT_ROUNDOFF, dot2};
use nalgebra::{Matrix2, Vector2};

/// A second pivot d₂ ≤ `BLOCK_RANK_RELATIVE`·d₁ counts as zero: the tangential block is then
/// treated as singular (condition number above about 1e12).
pub const BLOCK_RANK_RELATIVE: f64 = 1e-12;

/// A solution of a 2×2 system as an unevaluated sum x + lo, with a bound on its error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Solution2 {
    /// The solution.
    pub x: Vector2<f64>,
    /// The last computed correction, not added to `x`: x + lo is closer to x* than x is.
    pub lo: Vector2<f64>,
    /// A bound on |x − x*| (and so on |x + lo − x*|), x* the exact solution for the stored
    /// matrix and right side.
    pub error: f64,
}

/// The LDLᵀ factorization with symmetric pivoting of a symmetric positive semidefinite 2×2
/// matrix, with its numerical rank.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Factor2 {
    m: Matrix2<f64>,
    /// The low part of the matrix (M = m + m_lo exactly), used in the refinement residuals.
    m_lo: Matrix2<f64>,
    first: usize,
    second: usize,
    l: f64,
    d1: f64,
    d2: f64,
    rank: usize,
}

impl Factor2 {
    /// Factors M = `m` + `m_lo` (the factor uses `m`, the residuals both); a first pivot
    /// ≤ `zero` (an absolute size) makes the rank 0.
    pub fn new(m: &Matrix2<f64>, m_lo: &Matrix2<f64>, zero: f64) -> Self {
        let (first, second) = if m[(1, 1)] > m[(0, 0)] { (1, 0) } else { (0, 1) };
        let d1 = m[(first, first)];
        let mut factor = Self {
            m: *m,
            m_lo: *m_lo,
            first,
            second,
            l: 0.0,
            d1,
            d2: 0.0,
            rank: 0,
        };
        if !(d1 > zero && d1 > 0.0) {
            return factor;
        }
        factor.l = m[(second, first)] / d1;
        factor.d2 = (-factor.l).mul_add(m[(second, first)], m[(second, second)]);
        factor.rank = if factor.d2 > BLOCK_RANK_RELATIVE * d1 { 2 } else { 1 };
        factor
    }

    /// The numerical rank (0, 1 or 2).
    #[cfg(test)]
    pub fn rank(&self) -> usize {
        self.rank
    }

    /// ‖M‖₂, the largest eigenvalue, without cancellation.
    pub fn norm(&self) -> f64 {
        let (a, b, c) = (self.m[(0, 0)], self.m[(0, 1)], self.m[(1, 1)]);
        0.5 * (a + c + (a - c).hypot(2.0 * b)).max(0.0)
    }

    /// M⁻¹ r for rank 2, the minimum-norm M⁺ r for rank 1, zero for rank 0 (no refinement).
    fn apply_inverse(&self, r: &Vector2<f64>) -> Vector2<f64> {
        let (k, j) = (self.first, self.second);
        let mut x = Vector2::zeros();
        match self.rank {
            0 => {}
            1 => {
                // M ≈ c cᵀ/d₁ with c the pivot column, so M⁺ = d₁ c cᵀ/|c|⁴.
                let mut c = Vector2::zeros();
                c[k] = self.d1;
                c[j] = self.m[(j, k)];
                let c2 = c.norm_squared();
                x = c * (c.dot(r) * self.d1 / (c2 * c2));
            }
            _ => {
                let z2 = (-self.l).mul_add(r[k], r[j]);
                let w2 = z2 / self.d2;
                x[j] = w2;
                x[k] = (-self.l).mul_add(w2, r[k] / self.d1);
            }
        }
        x
    }

    /// The residual M x − b, b = `b` + `b_lo`, in compensated arithmetic.
    fn residual(&self, x: &Vector2<f64>, b: &Vector2<f64>, b_lo: &Vector2<f64>) -> Vector2<f64> {
        let row = |i: usize| {
            let (m, lo) = (self.m.row(i), self.m_lo.row(i));
            dot2(
                &[m[0], m[1], lo[0], lo[1], -1.0, -1.0],
                &[x[0], x[1], x[0], x[1], b[i], b_lo[i]],
            )
        };
        Vector2::new(row(0), row(1))
    }

    /// The solution of M x = b, b = `b` + `b_lo` (minimum-norm for a singular block), refined
    /// once, with its error bound (see the module documentation).
    pub fn solve(&self, b: &Vector2<f64>, b_lo: &Vector2<f64>) -> Solution2 {
        let mut x = self.apply_inverse(b);
        if self.rank < 2 {
            return Solution2 {
                x,
                lo: Vector2::zeros(),
                error: 4.0 * UNIT_ROUNDOFF * x.norm(),
            };
        }
        x -= self.apply_inverse(&self.residual(&x, b, b_lo));
        let correction = self.apply_inverse(&self.residual(&x, b, b_lo));
        Solution2 {
            x,
            lo: -correction,
            error: 2.0 * correction.norm() + 4.0 * UNIT_ROUNDOFF * x.norm(),
        }
    }
}

/// The unit direction ŝ of slip resuming from rest when sticking is impossible
/// (|W_TT⁻¹ W_Tn| > f): (W_Tn − f W_TT ŝ) = α ŝ with α > 0, i.e. ŝ = (f W_TT + α I)⁻¹ W_Tn with
/// |ŝ| = 1. α ∈ (0, |W_Tn|] is found by safeguarded Newton steps on ψ(α) = 1/|ŝ(α)| − 1
/// (increasing), each ŝ(α) by a refined factored solve; the result is then corrected once by
/// the linearised bordered system, whose next correction bounds the error.
/// `w_tt` and `w_tn` are pairs (hi, lo) of unevaluated sums.
pub(crate) fn slip_ray(
    w_tt: (&Matrix2<f64>, &Matrix2<f64>),
    w_tn: (&Vector2<f64>, &Vector2<f64>),
    f: f64,
) -> Solution2 {
    let zero = Vector2::zeros();
    let shifted = |alpha: f64| Factor2::new(&(w_tt.0 * f + Matrix2::identity() * alpha), &Matrix2::zeros(), 0.0);
    let w_tn_hi = w_tn.0;
    let (mut lo, mut hi) = (0.0_f64, w_tn_hi.norm());
    let mut alpha = 0.5 * hi;
    for _ in 0..200 {
        let factor = shifted(alpha);
        let s = factor.solve(w_tn_hi, &zero).x;
        let norm = s.norm();
        let psi = 1.0 / norm - 1.0;
        if psi < 0.0 {
            lo = alpha;
        } else {
            hi = alpha;
        }
        if psi.abs() <= 4.0 * f64::EPSILON || hi - lo <= 4.0 * f64::EPSILON * hi {
            break;
        }
        let dpsi = s.dot(&factor.solve(&s, &zero).x) / (norm * norm * norm);
        let next = alpha - psi / dpsi;
        alpha = if next > lo && next < hi && dpsi.is_finite() {
            next
        } else {
            0.5 * (lo + hi)
        };
    }
    let s = shifted(alpha).solve(w_tn_hi, &zero).x;
    let norm = s.norm();
    if !norm.is_finite() || norm <= 0.0 {
        return Solution2 {
            x: Vector2::new(1.0, 0.0),
            lo: Vector2::zeros(),
            error: 2.0,
        };
    }
    let (s, alpha) = ray_correction(w_tt, w_tn, f, &(s / norm), alpha);
    let (s, alpha) = ray_correction(w_tt, w_tn, f, &s, alpha);
    // ŝ + lo carries the last Newton step unrounded; the step from there bounds the error.
    let (d_alpha, lo) = ray_step(w_tt, w_tn, f, (&s, &Vector2::zeros()), alpha);
    let (_, next) = ray_step(w_tt, w_tn, f, (&s, &lo), alpha + d_alpha);
    Solution2 {
        x: s,
        lo,
        error: 2.0 * next.norm() + 2.0 * lo.norm_squared() + 4.0 * UNIT_ROUNDOFF * UNIT_ROUNDOFF,
    }
}

/// One Newton step on the bordered system (f W_TT + α I) ŝ = W_Tn, |ŝ| = 1, from the unit
/// `s` and `alpha` ([`ray_step`]): the renormalised direction and the new α.
fn ray_correction(
    w_tt: (&Matrix2<f64>, &Matrix2<f64>),
    w_tn: (&Vector2<f64>, &Vector2<f64>),
    f: f64,
    s: &Vector2<f64>,
    alpha: f64,
) -> (Vector2<f64>, f64) {
    let (d_alpha, step) = ray_step(w_tt, w_tn, f, (s, &Vector2::zeros()), alpha);
    let next = s + step;
    let norm = next.norm();
    if norm > 0.0 {
        (next / norm, alpha + d_alpha)
    } else {
        (*s, alpha)
    }
}

/// The Newton step (δα, δŝ) of the bordered system (f W_TT + α I) ŝ = W_Tn, |ŝ|² = 1, at
/// ŝ: with M = f W_TT + α I, the compensated residual ρ = W_Tn − M ŝ and the length defect
/// ε = |ŝ|² − 1, δŝ = M⁻¹ρ − δα M⁻¹ŝ and δα = (ŝᵀM⁻¹ρ + ε/2) / ŝᵀM⁻¹ŝ, so that
/// 2 ŝ·δŝ = −ε. (A defect removed along ŝ alone would leave the curve ŝ(α).)
/// The direction is ŝ = `s` + `s_lo` (an unevaluated sum; `s` a unit vector, `s_lo` ⟂ it and
/// tiny), and the residual includes both parts.
fn ray_step(
    (w_tt, w_tt_lo): (&Matrix2<f64>, &Matrix2<f64>),
    (w_tn, w_tn_lo): (&Vector2<f64>, &Vector2<f64>),
    f: f64,
    (s, s_lo): (&Vector2<f64>, &Vector2<f64>),
    alpha: f64,
) -> (f64, Vector2<f64>) {
    let factor = Factor2::new(&(w_tt * f + Matrix2::identity() * alpha), &Matrix2::zeros(), 0.0);
    let (f0, f0_err) = split_product(f, s[0]);
    let (f1, f1_err) = split_product(f, s[1]);
    let (g0, g1) = (f * s_lo[0], f * s_lo[1]);
    let rho = |i: usize| {
        let (m, lo) = (w_tt.row(i), w_tt_lo.row(i));
        dot2(
            &[
                w_tn[i], w_tn_lo[i], m[0], m[0], m[1], m[1], lo[0], lo[1], m[0], m[1], s[i], s_lo[i],
            ],
            &[1.0, 1.0, -f0, -f0_err, -f1, -f1_err, -f0, -f1, -g0, -g1, -alpha, -alpha],
        )
    };
    let rho = Vector2::new(rho(0), rho(1));
    let m_rho = factor.apply_inverse(&rho);
    let m_s = factor.apply_inverse(s);
    let curvature = s.dot(&m_s);
    if !curvature.is_finite() || curvature <= 0.0 {
        return (0.0, Vector2::zeros());
    }
    let defect = dot2(
        &[s.x, s.y, -1.0, 2.0 * s.x, 2.0 * s.y],
        &[s.x, s.y, 1.0, s_lo.x, s_lo.y],
    );
    let d_alpha = (s.dot(&m_rho) + 0.5 * defect) / curvature;
    (d_alpha, m_rho - m_s * d_alpha)
}

/// a·b = p + e exactly (TwoProduct).
fn split_product(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_factor_solves_well_and_ill_conditioned_blocks_to_a_few_ulps() {
        // M = V diag(1, κ⁻¹) Vᵀ with an exactly representable solution checked through the
        // residual in compensated arithmetic and against the closed-form 2×2 inverse.
        for kappa in [1.0, 1e4, 1e8, 1e11] {
            let (c, s) = (0.6_f64, 0.8_f64);
            let (l1, l2) = (1.0, 1.0 / kappa);
            let m = Matrix2::new(
                c * c * l1 + s * s * l2,
                c * s * (l1 - l2),
                c * s * (l1 - l2),
                s * s * l1 + c * c * l2,
            );
            let factor = Factor2::new(&m, &Matrix2::zeros(), 0.0);
            assert_eq!(factor.rank(), 2);
            let b = Vector2::new(0.3, -0.7);
            let sol = factor.solve(&b, &Vector2::zeros());
            // Closed form: M⁻¹ = adj(M)/det(M), with det from the factor-independent product.
            let det = m[(0, 0)] * m[(1, 1)] - m[(0, 1)] * m[(1, 0)];
            let exact = Vector2::new(m[(1, 1)] * b[0] - m[(0, 1)] * b[1], m[(0, 0)] * b[1] - m[(1, 0)] * b[0]) / det;
            // The closed form itself carries a relative error up to about κ u; the refined
            // solution must lie within its own bound plus that.
            let closed_error = 8.0 * kappa * f64::EPSILON * exact.norm();
            assert!((sol.x - exact).norm() <= sol.error + closed_error, "κ = {kappa}");
            assert!(sol.error <= 16.0 * f64::EPSILON * sol.x.norm() + closed_error);
        }
    }

    #[test]
    fn a_singular_block_gives_the_minimum_norm_solution() {
        // M = c cᵀ with c = (3, 4): rank 1; b = 2c lies in the range; M⁺ b = 2c/|c|².
        let m = Matrix2::new(9.0, 12.0, 12.0, 16.0);
        let factor = Factor2::new(&m, &Matrix2::zeros(), 0.0);
        assert_eq!(factor.rank(), 1);
        let x = factor.solve(&Vector2::new(6.0, 8.0), &Vector2::zeros()).x;
        assert!((x - Vector2::new(6.0, 8.0) / 25.0).norm() <= 4.0 * f64::EPSILON);
        assert_eq!(Factor2::new(&Matrix2::zeros(), &Matrix2::zeros(), 0.0).rank(), 0);
    }

    #[test]
    fn the_slip_ray_satisfies_its_defining_relation() {
        // (W_Tn − f W_TT ŝ) must be parallel to ŝ with a positive factor, |ŝ| = 1.
        let w_tt = Matrix2::new(2.0, 0.7, 0.7, 0.5);
        let w_tn = Vector2::new(1.3, -0.9);
        let f = 0.2;
        let ray = slip_ray((&w_tt, &Matrix2::zeros()), (&w_tn, &Vector2::zeros()), f);
        let s = ray.x;
        let g = w_tn - w_tt * s * f;
        assert!((s.norm() - 1.0).abs() <= 4.0 * f64::EPSILON);
        assert!((g.x * s.y - g.y * s.x).abs() <= 8.0 * f64::EPSILON * g.norm());
        assert!(g.dot(&s) > 0.0);
        assert!(ray.error <= 64.0 * f64::EPSILON);
    }
}
