//! Rotation matrices, unit quaternions, axis–angle and rotation vectors, the exponential and
//! logarithm maps of SO(3), re-orthonormalization, and the angular velocity Ω = Ṙ Rᵀ (2.7–2.12).
//!
//! A rotation R maps body components to fixed-frame components, x = R X + c (1.5), so
//! `R = R_WB` in Drake naming. All conversions here stay accurate near the identity and near
//! half turns: the exponential uses `sin θ/θ` and `2 sin²(θ/2)/θ²` (no cancellation), and the
//! logarithm goes through Shepperd's quaternion extraction and `2 atan2(‖v‖, w)`.

use crate::KinematicsError;
use crate::scaling::{self, power_of_two_above};
use nalgebra::{Matrix3, Quaternion, Rotation3, Unit, UnitQuaternion, Vector3};

/// Tolerance on ‖RᵀR − I‖_F for accepting a matrix as a rotation: a few hundred ulps,
/// enough for matrices that went through a handful of products, small enough to reject
/// anything that is visibly not orthogonal.
pub const ROTATION_TOLERANCE: f64 = 1e-12;

/// Tolerance on |‖a‖ − 1| for accepting a vector as a unit axis (same scale as
/// [`ROTATION_TOLERANCE`]).
pub const AXIS_TOLERANCE: f64 = 1e-12;

/// The largest rotation-vector length |φ| that [`exp_map`] accepts: 2⁵³ rad. Above it one
/// rounding of |φ| (which no computation in f64 avoids) exceeds a radian, so the rotation is
/// not determined by φ; [`exp_map`] refuses it with
/// [`KinematicsError::RotationAngleUnresolved`]. An angle given on its own
/// ([`rotation_from_axis_angle`]) is exact as a double and has no such limit.
pub const ROTATION_VECTOR_LIMIT: f64 = 9_007_199_254_740_992.0;

/// The skew-symmetric matrix Ω with Ω x = ω × x (2.10, 2.12).
pub fn skew(w: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -w.z, w.y, w.z, 0.0, -w.x, -w.y, w.x, 0.0)
}

/// The vector ω of the skew-symmetric part of `m`: ω = vee((m − mᵀ)/2), the inverse of [`skew`].
/// Halved before the difference, so that it never overflows for finite `m`.
pub fn vee(m: &Matrix3<f64>) -> Vector3<f64> {
    Vector3::new(
        0.5 * m[(2, 1)] - 0.5 * m[(1, 2)],
        0.5 * m[(0, 2)] - 0.5 * m[(2, 0)],
        0.5 * m[(1, 0)] - 0.5 * m[(0, 1)],
    )
}

/// Fails with [`KinematicsError::NonFiniteResult`] naming `quantity` unless every entry of
/// the computed `values` is finite.
pub(crate) fn check_result<'a>(
    mut values: impl Iterator<Item = &'a f64>,
    quantity: &'static str,
) -> Result<(), KinematicsError> {
    if values.all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(KinematicsError::NonFiniteResult { quantity })
    }
}

pub(crate) fn check_finite_vec(v: &Vector3<f64>, what: &'static str) -> Result<(), KinematicsError> {
    match v.iter().copied().find(|x| !x.is_finite()) {
        Some(value) => Err(KinematicsError::NonFinite { what, value }),
        None => Ok(()),
    }
}

pub(crate) fn check_finite_mat(m: &Matrix3<f64>, what: &'static str) -> Result<(), KinematicsError> {
    match m.iter().copied().find(|x| !x.is_finite()) {
        Some(value) => Err(KinematicsError::NonFinite { what, value }),
        None => Ok(()),
    }
}

pub(crate) fn check_finite(x: f64, what: &'static str) -> Result<(), KinematicsError> {
    if x.is_finite() {
        Ok(())
    } else {
        Err(KinematicsError::NonFinite { what, value: x })
    }
}

/// Checks that `r` is finite and orthogonal with det = +1 (1.14) and returns it as a rotation.
pub fn rotation_from_matrix(r: &Matrix3<f64>) -> Result<Rotation3<f64>, KinematicsError> {
    check_finite_mat(r, "rotation matrix entry")?;
    let orthogonality_error = (r.transpose() * r - Matrix3::identity()).norm();
    let determinant = r.determinant();
    // Written so that a NaN (RᵀR of entries near f64::MAX is ∞ − ∞) fails the check.
    let is_rotation = orthogonality_error <= ROTATION_TOLERANCE && determinant > 0.0;
    if !is_rotation {
        return Err(KinematicsError::NotARotation {
            orthogonality_error,
            determinant,
        });
    }
    Ok(Rotation3::from_matrix_unchecked(*r))
}

/// The unit quaternion of a rotation matrix (checked as in [`rotation_from_matrix`]), by
/// Shepperd's method, with the sign chosen so that w ≥ 0.
pub fn quaternion_from_matrix(r: &Matrix3<f64>) -> Result<UnitQuaternion<f64>, KinematicsError> {
    rotation_from_matrix(r).map(|rot| quaternion_from_rotation(&rot))
}

