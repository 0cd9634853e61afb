//! Sylvester inertia (Sturm) counts of the pencil: how many eigenvalues ω² = −λ of
//! det(λA + B) = 0 ((8.89), see docs/theory.md) lie below a shift s.
//!
//! With A positive definite, B − sA is congruent to diag(ω²_k − s) (take X A-orthonormal:
//! Xᵀ(B − sA)X = diag(ω²_k − s)), so by Sylvester's law of inertia the number of negative
//! eigenvalues of B − sA equals the number of modes with ω² < s. The negative eigenvalues are
//! counted on the block-diagonal factor of a Bunch–Kaufman LBLᵀ factorization (faer).

use crate::linalg::powers_of_two::{exponent, times_power_of_two};
use crate::{ModalError, PencilProblem};
use faer::{Mat, Side};

/// The inertia of B − sA: how many modes have ω² below, at (numerically), or above the shift s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InertiaCount {
    /// The shift s, in the units of ω² (rad²/s²).
    pub shift: f64,
    /// Number of negative eigenvalues of B − sA = number of modes with ω² < s.
    pub below: usize,
    /// Number of zero pivots (s is an eigenvalue to working precision, or the pencil is singular).
    pub zero: usize,
    /// Number of positive eigenvalues of B − sA = number of modes with ω² > s.
    pub above: usize,
}

/// Counts the modes with ω² below `shift` (ω² = −λ, λ of det(λA + B) = 0), certified by the
/// inertia of an LBLᵀ factorization of B − shift·A, scaled by a power of two (any finite pencil
/// and shift). Exact for the factorized matrix; the count can be off only for modes within about
/// n·u·(‖B‖ + |s|‖A‖)‖A⁻¹‖ of the shift.
pub fn count_below(problem: &PencilProblem, shift: f64) -> Result<InertiaCount, ModalError> {
    if !shift.is_finite() {
        return Err(ModalError::BadShift(shift));
    }
    let (below, zero, above) = inertia_of(&scaled_shifted(problem, shift));
    Ok(InertiaCount {
        shift,
        below,
        zero,
        above,
    })
}

/// (B − sA)·2⁻ᵉ with 2ᵉ near the largest of max|b_ij| and |s|·max|a_ij|: a positive multiple,
/// so of the same inertia, whose entries and factorization neither over- nor underflow for
/// pencils and shifts anywhere in the double range (B − sA itself overflows for |s|·a_ij beyond
/// f64::MAX, and the pivots' products for entries beyond 1e154). The scalings are exact but for
/// entries pushed below the normal range, which are then below u times the largest.
fn scaled_shifted(problem: &PencilProblem, shift: f64) -> Mat<f64> {
    let (a, b) = (problem.a(), problem.b());
    let n = problem.dim();
    let largest = |m: faer::MatRef<'_, f64>| {
        (0..n)
            .flat_map(|j| (0..n).map(move |i| m[(i, j)].abs()))
            .fold(0.0, f64::max)
    };
    let exponent_of = |x: f64| if x == 0.0 { None } else { Some(exponent(x)) };
    let (e_b, e_a, e_s) = (exponent_of(largest(b)), exponent_of(largest(a)), exponent_of(shift));
    let e_sa = e_a.zip(e_s).map(|(x, y)| x + y);
    let e = e_b.max(e_sa).unwrap_or(0);
    let (e_a, e_s) = (e_a.unwrap_or(0), e_s.unwrap_or(0));
    let unit_shift = times_power_of_two(shift, -e_s);
    // The shift's factor 2^(e_a + e_s − e)·s/2^e_s ≤ 2 in magnitude; 2^−e and 2^−e_a are single
    // normal doubles except at the ends of the range, where each entry is scaled in steps.
    let shift_factor = times_power_of_two(unit_shift, e_a + e_s - e);
    let normal = |x: i32| (-1021..=1022).contains(&x);
    if normal(e) && normal(e_a) {
        let (b_factor, a_factor) = (times_power_of_two(1.0, -e), times_power_of_two(1.0, -e_a));
        return Mat::from_fn(n, n, |i, j| {
            b[(i, j)] * b_factor - (a[(i, j)] * a_factor) * shift_factor
        });
    }
    Mat::from_fn(n, n, |i, j| {
        times_power_of_two(b[(i, j)], -e) - times_power_of_two(a[(i, j)], -e_a) * shift_factor
    })
}

