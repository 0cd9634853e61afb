//! C entry points of the kinematics crate.

use super::boundary::{FfiError, boundary};
use super::status::*;
use super::types::*;
use super::validate::*;
use mechanica_kinematics::KinematicsError;
use mechanica_kinematics::euler::{self, AngularVelocityFrame, EulerSequence};
use mechanica_kinematics::nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};
use mechanica_kinematics::relative_motion::{self, RelativeMotion};
use mechanica_kinematics::rigid_motion::RigidMotion;
use mechanica_kinematics::rotation::{self, QuaternionNorm};
use mechanica_kinematics::tree::{BaseState, Joint, KinematicTree, TreeBuilder, Workspace};

impl From<KinematicsError> for FfiError {
    fn from(error: KinematicsError) -> Self {
        let status = match error {
            KinematicsError::NonFinite { .. } | KinematicsError::NonFiniteEntry { .. } => MECH_STATUS_NON_FINITE,
            KinematicsError::EulerRateSingular { .. } => MECH_STATUS_SINGULAR,
            KinematicsError::WrongLength { .. } => MECH_STATUS_BAD_DIMENSION,
            KinematicsError::NotARotation { .. }
            | KinematicsError::NotAUnitQuaternion { .. }
            | KinematicsError::NotAUnitAxis { .. }
            | KinematicsError::JointAxisNotUnit { .. }
            | KinematicsError::EmptyTree
            | KinematicsError::ParentOutOfRange { .. }
            | KinematicsError::NoRoot
            | KinematicsError::MultipleRoots { .. }
            | KinematicsError::Cycle { .. }
            | KinematicsError::BodyOutOfRange { .. }
            | KinematicsError::WorkspaceNotReady { .. } => MECH_STATUS_INVALID_ARGUMENT,
        };
        FfiError::new(status, error.to_string())
    }
}

/// Converts a rotation matrix (column-major) into a unit quaternion.
///
/// Fails with MECH_STATUS_INVALID_ARGUMENT when `rotation` is not orthogonal with det = +1
/// within 1e-12 (‖RᵀR − I‖_F).
///
/// # Safety
/// `rotation` must point to a readable mech_mat3_t and `quaternion_out` to a writable mech_quat_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_quat_from_rotation_matrix(
    rotation: *const mech_mat3_t,
    quaternion_out: *mut mech_quat_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let r = unsafe { read(rotation, "rotation") }?;
        let out = Out::new(quaternion_out, "quaternion_out")?;
        finite(&r, "rotation")?;
        let q = rotation::quaternion_from_matrix(&Matrix3::from(r))?;
        // SAFETY: caller's contract.
        unsafe { out.write(q.into()) };
        Ok(())
    })
}

/// The angular velocity ω (in the fixed frame) of a body with orientation R and rate Ṙ,
/// from Ω = Ṙ Rᵀ (syllabus 2.7–2.12). Both matrices are column-major.
///
/// # Safety
/// `rotation` and `rotation_rate` must point to readable mech_mat3_t values and `omega_out` to a
/// writable mech_vec3_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_angular_velocity_from_rate(
    rotation: *const mech_mat3_t,
    rotation_rate: *const mech_mat3_t,
    omega_out: *mut mech_vec3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let (r, r_dot) = unsafe { (read(rotation, "rotation")?, read(rotation_rate, "rotation_rate")?) };
        let out = Out::new(omega_out, "omega_out")?;
        finite(&r, "rotation")?;
        finite(&r_dot, "rotation_rate")?;
        let r = rotation::rotation_from_matrix(&Matrix3::from(r))?;
        let omega = rotation::angular_velocity_from_rate(&r, &Matrix3::from(r_dot))?;
        // SAFETY: caller's contract.
        unsafe { out.write(omega.into()) };
        Ok(())
    })
}

/// How mech_rotation_matrix_from_quat treats a quaternion that is not of unit length.
pub type mech_quat_norm_t = i32;
/// Accept only quaternions with |‖q‖ − 1| ≤ 1e-12; others give MECH_STATUS_INVALID_ARGUMENT.
pub const MECH_QUAT_REQUIRE_UNIT: mech_quat_norm_t = 0;
/// Normalise any non-zero quaternion first (zero gives MECH_STATUS_INVALID_ARGUMENT).
pub const MECH_QUAT_NORMALIZE: mech_quat_norm_t = 1;

impl CEnum for QuaternionNorm {
    fn from_c(raw: i32) -> Option<Self> {
        match raw {
            MECH_QUAT_REQUIRE_UNIT => Some(QuaternionNorm::RequireUnit),
            MECH_QUAT_NORMALIZE => Some(QuaternionNorm::Normalize),
            _ => None,
        }
    }
}