/// The unit quaternion (w ≥ 0) of a rotation, by Shepperd's method: the component of largest
/// magnitude is taken from a square root of the largest of (trace, R₀₀, R₁₁, R₂₂) and the others
/// from sums/differences of off-diagonal entries divided by it, so the result is accurate to a
/// few ulps for every rotation, including half turns.
pub fn quaternion_from_rotation(r: &Rotation3<f64>) -> UnitQuaternion<f64> {
    let m = r.matrix();
    let (r00, r11, r22) = (m[(0, 0)], m[(1, 1)], m[(2, 2)]);
    let trace = r00 + r11 + r22;
    let q = if trace >= r00 && trace >= r11 && trace >= r22 {
        let s = 2.0 * (1.0 + trace).max(0.0).sqrt();
        Quaternion::new(
            0.25 * s,
            (m[(2, 1)] - m[(1, 2)]) / s,
            (m[(0, 2)] - m[(2, 0)]) / s,
            (m[(1, 0)] - m[(0, 1)]) / s,
        )
    } else if r00 >= r11 && r00 >= r22 {
        let s = 2.0 * (1.0 + r00 - r11 - r22).max(0.0).sqrt();
        Quaternion::new(
            (m[(2, 1)] - m[(1, 2)]) / s,
            0.25 * s,
            (m[(0, 1)] + m[(1, 0)]) / s,
            (m[(0, 2)] + m[(2, 0)]) / s,
        )
    } else if r11 >= r22 {
        let s = 2.0 * (1.0 + r11 - r00 - r22).max(0.0).sqrt();
        Quaternion::new(
            (m[(0, 2)] - m[(2, 0)]) / s,
            (m[(0, 1)] + m[(1, 0)]) / s,
            0.25 * s,
            (m[(1, 2)] + m[(2, 1)]) / s,
        )
    } else {
        let s = 2.0 * (1.0 + r22 - r00 - r11).max(0.0).sqrt();
        Quaternion::new(
            (m[(1, 0)] - m[(0, 1)]) / s,
            (m[(0, 2)] + m[(2, 0)]) / s,
            (m[(1, 2)] + m[(2, 1)]) / s,
            0.25 * s,
        )
    };
    let q = if q.w < 0.0 { -q } else { q };
    UnitQuaternion::new_normalize(q)
}

/// The rotation matrix of a unit quaternion: R = (w² − v·v) I + 2 v vᵀ + 2 w \[v\]×.
pub fn rotation_from_quaternion(q: &UnitQuaternion<f64>) -> Rotation3<f64> {
    q.to_rotation_matrix()
}

/// The exponential map of SO(3): the rotation by θ = |φ| about n = φ/|φ| (Rodrigues),
/// R = I + sin θ \[n\]× + 2 sin²(θ/2) \[n\]×², with |φ| computed on φ scaled by a power of
/// two (it neither overflows nor underflows). Exact to rounding for all θ up to
/// [`ROTATION_VECTOR_LIMIT`], including θ → 0 (no cancellation) and θ ≥ π; above it
/// [`KinematicsError::RotationAngleUnresolved`].
pub fn exp_map(phi: &Vector3<f64>) -> Result<Rotation3<f64>, KinematicsError> {
    check_finite_vec(phi, "rotation vector component")?;
    check_rotation_vector(phi, "rotation vector")?;
    Ok(exp_unchecked(phi))
}

/// Fails with [`KinematicsError::RotationAngleUnresolved`] when |φ| > [`ROTATION_VECTOR_LIMIT`].
pub(crate) fn check_rotation_vector(phi: &Vector3<f64>, what: &'static str) -> Result<(), KinematicsError> {
    let angle = scaling::norm(phi);
    if angle > ROTATION_VECTOR_LIMIT {
        return Err(KinematicsError::RotationAngleUnresolved {
            what,
            angle,
            limit: ROTATION_VECTOR_LIMIT,
        });
    }
    Ok(())
}

/// R = I + sin θ \[n\]× + 2 sin²(θ/2) \[n\]×² for a unit `n` and any finite angle: the sine
/// and cosine reduce the angle modulo 2π exactly (as the platform's libm does: correctly
/// rounded on glibc, macOS and MSVC), so the result is the rotation by the exact double θ.
pub(crate) fn axis_angle_matrix(n: &Vector3<f64>, theta: f64) -> Matrix3<f64> {
    let k = skew(n);
    let half = (0.5 * theta).sin();
    Matrix3::identity() + k * theta.sin() + k * k * (2.0 * half * half)
}

/// [`exp_map`] for an input already known to be finite and within [`ROTATION_VECTOR_LIMIT`].
pub(crate) fn exp_unchecked(phi: &Vector3<f64>) -> Rotation3<f64> {
    let theta = scaling::norm(phi);
    if theta == 0.0 {
        return Rotation3::identity();
    }
    Rotation3::from_matrix_unchecked(axis_angle_matrix(&(phi / theta), theta))
}

/// Series Σ_{n≥0} (−1)ⁿ x^n / (2n + m)! in x = θ², for the small-angle branches below.
fn alt_series(x: f64, m: u32) -> f64 {
    let mut fact = 1.0;
    for i in 1..=m {
        fact *= f64::from(i);
    }
    let (mut sum, mut term, mut k) = (0.0, 1.0 / fact, m);
    for n in 0..14 {
        sum += if n % 2 == 0 { term } else { -term };
        term *= x / (f64::from(k + 1) * f64::from(k + 2));
        k += 2;
    }
    sum
}

