//! Refinement against the dense bordered Newton step on graded and banded pencils.

use crate::dd::{Operand, SplitVector};
use crate::linalg::reduce::LowerFactor;
use crate::linalg::reduce::{Cholesky, back_transform, cholesky, reduce};
use crate::refine::batch::refine_simple_modes;
use crate::refine::bordered::{ACCURATE_RESIDUAL, SparseShifts, refine_pair, refine_pair_sparse};
use crate::refine::correction::{ReducedCorrection, ReducedSpectrum, TridiagonalCorrection};
use crate::refine::metric::Metric;
use crate::refine::pair::{RefinedPair, finish_pair};
use crate::refine::projected::refine_pair_projected;
use crate::testing;
use faer::{Mat, Par, Side};

/// A, B, L, Y, ω² and X = L⁻ᵀY.
type Reduced = (Mat<f64>, Mat<f64>, Mat<f64>, Mat<f64>, Vec<f64>, Mat<f64>);

/// The graded 1e12 chain: L, the reduced spectrum and the back-transformed modes.
fn graded() -> Reduced {
    let stiffness = testing::graded_exponents(16, 12);
    let (a, b) = testing::spring_chain(&stiffness, &[0; 16]);
    reduced_modes(a, b)
}

/// A, B, L, the spectrum of C = L⁻¹BL⁻ᵀ (faer's dense solver) and X = L⁻ᵀY.
fn reduced_modes(a: Mat<f64>, b: Mat<f64>) -> Reduced {
    let n = a.nrows();
    let Cholesky::Factor(l) = cholesky(a.as_ref(), Par::Seq) else {
        panic!("the test's masses are definite");
    };
    let c = reduce(l.as_ref(), b.as_ref(), Par::Seq);
    let eig = c.self_adjoint_eigen(Side::Lower).expect("small EVD converges");
    let omega: Vec<f64> = (0..n).map(|i| eig.S()[i]).collect();
    let y = eig.U().to_owned();
    let mut x = y.clone();
    back_transform(l.as_ref(), x.as_mut(), Par::Seq);
    (a, b, l, y, omega, x)
}

/// The spectral correction and the bordered LBLᵀ Newton step converge to the same pair: both
/// Rayleigh quotients agree to a few ulps, and the residuals are of the same size.
/// The bordered LBLᵀ Newton step from (ω₀², x₀), the reference the other steps must meet.
fn bordered(a: &Mat<f64>, b: &Mat<f64>, l: &Mat<f64>, x0: &[f64], omega0: f64) -> RefinedPair {
    refine_pair(
        &Operand::new(a.as_ref()),
        &Operand::new(b.as_ref()),
        Metric::Cholesky(LowerFactor::new(l.as_ref())),
        x0,
        omega0,
    )
    .expect("the bordered Newton step converges")
}

/// The pair `refined` with its vector rounded to double, measured again: the residual a
/// double-precision vector can reach (the projected and batched steps iterate in double).
fn rounded(a: &Mat<f64>, b: &Mat<f64>, l: &Mat<f64>, refined: &RefinedPair) -> RefinedPair {
    let (mass, stiffness) = (Operand::new(a.as_ref()), Operand::new(b.as_ref()));
    let metric = Metric::Cholesky(LowerFactor::new(l.as_ref()));
    finish_pair(&mass, &stiffness, metric, SplitVector::of(refined.x.clone()), 0).expect("the pair is finite")
}

/// Both steps reached the same ω², to 4 ulps (mode `i` named in the failure).
fn assert_same_value(fast: &RefinedPair, slow: &RefinedPair, i: usize) {
    let w = slow.omega_sq;
    assert!(
        (fast.omega_sq - w).abs() <= 4.0 * f64::EPSILON * w,
        "mode {i}: {} vs {w}",
        fast.omega_sq
    );
}