/// The rotation matrix (column-major) of the quaternion `quaternion`, under the norm policy
/// `norm` (a mech_quat_norm_t value; unknown values give MECH_STATUS_BAD_ENUM).
///
/// # Safety
/// `quaternion` must point to a readable mech_quat_t and `rotation_out` to a writable mech_mat3_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_rotation_matrix_from_quat(
    quaternion: *const mech_quat_t,
    norm: mech_quat_norm_t,
    rotation_out: *mut mech_mat3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let q = unsafe { read(quaternion, "quaternion") }?;
        let out = Out::new(rotation_out, "rotation_out")?;
        let policy: QuaternionNorm = enum_value(norm, "norm")?;
        let unit = rotation::unit_quaternion(q.w, q.x, q.y, q.z, policy)?;
        // SAFETY: caller's contract.
        unsafe { out.write((*unit.to_rotation_matrix().matrix()).into()) };
        Ok(())
    })
}

/// Reads and checks a rotation matrix argument (finite, orthogonal, det = +1 within 1e-12).
///
/// # Safety
/// `ptr` must be NULL or point to a readable mech_mat3_t.
unsafe fn read_rotation(
    ptr: *const mech_mat3_t,
    what: &str,
) -> Result<mechanica_kinematics::nalgebra::Rotation3<f64>, FfiError> {
    // SAFETY: caller's contract.
    let m = unsafe { read(ptr, what) }?;
    finite(&m, what)?;
    Ok(rotation::rotation_from_matrix(&Matrix3::from(m))?)
}

/// Reads a finite 3-vector argument.
///
/// # Safety
/// `ptr` must be NULL or point to a readable mech_vec3_t.
unsafe fn read_vec3(ptr: *const mech_vec3_t, what: &str) -> Result<Vector3<f64>, FfiError> {
    // SAFETY: caller's contract.
    let v = unsafe { read(ptr, what) }?;
    finite(&v, what)?;
    Ok(v.into())
}

/// Reads three finite doubles.
///
/// # Safety
/// `ptr` must be NULL or point to 3 readable doubles.
unsafe fn read_triple(ptr: *const f64, what: &str) -> Result<[f64; 3], FfiError> {
    if ptr.is_null() {
        return Err(FfiError::new(MECH_STATUS_NULL_POINTER, format!("{what} is NULL")));
    }
    // SAFETY: non-NULL; 3 readable doubles by the caller's contract.
    let s = unsafe { read_slice(ptr, 3, what) }?;
    finite(s, what)?;
    Ok([s[0], s[1], s[2]])
}

/// The rotation matrix exp([φ]×) of a rotation vector φ (Rodrigues, accurate for all |φ|,
/// including |φ| → 0).
///
/// # Safety
/// `rotation_vector` must point to a readable mech_vec3_t and `rotation_out` to a writable mech_mat3_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_rotation_exp(
    rotation_vector: *const mech_vec3_t,
    rotation_out: *mut mech_mat3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let phi = unsafe { read_vec3(rotation_vector, "rotation_vector") }?;
        let out = Out::new(rotation_out, "rotation_out")?;
        let r = rotation::exp_map(&phi)?;
        // SAFETY: caller's contract.
        unsafe { out.write((*r.matrix()).into()) };
        Ok(())
    })
}

/// The rotation vector φ (|φ| ≤ π) of a rotation matrix: the logarithm map, accurate near the
/// identity and near half turns. Fails with MECH_STATUS_INVALID_ARGUMENT for a non-rotation.
///
/// # Safety
/// `rotation` must point to a readable mech_mat3_t and `rotation_vector_out` to a writable mech_vec3_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_rotation_log(
    rotation: *const mech_mat3_t,
    rotation_vector_out: *mut mech_vec3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let r = unsafe { read_rotation(rotation, "rotation") }?;
        let out = Out::new(rotation_vector_out, "rotation_vector_out")?;
        // SAFETY: caller's contract.
        unsafe { out.write(rotation::log_map(&r).into()) };
        Ok(())
    })
}

/// The rotation by `angle` (rad) about the unit vector `axis`. A zero or non-unit axis
/// (|‖a‖ − 1| > 1e-12) gives MECH_STATUS_INVALID_ARGUMENT.
///
/// # Safety
/// `axis` must point to a readable mech_vec3_t and `rotation_out` to a writable mech_mat3_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_rotation_from_axis_angle(
    axis: *const mech_vec3_t,
    angle: f64,
    rotation_out: *mut mech_mat3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let a = unsafe { read_vec3(axis, "axis") }?;
        let out = Out::new(rotation_out, "rotation_out")?;
        finite(&angle, "angle")?;
        let r = rotation::rotation_from_axis_angle(&a, angle)?;
        // SAFETY: caller's contract.
        unsafe { out.write((*r.matrix()).into()) };
        Ok(())
    })
}