/// Series Σ_{n≥1} (−1)ⁿ 2n x^{n−1} / (2n + m)! (the derivative coefficients divided by θ).
fn alt_series_derivative(x: f64, m: u32) -> f64 {
    let mut fact = 1.0;
    for i in 1..=(m + 2) {
        fact *= f64::from(i);
    }
    let (mut sum, mut term, mut k) = (0.0, 1.0 / fact, m + 2);
    for n in 1..15 {
        let signed = if n % 2 == 1 { -term } else { term };
        sum += 2.0 * f64::from(n) * signed;
        term *= x / (f64::from(k + 1) * f64::from(k + 2));
        k += 2;
    }
    sum
}

/// (α, β, α′/θ, β′/θ) with α = (1 − cos θ)/θ², β = (θ − sin θ)/θ³: the coefficients of the
/// right Jacobian of SO(3) and of their derivatives. Series below θ = 2 (13 terms, truncation
/// < 1e-17 relative), closed forms above, where their cancellation costs less than ~16 ulps.
fn jacobian_coefficients(theta: f64) -> (f64, f64, f64, f64) {
    let x = theta * theta;
    if theta < 2.0 {
        (
            alt_series(x, 2),
            alt_series(x, 3),
            alt_series_derivative(x, 2),
            alt_series_derivative(x, 3),
        )
    } else {
        let (s, c) = theta.sin_cos();
        let h = (0.5 * theta).sin() / theta;
        let one_minus_cos = 2.0 * (0.5 * theta).sin().powi(2);
        (
            2.0 * h * h,
            (theta - s) / (x * theta),
            (theta * s - 2.0 * one_minus_cos) / (x * x),
            (theta * (1.0 - c) - 3.0 * (theta - s)) / (x * x * theta),
        )
    }
}

/// The right Jacobian of SO(3): with R(t) = exp(φ(t)), the body-frame angular velocity is
/// ω_B = J_r(φ) φ̇, J_r = I − ((1 − cos θ)/θ²)\[φ\]× + ((θ − sin θ)/θ³)\[φ\]×², θ = |φ|.
/// det J_r = 2(1 − cos θ)/θ², so J_r is invertible for θ < 2π. From θ = 2 on it is evaluated
/// with the unit axis n = φ/θ, J_r = I − ((1 − cos θ)/θ)\[n\]× + (1 − sin θ/θ)\[n\]×², whose
/// coefficients are bounded: finite for every finite φ.
pub fn right_jacobian(phi: &Vector3<f64>) -> Matrix3<f64> {
    let theta = scaling::norm(phi);
    if theta < 2.0 {
        let (alpha, beta, _, _) = jacobian_coefficients(theta);
        let k = skew(phi);
        return Matrix3::identity() - k * alpha + k * k * beta;
    }
    let theta = theta.min(f64::MAX);
    let k = skew(&(phi / theta));
    let half = (0.5 * theta).sin();
    Matrix3::identity() - k * (2.0 * half * half / theta) + k * k * (1.0 - theta.sin() / theta)
}

/// The time derivative dJ_r/dt of [`right_jacobian`] along φ(t) with rate φ̇:
/// −α̇\[φ\] − α\[φ̇\] + β̇\[φ\]² + β(\[φ̇\]\[φ\] + \[φ\]\[φ̇\]), α̇ = (α′/θ)(φ·φ̇), β̇ = (β′/θ)(φ·φ̇).
/// From θ = 2 on in terms of n = φ/θ and θ̇ = n·φ̇ with bounded coefficients (see the
/// source), so that it overflows only when φ̇ is of the order of f64::MAX.
pub fn right_jacobian_rate(phi: &Vector3<f64>, phi_dot: &Vector3<f64>) -> Matrix3<f64> {
    let theta = scaling::norm(phi);
    let kd = skew(phi_dot);
    if theta < 2.0 {
        let (alpha, beta, dalpha, dbeta) = jacobian_coefficients(theta);
        let d = phi.dot(phi_dot);
        let k = skew(phi);
        return -k * (dalpha * d) - kd * alpha + k * k * (dbeta * d) + (kd * k + k * kd) * beta;
    }
    let theta = theta.min(f64::MAX);
    let n = phi / theta;
    let (k, theta_dot) = (skew(&n), n.dot(phi_dot));
    let (s, c) = theta.sin_cos();
    let half = (0.5 * theta).sin();
    let one_minus_cos = 2.0 * half * half;
    // α′θ, α, β′θ², βθ with α = (1 − cos θ)/θ², β = (θ − sin θ)/θ³.
    let d_alpha = (s - 2.0 * one_minus_cos / theta) / theta;
    let alpha = one_minus_cos / theta / theta;
    let d_beta = ((1.0 - c) - 3.0 * (1.0 - s / theta)) / theta;
    let beta = (1.0 - s / theta) / theta;
    -k * (d_alpha * theta_dot) - kd * alpha + k * k * (d_beta * theta_dot) + (kd * k + k * kd) * beta
}

