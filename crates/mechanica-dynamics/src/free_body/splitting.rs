//! The free rigid body as a sum of three exactly solvable flows (Lie–Poisson splitting):
//! H = Σᵢ mᵢ²/(2Iᵢ) in the body momentum m = Iω, and the flow of Hᵢ = mᵢ²/(2Iᵢ) alone turns the
//! body about its principal axis i at the constant rate mᵢ/Iᵢ, so over a time τ, with
//! θ = τmᵢ/Iᵢ and Qᵢ(θ) the rotation by θ about eᵢ,
//!
//!   R ← R Qᵢ(θ),   m ← Qᵢ(θ)ᵀ m
//!
//! (Ṙ = R[ω]× (7.24) with ω = (mᵢ/Iᵢ)eᵢ, and the space momentum L = Rm fixed). The symmetric
//! composition S(h) = Φ₁(h/2) Φ₂(h/2) Φ₃(h) Φ₂(h/2) Φ₁(h/2) is of order 2; composed with the
//! weights of [`COMPOSITION_4`], [`COMPOSITION_6`] or [`COMPOSITION_8`] it is of order 4, 6 or 8.
//! Every sub-flow is an exact rotation, so R stays a rotation and |m| = |L| stays constant to
//! rounding, whatever the step.

use nalgebra::{Matrix3, Vector3};

/// Triple jump (Creutz–Gocksch, Yoshida 1990): the outer weight γ₁ = 1/(2 − 2^{1/3}) of the
/// composition γ₁, γ₀, γ₁ (γ₀ = 1 − 2γ₁) of order 4.
pub const COMPOSITION_4: [f64; 1] = [1.351_207_191_959_657_8];

/// Yoshida (1990) solution A: the 7 weights w₃, w₂, w₁, w₀, w₁, w₂, w₃ of an order-6 composition,
/// w₀ = 1 − 2(w₁ + w₂ + w₃) (formed in [`composition_weights`], so the weights sum to 1).
pub const COMPOSITION_6: [f64; 3] = [-1.177_679_984_178_87, 0.235_573_213_359_357, 0.784_513_610_477_560];

/// Yoshida (1990) solution D: w₁ … w₇ of an order-8 composition with 15 stages,
/// w₀ = 1 − 2(w₁ + … + w₇).
pub const COMPOSITION_8: [f64; 7] = [
    0.102_799_849_391_985,
    -1.960_610_232_975_49,
    1.938_139_137_622_76,
    -0.158_240_635_368_243,
    -1.444_852_236_860_48,
    0.253_693_336_566_229,
    0.914_844_246_229_740,
];

/// The symmetric weights w_m … w₁ w₀ w₁ … w_m from the one-sided list w₁ … w_m.
pub(crate) fn composition_weights(one_side: &[f64]) -> Vec<f64> {
    let middle = 1.0 - 2.0 * one_side.iter().sum::<f64>();
    let mut weights: Vec<f64> = one_side.iter().rev().copied().collect();
    weights.push(middle);
    weights.extend_from_slice(one_side);
    weights
}

/// The sequence of sub-flows (axis, fraction of the step) of the composition of Strang steps
/// with `weights`, with the outer axis `order[0]`, the middle one `order[1]` and the central one
/// `order[2]`; adjacent flows about the same axis are merged (their rotations commute).
pub(crate) fn flow_sequence(weights: &[f64], order: [usize; 3]) -> Vec<(usize, f64)> {
    let mut flows: Vec<(usize, f64)> = Vec::with_capacity(5 * weights.len());
    for &w in weights {
        let strang = [
            (order[0], 0.5 * w),
            (order[1], 0.5 * w),
            (order[2], w),
            (order[1], 0.5 * w),
            (order[0], 0.5 * w),
        ];
        for (axis, fraction) in strang {
            match flows.last_mut() {
                Some(last) if last.0 == axis => last.1 += fraction,
                _ => flows.push((axis, fraction)),
            }
        }
    }
    flows
}

/// One step of length h: the sub-flows of `flows` in order, on (R, m).
pub(crate) fn splitting_step(
    flows: &[(usize, f64)],
    inverse_moments: &Vector3<f64>,
    rotation: &mut Matrix3<f64>,
    momentum: &mut Vector3<f64>,
    h: f64,
) {
    for &(axis, fraction) in flows {
        let angle = (fraction * h) * momentum[axis] * inverse_moments[axis];
        rotate_about_axis(axis, angle, rotation, momentum);
    }
}

/// R ← R Qᵢ(θ) and m ← Qᵢ(θ)ᵀ m for the axis i: with (j, k) the next two axes in cyclic order,
/// Qᵢ(θ)e_j = c e_j + s e_k and Qᵢ(θ)e_k = −s e_j + c e_k.
fn rotate_about_axis(axis: usize, angle: f64, rotation: &mut Matrix3<f64>, momentum: &mut Vector3<f64>) {
    let (j, k) = ((axis + 1) % 3, (axis + 2) % 3);
    let (s, c) = angle.sin_cos();
    for row in 0..3 {
        let (rj, rk) = (rotation[(row, j)], rotation[(row, k)]);
        rotation[(row, j)] = c * rj + s * rk;
        rotation[(row, k)] = c * rk - s * rj;
    }
    let (mj, mk) = (momentum[j], momentum[k]);
    momentum[j] = c * mj + s * mk;
    momentum[k] = c * mk - s * mj;
}

/// The two first integrals of the body momentum: Γ² = |m|² and 2T = Σ mᵢ²/Iᵢ.
#[derive(Debug, Clone, Copy)]
pub(crate) struct MomentumInvariants {
    sphere: f64,
    ellipsoid: f64,
}

impl MomentumInvariants {
    /// Γ² and 2T of `momentum`.
    pub(crate) fn of(momentum: &Vector3<f64>, inverse_moments: &Vector3<f64>) -> Self {
        let w = momentum.component_mul(inverse_moments);
        Self {
            sphere: momentum.dot(momentum),
            ellipsoid: momentum.dot(&w),
        }
    }

    /// One Newton step that moves m to m + a m + b I⁻¹m on the intersection of the sphere
    /// |m|² = Γ² and the ellipsoid Σ mᵢ²/Iᵢ = 2T. Both integrals hold for the exact flow, so the
    /// step changes m by no more than the method's local error and the rounding of the step;
    /// it keeps the rounding errors of T and Γ from accumulating. The 2×2 system has the Gram
    /// determinant of m and I⁻¹m; when it is below 10⁻⁸ of its scale (m near a principal
    /// axis, where the intersection degenerates to a point) m is left as it is.
    pub(crate) fn project(&self, momentum: &mut Vector3<f64>, inverse_moments: &Vector3<f64>) {
        let w = momentum.component_mul(inverse_moments);
        let (a, b, c) = (momentum.dot(momentum), momentum.dot(&w), w.dot(&w));
        let gram = a * c - b * b;
        if gram.is_nan() || gram <= 1e-8 * a * c {
            return;
        }
        let (r_sphere, r_ellipsoid) = (a - self.sphere, b - self.ellipsoid);
        // 2a α + 2b β = −r_sphere, 2b α + 2c β = −r_ellipsoid.
        let alpha = (b * r_ellipsoid - c * r_sphere) / (2.0 * gram);
        let beta = (b * r_sphere - a * r_ellipsoid) / (2.0 * gram);
        *momentum += momentum.scale(alpha) + w * beta;
    }
}