/// The rotation nearest (Frobenius norm) to a drifted matrix `matrix`: its orthogonal polar
/// factor. `correction_out` receives ‖matrix − rotation‖_F. A matrix with det ≤ 0 gives
/// MECH_STATUS_INVALID_ARGUMENT.
///
/// # Safety
/// `matrix` must point to a readable mech_mat3_t, `rotation_out` to a writable mech_mat3_t and
/// `correction_out` to a writable double.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_rotation_orthonormalize(
    matrix: *const mech_mat3_t,
    rotation_out: *mut mech_mat3_t,
    correction_out: *mut f64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let m = unsafe { read(matrix, "matrix") }?;
        let out = Out::new(rotation_out, "rotation_out")?;
        let corr = Out::new(correction_out, "correction_out")?;
        finite(&m, "matrix")?;
        let fixed = rotation::orthonormalize_matrix(&Matrix3::from(m))?;
        // SAFETY: caller's contract.
        unsafe {
            out.write((*fixed.rotation.matrix()).into());
            corr.write(fixed.correction);
        }
        Ok(())
    })
}

/// An intrinsic Euler axis sequence: R = R_i(a) R_j(b) R_k(c), angles = {a, b, c}.
/// The EB1911 angles (θ, φ, ψ) of the seed are MECH_EULER_ZYZ with {a, b, c} = {ψ, θ, φ}.
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

impl CEnum for EulerSequence {
    fn from_c(raw: i32) -> Option<Self> {
        usize::try_from(raw)
            .ok()
            .and_then(|i| EulerSequence::ALL.get(i).copied())
    }
}

/// The frame in which an angular velocity is expressed.
pub type mech_frame_t = i32;
/// Fixed (world) frame components.
pub const MECH_FRAME_FIXED: mech_frame_t = 0;
/// Body frame components (EB1911's p, q, r).
pub const MECH_FRAME_BODY: mech_frame_t = 1;

impl CEnum for AngularVelocityFrame {
    fn from_c(raw: i32) -> Option<Self> {
        match raw {
            MECH_FRAME_FIXED => Some(AngularVelocityFrame::Fixed),
            MECH_FRAME_BODY => Some(AngularVelocityFrame::Body),
            _ => None,
        }
    }
}

/// The rotation matrix of Euler angles `angles` (3 doubles) in the sequence `sequence`.
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

/// The Euler angles {a, b, c} (into `angles_out`, 3 doubles) of a rotation in `sequence`.
/// a, c ∈ (−π, π]; b ∈ [−π/2, π/2] (Tait–Bryan) or [0, π] (proper). `gimbal_lock_out` is set to
/// 1 when |cos b| (Tait–Bryan) or |sin b| (proper) ≤ 1e-12, where only a ± c is determined (the
/// returned angles still reproduce the rotation to a few ulps; exactly at the lock c = 0), else
/// 0; `singularity_distance_out` receives that |cos b| or |sin b|.
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

/// The angular velocity ω = E(angles) rates (syllabus 2.7–2.12; EB1911 (13) for ZYZ in the body
/// frame), in the frame `frame`.
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

/// The Euler rates (3 doubles into `rates_out`) that give the angular velocity `omega`
/// (components in `frame`) at `angles`. At gimbal lock (|cos b| or |sin b| ≤ 1e-12) returns
/// MECH_STATUS_SINGULAR and writes nothing.
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

/// The state of a rigid motion x = R X + c (syllabus 1.5), all world components.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_rigid_motion_t {
    /// Orientation R (body → world), column-major; must be a rotation.
    pub rotation: mech_mat3_t,
    /// Position c of the reference point.
    pub c: mech_vec3_t,
    /// Velocity ċ of the reference point.
    pub c_dot: mech_vec3_t,
    /// Acceleration c̈ of the reference point.
    pub c_ddot: mech_vec3_t,
    /// Angular velocity ω.
    pub omega: mech_vec3_t,
    /// Angular acceleration ω̇.
    pub omega_dot: mech_vec3_t,
}