/// The logarithm map of SO(3): the rotation vector φ with exp(φ) = R and |φ| ∈ [0, π].
///
/// Computed from the quaternion q = (w, v) of R (Shepperd, w ≥ 0) as φ = 2 atan2(|v|, w) v/|v|,
/// which is accurate to a few ulps of |φ| near the identity and near half turns. At exactly
/// |φ| = π both ±φ are valid; the one with w ≥ 0 from Shepperd's branch is returned.
pub fn log_map(r: &Rotation3<f64>) -> Vector3<f64> {
    log_quaternion(&quaternion_from_rotation(r))
}

/// The rotation vector φ (|φ| ≤ π) of a unit quaternion: φ = 2 atan2(|v|, |w|) sign(w) v/|v|.
pub fn log_quaternion(q: &UnitQuaternion<f64>) -> Vector3<f64> {
    let (w, v) = if q.w < 0.0 { (-q.w, -q.imag()) } else { (q.w, q.imag()) };
    let n = v.norm();
    if n == 0.0 {
        return Vector3::zeros();
    }
    v * (2.0 * n.atan2(w) / n)
}

/// An axis–angle pair. `axis` is a unit vector and `angle` ∈ [0, π]; for the identity the
/// angle is 0 and the axis is, by convention, e_x.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisAngle {
    /// Unit rotation axis (fixed-frame and body-frame components agree: R a = a).
    pub axis: Unit<Vector3<f64>>,
    /// Rotation angle in radians, in [0, π].
    pub angle: f64,
}

/// The axis–angle pair of a rotation (from [`log_map`]).
pub fn axis_angle_from_rotation(r: &Rotation3<f64>) -> AxisAngle {
    let phi = log_map(r);
    let angle = phi.norm();
    if angle == 0.0 {
        AxisAngle {
            axis: Vector3::x_axis(),
            angle: 0.0,
        }
    } else {
        AxisAngle {
            axis: Unit::new_unchecked(phi / angle),
            angle,
        }
    }
}

/// Checks that `axis` is finite and of unit length within [`AXIS_TOLERANCE`]; `what` names it.
pub fn unit_axis(axis: &Vector3<f64>, what: &'static str) -> Result<Unit<Vector3<f64>>, KinematicsError> {
    check_finite_vec(axis, what)?;
    let norm = axis.norm();
    if (norm - 1.0).abs() > AXIS_TOLERANCE {
        return Err(KinematicsError::NotAUnitAxis { what, norm });
    }
    Ok(Unit::new_normalize(*axis))
}

/// The rotation by `angle` (rad) about the unit vector `axis` (rejects non-unit, zero or
/// non-finite axes), R = I + sin θ \[a\]× + 2 sin²(θ/2) \[a\]×².
///
/// Every finite angle is accepted and reduced modulo 2π exactly: the result is the rotation
/// by the angle the double holds, to a few ulps. Beyond 2⁵³ rad adjacent doubles are more
/// than a radian apart, so an angle computed with any rounding no longer determines the
/// rotation; the result is still the exact one for the double given.
pub fn rotation_from_axis_angle(axis: &Vector3<f64>, angle: f64) -> Result<Rotation3<f64>, KinematicsError> {
    let axis = unit_axis(axis, "rotation axis")?;
    check_finite(angle, "rotation angle")?;
    Ok(Rotation3::from_matrix_unchecked(axis_angle_matrix(&axis, angle)))
}

/// A rotation repaired from a drifted input, with the size of the repair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orthonormalized {
    /// The nearest rotation.
    pub rotation: Rotation3<f64>,
    /// ‖input − rotation‖_F for matrices, |‖q‖ − 1| for quaternions: how far the input had drifted.
    pub correction: f64,
}

/// The rotation nearest to `m` in the Frobenius norm: the orthogonal polar factor U Vᵀ of the
/// SVD m = U Σ Vᵀ, computed on m scaled by a power of two (the polar factor of a positive
/// multiple is the same), so that any finite m works. Fails for non-finite input, for
/// det m ≤ 0 (a reflection or a singular matrix is not a drifted rotation), and with
/// [`KinematicsError::NonFiniteResult`] when the correction ‖m − R‖_F exceeds f64::MAX. The
/// result is checked: ‖RᵀR − I‖_F ≤ 64u and det R > 0, or [`KinematicsError::NotARotation`].
pub fn orthonormalize_matrix(m: &Matrix3<f64>) -> Result<Orthonormalized, KinematicsError> {
    check_finite_mat(m, "matrix entry")?;
    let scale = power_of_two_above(m.amax());
    let scaled = m / scale;
    let determinant = scaled.determinant();
    if determinant <= 0.0 {
        return Err(KinematicsError::NotARotation {
            orthogonality_error: (m.transpose() * m - Matrix3::identity()).norm(),
            determinant: determinant * scale * scale * scale,
        });
    }
    let svd = scaled.svd(true, true);
    let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
        return Err(KinematicsError::NotARotation {
            orthogonality_error: f64::INFINITY,
            determinant,
        });
    };
    let r = refine_polar_factor(proper_polar_factor(u, &svd.singular_values, v_t), &scaled);
    let orthogonality_error = (r.transpose() * r - Matrix3::identity()).norm();
    if !(orthogonality_error <= 64.0 * f64::EPSILON && r.determinant() > 0.0) {
        return Err(KinematicsError::NotARotation {
            orthogonality_error,
            determinant: determinant * scale * scale * scale,
        });
    }
    let correction = scaling::frobenius_norm(&(m - r));
    check_result([correction].iter(), "correction ‖m − R‖")?;
    Ok(Orthonormalized {
        rotation: Rotation3::from_matrix_unchecked(r),
        correction,
    })
}