/// Whether every mode has ω² > `shift`: B − shift·A is positive definite to working precision
/// (its Cholesky factorization succeeds with no negligible pivot). The count 0 it certifies
/// costs a third of the LBLᵀ of [`count_below`] (n³/3 flops at Cholesky speed).
/// The factorization works in kept storage ([`crate::runtime::scratch`]), given back afterwards.
pub(crate) fn all_above(problem: &PencilProblem, shift: f64, par: faer::Par) -> bool {
    let mut k = shifted_lower(problem, shift);
    let positive = crate::linalg::reduce::factor_in_place(k.as_mut(), par).is_ok();
    crate::runtime::scratch::give_back(k);
    positive
}

/// Whether B itself is positive definite beyond rounding: its Cholesky factorization succeeds
/// and every pivot l_jj² exceeds 4n·u·max_k b_kk, the rounding that elimination can leave in a
/// pivot of a matrix singular up to rounding (the stiffness of a free structure, assembled
/// from springs up to max b_kk); or, where that cannot decide and B's pattern is a forest
/// (spring chains and trees), the extended-precision proof of [`super::forest`]. Then, by
/// Sylvester's law, no mode has ω² ≤ 0: the pencil has neither rigid-body nor unstable modes.
pub(crate) fn stiffness_is_definite(problem: &PencilProblem, par: faer::Par) -> bool {
    double_precision_definite(problem, par) || super::forest::forest_is_positive_definite(problem.b())
}

/// The Cholesky test with the pivot margin 4n·u·max_k b_kk of [`stiffness_is_definite`].
fn double_precision_definite(problem: &PencilProblem, par: faer::Par) -> bool {
    let b = problem.b();
    let n = problem.dim();
    let largest = (0..n).map(|j| b[(j, j)]).fold(0.0_f64, f64::max);
    let mut k = shifted_lower(problem, 0.0);
    let factored = crate::linalg::reduce::factor_unchecked(k.as_mut(), par).is_ok();
    let tolerance = 4.0 * n as f64 * f64::EPSILON * largest;
    let definite = factored && (0..n).all(|j| k[(j, j)] * k[(j, j)] > tolerance);
    crate::runtime::scratch::give_back(k);
    definite
}

/// The lower triangle of B − shift·A (the strict upper triangle zero), in kept storage when
/// some fits ([`crate::runtime::scratch`]).
pub(crate) fn shifted_lower(problem: &PencilProblem, shift: f64) -> Mat<f64> {
    let (a, b) = (problem.a(), problem.b());
    let n = problem.dim();
    let mut k = crate::runtime::scratch::empty(n, n);
    k.resize_with(n, n, |i, j| if i >= j { b[(i, j)] - shift * a[(i, j)] } else { 0.0 });
    k
}

