//! One rigid body at an impact, in inverse form: its C description, impulses on it, and the
//! fixation of one of its points.

use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::c_enum::{c_enum, enum_value};
use crate::ffi::mass::{check_finite_properties, mech_mass_properties_t};
use crate::ffi::status::*;
use crate::ffi::types::*;
use crate::ffi::validate::*;
use mechanica_impulse::{RigidBody, fix_point};
use mechanica_kinematics::nalgebra::Matrix3;
use mechanica_mass::MassProperties;

/// How a body is held during an impact (int32).
pub type mech_body_constraint_t = i32;
/// The body is free.
pub const MECH_BODY_FREE: mech_body_constraint_t = 0;
/// The body is held by a spherical hinge at `hinge_point` (world-fixed) (7.87*–7.91*).
pub const MECH_BODY_HINGE_POINT: mech_body_constraint_t = 1;
/// The body can only rotate about the unit `hinge_axis` through `hinge_point` (7.87*–7.91*).
pub const MECH_BODY_HINGE_AXIS: mech_body_constraint_t = 2;

/// The holds of [`mech_body_constraint_t`].
#[derive(Clone, Copy)]
enum BodyConstraint {
    Free,
    HingePoint,
    HingeAxis,
}

c_enum!(BodyConstraint,
    MECH_BODY_FREE => BodyConstraint::Free,
    MECH_BODY_HINGE_POINT => BodyConstraint::HingePoint,
    MECH_BODY_HINGE_AXIS => BodyConstraint::HingeAxis,
);

/// A rigid body at the instant of an impact, in inverse form (world frame W). Infinite mass
/// is `inverse_mass = 0`; a locked rotation axis is a zero eigenvalue of `inverse_inertia`; a
/// static body has both zero. For rods and point masses use the pseudo-inverse of the central
/// inertia (see mech_impulse_body_from_mass_properties): the zero-inertia axis then acts as
/// locked, which is exact when every impulse passes through that axis.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_impulse_body_t {
    /// 1/m (1/kg), ≥ 0.
    pub inverse_mass: f64,
    /// Inverse central inertia J₀⁻¹ in world axes (1/(kg·m²)), symmetric positive semidefinite, column-major.
    pub inverse_inertia: mech_mat3_t,
    /// Centre of mass p_WC (m).
    pub center_of_mass: mech_vec3_t,
    /// Velocity of the centre of mass just before the impact (m/s).
    pub velocity: mech_vec3_t,
    /// Angular velocity just before the impact (rad/s).
    pub angular_velocity: mech_vec3_t,
    /// A MECH_BODY_* value: free or hinged.
    pub constraint: mech_body_constraint_t,
    /// The world-fixed hinge point (used by MECH_BODY_HINGE_POINT and MECH_BODY_HINGE_AXIS).
    pub hinge_point: mech_vec3_t,
    /// The unit hinge axis (used by MECH_BODY_HINGE_AXIS).
    pub hinge_axis: mech_vec3_t,
}

/// Validates a C body description and builds the Rust body: NON_FINITE for a NaN or infinite
/// number, BAD_ENUM for an unknown constraint, INVALID_ARGUMENT for a negative inverse mass, a
/// non-unit hinge axis or velocities that violate the hinge, NOT_POSITIVE_DEFINITE for an inverse inertia that is not positive
/// semidefinite.
pub(super) fn body_from_c(b: &mech_impulse_body_t, what: &str) -> Result<RigidBody, FfiError> {
    finite(&b.inverse_mass, &format!("{what}.inverse_mass"))?;
    finite(&b.inverse_inertia, &format!("{what}.inverse_inertia"))?;
    finite(&b.center_of_mass, &format!("{what}.center_of_mass"))?;
    finite(&b.velocity, &format!("{what}.velocity"))?;
    finite(&b.angular_velocity, &format!("{what}.angular_velocity"))?;
    let constraint: BodyConstraint = enum_value(b.constraint, &format!("{what}.constraint"))?;
    let body = RigidBody::from_inverse(
        b.inverse_mass,
        &Matrix3::from(b.inverse_inertia),
        b.center_of_mass.into(),
        b.velocity.into(),
        b.angular_velocity.into(),
    )?;
    let body = match constraint {
        BodyConstraint::Free => body,
        BodyConstraint::HingePoint => {
            finite(&b.hinge_point, &format!("{what}.hinge_point"))?;
            body.hinged_at_point(&b.hinge_point.into())?
        }
        BodyConstraint::HingeAxis => {
            finite(&b.hinge_point, &format!("{what}.hinge_point"))?;
            finite(&b.hinge_axis, &format!("{what}.hinge_axis"))?;
            body.hinged_on_axis(&b.hinge_point.into(), &b.hinge_axis.into())?
        }
    };
    Ok(body)
}