/// Newton steps towards the rotation R with Rᵀm symmetric (the proper polar factor): with
/// S = Rᵀm and its skew part [k]×, the rotation exp([ω]×) with (tr S·I − S) ω = 2k makes
/// exp(−[ω]×) S symmetric to first order ([ω]× S + S [ω]× = [(tr S·I − S) ω]× for symmetric S).
/// The matrix tr S·I − S has the eigenvalues σ_i + σ_j, so each step costs a 3 × 3 solve and
/// brings R to the rounding level u κ that m's own rounding allows, which an SVD by iteration
/// does not always reach. A step whose solve fails (m nearly singular) leaves R as it is.
fn refine_polar_factor(mut r: Matrix3<f64>, m: &Matrix3<f64>) -> Matrix3<f64> {
    for _ in 0..2 {
        let s = r.transpose() * m;
        // Twice the axial vector of S's skew part.
        let k = Vector3::new(s[(2, 1)] - s[(1, 2)], s[(0, 2)] - s[(2, 0)], s[(1, 0)] - s[(0, 1)]);
        let system = Matrix3::identity() * s.trace() - 0.5 * (s + s.transpose());
        let Some(omega) = system.lu().solve(&k) else { break };
        if !omega.iter().all(|w| w.is_finite()) || omega.norm() > 1e-3 {
            break;
        }
        r *= Rotation3::from_scaled_axis(omega).matrix();
    }
    r
}

/// U Vᵀ with det +1: when rounding in a nearly singular m leaves det(U) det(Vᵀ) = −1 although
/// det m > 0, the column of U of the smallest singular value changes sign (the rotation nearest
/// to m among proper ones, as in the Kabsch construction).
fn proper_polar_factor(mut u: Matrix3<f64>, singular_values: &Vector3<f64>, v_t: Matrix3<f64>) -> Matrix3<f64> {
    if u.determinant() * v_t.determinant() < 0.0 {
        let smallest = singular_values.imin();
        u.column_mut(smallest).neg_mut();
    }
    u * v_t
}

/// The unit quaternion nearest to a drifted q = (w, x, y, z): q/‖q‖, with correction |‖q‖ − 1|.
/// Fails for a zero or non-finite q.
pub fn orthonormalize_quaternion(q: &Quaternion<f64>) -> Result<(UnitQuaternion<f64>, f64), KinematicsError> {
    for value in q.coords.iter().copied() {
        check_finite(value, "quaternion component")?;
    }
    let scale = power_of_two_above(q.coords.amax());
    let scaled = q / scale;
    let norm = scaled.norm() * scale;
    if scaled.norm() == 0.0 {
        return Err(KinematicsError::NotAUnitQuaternion { norm });
    }
    let correction = (norm - 1.0).abs();
    check_result([correction].iter(), "quaternion norm")?;
    Ok((UnitQuaternion::new_unchecked(scaled / scaled.norm()), correction))
}

/// The angular velocity ω, expressed in the fixed frame, from R and Ṙ: Ω = Ṙ Rᵀ (2.7–2.12).
///
/// Ω is skew-symmetric for an exact rotation; the symmetric part that rounding leaves is
/// discarded by averaging the two off-diagonal entries. Ṙ is scaled by a power of two for the
/// product, so the result overflows only when ω itself exceeds f64::MAX
/// ([`KinematicsError::NonFiniteResult`]).
pub fn angular_velocity_from_rate(r: &Rotation3<f64>, r_dot: &Matrix3<f64>) -> Result<Vector3<f64>, KinematicsError> {
    check_finite_mat(r_dot, "rotation rate entry")?;
    let scale = power_of_two_above(r_dot.amax());
    let omega = vee(&(r_dot / scale * r.matrix().transpose())) * scale;
    check_result(omega.iter(), "angular velocity")?;
    Ok(omega)
}

/// The angular velocity expressed in the body frame, ω_B = Rᵀ ω = vee(Rᵀ Ṙ) (scaled as
/// [`angular_velocity_from_rate`]).
pub fn body_angular_velocity_from_rate(
    r: &Rotation3<f64>,
    r_dot: &Matrix3<f64>,
) -> Result<Vector3<f64>, KinematicsError> {
    check_finite_mat(r_dot, "rotation rate entry")?;
    let scale = power_of_two_above(r_dot.amax());
    let omega = vee(&(r.matrix().transpose() * (r_dot / scale))) * scale;
    check_result(omega.iter(), "angular velocity")?;
    Ok(omega)
}