/// (negative, zero, positive) eigenvalue counts of the symmetric matrix `k` (lower triangle read).
pub(crate) fn inertia_of(k: &Mat<f64>) -> (usize, usize, usize) {
    let n = k.nrows();
    if n == 0 {
        return (0, 0, 0);
    }
    let lblt = k.lblt(Side::Lower);
    let d = lblt.B_diag();
    let s = lblt.B_subdiag();
    let (mut neg, mut zero, mut pos) = (0, 0, 0);
    let mut i = 0;
    while i < n {
        if i + 1 < n && s[i] != 0.0 {
            // 2×2 block [d_i s_i; s_i d_{i+1}]: eigenvalue signs from determinant and trace,
            // on the block divided by a power of two near its largest entry (no over- or
            // underflow of the products).
            let top = d[i].abs().max(d[i + 1].abs()).max(s[i].abs());
            let e = if top > 0.0 && top.is_finite() { exponent(top) } else { 0 };
            let [d0, d1, s0] = [d[i], d[i + 1], s[i]].map(|x| times_power_of_two(x, -e));
            let det = d0 * d1 - s0 * s0;
            let trace = d0 + d1;
            if det < 0.0 {
                neg += 1;
                pos += 1;
            } else if det > 0.0 {
                if trace > 0.0 {
                    pos += 2;
                } else {
                    neg += 2;
                }
            } else {
                zero += 1;
                if trace > 0.0 {
                    pos += 1;
                } else if trace < 0.0 {
                    neg += 1;
                } else {
                    zero += 1;
                }
            }
            i += 2;
        } else {
            if d[i] < 0.0 {
                neg += 1;
            } else if d[i] > 0.0 {
                pos += 1;
            } else {
                zero += 1;
            }
            i += 1;
        }
    }
    (neg, zero, pos)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing;

    #[test]
    fn fixed_chain_counts_match_the_closed_form() {
        // Unit chain fixed at both ends: ω²_k = 4 sin²(kπ / (2(n+1))), k = 1..n.
        let n = 40;
        let (a, b) = testing::fixed_chain(n);
        let p = PencilProblem::new(a.as_ref(), b.as_ref()).expect("valid pencil");
        let exact = testing::fixed_chain_omega_sq(n);
        for s in [-1.0, 0.0, 0.3, 1.7, 2.0, 3.99, 5.0] {
            let c = count_below(&p, s).expect("finite shift");
            let expected = exact.iter().filter(|&&w| w < s).count();
            assert_eq!(c.below, expected, "shift {s}");
            assert_eq!(c.below + c.zero + c.above, n);
        }
        assert!(matches!(count_below(&p, f64::NAN), Err(ModalError::BadShift(_))));
    }

    /// Blocks [[c, 2c], [2c, c]] (eigenvalues 3c and −c; Bunch–Kaufman takes them as 2×2
    /// pivots) with c from 1e-300 to 1e300 and A = I: one mode below each shift in (−c, 3c).
    /// The block's determinant c² − 4c² was ∞ − ∞ above 1e154 and 0 − 0 below 1e-162, and the
    /// block was counted as a zero eigenvalue.
    #[test]
    fn two_by_two_pivots_keep_their_signs_across_the_double_range() {
        for p in (-300..=300).step_by(25) {
            let c = 10f64.powi(p);
            let b = Mat::from_fn(2, 2, |i, j| if i == j { c } else { 2.0 * c });
            let a = Mat::<f64>::identity(2, 2);
            let problem = PencilProblem::new(a.as_ref(), b.as_ref()).expect("valid pencil");
            for (s, expected) in [(-2.0, 0), (-0.5, 1), (0.0, 1), (2.5, 1), (4.0, 2)] {
                let count = count_below(&problem, s * c).expect("finite shift");
                assert_eq!((count.below, count.zero), (expected, 0), "c = 1e{p}, shift {s}·c");
            }
        }
    }

    /// The same chain with B scaled by 10^p and A by 10^q anywhere in the double range (ω² and
    /// the shifts by 10^(p−q)): the counts are those of the closed form.
    #[test]
    fn counts_hold_across_the_double_range() {
        let n = 12;
        let (a, b) = testing::fixed_chain(n);
        let exact = testing::fixed_chain_omega_sq(n);
        for p in [-300, -160, -20, 0, 40, 155, 300] {
            for q in [-300, -150, 0, 150, 300] {
                if p - q > 300 || q - p > 300 {
                    continue;
                }
                let (sb, sa) = (10f64.powi(p), 10f64.powi(q));
                let scaled_b = Mat::from_fn(n, n, |i, j| b[(i, j)] * sb);
                let scaled_a = Mat::from_fn(n, n, |i, j| a[(i, j)] * sa);
                let problem = PencilProblem::new(scaled_a.as_ref(), scaled_b.as_ref()).expect("valid pencil");
                for s in [-1.0, 0.05, 0.3, 1.7, 2.0, 3.99, 5.0] {
                    let expected = exact.iter().filter(|&&w| w < s).count();
                    let count = count_below(&problem, s * (sb / sa)).expect("finite shift");
                    assert_eq!(count.below, expected, "B·1e{p}, A·1e{q}, shift {s}");
                    assert_eq!(count.below + count.zero + count.above, n);
                }
            }
        }
    }
}
