//! Euler angles of the twelve intrinsic sequences: rotation matrices from angles and back, and
//! the maps between Euler rates and angular velocity.

use crate::ffi::boundary::boundary;
use crate::ffi::c_enum::{c_enum, enum_value};
use crate::ffi::spatial::{read_rotation, read_triple, read_vec3};
use crate::ffi::status::*;
use crate::ffi::types::*;
use crate::ffi::validate::*;
use mechanica_kinematics::euler::{self, AngularVelocityFrame, EulerSequence};

/// An intrinsic Euler axis sequence: R = R_i(a) R_j(b) R_k(c), angles = {a, b, c} (rad).
/// EB1911's angles (θ, φ, ψ) are MECH_EULER_ZYZ with {a, b, c} = {ψ, θ, φ}.
pub type mech_euler_sequence_t = i32;
/// Tait–Bryan XYZ (robotics / Cardan).
pub const MECH_EULER_XYZ: mech_euler_sequence_t = 0;
/// Tait–Bryan XZY.
pub const MECH_EULER_XZY: mech_euler_sequence_t = 1;
/// Tait–Bryan YXZ.
pub const MECH_EULER_YXZ: mech_euler_sequence_t = 2;
/// Tait–Bryan YZX.
pub const MECH_EULER_YZX: mech_euler_sequence_t = 3;
/// Tait–Bryan ZXY.
pub const MECH_EULER_ZXY: mech_euler_sequence_t = 4;
/// Tait–Bryan ZYX (aerospace yaw, pitch, roll).
pub const MECH_EULER_ZYX: mech_euler_sequence_t = 5;
/// Proper Euler XYX.
pub const MECH_EULER_XYX: mech_euler_sequence_t = 6;
/// Proper Euler XZX.
pub const MECH_EULER_XZX: mech_euler_sequence_t = 7;
/// Proper Euler YXY.
pub const MECH_EULER_YXY: mech_euler_sequence_t = 8;
/// Proper Euler YZY.
pub const MECH_EULER_YZY: mech_euler_sequence_t = 9;
/// Proper Euler ZXZ.
pub const MECH_EULER_ZXZ: mech_euler_sequence_t = 10;
/// Proper Euler ZYZ (robotics ZYZ; EB1911 as {ψ, θ, φ}).
pub const MECH_EULER_ZYZ: mech_euler_sequence_t = 11;

c_enum!(EulerSequence,
    MECH_EULER_XYZ => EulerSequence::Xyz,
    MECH_EULER_XZY => EulerSequence::Xzy,
    MECH_EULER_YXZ => EulerSequence::Yxz,
    MECH_EULER_YZX => EulerSequence::Yzx,
    MECH_EULER_ZXY => EulerSequence::Zxy,
    MECH_EULER_ZYX => EulerSequence::Zyx,
    MECH_EULER_XYX => EulerSequence::Xyx,
    MECH_EULER_XZX => EulerSequence::Xzx,
    MECH_EULER_YXY => EulerSequence::Yxy,
    MECH_EULER_YZY => EulerSequence::Yzy,
    MECH_EULER_ZXZ => EulerSequence::Zxz,
    MECH_EULER_ZYZ => EulerSequence::Zyz,
);

/// The frame in which an angular velocity is expressed.
pub type mech_frame_t = i32;
/// Fixed (world) frame components.
pub const MECH_FRAME_FIXED: mech_frame_t = 0;
/// Body frame components (EB1911's p, q, r).
pub const MECH_FRAME_BODY: mech_frame_t = 1;

c_enum!(AngularVelocityFrame,
    MECH_FRAME_FIXED => AngularVelocityFrame::Fixed,
    MECH_FRAME_BODY => AngularVelocityFrame::Body,
);

/// The rotation matrix R = R_i(a) R_j(b) R_k(c) (column-major) of the Euler angles `angles` =
/// {a, b, c} (3 doubles, rad) in the sequence `sequence` (a mech_euler_sequence_t), written to
/// `rotation_out`. Any finite angles are accepted.
///
/// Errors: MECH_STATUS_BAD_ENUM for an unknown `sequence`; MECH_STATUS_NON_FINITE for a NaN or
/// infinite angle.
///
/// # Safety
/// `angles` must point to 3 readable doubles and `rotation_out` to a writable mech_mat3_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_rotation_from_euler(
    sequence: mech_euler_sequence_t,
    angles: *const f64,
    rotation_out: *mut mech_mat3_t,
) -> mech_status_t {
    boundary(|| {
        let seq: EulerSequence = enum_value(sequence, "sequence")?;
        // SAFETY: caller's contract.
        let a = unsafe { read_triple(angles, "angles") }?;
        let out = Out::new(rotation_out, "rotation_out")?;
        let r = euler::rotation_from_euler(seq, &a)?;
        // SAFETY: caller's contract.
        unsafe { out.write((*r.matrix()).into()) };
        Ok(())
    })
}

