//! Refinement of a statically condensed pencil: residuals of the full pencil (B, A) mapped
//! exactly to residuals of the condensed definite pencil (S, A₁), and corrections by block
//! elimination through the condensed spectrum.

use crate::linalg::norms::{euclidean_norm, frobenius_norm};
use crate::refine::correction::ReducedCorrection;
use faer::{Mat, MatRef};

/// The static condensation of the pencil (B, A) as refinement needs it: the exact identity (S −
/// ρA₁)z = r₁ − B₁₀B₀₀⁻¹r₀ for any x = Q[w; z] and its residual r = (B − ρA)x, with S = B₁₁ −
/// B₁₀B₀₀⁻¹B₀₁ the condensed stiffness. A residual measured in double-double on the stored A and B
/// thus becomes the residual of the condensed definite pencil (S, A₁), whose residual bounds
/// ([`crate::certify::residual_bounds::residual_bounds`]) then hold for the stored data, however
/// much the condensation's own rounding (stiff springs to massless nodes: the subtraction in S
/// loses u·‖B₁₀‖‖B₀₀⁻¹‖‖B₀₁‖) changed S.
pub(crate) struct Condensation {
    /// The massless coordinates first, then the others (the permutation that sorts a diagonal A).
    order: Vec<usize>,
    /// Number r of massless coordinates.
    massless: usize,
    /// B₁₀: rows of the coordinates with mass, columns of the massless ones.
    b10: Mat<f64>,
    /// B₀₀ = V diag(d) Vᵀ.
    v: Mat<f64>,
    d: Vec<f64>,
    /// G = B₀₀⁻¹B₀₁ (w = −G z on the condensed modes).
    pub(crate) g: Mat<f64>,
    /// L₁ = diag(√a₁), the Cholesky factor of the condensed mass matrix.
    pub(crate) l1: Mat<f64>,
    /// 4r·u·(κ(B₀₀) + 2)·‖B₁₀‖_F·‖B₀₀⁻¹‖₂: the rounding of B₁₀B₀₀⁻¹r₀ per unit ‖r₀‖.
    rounding: f64,
    /// κ(B₀₀) = max|d| / min|d|.
    condition: f64,
    /// Refinement is offered only when A is diagonal and its massless entries are exactly zero,
    /// so that the condensed pencil is the stored one, not a perturbation of it.
    pub(crate) refinable: bool,
}

/// The blocks of QᵀBQ a condensation keeps: B₁₀, B₀₀ = V diag(d) Vᵀ and G = B₀₀⁻¹B₀₁.
pub(crate) struct Blocks {
    pub(crate) b10: Mat<f64>,
    pub(crate) v: Mat<f64>,
    pub(crate) d: Vec<f64>,
    pub(crate) g: Mat<f64>,
}

impl Condensation {
    /// The condensation of the blocks of QᵀBQ whose first `r` coordinates (of A's eigenvalues
    /// `values`, ascending) are massless; `order` is the permutation Q of a diagonal A (the
    /// massless coordinates first), empty for a dense Q, which is not offered to refinement.
    pub(crate) fn new(order: Vec<usize>, values: &[f64], r: usize, blocks: Blocks, l1: Mat<f64>) -> Self {
        let Blocks { b10, v, d, g } = blocks;
        let refinable = !order.is_empty() && values[..r].iter().all(|&a| a == 0.0);
        let dmin = d.iter().fold(f64::INFINITY, |m, v| m.min(v.abs()));
        let dmax = d.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let condition = dmax / dmin;
        let rounding = 4.0 * r as f64 * f64::EPSILON * (condition + 2.0) * frobenius_norm(b10.as_ref()) / dmin;
        Self {
            order,
            massless: r,
            b10,
            v,
            d,
            g,
            l1,
            rounding,
            condition,
            refinable,
        }
    }

    /// u·κ(B₀₀), the relative rounding of the condensation along B₀₀'s most nearly singular
    /// direction: where it exceeds the accuracy asked of a first-order bound, the condensed
    /// stiffness S is perturbed beyond what the first-order theory of the full pencil accounts
    /// for (a B₀₀ of condition 1.6e10 gave a first-order bound of 5e-11 on a value 7e-10 off).
    pub(crate) fn relative_rounding(&self) -> f64 {
        f64::EPSILON * self.condition
    }

