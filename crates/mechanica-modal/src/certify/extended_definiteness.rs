//! The definiteness proof of [`super::inertia`] in double-double arithmetic: it decides between
//! a matrix that is singular and one whose smallest scaled eigenvalue is a few hundred units of
//! rounding, which double precision cannot (a mass matrix A₀ + 2⁻⁴⁴I beside one of rank n − 1).

use super::inertia::diagonal_half_exponents;
use crate::dd::Dd;
use crate::linalg::powers_of_two::times_power_of_two;
use faer::MatRef;

/// The unit roundoff taken for double-double operations: 2⁻⁹⁶, a thousand times the 2⁻¹⁰⁶ of
/// an addition (whose error is below 3·2⁻¹⁰⁶ of its operands' magnitudes), product, quotient
/// or square root, so that the standard model the proof needs holds with room to spare.
const EXTENDED_UNIT_ROUNDOFF: f64 = 1.262_177_448_353_619e-29;

/// Whether the symmetric M (lower triangle read) is proven positive definite by the scaled and
/// shifted Cholesky test of [`super::inertia::proven_definite_with_margin`] (docs/theory.md,
/// §6, "Definiteness proofs") carried out in double-double arithmetic with the unit roundoff
/// u = 2⁻⁹⁶: H = D⁻¹MD⁻¹ by powers of two, G = H − c·diag(H) with c = 2nγ/(1 − γ) + 4u,
/// γ = γ_{2n+2}; completion with positive pivots gives S H S ⪰ (c − 3u − nγ/(1 − γ))·I ≻ 0.
/// Decides for λ_min(SHS) above about 4n²·2⁻⁹⁶ (1e-24 at n = 256). False beyond
/// `max_order` (the test costs about 20 n³/3 flops) or for a diagonal entry that is not
/// positive and finite.
pub(crate) fn proven_definite_extended(m: MatRef<'_, f64>, max_order: usize) -> bool {
    let n = m.nrows();
    if m.ncols() != n || n > max_order {
        return false;
    }
    let Some(half_exponents) = diagonal_half_exponents(m) else {
        return false;
    };
    let u = EXTENDED_UNIT_ROUNDOFF;
    let gamma_order = 2.0 * n as f64 + 2.0;
    let gamma = gamma_order * u / (1.0 - gamma_order * u);
    let shift = Dd::of(2.0 * n as f64 * gamma / (1.0 - gamma) + 4.0 * u);
    let h = |i: usize, j: usize| Dd::of(times_power_of_two(m[(i, j)], -(half_exponents[i] + half_exponents[j])));
    // L by columns, lower triangle: column j holds l_ij for i ≥ j at j·n + i.
    let mut l = vec![Dd::of(0.0); n * n];
    for j in 0..n {
        let mut pivot = h(j, j).minus(shift.times(h(j, j)));
        for k in 0..j {
            let l_jk = l[k * n + j];
            pivot = pivot.minus(l_jk.times(l_jk));
        }
        if !(pivot.hi > 0.0 && pivot.hi.is_finite()) {
            return false;
        }
        let l_jj = square_root(pivot);
        l[j * n + j] = l_jj;
        for i in j + 1..n {
            let mut sum = h(i, j);
            for k in 0..j {
                sum = sum.minus(l[k * n + i].times(l[k * n + j]));
            }
            l[j * n + i] = sum.over(l_jj);
        }
    }
    true
}

/// √x of a positive double-double: the double root with one Newton correction.
fn square_root(x: Dd) -> Dd {
    let s = x.hi.sqrt();
    let square = Dd::of(s).times(Dd::of(s));
    let correction = x.minus(square).hi / (2.0 * s);
    Dd::of(s).plus(Dd::of(correction))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::graded::SplitMix;
    use faer::Mat;

    /// Gram matrices XXᵀ of small integers (exact) with X of n − 1 columns: singular, never
    /// proven; with each diagonal entry raised by 2⁻⁴⁰ or 2⁻⁴⁴ of itself (exact: the entries have
    /// at most nine bits), definite with λ_min(SHS) of a few hundred units of rounding or less:
    /// proven. Graded by powers of two over 2^±30.
    #[test]
    fn singular_and_barely_definite_gram_matrices_are_told_apart() {
        let mut rng = SplitMix::new(35);
        for case in 0..100 {
            let n = 2 + rng.below(40);
            let x = Mat::from_fn(n, n - 1, |_, _| rng.below(7) as f64 - 3.0);
            let gram = Mat::from_fn(n, n, |i, j| (0..n - 1).map(|k| x[(i, k)] * x[(j, k)]).sum::<f64>());
            if (0..n).any(|i| gram[(i, i)] == 0.0) {
                continue;
            }
            let e: Vec<i32> = (0..n).map(|_| rng.below(61) as i32 - 30).collect();
            let graded = |m: &Mat<f64>| Mat::from_fn(n, n, |i, j| times_power_of_two(m[(i, j)], e[i] + e[j]));
            assert!(
                !proven_definite_extended(graded(&gram).as_ref(), 256),
                "case {case}: singular, n = {n}"
            );
            let raise = if case % 2 == 0 { -44 } else { -40 };
            let definite = Mat::from_fn(n, n, |i, j| {
                gram[(i, j)]
                    + if i == j {
                        times_power_of_two(gram[(i, i)], raise)
                    } else {
                        0.0
                    }
            });
            assert!(
                proven_definite_extended(graded(&definite).as_ref(), 256),
                "case {case}: n = {n}, raised by 2^{raise}"
            );
            assert!(
                !proven_definite_extended(graded(&definite).as_ref(), n - 1),
                "case {case}: beyond the order"
            );
        }
    }
}