/// How a quaternion that is not exactly of unit length is treated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum QuaternionNorm {
    /// Accept only |‖q‖ − 1| ≤ [`ROTATION_TOLERANCE`]; anything else is an error.
    RequireUnit,
    /// Divide by ‖q‖ (any non-zero finite q), e.g. to repair drift after integration.
    Normalize,
}

/// The unit quaternion of `q = (w, x, y, z)` under the given norm policy.
pub fn unit_quaternion(
    w: f64,
    x: f64,
    y: f64,
    z: f64,
    policy: QuaternionNorm,
) -> Result<UnitQuaternion<f64>, KinematicsError> {
    if let Some(value) = [w, x, y, z].into_iter().find(|v| !v.is_finite()) {
        return Err(KinematicsError::NonFinite {
            what: "quaternion component",
            value,
        });
    }
    let q = nalgebra::Quaternion::new(w, x, y, z);
    // Normalised on q/2^k, so that any non-zero finite q works under `Normalize`.
    let scale = power_of_two_above(q.coords.amax());
    let scaled = q / scale;
    let norm = scaled.norm() * scale;
    let acceptable = match policy {
        QuaternionNorm::RequireUnit => (norm - 1.0).abs() <= ROTATION_TOLERANCE,
        QuaternionNorm::Normalize => scaled.norm() > 0.0,
    };
    if !acceptable {
        return Err(KinematicsError::NotAUnitQuaternion { norm });
    }
    Ok(UnitQuaternion::new_normalize(scaled))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::f64::consts::PI;

    const EPS: f64 = f64::EPSILON;

    #[test]
    fn skew_is_the_cross_product() {
        let w = Vector3::new(0.3, -1.2, 2.5);
        let x = Vector3::new(-0.7, 0.4, 1.1);
        assert!((skew(&w) * x - w.cross(&x)).norm() < 1e-15);
        assert_eq!(vee(&skew(&w)), w);
    }

    #[test]
    fn angular_velocity_of_a_steady_spin_about_z() {
        // R(t) = Rz(w t); Ṙ = w Ω_z R, so ω = (0, 0, w).
        let w = 1.7;
        let t = 0.4;
        let r = Rotation3::from_axis_angle(&Vector3::z_axis(), w * t);
        let r_dot = skew(&Vector3::new(0.0, 0.0, w)) * r.matrix();
        let omega = angular_velocity_from_rate(&r, &r_dot).expect("finite input");
        assert!((omega - Vector3::new(0.0, 0.0, w)).norm() < 1e-15);
        let omega_b = body_angular_velocity_from_rate(&r, &r_dot).expect("finite input");
        assert!((omega_b - Vector3::new(0.0, 0.0, w)).norm() < 1e-15);
    }

    #[test]
    fn angular_velocity_matches_finite_differences_of_exp() {
        // R(t) = exp(φ0 + t φ1); ω from Ω = Ṙ Rᵀ with Ṙ by central differences, step h:
        // truncation O(h²·|R'''|) ≈ h², rounding O(eps/h).
        let phi0 = Vector3::new(0.4, -1.1, 0.7);
        let phi1 = Vector3::new(-0.3, 0.5, 0.9);
        let h = 1e-5;
        let r = exp_unchecked(&phi0);
        let r_dot =
            (exp_unchecked(&(phi0 + phi1 * h)).matrix() - exp_unchecked(&(phi0 - phi1 * h)).matrix()) / (2.0 * h);
        let omega = angular_velocity_from_rate(&r, &r_dot).expect("finite");
        // Independent closed form: ω_W = R J_r(φ0) φ1, J_r = I − ((1−cos)/θ²)[φ] + ((θ−sin)/θ³)[φ]².
        let th = phi0.norm();
        let k = skew(&phi0);
        let jr = Matrix3::identity() - k * ((1.0 - th.cos()) / (th * th)) + k * k * ((th - th.sin()) / th.powi(3));
        let expected = r * (jr * phi1);
        let tol = 10.0 * (h * h + EPS / h);
        assert!((omega - expected).norm() < tol, "{omega} vs {expected}");
    }

    #[test]
    fn a_reflection_is_not_a_rotation() {
        let m = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0));
        assert!(matches!(
            quaternion_from_matrix(&m),
            Err(KinematicsError::NotARotation { .. })
        ));
        assert!(matches!(
            orthonormalize_matrix(&m),
            Err(KinematicsError::NotARotation { .. })
        ));
    }

    #[test]
    fn quaternion_norm_policies() {
        let half = std::f64::consts::FRAC_1_SQRT_2;
        let q = unit_quaternion(half, 0.0, 0.0, half, QuaternionNorm::RequireUnit).expect("unit");
        let r = q.to_rotation_matrix();
        assert!((r * Vector3::x() - Vector3::y()).norm() < 1e-15);
        assert!(matches!(
            unit_quaternion(2.0, 0.0, 0.0, 0.0, QuaternionNorm::RequireUnit),
            Err(KinematicsError::NotAUnitQuaternion { .. })
        ));
        let q = unit_quaternion(2.0, 0.0, 0.0, 0.0, QuaternionNorm::Normalize).expect("normalizable");
        assert_eq!(q.w, 1.0);
        assert!(unit_quaternion(0.0, 0.0, 0.0, 0.0, QuaternionNorm::Normalize).is_err());
    }

    #[test]
    fn nan_is_rejected() {
        let mut m = Matrix3::identity();
        m[(1, 2)] = f64::NAN;
        assert!(matches!(
            rotation_from_matrix(&m),
            Err(KinematicsError::NonFinite { .. })
        ));
        assert!(exp_map(&Vector3::new(0.0, f64::INFINITY, 0.0)).is_err());
        assert!(orthonormalize_matrix(&m).is_err());
        assert!(orthonormalize_quaternion(&Quaternion::new(f64::NAN, 0.0, 0.0, 0.0)).is_err());
        assert!(matches!(
            orthonormalize_quaternion(&Quaternion::new(0.0, 0.0, 0.0, 0.0)),
            Err(KinematicsError::NotAUnitQuaternion { norm: 0.0 })
        ));
    }

    #[test]
    fn exp_of_tiny_vectors_is_first_order_exact() {
        // exp(φ) = I + [φ] + ½[φ]² + O(|φ|³): for |φ| = 1e-9 the matrix equals I + [φ] to rounding.
        for &s in &[1e-300, 1e-100, 1e-9, 1e-5] {
            let phi = Vector3::new(0.6, -0.8, 0.0) * s;
            let r = exp_map(&phi).expect("finite");
            let k = skew(&phi);
            let series = Matrix3::identity() + k + k * k * 0.5 - k * k * k / 6.0;
            assert!((r.matrix() - series).norm() <= 4.0 * EPS + s.powi(4), "s = {s}");
            // The logarithm recovers φ to a relative accuracy eps/|φ| (the information the
            // matrix holds about φ is absolute, ~eps).
            let back = log_map(&r);
            assert!((back - phi).norm() <= 4.0 * EPS, "s = {s}: {back} vs {phi}");
        }
        assert_eq!(log_map(&Rotation3::identity()), Vector3::zeros());
    }

    #[test]
    fn log_near_and_at_a_half_turn() {
        let axis = Vector3::new(2.0, -1.0, 3.0).normalize();
        for &d in &[0.0, 1e-15, 1e-12, 1e-8, 1e-4] {
            let phi = axis * (PI - d);
            let r = exp_map(&phi).expect("finite");
            let back = log_map(&r);
            assert!(back.norm() <= PI + 4.0 * EPS);
            // exp(log R) = R always; log(exp φ) = φ up to the ±axis ambiguity at exactly π.
            assert!(
                (exp_unchecked(&back).matrix() - r.matrix()).norm() <= 8.0 * EPS,
                "d = {d}"
            );
            let err = (back - phi).norm().min((back + phi).norm());
            assert!(err <= 16.0 * EPS, "d = {d}: error {err}");
            if d >= 1e-8 {
                assert!((back - phi).norm() <= 16.0 * EPS, "d = {d}: sign");
            }
        }
        // Exact half turns about the coordinate axes (the trace-branch fails here).
        for i in 0..3 {
            let mut phi = Vector3::zeros();
            phi[i] = PI;
            let r = exp_map(&phi).expect("finite");
            let back = log_map(&r);
            assert!((back.norm() - PI).abs() <= 4.0 * EPS);
            assert!((back.abs() - phi).norm() <= 8.0 * EPS);
        }
    }

    #[test]
    fn axis_angle_round_trip_and_bad_axes() {
        let r = rotation_from_axis_angle(&Vector3::new(0.0, 0.6, 0.8), 2.0).expect("unit axis");
        let aa = axis_angle_from_rotation(&r);
        assert!((aa.angle - 2.0).abs() < 4.0 * EPS);
        assert!((aa.axis.into_inner() - Vector3::new(0.0, 0.6, 0.8)).norm() < 4.0 * EPS);
        assert_eq!(axis_angle_from_rotation(&Rotation3::identity()).angle, 0.0);
        assert!(matches!(
            rotation_from_axis_angle(&Vector3::zeros(), 1.0),
            Err(KinematicsError::NotAUnitAxis { norm: 0.0, .. })
        ));
        assert!(matches!(
            rotation_from_axis_angle(&Vector3::new(1.0, 1.0, 0.0), 1.0),
            Err(KinematicsError::NotAUnitAxis { .. })
        ));
        assert!(matches!(
            rotation_from_axis_angle(&Vector3::x(), f64::NAN),
            Err(KinematicsError::NonFinite { .. })
        ));
    }

    #[test]
    fn orthonormalize_a_drifted_matrix() {
        // R + E with small E: the polar factor is within O(|E|²) of R, and the correction is
        // |E_sym|-sized; a rotation itself comes back unchanged.
        let r = exp_unchecked(&Vector3::new(0.3, 1.9, -0.4));
        let fixed = orthonormalize_matrix(r.matrix()).expect("rotation");
        assert!(fixed.correction < 8.0 * EPS);
        let e = Matrix3::new(1.0, -2.0, 0.5, 0.3, 0.7, -1.1, 0.2, 0.9, -0.4) * 1e-6;
        let fixed = orthonormalize_matrix(&(r.matrix() + e)).expect("near rotation");
        let q = fixed.rotation.matrix();
        assert!((q.transpose() * q - Matrix3::identity()).norm() < 8.0 * EPS);
        assert!((q.determinant() - 1.0).abs() < 8.0 * EPS);
        assert!((q - r.matrix()).norm() < 2.0 * e.norm());
        // Polar factor property: Qᵀ M is symmetric.
        let s = q.transpose() * (r.matrix() + e);
        assert!((s - s.transpose()).norm() < 16.0 * EPS);
        let (uq, drift) = orthonormalize_quaternion(&Quaternion::new(1.0 + 1e-7, 0.0, 0.0, 0.0)).expect("finite");
        assert_eq!(uq.w, 1.0);
        assert!((drift - 1e-7).abs() < 1e-15);
    }

    #[test]
    fn right_jacobian_and_its_rate_match_finite_differences() {
        // ω_B = vee(Rᵀ Ṙ) with Ṙ by central differences of exp along φ(t) = φ0 + t φ1; and
        // dJ_r/dt against differences of J_r. Angles on both sides of the series switch (θ = 2).
        for phi0 in [
            Vector3::new(1e-3, -2e-3, 5e-4),
            Vector3::new(0.4, -1.1, 0.7),
            Vector3::new(1.2, 1.1, -0.9),
            Vector3::new(2.5, -1.0, 2.0),
        ] {
            let phi1 = Vector3::new(-0.3, 0.5, 0.9);
            let h = 1e-5;
            let r = exp_unchecked(&phi0);
            let r_dot =
                (exp_unchecked(&(phi0 + phi1 * h)).matrix() - exp_unchecked(&(phi0 - phi1 * h)).matrix()) / (2.0 * h);
            let w_fd = vee(&(r.matrix().transpose() * r_dot));
            let tol = 10.0 * (h * h + EPS / h);
            assert!((right_jacobian(&phi0) * phi1 - w_fd).norm() < tol, "{phi0}");
            let jd_fd = (right_jacobian(&(phi0 + phi1 * h)) - right_jacobian(&(phi0 - phi1 * h))) / (2.0 * h);
            assert!((right_jacobian_rate(&phi0, &phi1) - jd_fd).norm() < tol, "{phi0}");
        }
        // The series and the closed forms agree where both are accurate (θ ∈ [1.5, 3]):
        // the closed forms lose ~eps·θ⁵/|numerator| there, a few dozen ulps at most.
        for theta in [1.5f64, 2.0, 2.5, 3.0] {
            let x = theta * theta;
            let (s, c) = theta.sin_cos();
            let closed = [
                (1.0 - c) / x,
                (theta - s) / (x * theta),
                (theta * s - 2.0 * (1.0 - c)) / (x * x),
                (theta * (1.0 - c) - 3.0 * (theta - s)) / (x * x * theta),
            ];
            let series = [
                alt_series(x, 2),
                alt_series(x, 3),
                alt_series_derivative(x, 2),
                alt_series_derivative(x, 3),
            ];
            for (a, b) in closed.iter().zip(series) {
                assert!((a - b).abs() <= 64.0 * EPS * a.abs(), "θ = {theta}: {a} vs {b}");
            }
        }
        assert_eq!(right_jacobian(&Vector3::zeros()), Matrix3::identity());
    }

    proptest! {
        #[test]
        // Components within ±1.81 keep |φ| ≤ 1.81·√3 ≈ 3.135 < π without rejecting samples.
        fn exp_log_round_trip(x in -1.81f64..1.81, y in -1.81f64..1.81, z in -1.81f64..1.81) {
            let phi = Vector3::new(x, y, z);
            let r = exp_map(&phi).expect("finite");
            let m = r.matrix();
            let ortho = (m.transpose() * m - Matrix3::identity()).norm();
            // Rodrigues sums terms of size up to 1, |sin θ| and (1 − cos θ) ≤ 2 built from
            // entries of [φ]² (size θ²): entry errors ~ 4 eps (1 + θ²·b) with b ≤ 1/2, so the
            // bound 2‖δR‖_F on ‖RᵀR − I‖_F is about 8 eps (1 + θ²).
            prop_assert!(ortho < 8.0 * EPS * (1.0 + phi.norm_squared()), "orthogonality {}", ortho / EPS);
            prop_assert!((log_map(&r) - phi).norm() < 32.0 * EPS * (1.0 + phi.norm()));
            // Quaternion <-> matrix round trip and agreement with nalgebra's independent formula.
            let q = quaternion_from_rotation(&r);
            let q_ref = UnitQuaternion::from_scaled_axis(phi);
            let d = (q.coords - q_ref.coords).norm().min((q.coords + q_ref.coords).norm());
            prop_assert!(d < 8.0 * EPS);
            // The round trip returns a rotation to rounding, while m carries the entry errors
            // of Rodrigues' sum above (‖δR‖_F up to about 4 eps (1 + θ²)); so the two differ by
            // that plus the quaternion's few ulps, not by a few ulps alone (θ = 2.88 gave 8.25 eps).
            prop_assert!(
                (rotation_from_quaternion(&q).matrix() - m).norm() < 8.0 * EPS * (1.0 + phi.norm_squared())
            );
        }
    }
}
