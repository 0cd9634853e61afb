//! Refinement of one simple eigenpair of det(λA + B) = 0 with extended-precision residuals,
//! for stiff and graded problems where the Cholesky reduction is accurate only relative to the
//! largest eigenvalue.
//!
//! Method (Dongarra, Moler & Wilkinson, "Improving the accuracy of computed eigenvalues and
//! eigenvectors", SIAM J. Numer. Anal. 20, 1983, adapted to the symmetric pencil): Newton's
//! method on F(x, ω²) = (B − ω²A)x = 0 with the normalisation (Ax₀)ᵀx = 1, the Jacobian frozen
//! at the starting pair and factored once, in double precision, as the symmetric bordered matrix
//! [[B − ω₀²A, −Ax₀], [−(Ax₀)ᵀ, 0]] (Bunch–Kaufman LBLᵀ). The residual (B − ω²A)x and the
//! Rayleigh quotient are computed in double-double, so the iteration converges to the pair of
//! the pencil as stored, to working precision, as long as the double-precision solve has a
//! relative accuracy below 1 (true for stiffness ratios far beyond 1e12). Its cost is one
//! (n+1)³/3 factorization plus a few O(n²) double-double residuals per refined mode.
//!
//! It is chosen by [`crate::Refinement::Auto`] for every selected simple mode whose first-order
//! bound from the reduction exceeds 1e-8·|ω²| (fewer than 8 guaranteed digits).

use crate::dd::{Dd, dot, mat_vec};
use crate::symmetric_eigen::TridiagonalForm;
use crate::tridiagonal_vectors::{ShiftedTridiagonal, one_norm};
use faer::linalg::solvers::Solve;
use faer::linalg::triangular_solve::{solve_lower_triangular_in_place, solve_upper_triangular_in_place};
use faer::{Mat, MatRef, Par, Side};

/// Maximum Newton steps per pair.
pub const MAX_STEPS: usize = 12;

/// A refined pair.
#[derive(Debug, Clone)]
pub(crate) struct RefinedPair {
    /// A-normalised eigenvector.
    pub x: Vec<f64>,
    /// ω² (the double-double Rayleigh quotient, rounded).
    pub omega_sq: f64,
    /// ‖(B − ω²A)x‖_{A⁻¹} / ‖x‖_A from the double-double residual.
    pub residual_a_inv: f64,
    /// The residual (B − ω²A)x from double-double, rounded to double.
    pub residual: Vec<f64>,
    /// Newton steps taken.
    pub steps: usize,
}

/// Refines (ω₀², x₀), with `l` the Cholesky factor of A (for the A⁻¹-norm of the residual); None if the bordered matrix is singular to working precision (the
/// eigenvalue is not simple) or A is not positive definite.
pub(crate) fn refine_pair(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    l: MatRef<'_, f64>,
    x0: &[f64],
    omega0: f64,
) -> Option<RefinedPair> {
    let n = a.nrows();
    let ax0: Vec<f64> = mat_vec(a, x0).iter().map(|v| v.to_f64()).collect();
    let border = Mat::from_fn(n + 1, n + 1, |i, j| match (i < n, j < n) {
        (true, true) => b[(i, j)] - omega0 * a[(i, j)],
        (true, false) => -ax0[i],
        (false, true) => -ax0[j],
        (false, false) => 0.0,
    });
    let lblt = border.lblt(Side::Lower);
    let mut x = x0.to_vec();
    let mut omega = Dd::of(omega0);
    let mut steps = 0;
    for _ in 0..MAX_STEPS {
        let bx = mat_vec(b, &x);
        let axd = mat_vec(a, &x);
        let mut rhs = Mat::<f64>::zeros(n + 1, 1);
        for i in 0..n {
            rhs[(i, 0)] = -(bx[i].minus(omega.times(axd[i]))).to_f64();
        }
        // Normalisation residual: (Ax₀)ᵀx − 1, computed as x₀ᵀ(Ax) in double-double.
        rhs[(n, 0)] = dot(x0, &axd).minus(Dd::of(1.0)).to_f64();
        let delta = lblt.solve(&rhs);
        if !(0..=n).all(|i| delta[(i, 0)].is_finite()) {
            return None;
        }
        steps += 1;
        let xmax = x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let dmax = (0..n).fold(0.0_f64, |m, i| m.max(delta[(i, 0)].abs()));
        for i in 0..n {
            x[i] += delta[(i, 0)];
        }
        omega = omega.plus(Dd::of(delta[(n, 0)]));
        if dmax <= 2.0 * f64::EPSILON * xmax && delta[(n, 0)].abs() <= 2.0 * f64::EPSILON * omega.hi.abs() {
            break;
        }
    }
    finish_pair(a, b, l, x, steps)
}