    /// The residual s = r₁ − B₁₀B₀₀⁻¹r₀ of the condensed pencil, t = B₀₀⁻¹r₀, and ‖r₀‖, for a
    /// residual r of the full pencil in the original coordinates.
    pub(crate) fn condensed_residual(&self, r: &[f64]) -> (Vec<f64>, Vec<f64>, f64) {
        let (massless, massed) = self.order.split_at(self.massless);
        let r0: Vec<f64> = massless.iter().map(|&i| r[i]).collect();
        let vt_r0: Vec<f64> = (0..self.massless)
            .map(|k| (0..self.massless).map(|i| self.v[(i, k)] * r0[i]).sum::<f64>() / self.d[k])
            .collect();
        let t: Vec<f64> = (0..self.massless)
            .map(|i| (0..self.massless).map(|k| self.v[(i, k)] * vt_r0[k]).sum())
            .collect();
        let s = massed
            .iter()
            .enumerate()
            .map(|(row, &i)| r[i] - (0..self.massless).map(|k| self.b10[(row, k)] * t[k]).sum::<f64>())
            .collect();
        let r0_norm = euclidean_norm(&r0);
        (s, t, r0_norm)
    }

    /// ‖L₁⁻¹s‖ for the condensed residual s of [`Self::condensed_residual`], plus the rounding
    /// allowance of s (a bound of ‖L₁⁻¹‖ times [`Self::rounding`]·‖r₀‖).
    pub(crate) fn inverse_mass_norm(&self, s: &[f64], r0_norm: f64) -> f64 {
        // Without squaring: residuals of a pencil scaled to the edge of the range are tiny.
        let scaled: Vec<f64> = s.iter().enumerate().map(|(i, v)| v / self.l1[(i, i)]).collect();
        let scaled = euclidean_norm(&scaled);
        let lmin = (0..self.l1.nrows()).fold(f64::INFINITY, |m, i| m.min(self.l1[(i, i)]));
        scaled + self.rounding * r0_norm / lmin
    }

    /// The correction δX ≈ (B − ρA)⁻¹R by block elimination: δz = L₁⁻ᵀ K L₁⁻¹ s with K the
    /// reduced correction of the condensed pencil, δw = B₀₀⁻¹r₀ − G δz, scattered back.
    pub(crate) fn correction(&self, r: &Mat<f64>, rho: f64, reduced: &mut dyn ReducedCorrection) -> Mat<f64> {
        let (n, p) = (r.nrows(), r.ncols());
        let (massless, massed) = self.order.split_at(self.massless);
        let mut scaled = Mat::<f64>::zeros(massed.len(), p);
        let mut t = Mat::<f64>::zeros(massless.len(), p);
        for k in 0..p {
            let (s, tk, _) = self.condensed_residual(r.col_as_slice(k));
            for (i, v) in s.iter().enumerate() {
                scaled[(i, k)] = v / self.l1[(i, i)];
            }
            t.col_as_slice_mut(k).copy_from_slice(&tk);
        }
        let mut dz = reduced.apply(scaled, rho);
        for k in 0..p {
            for i in 0..massed.len() {
                dz[(i, k)] /= self.l1[(i, i)];
            }
        }
        let dw = &t - &self.g * &dz;
        let mut dx = Mat::<f64>::zeros(n, p);
        for k in 0..p {
            for (i, &row) in massed.iter().enumerate() {
                dx[(row, k)] = dz[(i, k)];
            }
            for (i, &row) in massless.iter().enumerate() {
                dx[(row, k)] = dw[(i, k)];
            }
        }
        dx
    }

    /// A₁ = L₁L₁ᵀ, the condensed mass matrix (diagonal).
    pub(crate) fn condensed_mass(&self) -> Mat<f64> {
        let m = self.l1.nrows();
        Mat::from_fn(
            m,
            m,
            |i, j| if i == j { self.l1[(i, i)] * self.l1[(i, i)] } else { 0.0 },
        )
    }

    /// The rows of X at the coordinates with mass: the condensed mode shapes Z.
    pub(crate) fn massed_rows(&self, x: MatRef<'_, f64>) -> Mat<f64> {
        let massed = &self.order[self.massless..];
        Mat::from_fn(massed.len(), x.ncols(), |i, k| x[(massed[i], k)])
    }
}