/// Builds a free ::mech_impulse_body_t into `out` from mass properties expressed in the world
/// frame (mass in kg, centre of mass p_WC in m, central inertia in W axes in kg·m²) and the
/// velocities just before the impact (`velocity` of the centre in m/s, `angular_velocity` in
/// rad/s). The inverse inertia is the pseudo-inverse (eigenvalues ≤ 1e-12·λ_max count as zero),
/// so rods and point masses are accepted.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_INVALID_ARGUMENT for
/// a mass ≤ 0; MECH_STATUS_NOT_POSITIVE_DEFINITE for an inertia tensor that is not positive
/// semidefinite.
///
/// # Safety
/// `properties`, `velocity` and `angular_velocity` must be readable, `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_impulse_body_from_mass_properties(
    properties: *const mech_mass_properties_t,
    velocity: *const mech_vec3_t,
    angular_velocity: *const mech_vec3_t,
    out: *mut mech_impulse_body_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let (m, v, w) = unsafe {
            (
                read(properties, "properties")?,
                read(velocity, "velocity")?,
                read(angular_velocity, "angular_velocity")?,
            )
        };
        let out = Out::new(out, "out")?;
        check_finite_properties(&m, "properties")?;
        finite(&v, "velocity")?;
        finite(&w, "angular_velocity")?;
        let mut props = MassProperties::point(m.mass, m.center_of_mass.into())?;
        props.inertia_c = Matrix3::from(m.inertia_about_com);
        let body = RigidBody::from_mass_properties(&props, v.into(), w.into())?;
        let g = body.mobility();
        let value = mech_impulse_body_t {
            inverse_mass: g[(0, 0)],
            inverse_inertia: Matrix3::from(g.fixed_view::<3, 3>(3, 3)).into(),
            center_of_mass: body.p_wc().into(),
            velocity: v,
            angular_velocity: w,
            constraint: MECH_BODY_FREE,
            hinge_point: mech_vec3_t::default(),
            hinge_axis: mech_vec3_t::default(),
        };
        // SAFETY: caller's contract.
        unsafe { out.write(value) };
        Ok(())
    })
}

/// The response of one body to an impulse.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_body_response_t {
    /// Velocity of the centre of mass just after (m/s).
    pub velocity_after: mech_vec3_t,
    /// Angular velocity just after (rad/s).
    pub angular_velocity_after: mech_vec3_t,
    /// ΔT = ½ S·(V₀ + v₀) + ½ M₀S·(Ω + ω) (7.107) (J).
    pub energy_change: f64,
}

/// Applies the impulse `impulse` (N·s) at the world point `point` (m) together with the
/// impulsive moment `moment_about_point` (N·m·s) about that point to `body` (7.61–7.71), all in
/// world components, and writes the velocities after and the energy change to `out`. For a
/// hinged body the hinge impulse is included (it does no work).
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_BAD_ENUM for an
/// unknown `body->constraint`; MECH_STATUS_INVALID_ARGUMENT for an invalid body (negative
/// inverse mass, non-unit hinge axis, velocities that violate the hinge) or an impulse that
/// excites an axis of zero inertia;
/// MECH_STATUS_NOT_POSITIVE_DEFINITE for an inverse inertia that is not positive semidefinite.
///
/// # Safety
/// All pointers must be readable, `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_impulse_apply(
    body: *const mech_impulse_body_t,
    impulse: *const mech_vec3_t,
    point: *const mech_vec3_t,
    moment_about_point: *const mech_vec3_t,
    out: *mut mech_body_response_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let (b, s, p, m) = unsafe {
            (
                read(body, "body")?,
                read(impulse, "impulse")?,
                read(point, "point")?,
                read(moment_about_point, "moment_about_point")?,
            )
        };
        let out = Out::new(out, "out")?;
        let body = body_from_c(&b, "body")?;
        let r = body.apply_impulse_at(&s.into(), &p.into(), &m.into())?;
        let value = mech_body_response_t {
            velocity_after: r.v_wc_after.into(),
            angular_velocity_after: r.w_w_after.into(),
            energy_change: r.energy_change,
        };
        // SAFETY: caller's contract.
        unsafe { out.write(value) };
        Ok(())
    })
}

/// The outcome of fixing a body point (7.100–7.108).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_fixation_t {
    /// The impulse S applied at the fixed point (N·s).
    pub impulse: mech_vec3_t,
    /// Velocity of the centre of mass after (m/s).
    pub velocity_after: mech_vec3_t,
    /// Angular velocity after, Ω (rad/s).
    pub angular_velocity_after: mech_vec3_t,
    /// ΔT = ½ S·v (7.108) (J).
    pub energy_change: f64,
    /// |velocity of the point| after, as computed (m/s): a check of the solve.
    pub residual: f64,
}

/// Brings the body point at world position `point` (m) to rest by a single impulse at that
/// point (7.100–7.108) and writes the impulse, the velocities after, the energy change and the
/// residual speed of the point (the accuracy of the solve) to `out`.
///
/// Errors: as mech_impulse_apply, and MECH_STATUS_SINGULAR when the point cannot be stopped
/// (e.g. a moving body of infinite mass) or the solve leaves it moving at more than 1e-8 of
/// its speed before (a hinged body whose point mobility is too ill-conditioned; a free body is
/// solved in the lever's frame and stays accurate for points any distance away).
///
/// # Safety
/// `body` and `point` must be readable, `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_impulse_fix_point(
    body: *const mech_impulse_body_t,
    point: *const mech_vec3_t,
    out: *mut mech_fixation_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let (b, p) = unsafe { (read(body, "body")?, read(point, "point")?) };
        let out = Out::new(out, "out")?;
        finite(&p, "point")?;
        let body = body_from_c(&b, "body")?;
        let r = fix_point(&body, &p.into())?;
        let value = mech_fixation_t {
            impulse: r.impulse_w.into(),
            velocity_after: r.v_wc_after.into(),
            angular_velocity_after: r.w_w_after.into(),
            energy_change: r.energy_change,
            residual: r.residual,
        };
        // SAFETY: caller's contract.
        unsafe { out.write(value) };
        Ok(())
    })
}