/// The correction of [`refine_pair_projected`]: an approximate inverse of C − ρI on the
/// complement of the refined mode, C = L⁻¹BL⁻ᵀ, applied in the reduced coordinates.
pub(crate) trait ReducedCorrection {
    /// Σ_{j≠i} y_j (y_jᵀw)/(ω̃²_j − ρ) for the computed eigenpairs (ω̃²_j, y_j) of C.
    fn apply(&mut self, w: Mat<f64>, rho: f64) -> Mat<f64>;
}

/// The reduced problem's spectrum C = Y diag(ω²) Yᵀ, C = L⁻¹BL⁻ᵀ, A = LLᵀ: an approximate
/// inverse of B − ρA that costs O(n²) to apply, so refinement needs no new factorization.
pub(crate) struct ReducedSpectrum<'a> {
    /// All n orthonormal eigenvectors of C.
    pub y: MatRef<'a, f64>,
    /// All n eigenvalues of C (ω², ascending).
    pub omega_sq: &'a [f64],
    /// The mode being refined.
    pub mode: usize,
}

impl ReducedCorrection for ReducedSpectrum<'_> {
    fn apply(&mut self, w: Mat<f64>, rho: f64) -> Mat<f64> {
        let mut c = self.y.transpose() * &w;
        for j in 0..c.nrows() {
            let gap = self.omega_sq[j] - rho;
            c[(j, 0)] = if j == self.mode || gap == 0.0 {
                0.0
            } else {
                c[(j, 0)] / gap
            };
        }
        self.y * &c
    }
}

/// The reduced problem in tridiagonal form C = Q T Qᵀ with one eigenvector z of T (unit): the
/// correction of a values-only solve, which has no Y. The same operator as
/// [`ReducedSpectrum`] evaluated as Q P (T − ρI)⁻¹ P Qᵀ with P = I − z zᵀ: the shifted
/// tridiagonal solve is nearly singular at ρ ≈ θ, but its error lies almost entirely along z
/// (Wilkinson, "The Algebraic Eigenvalue Problem", §5.56), which the second projection removes.
pub(crate) struct TridiagonalCorrection<'a> {
    /// T and Q.
    pub form: &'a mut TridiagonalForm,
    /// The refined mode's unit eigenvector of T.
    pub z: &'a [f64],
}

impl ReducedCorrection for TridiagonalCorrection<'_> {
    fn apply(&mut self, mut w: Mat<f64>, rho: f64) -> Mat<f64> {
        self.form.apply_q_transpose(w.as_mut());
        let u = w.col_as_slice_mut(0);
        project_out(u, self.z);
        let (diag, subdiag) = (self.form.diag(), self.form.subdiag());
        let tiny = f64::EPSILON * one_norm(diag, subdiag);
        let shrunk = ShiftedTridiagonal::new(diag, subdiag, rho, tiny).solve_in_place(u);
        if shrunk != 1.0 {
            // Growth beyond 1e150: no usable correction (the caller sees non-finite values).
            u.iter_mut().for_each(|v| *v = f64::NAN);
            return w;
        }
        project_out(u, self.z);
        self.form.apply_q(w.as_mut());
        w
    }
}

/// u ← u − z (zᵀu) for a unit z.
fn project_out(u: &mut [f64], z: &[f64]) {
    let overlap: f64 = u.iter().zip(z).map(|(p, q)| p * q).sum();
    u.iter_mut().zip(z).for_each(|(p, q)| *p -= overlap * q);
}

/// Maximum steps of [`refine_pair_projected`] before it gives up.
pub const MAX_PROJECTED_STEPS: usize = 8;

/// A correction below this many ulps of x that no longer halves has reached rounding level:
/// the iteration stops there (the bound comes from the final residual either way).
const STAGNATION_ULPS: f64 = 16.0;