/// Reads and validates a rigid motion.
///
/// # Safety
/// `ptr` must be NULL or point to a readable mech_rigid_motion_t.
unsafe fn read_motion(ptr: *const mech_rigid_motion_t, what: &str) -> Result<RigidMotion, FfiError> {
    // SAFETY: caller's contract.
    let m = unsafe { read(ptr, what) }?;
    finite(&m.rotation, "motion rotation")?;
    let rotation = rotation::rotation_from_matrix(&Matrix3::from(m.rotation))?;
    for (v, name) in [
        (&m.c, "motion c"),
        (&m.c_dot, "motion c_dot"),
        (&m.c_ddot, "motion c_ddot"),
        (&m.omega, "motion omega"),
        (&m.omega_dot, "motion omega_dot"),
    ] {
        finite(v, name)?;
    }
    Ok(RigidMotion::new(
        rotation,
        m.c.into(),
        m.c_dot.into(),
        m.c_ddot.into(),
        m.omega.into(),
        m.omega_dot.into(),
    )?)
}

/// The velocity v = ω × (x − c) + ċ (syllabus 2.13) of the body point at world position `x`.
///
/// # Safety
/// `motion` must point to a readable mech_rigid_motion_t, `x` to a readable mech_vec3_t and
/// `velocity_out` to a writable mech_vec3_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_velocity_field(
    motion: *const mech_rigid_motion_t,
    x: *const mech_vec3_t,
    velocity_out: *mut mech_vec3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let (m, x) = unsafe { (read_motion(motion, "motion")?, read_vec3(x, "x")?) };
        let out = Out::new(velocity_out, "velocity_out")?;
        // SAFETY: caller's contract.
        unsafe { out.write(m.velocity_at(&x).into()) };
        Ok(())
    })
}

/// The acceleration a = ω̇ × (x − c) + ω × (ω × (x − c)) + c̈ (syllabus 2.18) of the body point
/// at world position `x`.
///
/// # Safety
/// `motion` must point to a readable mech_rigid_motion_t, `x` to a readable mech_vec3_t and
/// `acceleration_out` to a writable mech_vec3_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_acceleration_field(
    motion: *const mech_rigid_motion_t,
    x: *const mech_vec3_t,
    acceleration_out: *mut mech_vec3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let (m, x) = unsafe { (read_motion(motion, "motion")?, read_vec3(x, "x")?) };
        let out = Out::new(acceleration_out, "acceleration_out")?;
        // SAFETY: caller's contract.
        unsafe { out.write(m.acceleration_at(&x).into()) };
        Ok(())
    })
}

/// A point's absolute motion decomposed relative to a moving frame (world components,
/// syllabus 2.22–2.32): v = v_drag + v_rel, a = a_drag + a_coriolis + a_rel.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_relative_decomposition_t {
    /// Position x = R ξ + c.
    pub position: mech_vec3_t,
    /// Drag velocity ω × (x − c) + ċ.
    pub v_drag: mech_vec3_t,
    /// Relative velocity R ξ̇.
    pub v_rel: mech_vec3_t,
    /// Drag acceleration ω̇ × (x − c) + ω × (ω × (x − c)) + c̈.
    pub a_drag: mech_vec3_t,
    /// Coriolis acceleration 2 ω × v_rel.
    pub a_coriolis: mech_vec3_t,
    /// Relative acceleration R ξ̈.
    pub a_rel: mech_vec3_t,
}

/// Decomposes the motion of a point with relative position, velocity and acceleration `xi`,
/// `xi_dot`, `xi_ddot` (moving-frame components) in the moving frame `frame`.
///
/// # Safety
/// `frame` must point to a readable mech_rigid_motion_t, `xi`, `xi_dot`, `xi_ddot` to readable
/// mech_vec3_t values and `decomposition_out` to a writable mech_relative_decomposition_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_relative_motion_decompose(
    frame: *const mech_rigid_motion_t,
    xi: *const mech_vec3_t,
    xi_dot: *const mech_vec3_t,
    xi_ddot: *const mech_vec3_t,
    decomposition_out: *mut mech_relative_decomposition_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let (m, rel) = unsafe {
            (
                read_motion(frame, "frame")?,
                RelativeMotion {
                    xi: read_vec3(xi, "xi")?,
                    xi_dot: read_vec3(xi_dot, "xi_dot")?,
                    xi_ddot: read_vec3(xi_ddot, "xi_ddot")?,
                },
            )
        };
        let out = Out::new(decomposition_out, "decomposition_out")?;
        let d = relative_motion::decompose(&m, &rel)?;
        let value = mech_relative_decomposition_t {
            position: d.position.into(),
            v_drag: d.v_drag.into(),
            v_rel: d.v_rel.into(),
            a_drag: d.a_drag.into(),
            a_coriolis: d.a_coriolis.into(),
            a_rel: d.a_rel.into(),
        };
        // SAFETY: caller's contract.
        unsafe { out.write(value) };
        Ok(())
    })
}