/// The Euler angles {a, b, c} (rad, written to the 3 doubles of `angles_out`) of the rotation
/// matrix `rotation` (column-major) in `sequence`: a, c ∈ (−π, π]; b ∈ [−π/2, π/2]
/// (Tait–Bryan) or [0, π] (proper). `singularity_distance_out` receives |cos b| (Tait–Bryan) or
/// |sin b| (proper), the distance to the gimbal lock: a and c are each determined to about
/// 2.2e-16 / distance, while the angles always reproduce the rotation to a few ulps.
/// `gimbal_lock_out` is set to 1 when that distance is ≤ 1e-12, where only a ± c is determined
/// (exactly at the lock c = 0), else to 0.
///
/// Errors: MECH_STATUS_BAD_ENUM for an unknown `sequence`; MECH_STATUS_NON_FINITE for a NaN or
/// infinite entry; MECH_STATUS_INVALID_ARGUMENT when `rotation` is not a rotation within
/// ‖RᵀR − I‖_F ≤ 1e-12.
///
/// # Safety
/// `rotation` must point to a readable mech_mat3_t, `angles_out` to 3 writable doubles,
/// `gimbal_lock_out` to a writable int32_t and `singularity_distance_out` to a writable double.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_euler_from_rotation(
    rotation: *const mech_mat3_t,
    sequence: mech_euler_sequence_t,
    angles_out: *mut f64,
    gimbal_lock_out: *mut i32,
    singularity_distance_out: *mut f64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let r = unsafe { read_rotation(rotation, "rotation") }?;
        let seq: EulerSequence = enum_value(sequence, "sequence")?;
        let angles = OutSlice::new(angles_out, 3, "angles_out")?;
        let lock = Out::new(gimbal_lock_out, "gimbal_lock_out")?;
        let dist = Out::new(singularity_distance_out, "singularity_distance_out")?;
        let d = euler::euler_from_rotation(seq, &r);
        // SAFETY: caller's contract.
        unsafe {
            angles.write(&d.angles);
            lock.write(i32::from(d.gimbal_lock));
            dist.write(d.singularity_distance);
        }
        Ok(())
    })
}

/// The angular velocity ω = E(angles) · rates (rad/s; syllabus 2.7–2.12, EB1911 (13) for ZYZ in
/// the body frame) of a body whose Euler angles `angles` (3 doubles, rad) in `sequence` change
/// at `rates` (3 doubles, rad/s), in the components of `frame` (a mech_frame_t), written to
/// `omega_out`.
///
/// Errors: MECH_STATUS_BAD_ENUM for an unknown `sequence` or `frame`; MECH_STATUS_NON_FINITE for
/// a NaN or infinite angle or rate.
///
/// # Safety
/// `angles` and `rates` must point to 3 readable doubles each, `omega_out` to a writable mech_vec3_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_angular_velocity_from_euler_rates(
    sequence: mech_euler_sequence_t,
    angles: *const f64,
    rates: *const f64,
    frame: mech_frame_t,
    omega_out: *mut mech_vec3_t,
) -> mech_status_t {
    boundary(|| {
        let seq: EulerSequence = enum_value(sequence, "sequence")?;
        let fr: AngularVelocityFrame = enum_value(frame, "frame")?;
        // SAFETY: caller's contract.
        let (a, r) = unsafe { (read_triple(angles, "angles")?, read_triple(rates, "rates")?) };
        let out = Out::new(omega_out, "omega_out")?;
        let w = euler::angular_velocity_from_euler_rates(seq, &a, &r, fr)?;
        // SAFETY: caller's contract.
        unsafe { out.write(w.into()) };
        Ok(())
    })
}

/// The Euler rates {ȧ, ḃ, ċ} (rad/s, written to the 3 doubles of `rates_out`) that give the
/// angular velocity `omega` (rad/s, components in `frame`) at the Euler angles `angles` (3
/// doubles, rad) of `sequence`: the inverse of mech_angular_velocity_from_euler_rates. The rates
/// carry a relative error of about 2.2e-16 / |cos b| (Tait–Bryan) or / |sin b| (proper).
///
/// Errors: MECH_STATUS_BAD_ENUM for an unknown `sequence` or `frame`; MECH_STATUS_NON_FINITE for
/// a NaN or infinite input; MECH_STATUS_SINGULAR at a gimbal lock (|cos b| or |sin b| ≤ 1e-12).
///
/// # Safety
/// `angles` must point to 3 readable doubles, `omega` to a readable mech_vec3_t and
/// `rates_out` to 3 writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_euler_rates_from_angular_velocity(
    sequence: mech_euler_sequence_t,
    angles: *const f64,
    omega: *const mech_vec3_t,
    frame: mech_frame_t,
    rates_out: *mut f64,
) -> mech_status_t {
    boundary(|| {
        let seq: EulerSequence = enum_value(sequence, "sequence")?;
        let fr: AngularVelocityFrame = enum_value(frame, "frame")?;
        // SAFETY: caller's contract.
        let (a, w) = unsafe { (read_triple(angles, "angles")?, read_vec3(omega, "omega")?) };
        let out = OutSlice::new(rates_out, 3, "rates_out")?;
        let r = euler::euler_rates_from_angular_velocity(seq, &a, &w, fr)?;
        // SAFETY: caller's contract.
        unsafe { out.write(&r.rates) };
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ffi::c_enum::CEnum;

    #[test]
    fn each_sequence_constant_is_its_place_in_the_list_of_all_sequences() {
        for (i, sequence) in EulerSequence::ALL.iter().enumerate() {
            let raw = i32::try_from(i).expect("twelve sequences");
            assert_eq!(EulerSequence::from_c(raw), Some(*sequence));
        }
        assert_eq!(EulerSequence::from_c(12), None);
        assert_eq!(EulerSequence::from_c(-1), None);
    }
}