/// Refines the simple pair (ω²_i, x₀) by Rayleigh-quotient steps with a projected correction:
/// ρ and r = (B − ρA)x in double-double, then x ← x − L⁻ᵀ K L⁻¹ r with K the
/// [`ReducedCorrection`], Σ_{j≠i} y_j y_jᵀ/(ω̃²_j − ρ). This is the Newton step of
/// [`refine_pair`] with the bordered Jacobian replaced by the reduction's computed
/// decomposition, which has a backward error of the same order as an LBLᵀ factorization of
/// B − ρA when the reduction is accurate; it converges linearly with the ratio of that error to
/// the gap. None when a step above rounding level fails to halve the correction (graded
/// problems, where the computed spectrum is too far from the exact one): the caller then falls
/// back to [`refine_pair`].
pub(crate) fn refine_pair_projected(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    l: MatRef<'_, f64>,
    correction: &mut dyn ReducedCorrection,
    x0: &[f64],
) -> Option<RefinedPair> {
    let n = a.nrows();
    let mut x = x0.to_vec();
    let mut previous = f64::INFINITY;
    for step in 1..=MAX_PROJECTED_STEPS {
        let axd = mat_vec(a, &x);
        let bxd = mat_vec(b, &x);
        let rq = dot(&x, &bxd).over(dot(&x, &axd));
        let mut w = Mat::from_fn(n, 1, |k, _| bxd[k].minus(rq.times(axd[k])).to_f64());
        solve_lower_triangular_in_place(l, w.as_mut(), Par::Seq);
        let mut delta = correction.apply(w, rq.to_f64());
        solve_upper_triangular_in_place(l.transpose(), delta.as_mut(), Par::Seq);
        // f64::max ignores NaN, so a failed correction is caught here, not by dmax.
        if !(0..n).all(|k| delta[(k, 0)].is_finite()) {
            return None;
        }
        let xmax = x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let dmax = (0..n).fold(0.0_f64, |m, k| m.max(delta[(k, 0)].abs()));
        let at_rounding = dmax <= STAGNATION_ULPS * f64::EPSILON * xmax;
        let contracting = dmax <= 0.5 * previous;
        if !dmax.is_finite() || !(contracting || at_rounding) {
            return None;
        }
        for k in 0..n {
            x[k] -= delta[(k, 0)];
        }
        if dmax <= 2.0 * f64::EPSILON * xmax || (at_rounding && !contracting) {
            return finish_pair(a, b, l, x, step);
        }
        previous = dmax;
    }
    None
}