/// The projected step from x₀ on the dense pencil (A, B) with factor L, through `correction`.
fn projected(
    a: &Mat<f64>,
    b: &Mat<f64>,
    l: &Mat<f64>,
    correction: &mut dyn ReducedCorrection,
    x0: &[f64],
) -> Option<RefinedPair> {
    refine_pair_projected(
        &Operand::new(a.as_ref()),
        &Operand::new(b.as_ref()),
        Metric::Cholesky(LowerFactor::new(l.as_ref())),
        correction,
        x0,
    )
}

#[test]
fn spectral_and_bordered_refinement_agree_on_a_graded_chain() {
    let (a, b, l, y, omega, x) = graded();
    for i in 0..4 {
        let mut spectrum = ReducedSpectrum {
            y: y.as_ref(),
            omega_sq: &omega,
            modes: i..i + 1,
        };
        let x0: Vec<f64> = (0..16).map(|r| x[(r, i)]).collect();
        let fast = projected(&a, &b, &l, &mut spectrum, &x0).expect("converges");
        let slow = bordered(&a, &b, &l, &x0, omega[i]);
        assert_same_value(&fast, &slow, i);
        let limit = rounded(&a, &b, &l, &slow).residual_a_inv;
        assert!(
            fast.residual_a_inv <= 4.0 * limit,
            "mode {i}: {:e}",
            fast.residual_a_inv
        );
    }
}

/// The sparse bordered step (LU of K = B − ω₀²A, border by block elimination) converges to
/// the pair of the dense LBLᵀ step on banded pencils of order 64 (stored densely, so taken
/// sparse): the graded 1e12 chain with lumped masses, and the same chain with a tridiagonal
/// consistent mass matrix (A's pattern merged into B's), each to a residual as small as the
/// other's or below the accuracy at which both stop; the double-double iterate has a residual
/// far below that of its rounding to double; a dense B is not taken sparse.
#[test]
fn sparse_and_dense_bordered_steps_agree_on_banded_pencils() {
    let n = 64;
    let (lumped, b) = testing::spring_chain(&testing::graded_exponents(n, 12), &vec![0; n]);
    let consistent = Mat::from_fn(n, n, |i, j| match i.abs_diff(j) {
        0 => 4.0 / 6.0,
        1 => 1.0 / 6.0,
        _ => 0.0,
    });
    for mass in [lumped, consistent] {
        let (a, b, l, _, omega, x) = reduced_modes(mass, b.clone());
        let (mass, stiffness) = (Operand::new(a.as_ref()), Operand::new(b.as_ref()));
        let shifts = SparseShifts::new(&mass, &stiffness).expect("banded operands are sparse");
        let metric = Metric::Cholesky(LowerFactor::new(l.as_ref()));
        for i in [0, 1, 2, n / 2, n - 1] {
            let x0: Vec<f64> = (0..n).map(|r| x[(r, i)]).collect();
            let fast = refine_pair_sparse(&mass, &stiffness, &shifts, metric, &x0, omega[i]).expect("converges");
            let slow = bordered(&a, &b, &l, &x0, omega[i]);
            assert_same_value(&fast, &slow, i);
            // Both stop once the residual is below ACCURATE_RESIDUAL relative to ω².
            let accurate = ACCURATE_RESIDUAL * fast.omega_sq.abs();
            assert!(
                fast.residual_a_inv <= (4.0 * slow.residual_a_inv).max(accurate),
                "mode {i}: {:e} vs {:e}",
                fast.residual_a_inv,
                slow.residual_a_inv
            );
            // The double-double iterate's residual is far below its rounding's (about 1e-22–1e-19
            // against 3e-6–5e-4 on these chains).
            let limit = rounded(&a, &b, &l, &fast).residual_a_inv;
            assert!(
                fast.residual_a_inv <= 1e-8 * limit,
                "mode {i}: {:e} vs {limit:e}",
                fast.residual_a_inv
            );
        }
    }
    let dense = crate::certify::sketch::gaussian(n, n, 3);
    let dense_b = Mat::from_fn(n, n, |i, j| dense[(i, j)] + dense[(j, i)]);
    let identity = Mat::<f64>::identity(n, n);
    assert!(SparseShifts::new(&Operand::new(identity.as_ref()), &Operand::new(dense_b.as_ref())).is_none());
}

