//! The right-hand sides of the rigid body's rotational equations of motion in principal axes,
//! for integrators: Euler's equations (7.41) with a torque, and the attitude kinematics.

use nalgebra::{Matrix3, Vector3};

use crate::error::{DynamicsError, check_input, check_result};

/// ω̇ in principal axes from Euler's equations (7.41):
/// I₁ω̇₁ = M₁ + (I₂ − I₃)ω₂ω₃, I₂ω̇₂ = M₂ + (I₃ − I₁)ω₃ω₁, I₃ω̇₃ = M₃ + (I₁ − I₂)ω₁ω₂.
///
/// `moments` are the principal moments (I₁, I₂, I₃) > 0 about the centre of mass or a fixed
/// point, in any order; `omega` and `torque` are body-frame components along the same principal
/// axes (rad/s, N·m). Errors: a non-finite input, a moment ≤ 0, or a non-finite result.
pub fn euler_rates(
    moments: &Vector3<f64>,
    omega: &Vector3<f64>,
    torque: &Vector3<f64>,
) -> Result<Vector3<f64>, DynamicsError> {
    check_input(moments.as_slice(), "principal moments")?;
    check_input(omega.as_slice(), "angular velocity ω")?;
    check_input(torque.as_slice(), "torque")?;
    if let Some(&bad) = moments.iter().find(|m| **m <= 0.0) {
        return Err(DynamicsError::OutOfRange {
            what: "principal moment",
            requirement: "> 0",
            value: bad,
        });
    }
    let [i1, i2, i3] = [moments.x, moments.y, moments.z];
    let [w1, w2, w3] = [omega.x, omega.y, omega.z];
    let rates = Vector3::new(
        (torque.x + (i2 - i3) * w2 * w3) / i1,
        (torque.y + (i3 - i1) * w3 * w1) / i2,
        (torque.z + (i1 - i2) * w1 * w2) / i3,
    );
    check_result(rates.iter(), "Euler's equations ω̇")?;
    Ok(rates)
}

/// Ṙ = R [ω]× for the rotation R that maps body components to space components and the
/// body-frame angular velocity ω ((7.24): ė_k = ω × e_k for the body axes e_k = R E_k).
/// Errors: a non-finite input or result.
pub fn attitude_rate(rotation: &Matrix3<f64>, omega: &Vector3<f64>) -> Result<Matrix3<f64>, DynamicsError> {
    check_input(rotation.as_slice(), "rotation R")?;
    check_input(omega.as_slice(), "angular velocity ω")?;
    let rate = rotation * omega.cross_matrix();
    check_result(rate.iter(), "attitude rate Ṙ")?;
    Ok(rate)
}