/// The joint type of a tree body.
pub type mech_joint_type_t = i32;
/// One rotation about a unit axis (q: angle).
pub const MECH_JOINT_REVOLUTE: mech_joint_type_t = 0;
/// One translation along a unit axis (q: distance).
pub const MECH_JOINT_PRISMATIC: mech_joint_type_t = 1;
/// Three rotations about the joint origin (q: rotation vector about a reference orientation).
pub const MECH_JOINT_SPHERICAL: mech_joint_type_t = 2;
/// Six degrees of freedom (q: translation in the joint frame, then rotation vector).
pub const MECH_JOINT_FREE: mech_joint_type_t = 3;
/// Planar motion in the joint frame's xy plane (q: x, y, angle about z).
pub const MECH_JOINT_PLANAR: mech_joint_type_t = 4;
/// Rigid attachment (no coordinates).
pub const MECH_JOINT_FIXED: mech_joint_type_t = 5;

#[derive(Clone, Copy)]
enum JointKind {
    Revolute,
    Prismatic,
    Spherical,
    Free,
    Planar,
    Fixed,
}

impl CEnum for JointKind {
    fn from_c(raw: i32) -> Option<Self> {
        match raw {
            MECH_JOINT_REVOLUTE => Some(JointKind::Revolute),
            MECH_JOINT_PRISMATIC => Some(JointKind::Prismatic),
            MECH_JOINT_SPHERICAL => Some(JointKind::Spherical),
            MECH_JOINT_FREE => Some(JointKind::Free),
            MECH_JOINT_PLANAR => Some(JointKind::Planar),
            MECH_JOINT_FIXED => Some(JointKind::Fixed),
            _ => None,
        }
    }
}

/// A kinematic tree (opaque). Created empty by mech_tree_create, filled with
/// mech_tree_add_body, validated by mech_tree_finalize, then queried; freed by mech_tree_destroy.
pub struct mech_tree_t {
    pub(crate) builder: TreeBuilder,
    pub(crate) built: Option<(KinematicTree, Workspace)>,
}

/// Borrows the tree behind a handle.
///
/// # Safety
/// `tree` must be NULL or a handle from mech_tree_create that was not destroyed.
pub(crate) unsafe fn tree_mut<'a>(tree: *mut mech_tree_t) -> Result<&'a mut mech_tree_t, FfiError> {
    if !tree.is_aligned() {
        return Err(FfiError::new(MECH_STATUS_MISALIGNED_POINTER, "tree is misaligned"));
    }
    // SAFETY: caller's contract (a live handle or NULL).
    unsafe { tree.as_mut() }.ok_or_else(|| FfiError::new(MECH_STATUS_NULL_POINTER, "tree is NULL"))
}

pub(crate) fn built(t: &mut mech_tree_t) -> Result<(&KinematicTree, &mut Workspace), FfiError> {
    match &mut t.built {
        Some((tree, ws)) => Ok((tree, ws)),
        None => Err(FfiError::new(
            MECH_STATUS_INVALID_ARGUMENT,
            "tree is not finalized (call mech_tree_finalize)",
        )),
    }
}

/// Creates an empty kinematic tree into `*tree_out`. Free it with mech_tree_destroy.
///
/// # Safety
/// `tree_out` must point to a writable mech_tree_t pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_create(tree_out: *mut *mut mech_tree_t) -> mech_status_t {
    boundary(|| {
        let out = Out::new(tree_out, "tree_out")?;
        let handle = Box::new(mech_tree_t {
            builder: TreeBuilder::new(),
            built: None,
        });
        // SAFETY: caller's contract.
        unsafe { out.write(Box::into_raw(handle)) };
        Ok(())
    })
}

/// Frees a tree. NULL is accepted and ignored.
///
/// # Safety
/// `tree` must be NULL or a handle from mech_tree_create not yet destroyed.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_destroy(tree: *mut mech_tree_t) {
    if !tree.is_null() {
        // SAFETY: the handle came from Box::into_raw in mech_tree_create (caller's contract).
        let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| drop(unsafe { Box::from_raw(tree) })));
    }
}

