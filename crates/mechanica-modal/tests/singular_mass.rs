//! Mass matrices that are exactly singular with null vectors that are not coordinates:
//! A = D XXᵀ D with X = P[I; Y], Y a random r × (n − r) integer matrix and P a random row
//! order (XᵀX = I + YᵀY ⪰ I: rank n − r, its nonzero eigenvalues far from zero), and D a
//! grading by powers of two over 2^±10 (every entry exact), B = YYᵀ + I with Y an integer matrix (exactly positive definite).
//! The pencil has exactly r infinite eigenvalues and n − r positive finite ones. A Cholesky
//! factorization of such an A often passes its pivot test, its last pivots of rounding size;
//! the solve must still report r infinite modes, never a finite mode standing for one, and the
//! finite modes within their bounds of the role-reversed reference: the eigenvalues μ = 1/ω² of
//! R⁻ᵀAR⁻¹ with B = RᵀR, computed independently in double (accurate to about n·u·‖C‖/μ).

use faer::{Mat, Side};
use mechanica_modal::testing::graded::SplitMix;
use mechanica_modal::{ModeKind, PencilProblem, Selection, SolveOptions, solve};
use proptest::prelude::*;

/// A random integer matrix with entries in −3..=3.
fn small_integers(rng: &mut SplitMix, rows: usize, cols: usize) -> Mat<f64> {
    Mat::from_fn(rows, cols, |_, _| rng.below(7) as f64 - 3.0)
}

/// P[I; Y]: the m × m identity and n − m rows of `small_integers`, in a random row order.
fn full_column_rank(rng: &mut SplitMix, n: usize, m: usize) -> Mat<f64> {
    let extra = small_integers(rng, n - m, m);
    let mut order: Vec<usize> = (0..n).collect();
    for i in (1..n).rev() {
        order.swap(i, rng.below(i + 1));
    }
    Mat::from_fn(n, m, |i, j| {
        let row = order[i];
        if row < m {
            if row == j { 1.0 } else { 0.0 }
        } else {
            extra[(row - m, j)]
        }
    })
}

/// The finite ω² of (B, A), ascending, by role reversal: the positive eigenvalues μ of
/// R⁻ᵀAR⁻¹ (B = RᵀR), each with its own accuracy estimate 8n·u·‖C‖₂/μ relative.
fn reversed_reference(a: &Mat<f64>, b: &Mat<f64>, massless: usize) -> Vec<(f64, f64)> {
    let n = a.nrows();
    let l = b.llt(Side::Lower).expect("B is positive definite").L().to_owned();
    let mut c = a.clone();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(l.as_ref(), c.as_mut(), faer::Par::Seq);
    let mut c = c.transpose().to_owned();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(l.as_ref(), c.as_mut(), faer::Par::Seq);
    let c = Mat::from_fn(n, n, |i, j| 0.5 * (c[(i, j)] + c[(j, i)]));
    let mut mu: Vec<f64> = c.self_adjoint_eigenvalues(Side::Lower).expect("eigenvalues");
    mu.sort_by(|x, y| y.total_cmp(x));
    let norm = mu[0];
    let u = f64::EPSILON / 2.0;
    mu[..n - massless]
        .iter()
        .map(|&m| (1.0 / m, 8.0 * n as f64 * u * norm / m))
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    #[test]
    fn exactly_singular_masses_give_their_infinite_modes(
        seed in any::<u64>(),
        n in 3usize..30,
        two_massless in any::<bool>(),
        lowest in any::<bool>(),
    ) {
        let mut rng = SplitMix::new(seed);
        let r = if two_massless { 2 } else { 1 };
        let x = full_column_rank(&mut rng, n, n - r);
        let grading: Vec<i32> = (0..n).map(|_| rng.below(21) as i32 - 10).collect();
        let scale = |i: usize| 2f64.powi(grading[i]);
        let a = Mat::from_fn(n, n, |i, j| scale(i) * (0..n - r).map(|k| x[(i, k)] * x[(j, k)]).sum::<f64>() * scale(j));
        prop_assume!((0..n).all(|i| a[(i, i)] > 0.0));
        let y = small_integers(&mut rng, n, n);
        let b = Mat::from_fn(n, n, |i, j| {
            (0..n).map(|k| y[(i, k)] * y[(j, k)]).sum::<f64>() + if i == j { 1.0 } else { 0.0 }
        });
        let problem = PencilProblem::new(a.as_ref(), b.as_ref()).expect("valid pencil");
        let selection = if lowest { Selection::Lowest(n - r) } else { Selection::All };
        let options = SolveOptions { selection, ..SolveOptions::default() };
        let modes = solve(&problem, &options).expect("dense solve").modes;
        let reference = reversed_reference(&a, &b, r);
        let finite: Vec<_> = modes.iter().filter(|m| m.kind != ModeKind::Infinite).collect();
        let infinite = modes.len() - finite.len();
        if !lowest {
            prop_assert_eq!(infinite, r, "n = {}: {:?}", n, modes);
        }
        prop_assert_eq!(finite.len(), n - r, "n = {}: {:?}", n, modes);
        for (k, (mode, &(exact, accuracy))) in finite.iter().zip(&reference).enumerate() {
            prop_assert!(matches!(mode.kind, ModeKind::Oscillatory { .. }), "mode {}: {:?}", k, mode);
            prop_assert!(
                (mode.omega_sq - exact).abs() <= mode.error_bound + accuracy * exact,
                "mode {}: {:?}, reference {} (±{})", k, mode, exact, accuracy * exact
            );
        }
    }
}