/// A-normalises x, then its double-double Rayleigh quotient, residual and A⁻¹-norm residual.
fn finish_pair(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    l: MatRef<'_, f64>,
    mut x: Vec<f64>,
    steps: usize,
) -> Option<RefinedPair> {
    let n = a.nrows();
    let axd = mat_vec(a, &x);
    let xax = dot(&x, &axd);
    if xax.hi.is_nan() || xax.hi <= 0.0 {
        return None;
    }
    let scale = 1.0 / xax.hi.sqrt();
    x.iter_mut().for_each(|v| *v *= scale);
    let axd = mat_vec(a, &x);
    let bxd = mat_vec(b, &x);
    let xax = dot(&x, &axd);
    let rq = dot(&x, &bxd).over(xax);
    let r: Vec<f64> = (0..n).map(|i| bxd[i].minus(rq.times(axd[i])).to_f64()).collect();
    let mut y = Mat::from_fn(n, 1, |i, _| r[i]);
    solve_lower_triangular_in_place(l, y.as_mut(), Par::Seq);
    let residual_a_inv = y.norm_l2() / xax.to_f64().sqrt();
    let omega_sq = rq.to_f64();
    if !omega_sq.is_finite() || !residual_a_inv.is_finite() {
        return None;
    }
    Some(RefinedPair {
        x,
        omega_sq,
        residual_a_inv,
        residual: r,
        steps,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::families;
    use crate::reduce::{Cholesky, back_transform, cholesky, reduce};

    /// A, B, L, Y, ω² and X = L⁻ᵀY.
    type Reduced = (Mat<f64>, Mat<f64>, Mat<f64>, Mat<f64>, Vec<f64>, Mat<f64>);

    /// The graded 1e12 chain: L, the reduced spectrum and the back-transformed modes.
    fn graded() -> Reduced {
        let stiffness = families::graded_exponents(16, 12);
        let (a, b) = families::spring_chain(&stiffness, &[0; 16]);
        let Cholesky::Factor(l) = cholesky(a.as_ref(), Par::Seq) else {
            panic!("unit masses are definite");
        };
        let c = reduce(l.as_ref(), b.as_ref(), Par::Seq);
        let eig = c.self_adjoint_eigen(Side::Lower).expect("small EVD converges");
        let omega: Vec<f64> = (0..16).map(|i| eig.S()[i]).collect();
        let y = eig.U().to_owned();
        let mut x = y.clone();
        back_transform(l.as_ref(), x.as_mut(), Par::Seq);
        (a, b, l, y, omega, x)
    }

    /// The spectral correction and the bordered LBLᵀ Newton step converge to the same pair: both
    /// Rayleigh quotients agree to a few ulps, and the residuals are of the same size.
    #[test]
    fn spectral_and_bordered_refinement_agree_on_a_graded_chain() {
        let (a, b, l, y, omega, x) = graded();
        for i in 0..4 {
            let mut spectrum = ReducedSpectrum {
                y: y.as_ref(),
                omega_sq: &omega,
                mode: i,
            };
            let x0: Vec<f64> = (0..16).map(|r| x[(r, i)]).collect();
            let fast =
                refine_pair_projected(a.as_ref(), b.as_ref(), l.as_ref(), &mut spectrum, &x0).expect("converges");
            let slow = refine_pair(a.as_ref(), b.as_ref(), l.as_ref(), &x0, omega[i]).expect("converges");
            let w = slow.omega_sq;
            assert!(
                (fast.omega_sq - w).abs() <= 4.0 * f64::EPSILON * w,
                "mode {i}: {} vs {w}",
                fast.omega_sq
            );
            assert!(
                fast.residual_a_inv <= 4.0 * slow.residual_a_inv,
                "mode {i}: {:e}",
                fast.residual_a_inv
            );
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
            crate::symmetric_eigen::symmetric_values_keeping_form(c, Par::Seq).expect("values converge");
        let (mut x, z) = form.eigenvectors(&values[..4]).expect("inverse iteration converges");
        back_transform(l.as_ref(), x.as_mut(), Par::Seq);
        for i in 0..4 {
            let x0: Vec<f64> = x.col(i).iter().copied().collect();
            let mut correction = TridiagonalCorrection {
                form: &mut form,
                z: z.col_as_slice(i),
            };
            let fast = refine_pair_projected(a.as_ref(), b.as_ref(), l.as_ref(), &mut correction, &x0)
                .expect("the tridiagonal correction converges");
            let slow = refine_pair(a.as_ref(), b.as_ref(), l.as_ref(), &x0, values[i]).expect("converges");
            let w = slow.omega_sq;
            assert!(
                (fast.omega_sq - w).abs() <= 4.0 * f64::EPSILON * w,
                "mode {i}: {} vs {w}",
                fast.omega_sq
            );
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
            mode: 0,
        };
        // Start from a mixture of modes 0 and 1, so the wrong ω²₁ drives the correction.
        let x0: Vec<f64> = (0..16).map(|r| x[(r, 0)] + 0.3 * x[(r, 1)]).collect();
        assert!(refine_pair_projected(a.as_ref(), b.as_ref(), l.as_ref(), &mut spectrum, &x0).is_none());
        let slow = refine_pair(a.as_ref(), b.as_ref(), l.as_ref(), &x0, omega[0]).expect("bordered Newton converges");
        let x0: Vec<f64> = (0..16).map(|r| x[(r, 0)]).collect();
        let mut right = ReducedSpectrum {
            y: y.as_ref(),
            omega_sq: &omega,
            mode: 0,
        };
        let w = refine_pair_projected(a.as_ref(), b.as_ref(), l.as_ref(), &mut right, &x0)
            .expect("converges")
            .omega_sq;
        assert!(
            (slow.omega_sq - w).abs() <= 4.0 * f64::EPSILON * w,
            "{} vs {w}",
            slow.omega_sq
        );
    }
}