/// Adds a body to a tree that is not finalized yet. `parent` is the parent's body index, or
/// −1 for the root (attached to the base); it may name a body added later. `joint_type` is a
/// mech_joint_type_t; `axis` (joint-frame components, unit length) is required for revolute and
/// prismatic joints and ignored (may be NULL) otherwise. The joint frame sits at rotation
/// `placement_rotation` (a rotation matrix, column-major) and translation `placement_translation`
/// in the parent's body frame. The new body's index is written to `body_out`. Structural checks
/// (one root, no cycles, unit axes) happen in mech_tree_finalize.
///
/// # Safety
/// `tree` must be a live handle; `axis` NULL or readable; `placement_rotation` and
/// `placement_translation` readable; `body_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_add_body(
    tree: *mut mech_tree_t,
    parent: i64,
    joint_type: mech_joint_type_t,
    axis: *const mech_vec3_t,
    placement_rotation: *const mech_mat3_t,
    placement_translation: *const mech_vec3_t,
    body_out: *mut usize,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { tree_mut(tree) }?;
        let kind: JointKind = enum_value(joint_type, "joint_type")?;
        // SAFETY: caller's contract.
        let (r, p) = unsafe {
            (
                read_rotation(placement_rotation, "placement_rotation")?,
                read_vec3(placement_translation, "placement_translation")?,
            )
        };
        let out = Out::new(body_out, "body_out")?;
        if t.built.is_some() {
            return Err(FfiError::new(
                MECH_STATUS_INVALID_ARGUMENT,
                "tree is already finalized; bodies can no longer be added",
            ));
        }
        let parent = match parent {
            -1 => None,
            p if p >= 0 => Some(
                usize::try_from(p)
                    .map_err(|_| FfiError::new(MECH_STATUS_INVALID_ARGUMENT, format!("parent {p} is out of range")))?,
            ),
            p => {
                return Err(FfiError::new(
                    MECH_STATUS_INVALID_ARGUMENT,
                    format!("parent must be −1 (root) or a body index, got {p}"),
                ));
            }
        };
        let joint = match kind {
            JointKind::Revolute | JointKind::Prismatic => {
                // SAFETY: caller's contract.
                let a = unsafe { read_vec3(axis, "axis") }?;
                rotation::unit_axis(&a, "joint axis")?;
                if matches!(kind, JointKind::Revolute) {
                    Joint::Revolute { axis: a }
                } else {
                    Joint::Prismatic { axis: a }
                }
            }
            JointKind::Spherical => Joint::Spherical,
            JointKind::Free => Joint::Free,
            JointKind::Planar => Joint::Planar,
            JointKind::Fixed => Joint::Fixed,
        };
        let placement = Isometry3::from_parts(Translation3::from(p), UnitQuaternion::from_rotation_matrix(&r));
        let index = t.builder.add_body(parent, joint, placement);
        // SAFETY: caller's contract.
        unsafe { out.write(index) };
        Ok(())
    })
}

/// Validates the tree (at least one body, exactly one root, parents in range, no cycles) and
/// makes it ready for queries. Errors are MECH_STATUS_INVALID_ARGUMENT with the offending body
/// index in mech_last_error. Finalizing twice is an error.
///
/// # Safety
/// `tree` must be a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_finalize(tree: *mut mech_tree_t) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { tree_mut(tree) }?;
        if t.built.is_some() {
            return Err(FfiError::new(MECH_STATUS_INVALID_ARGUMENT, "tree is already finalized"));
        }
        let kt = t.builder.clone().build()?;
        let ws = kt.workspace();
        t.built = Some((kt, ws));
        Ok(())
    })
}

/// The number of bodies and of coordinates (= velocities) of a finalized tree.
///
/// # Safety
/// `tree` must be a live handle; `body_count_out` and `dof_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_size(
    tree: *mut mech_tree_t,
    body_count_out: *mut usize,
    dof_out: *mut usize,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { tree_mut(tree) }?;
        let bodies = Out::new(body_count_out, "body_count_out")?;
        let dof = Out::new(dof_out, "dof_out")?;
        let (kt, _) = built(t)?;
        // SAFETY: caller's contract.
        unsafe {
            bodies.write(kt.body_count());
            dof.write(kt.dof());
        }
        Ok(())
    })
}

/// Sets the coordinates q and velocities q̇ (each `n` = dof doubles; pass n = 0 and NULL for a
/// tree without coordinates) and computes all body poses, velocities and Jacobian columns.
/// Wrong n gives MECH_STATUS_BAD_DIMENSION; NaN/inf MECH_STATUS_NON_FINITE (the state is then
/// left unset).
///
/// # Safety
/// `tree` must be a live handle; `q` and `q_dot` must point to `n` readable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_set_state(
    tree: *mut mech_tree_t,
    q: *const f64,
    q_dot: *const f64,
    n: usize,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { tree_mut(tree) }?;
        // SAFETY: caller's contract.
        let (q, qd) = unsafe { (read_slice(q, n, "q")?, read_slice(q_dot, n, "q_dot")?) };
        let (kt, ws) = built(t)?;
        kt.update_positions(ws, q)?;
        kt.update_velocities(ws, qd)?;
        Ok(())
    })
}