/// The batch of simple modes converges, on one thread and on two, to the pairs the bordered
/// Newton step finds one at a time: the batched corrections are the single-mode ones.
#[test]
fn batched_simple_modes_agree_with_the_bordered_step() {
    let (a, b, l, y, omega, x) = graded();
    let modes = [0, 1, 2, 3, 5];
    let x0 = Mat::from_fn(16, modes.len(), |r, c| x[(r, modes[c])]);
    for par in [Par::Seq, Par::rayon(2)] {
        let batch = refine_simple_modes(
            &Operand::new(a.as_ref()),
            &Operand::new(b.as_ref()),
            LowerFactor::new(l.as_ref()),
            (y.as_ref(), &omega),
            &modes,
            x0.as_ref(),
            par,
        );
        for (c, &i) in modes.iter().enumerate() {
            let fast = batch[c].as_ref().expect("the batch step converges");
            let start: Vec<f64> = x0.col(c).iter().copied().collect();
            let slow = bordered(&a, &b, &l, &start, omega[i]);
            assert_same_value(fast, &slow, i);
            assert!(
                fast.residual_a_inv <= 4.0 * rounded(&a, &b, &l, &slow).residual_a_inv,
                "mode {i}"
            );
            assert!(fast.steps >= 1, "mode {i}");
        }
    }
}

/// The values-only correction through Q and (T − ρI)⁻¹ converges without the eigenvectors
/// Y, to the pair the bordered Newton step finds, from start vectors formed by inverse
/// iteration on T.
#[test]
fn tridiagonal_correction_agrees_with_the_bordered_step() {
    let (a, b, l, _, _, _) = graded();
    let c = reduce(l.as_ref(), b.as_ref(), Par::Seq);
    let (values, mut form) =
        crate::linalg::eigen::symmetric_values_keeping_form(c, Par::Seq, None).expect("values converge");
    let (mut x, z) = form.eigenvectors(&values[..4]).expect("inverse iteration converges");
    back_transform(l.as_ref(), x.as_mut(), Par::Seq);
    for i in 0..4 {
        let x0: Vec<f64> = x.col(i).iter().copied().collect();
        let mut correction = TridiagonalCorrection {
            form: &mut form,
            z: z.subcols(i, 1).to_owned(),
            purified: false,
        };
        let fast = projected(&a, &b, &l, &mut correction, &x0).expect("the tridiagonal correction converges");
        let slow = bordered(&a, &b, &l, &x0, values[i]);
        assert_same_value(&fast, &slow, i);
    }
}

/// A spectrum too far from the true one (eigenvalues off by a factor 3) makes the correction
/// stop contracting; the spectral refinement then declines, and the bordered one still works.
#[test]
fn a_wrong_spectrum_is_declined() {
    let (a, b, l, y, omega, x) = graded();
    let wrong: Vec<f64> = omega
        .iter()
        .enumerate()
        .map(|(j, w)| if j == 1 { 3.0 * w } else { *w })
        .collect();
    let mut spectrum = ReducedSpectrum {
        y: y.as_ref(),
        omega_sq: &wrong,
        modes: 0..1,
    };
    // Start from a mixture of modes 0 and 1, so the wrong ω²₁ drives the correction.
    let x0: Vec<f64> = (0..16).map(|r| x[(r, 0)] + 0.3 * x[(r, 1)]).collect();
    assert!(projected(&a, &b, &l, &mut spectrum, &x0).is_none());
    let slow = bordered(&a, &b, &l, &x0, omega[0]);
    let x0: Vec<f64> = (0..16).map(|r| x[(r, 0)]).collect();
    let mut right = ReducedSpectrum {
        y: y.as_ref(),
        omega_sq: &omega,
        modes: 0..1,
    };
    let w = projected(&a, &b, &l, &mut right, &x0).expect("converges").omega_sq;
    assert!(
        (slow.omega_sq - w).abs() <= 4.0 * f64::EPSILON * w,
        "{} vs {w}",
        slow.omega_sq
    );
}
