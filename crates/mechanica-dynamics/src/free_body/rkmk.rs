//! The Runge–Kutta–Munthe-Kaas method of order 4 for (R, ω) ∈ SO(3) × ℝ³: R = R₀ exp([u]×) with
//! u̇ = dexp⁻¹_u(ω), u(0) = 0, and Euler's equations (7.41) for ω, both by the classical RK4
//! tableau; R₁ = R₀ exp([Θ]×) with Θ the RK4 value of u(h). With the body-frame ω the group
//! acts on the right (Ṙ = R[ω]×), so ω = dexp_{−u}(u̇) and u̇ = dexp⁻¹_{−u}(ω); the series
//! dexp⁻¹_{−u}(v) = v + ½ u × v + (1/12) u × (u × v) + O(|u|⁴|v|) is truncated after the terms
//! of order 2 in u, which order 4 requires (the omitted terms are O(h⁴) in the stages, O(h⁵)
//! in Θ).

use mechanica_kinematics::rotation::exp_map;
use nalgebra::{Matrix3, Vector3};

use crate::error::DynamicsError;

/// dexp⁻¹_{−u}(v) truncated after the double commutator.
fn dexp_inverse(u: &Vector3<f64>, v: &Vector3<f64>) -> Vector3<f64> {
    let uv = u.cross(v);
    v + uv * 0.5 + u.cross(&uv) / 12.0
}

/// Euler's equations (7.41) without torque, for validated moments.
fn omega_rate(moments: &Vector3<f64>, w: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(
        (moments.y - moments.z) * w.y * w.z / moments.x,
        (moments.z - moments.x) * w.z * w.x / moments.y,
        (moments.x - moments.y) * w.x * w.y / moments.z,
    )
}

/// One RKMK4 step of length h on (R, ω).
pub(crate) fn rkmk4_step(
    moments: &Vector3<f64>,
    rotation: &mut Matrix3<f64>,
    omega: &mut Vector3<f64>,
    h: f64,
) -> Result<(), DynamicsError> {
    let w0 = *omega;
    let (k1, l1) = (w0, omega_rate(moments, &w0));
    let (u2, w2) = (k1 * (0.5 * h), w0 + l1 * (0.5 * h));
    let (k2, l2) = (dexp_inverse(&u2, &w2), omega_rate(moments, &w2));
    let (u3, w3) = (k2 * (0.5 * h), w0 + l2 * (0.5 * h));
    let (k3, l3) = (dexp_inverse(&u3, &w3), omega_rate(moments, &w3));
    let (u4, w4) = (k3 * h, w0 + l3 * h);
    let (k4, l4) = (dexp_inverse(&u4, &w4), omega_rate(moments, &w4));
    let theta = (k1 + (k2 + k3) * 2.0 + k4) * (h / 6.0);
    *omega = w0 + (l1 + (l2 + l3) * 2.0 + l4) * (h / 6.0);
    *rotation *= exp_map(&theta)?.matrix();
    Ok(())
}