/// The prescribed motion of a tree's base frame 0 at the current time, all in world
/// components: a moving (rheonomic) base makes the drag velocity of a point x equal to
/// v₀ + ω₀ × (x − p₀) and splits T = T₀ + T₁ + T₂ (9.7–9.10).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_base_state_t {
    /// Rotation R_W0 of the base frame (a rotation matrix, column-major).
    pub rotation: mech_mat3_t,
    /// Origin p_W0 of the base frame.
    pub position: mech_vec3_t,
    /// Angular velocity ω₀ of the base.
    pub omega: mech_vec3_t,
    /// Velocity v₀ of the base origin.
    pub velocity: mech_vec3_t,
    /// Angular acceleration ω̇₀ of the base.
    pub omega_dot: mech_vec3_t,
    /// Acceleration a₀ of the base origin.
    pub acceleration: mech_vec3_t,
}

/// Prescribes the motion of the base frame of a finalized tree (the default is a base at rest
/// with R_W0 = I, p_W0 = 0). It applies from the next mech_tree_set_state on: setting the base
/// discards the computed state, so queries fail with MECH_STATUS_INVALID_ARGUMENT until the
/// state is set again. Pass the same ω₀ and v₀ to mech_tree_energy_split for the drag field.
///
/// Errors: NULL_POINTER; NON_FINITE for a NaN/inf entry; INVALID_ARGUMENT when `rotation` is
/// not a rotation matrix (orthonormal to rounding, determinant +1) or the tree is not finalized.
/// Nothing changes on error.
///
/// # Safety
/// `tree` must be a live handle; `base` must point to a readable mech_base_state_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_set_base(tree: *mut mech_tree_t, base: *const mech_base_state_t) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { tree_mut(tree) }?;
        // SAFETY: caller's contract.
        let b = unsafe { read(base, "base") }?;
        for (v, what) in [
            (&b.position, "base.position"),
            (&b.omega, "base.omega"),
            (&b.velocity, "base.velocity"),
            (&b.omega_dot, "base.omega_dot"),
            (&b.acceleration, "base.acceleration"),
        ] {
            finite(v, what)?;
        }
        finite(&b.rotation, "base.rotation")?;
        let rotation = rotation::rotation_from_matrix(&Matrix3::from(b.rotation))?;
        let (_, ws) = built(t)?;
        ws.set_base(BaseState {
            rotation,
            position: b.position.into(),
            omega: b.omega.into(),
            velocity: b.velocity.into(),
            omega_dot: b.omega_dot.into(),
            acceleration: b.acceleration.into(),
        })?;
        Ok(())
    })
}

/// Sets the accelerations q̈ (`n` = dof doubles) after mech_tree_set_state and computes body
/// accelerations.
///
/// # Safety
/// `tree` must be a live handle; `q_ddot` must point to `n` readable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_set_accelerations(
    tree: *mut mech_tree_t,
    q_ddot: *const f64,
    n: usize,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { tree_mut(tree) }?;
        // SAFETY: caller's contract.
        let qdd = unsafe { read_slice(q_ddot, n, "q_ddot") }?;
        let (kt, ws) = built(t)?;
        kt.update_accelerations(ws, qdd)?;
        Ok(())
    })
}

/// The pose of `body`: rotation R_WB (column-major) and origin position p_WB (world).
///
/// # Safety
/// `tree` must be a live handle; `rotation_out` and `position_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_body_pose(
    tree: *mut mech_tree_t,
    body: usize,
    rotation_out: *mut mech_mat3_t,
    position_out: *mut mech_vec3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { tree_mut(tree) }?;
        let r_out = Out::new(rotation_out, "rotation_out")?;
        let p_out = Out::new(position_out, "position_out")?;
        let (_, ws) = built(t)?;
        let r = ws.rotation(body)?;
        let p = ws.position(body)?;
        // SAFETY: caller's contract.
        unsafe {
            r_out.write((*r.matrix()).into());
            p_out.write(p.into());
        }
        Ok(())
    })
}

/// The angular velocity of `body` and the velocity of its point with body coordinates `point`
/// (world components), from the state of mech_tree_set_state.
///
/// # Safety
/// `tree` must be a live handle; `point` readable; `omega_out` and `velocity_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_body_velocity(
    tree: *mut mech_tree_t,
    body: usize,
    point: *const mech_vec3_t,
    omega_out: *mut mech_vec3_t,
    velocity_out: *mut mech_vec3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { tree_mut(tree) }?;
        // SAFETY: caller's contract.
        let p = unsafe { read_vec3(point, "point") }?;
        let w_out = Out::new(omega_out, "omega_out")?;
        let v_out = Out::new(velocity_out, "velocity_out")?;
        let (_, ws) = built(t)?;
        let w = ws.angular_velocity(body)?;
        let v = ws.point_velocity(body, &p)?;
        // SAFETY: caller's contract.
        unsafe {
            w_out.write(w.into());
            v_out.write(v.into());
        }
        Ok(())
    })
}

/// The angular acceleration of `body` and the acceleration of its point with body coordinates
/// `point` (world), after mech_tree_set_accelerations.
///
/// # Safety
/// `tree` must be a live handle; `point` readable; both outputs writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_body_acceleration(
    tree: *mut mech_tree_t,
    body: usize,
    point: *const mech_vec3_t,
    omega_dot_out: *mut mech_vec3_t,
    acceleration_out: *mut mech_vec3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { tree_mut(tree) }?;
        // SAFETY: caller's contract.
        let p = unsafe { read_vec3(point, "point") }?;
        let w_out = Out::new(omega_dot_out, "omega_dot_out")?;
        let a_out = Out::new(acceleration_out, "acceleration_out")?;
        let (_, ws) = built(t)?;
        let w = ws.angular_acceleration(body)?;
        let a = ws.point_acceleration(body, &p)?;
        // SAFETY: caller's contract.
        unsafe {
            w_out.write(w.into());
            a_out.write(a.into());
        }
        Ok(())
    })
}

/// Which Jacobian mech_tree_jacobian computes.
pub type mech_jacobian_kind_t = i32;
/// ∂x/∂q of a body point (syllabus 1.37): 3×dof.
pub const MECH_JACOBIAN_POINT: mech_jacobian_kind_t = 0;
/// ∂ω/∂q̇ of the body: 3×dof.
pub const MECH_JACOBIAN_ANGULAR: mech_jacobian_kind_t = 1;
/// d/dt of MECH_JACOBIAN_POINT along the current (q, q̇): 3×dof.
pub const MECH_JACOBIAN_POINT_RATE: mech_jacobian_kind_t = 2;
/// d/dt of MECH_JACOBIAN_ANGULAR: 3×dof.
pub const MECH_JACOBIAN_ANGULAR_RATE: mech_jacobian_kind_t = 3;

#[derive(Clone, Copy)]
enum JacobianKind {
    Point,
    Angular,
    PointRate,
    AngularRate,
}

impl CEnum for JacobianKind {
    fn from_c(raw: i32) -> Option<Self> {
        match raw {
            MECH_JACOBIAN_POINT => Some(JacobianKind::Point),
            MECH_JACOBIAN_ANGULAR => Some(JacobianKind::Angular),
            MECH_JACOBIAN_POINT_RATE => Some(JacobianKind::PointRate),
            MECH_JACOBIAN_ANGULAR_RATE => Some(JacobianKind::AngularRate),
            _ => None,
        }
    }
}

/// A 3×dof Jacobian of `body` (kind: a mech_jacobian_kind_t) into the caller's column-major
/// buffer `out` of `capacity` doubles (≥ 3·dof, else MECH_STATUS_BUFFER_TOO_SMALL; exactly
/// 3·dof are written). Column k belongs to coordinate k; world components. `point` (body
/// coordinates) is used by the point kinds and ignored (may be NULL) by the angular kinds.
///
/// # Safety
/// `tree` must be a live handle; `point` NULL or readable; `out` must hold `capacity` writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_jacobian(
    tree: *mut mech_tree_t,
    body: usize,
    kind: mech_jacobian_kind_t,
    point: *const mech_vec3_t,
    out: *mut f64,
    capacity: usize,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { tree_mut(tree) }?;
        let kind: JacobianKind = enum_value(kind, "kind")?;
        let p = match kind {
            // SAFETY: caller's contract.
            JacobianKind::Point | JacobianKind::PointRate => unsafe { read_vec3(point, "point") }?,
            JacobianKind::Angular | JacobianKind::AngularRate => Vector3::zeros(),
        };
        let (kt, ws) = built(t)?;
        let len = 3 * kt.dof();
        if capacity < len {
            return Err(FfiError::new(
                MECH_STATUS_BUFFER_TOO_SMALL,
                format!("out holds {capacity} doubles, the Jacobian needs {len}"),
            ));
        }
        let dest = OutSlice::new(out, len, "out")?;
        let mut j = vec![0.0; len];
        match kind {
            JacobianKind::Point => kt.point_jacobian(ws, body, &p, &mut j)?,
            JacobianKind::Angular => kt.angular_jacobian(ws, body, &mut j)?,
            JacobianKind::PointRate => kt.point_jacobian_rate(ws, body, &p, &mut j)?,
            JacobianKind::AngularRate => kt.angular_jacobian_rate(ws, body, &mut j)?,
        }
        // SAFETY: caller's contract.
        unsafe { dest.write(&j) };
        Ok(())
    })
}
