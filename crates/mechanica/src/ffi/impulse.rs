//! C entry points of the impulse-dynamics crate: impulses on points and bodies, point
//! collisions, fixation and two-body frictional impacts (syllabus 5c–d, 7h–j).
//!
//! Bodies cross the boundary as plain data in *inverse* form ([`mech_impulse_body_t`]):
//! inverse mass and inverse central inertia in world axes, so an infinite mass or a locked
//! axis is a zero, plus an optional hinge. All vectors are in the world frame W.
//!
//! Mechanisms (part 5, 7.115–7.117) act through the kinematic tree handle at the state set by
//! mech_tree_set_state, with one ::mech_mass_properties_t per body (body frame).

use super::boundary::{FfiError, boundary};
use super::kinematics::{built, mech_tree_t, tree_mut};
use super::mass::mech_mass_properties_t;
use super::status::*;
use super::types::*;
use super::validate::*;
use mechanica_impulse::point::{collide_collinear, collide_points, impulse_on_point};
use mechanica_impulse::{
    BodyPoint, ContactLaw, ContactMode, ContactSpace, ImpactModel, ImpactOptions, ImpulseError, MechanismContact,
    MechanismInertia, MultiContactOptions, PointImpulse, RestitutionLaw, RigidBody, apply_point_impulses, fix_point,
    resolve_contact, resolve_contacts,
};
use mechanica_kinematics::nalgebra::{Matrix3, Vector3};
use mechanica_kinematics::tree::{KinematicTree, Workspace};
use mechanica_mass::MassProperties;
use mechanica_mass::mechanism::TreeMass;

impl From<ImpulseError> for FfiError {
    fn from(error: ImpulseError) -> Self {
        let status = match error {
            ImpulseError::InContact { contact, source } => {
                let inner = FfiError::from(*source);
                return FfiError::new(inner.status, format!("contact {contact}: {}", inner.message));
            }
            ImpulseError::Kinematics(e) => return FfiError::from(e),
            ImpulseError::Mass(e) => return FfiError::from(e),
            ImpulseError::SingularMassMatrix { .. } => MECH_STATUS_NOT_POSITIVE_DEFINITE,
            ImpulseError::BodyOutOfRange { .. } => MECH_STATUS_INVALID_ARGUMENT,
            ImpulseError::ContactImmovable { .. } => MECH_STATUS_SINGULAR,
            ImpulseError::NonFinite { .. } => MECH_STATUS_NON_FINITE,
            ImpulseError::NonPositiveMass { .. }
            | ImpulseError::NegativeInverseMass { .. }
            | ImpulseError::RestitutionOutOfRange(_)
            | ImpulseError::NegativeFriction(_)
            | ImpulseError::NotUnit { .. }
            | ImpulseError::ZeroInertiaAxisExcited { .. }
            | ImpulseError::ConstraintViolated { .. } => MECH_STATUS_INVALID_ARGUMENT,
            ImpulseError::InvalidInertia { .. } => MECH_STATUS_NOT_POSITIVE_DEFINITE,
            ImpulseError::Singular { .. } => MECH_STATUS_SINGULAR,
            ImpulseError::NotConverged { .. } => MECH_STATUS_NOT_CONVERGED,
            ImpulseError::DimensionMismatch { .. } => MECH_STATUS_BAD_DIMENSION,
        };
        FfiError::new(status, error.to_string())
    }
}

/// The outcome of a collinear collision of two point masses (syllabus 5.16–5.23).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_collinear_impact_t {
    /// Velocity of point 1 after the impact (m/s).
    pub v1_after: f64,
    /// Velocity of point 2 after the impact (m/s).
    pub v2_after: f64,
    /// Impulse on point 2 (N·s); point 1 receives its negative.
    pub impulse_on_2: f64,
    /// Kinetic-energy change T⁺ − T⁻ (J), ≤ 0 for restitution ≤ 1 (5.23).
    pub energy_change: f64,
}

/// Collides point 1 (mass `m1`, velocity `v1`) with point 2 (mass `m2`, velocity `v2`) on one
/// line with Newton's restitution coefficient `restitution` ∈ [0, 1]. Points that do not
/// approach (v1 ≤ v2) receive no impulse.
///
/// # Safety
/// `out` must point to a writable mech_collinear_impact_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_collide_collinear(
    m1: f64,
    v1: f64,
    m2: f64,
    v2: f64,
    restitution: f64,
    out: *mut mech_collinear_impact_t,
) -> mech_status_t {
    boundary(|| {
        let out = Out::new(out, "out")?;
        let r = collide_collinear(m1, v1, m2, v2, restitution)?;
        let value = mech_collinear_impact_t {
            v1_after: r.v1_after,
            v2_after: r.v2_after,
            impulse_on_2: r.impulse_on_2,
            energy_change: r.energy_change,
        };
        // SAFETY: caller's contract.
        unsafe { out.write(value) };
        Ok(())
    })
}

/// The response of a point mass to an impulse (5.13, 7.106).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_point_impulse_t {
    /// Velocity just after, V = v + S/m (m/s).
    pub velocity_after: mech_vec3_t,
    /// ΔT = ½ S·(V + v) (J).
    pub energy_change: f64,
}

/// Applies the impulse `impulse` (N·s) to a point of mass `mass` moving at `velocity`
/// (5.10–5.15): the momentum jumps by the impulse; the position does not change.
///
/// # Safety
/// `velocity` and `impulse` must be readable, `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_impulse_on_point(
    mass: f64,
    velocity: *const mech_vec3_t,
    impulse: *const mech_vec3_t,
    out: *mut mech_point_impulse_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let (v, s) = unsafe { (read(velocity, "velocity")?, read(impulse, "impulse")?) };
        let out = Out::new(out, "out")?;
        let r = impulse_on_point(mass, &v.into(), &s.into())?;
        let value = mech_point_impulse_t {
            velocity_after: r.v_after.into(),
            energy_change: r.energy_change,
        };
        // SAFETY: caller's contract.
        unsafe { out.write(value) };
        Ok(())
    })
}

/// The outcome of a 3-D collision of two smooth point masses along a normal.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_point_impact_t {
    /// Velocity of point 1 after the impact (m/s).
    pub velocity_after_1: mech_vec3_t,
    /// Velocity of point 2 after the impact (m/s).
    pub velocity_after_2: mech_vec3_t,
    /// Impulse on point 2, along the normal (N·s); point 1 receives its negative.
    pub impulse_on_2: mech_vec3_t,
    /// Kinetic-energy change (J), −½(1 − λ²) μ (approach speed)² (5.23).
    pub energy_change: f64,
}

/// Collides two smooth point masses (spheres) along the unit `normal` pointing from point 1 to
/// point 2, with restitution λ ∈ [0, 1] (5.16–5.23 on the normal components). Points that do
/// not approach receive no impulse.
///
/// # Safety
/// `v1`, `v2` and `normal` must be readable, `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_collide_points(
    m1: f64,
    v1: *const mech_vec3_t,
    m2: f64,
    v2: *const mech_vec3_t,
    normal: *const mech_vec3_t,
    restitution: f64,
    out: *mut mech_point_impact_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let (a, b, n) = unsafe { (read(v1, "v1")?, read(v2, "v2")?, read(normal, "normal")?) };
        let out = Out::new(out, "out")?;
        let r = collide_points(m1, &a.into(), m2, &b.into(), &n.into(), restitution)?;
        let value = mech_point_impact_t {
            velocity_after_1: r.v1_after.into(),
            velocity_after_2: r.v2_after.into(),
            impulse_on_2: r.impulse_on_2.into(),
            energy_change: r.energy_change,
        };
        // SAFETY: caller's contract.
        unsafe { out.write(value) };
        Ok(())
    })
}

/// How a body is held during an impact (int32).
pub type mech_body_constraint_t = i32;
/// The body is free.
pub const MECH_BODY_FREE: mech_body_constraint_t = 0;
/// The body is held by a spherical hinge at `hinge_point` (world-fixed) (7.87*–7.91*).
pub const MECH_BODY_HINGE_POINT: mech_body_constraint_t = 1;
/// The body can only rotate about the unit `hinge_axis` through `hinge_point` (7.87*–7.91*).
pub const MECH_BODY_HINGE_AXIS: mech_body_constraint_t = 2;

/// Which relation ends restitution in a frictional impact (int32).
pub type mech_restitution_law_t = i32;
/// Newton's kinematic law u_n⁺ = −e u_n⁻ (7.94); may gain energy with friction (Kane's paradox).
pub const MECH_RESTITUTION_NEWTON: mech_restitution_law_t = 0;
/// Poisson's kinetic law: restitution impulse = e × compression impulse.
pub const MECH_RESTITUTION_POISSON: mech_restitution_law_t = 1;
/// Stronge's energetic law: restitution work = −e² × compression work; never gains energy.
/// The recommended default.
pub const MECH_RESTITUTION_STRONGE: mech_restitution_law_t = 2;

/// The contact mode of an impact (int32), as reported in ::mech_impact_result_t.
pub type mech_contact_mode_t = i32;
/// No impulse: the contact was separating or grazing.
pub const MECH_CONTACT_NO_IMPACT: mech_contact_mode_t = 0;
/// Smooth contact (friction 0).
pub const MECH_CONTACT_FRICTIONLESS: mech_contact_mode_t = 1;
/// The contact stuck from the start (or friction = +inf).
pub const MECH_CONTACT_STICK: mech_contact_mode_t = 2;
/// The contact slipped throughout (possibly swerving in 3-D).
pub const MECH_CONTACT_SLIP: mech_contact_mode_t = 3;
/// The slip halted and the contact stuck for the rest of the impact.
pub const MECH_CONTACT_SLIP_THEN_STICK: mech_contact_mode_t = 4;
/// The slip halted and resumed in a new direction (reversal).
pub const MECH_CONTACT_REVERSED: mech_contact_mode_t = 5;

struct Constraint(mech_body_constraint_t);
impl CEnum for Constraint {
    fn from_c(raw: i32) -> Option<Self> {
        matches!(raw, MECH_BODY_FREE | MECH_BODY_HINGE_POINT | MECH_BODY_HINGE_AXIS).then_some(Constraint(raw))
    }
}
impl CEnum for RestitutionLaw {
    fn from_c(raw: i32) -> Option<Self> {
        match raw {
            MECH_RESTITUTION_NEWTON => Some(RestitutionLaw::Newton),
            MECH_RESTITUTION_POISSON => Some(RestitutionLaw::Poisson),
            MECH_RESTITUTION_STRONGE => Some(RestitutionLaw::Stronge),
            _ => None,
        }
    }
}

fn mode_to_c(mode: ContactMode) -> mech_contact_mode_t {
    match mode {
        ContactMode::NoImpact => MECH_CONTACT_NO_IMPACT,
        ContactMode::Frictionless => MECH_CONTACT_FRICTIONLESS,
        ContactMode::Stick => MECH_CONTACT_STICK,
        ContactMode::Slip => MECH_CONTACT_SLIP,
        ContactMode::SlipThenStick => MECH_CONTACT_SLIP_THEN_STICK,
        ContactMode::Reversed => MECH_CONTACT_REVERSED,
    }
}

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

/// Validates a C body description and builds the Rust body.
fn body_from_c(b: &mech_impulse_body_t, what: &str) -> Result<RigidBody, FfiError> {
    finite(&b.inverse_mass, &format!("{what}.inverse_mass"))?;
    finite(&b.inverse_inertia, &format!("{what}.inverse_inertia"))?;
    finite(&b.center_of_mass, &format!("{what}.center_of_mass"))?;
    finite(&b.velocity, &format!("{what}.velocity"))?;
    finite(&b.angular_velocity, &format!("{what}.angular_velocity"))?;
    let Constraint(kind) = enum_value::<Constraint>(b.constraint, &format!("{what}.constraint"))?;
    let body = RigidBody::from_inverse(
        b.inverse_mass,
        &Matrix3::from(b.inverse_inertia),
        b.center_of_mass.into(),
        b.velocity.into(),
        b.angular_velocity.into(),
    )?;
    let body = match kind {
        MECH_BODY_HINGE_POINT => {
            finite(&b.hinge_point, &format!("{what}.hinge_point"))?;
            body.hinged_at_point(&b.hinge_point.into())?
        }
        MECH_BODY_HINGE_AXIS => {
            finite(&b.hinge_point, &format!("{what}.hinge_point"))?;
            finite(&b.hinge_axis, &format!("{what}.hinge_axis"))?;
            body.hinged_on_axis(&b.hinge_point.into(), &b.hinge_axis.into())?
        }
        _ => body,
    };
    Ok(body)
}

/// Builds a free ::mech_impulse_body_t from mass properties expressed in the world frame
/// (centre of mass p_WC, central inertia in W axes) and the velocities just before the impact.
/// The inverse inertia is the pseudo-inverse (eigenvalues ≤ 1e-12·λ_max count as zero), so
/// rods and point masses are accepted.
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
        finite(&m.mass, "properties.mass")?;
        finite(&m.center_of_mass, "properties.center_of_mass")?;
        finite(&m.inertia_about_com, "properties.inertia_about_com")?;
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

/// Applies the impulse `impulse` at the world point `point` together with the impulsive moment
/// `moment_about_point` about that point to `body` (7.61–7.71). For a hinged body the hinge
/// impulse is included (it does no work).
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

/// Brings the body point at `point` to rest by a single impulse at that point (7.100–7.108).
/// MECH_STATUS_SINGULAR if the point cannot be stopped (e.g. a moving body of infinite mass).
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

/// A point contact between body 1 and body 2 and its material law.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_impulse_contact_t {
    /// The contact point R (world frame, m).
    pub point: mech_vec3_t,
    /// The unit normal pointing from body 1 into body 2 (|n| = 1 within 1e-9).
    pub normal: mech_vec3_t,
    /// Coefficient of restitution e ∈ [0, 1].
    pub restitution: f64,
    /// Coulomb friction coefficient f ≥ 0; +INFINITY means the contact cannot slip.
    pub friction: f64,
    /// A MECH_RESTITUTION_* value.
    pub law: mech_restitution_law_t,
    /// Relative tolerance of the 3-D swerving-slip integration (> 0, e.g. 1e-10).
    pub tolerance: f64,
}

/// The outcome of a two-body point impact.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_impact_result_t {
    /// Impulse P on body 2 (body 1 receives −P) (N·s).
    pub impulse: mech_vec3_t,
    /// Normal impulse P·n ≥ 0 (N·s).
    pub normal_impulse: f64,
    /// Tangential (friction) impulse P − (P·n) n (N·s).
    pub tangential_impulse: mech_vec3_t,
    /// Normal impulse at the end of compression (N·s).
    pub compression_impulse: f64,
    /// Relative velocity of the contact point (body 2 minus body 1) after the impact (m/s).
    pub relative_velocity_after: mech_vec3_t,
    /// A MECH_CONTACT_* value.
    pub mode: mech_contact_mode_t,
    /// Body 1 centre-of-mass velocity after (m/s).
    pub velocity_after_1: mech_vec3_t,
    /// Body 1 angular velocity after (rad/s).
    pub angular_velocity_after_1: mech_vec3_t,
    /// Body 2 centre-of-mass velocity after (m/s).
    pub velocity_after_2: mech_vec3_t,
    /// Body 2 angular velocity after (rad/s).
    pub angular_velocity_after_2: mech_vec3_t,
    /// Total kinetic-energy change ΔT = P·(u⁻ + ½ W P) (J).
    pub energy_change: f64,
    /// Estimated error of the impulse from the swerving-slip integration (N·s); 0 if exact.
    pub integration_error: f64,
    /// Integration steps plus closed-form segments used.
    pub steps: u64,
}

/// Resolves the impact of `body1` and `body2` at `contact` (7.72–7.99): smooth or rough
/// (isotropic Coulomb, with stick, slip, halting, reversal and 3-D swerving slip) with the
/// selected restitution law. MECH_STATUS_INVALID_ARGUMENT for a non-unit normal, restitution
/// outside [0, 1] or negative friction; MECH_STATUS_BAD_ENUM for an unknown law or constraint;
/// MECH_STATUS_SINGULAR when neither body can move along the normal; MECH_STATUS_NOT_CONVERGED
/// for a frictional jam.
///
/// # Safety
/// `body1`, `body2` and `contact` must be readable, `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_impulse_resolve_contact(
    body1: *const mech_impulse_body_t,
    body2: *const mech_impulse_body_t,
    contact: *const mech_impulse_contact_t,
    out: *mut mech_impact_result_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let (b1, b2, c) = unsafe { (read(body1, "body1")?, read(body2, "body2")?, read(contact, "contact")?) };
        let out = Out::new(out, "out")?;
        let body1 = body_from_c(&b1, "body1")?;
        let body2 = body_from_c(&b2, "body2")?;
        finite(&c.point, "contact.point")?;
        finite(&c.normal, "contact.normal")?;
        finite(&c.restitution, "contact.restitution")?;
        finite(&c.tolerance, "contact.tolerance")?;
        let law = enum_value::<RestitutionLaw>(c.law, "contact.law")?;
        let law = ContactLaw::new(c.restitution, c.friction, law)?;
        if c.tolerance <= 0.0 {
            return Err(FfiError::new(
                MECH_STATUS_INVALID_ARGUMENT,
                format!("contact.tolerance must be positive, got {}", c.tolerance),
            ));
        }
        let options = ImpactOptions {
            tolerance: c.tolerance,
            ..ImpactOptions::default()
        };
        let point: Vector3<f64> = c.point.into();
        let r = resolve_contact(&body1, &body2, &point, &c.normal.into(), &law, &options)?;
        let value = mech_impact_result_t {
            impulse: r.contact.impulse_w.into(),
            normal_impulse: r.contact.normal_impulse,
            tangential_impulse: r.contact.tangential_impulse_w.into(),
            compression_impulse: r.contact.compression_impulse,
            relative_velocity_after: r.contact.u_after_w.into(),
            mode: mode_to_c(r.contact.mode),
            velocity_after_1: r.body1.v_wc_after.into(),
            angular_velocity_after_1: r.body1.w_w_after.into(),
            velocity_after_2: r.body2.v_wc_after.into(),
            angular_velocity_after_2: r.body2.w_w_after.into(),
            energy_change: r.contact.energy_change,
            integration_error: r.contact.integration_error,
            steps: r.contact.steps as u64,
        };
        // SAFETY: caller's contract.
        unsafe { out.write(value) };
        Ok(())
    })
}

/// The body mass properties of a tree from C (one per body, each in its body frame), checked
/// for finite numbers, and the factored mass matrix A(q) at the tree's current configuration.
///
/// # Safety
/// `bodies` must point to `body_count` readable values (or be NULL with body_count = 0).
unsafe fn tree_inertia(
    tree: &KinematicTree,
    ws: &Workspace,
    bodies: *const mech_mass_properties_t,
    body_count: usize,
) -> Result<MechanismInertia, FfiError> {
    // SAFETY: caller's contract.
    let raw = unsafe { read_slice(bodies, body_count, "bodies") }?;
    let mut props = Vec::with_capacity(raw.len());
    for (i, b) in raw.iter().enumerate() {
        finite(&b.mass, &format!("bodies[{i}].mass"))?;
        finite(&b.center_of_mass, &format!("bodies[{i}].center_of_mass"))?;
        finite(&b.inertia_about_com, &format!("bodies[{i}].inertia_about_com"))?;
        props.push(MassProperties {
            mass: b.mass,
            p_oc: b.center_of_mass.into(),
            inertia_c: Matrix3::from(b.inertia_about_com),
        });
    }
    let mut mass = TreeMass::new(tree, props)?;
    Ok(MechanismInertia::new(tree, ws, &mut mass)?)
}

/// Checks that a caller's dof argument matches the tree.
fn check_dof(tree: &KinematicTree, dof: usize, what: &str) -> Result<(), FfiError> {
    if dof != tree.dof() {
        return Err(FfiError::new(
            MECH_STATUS_BAD_DIMENSION,
            format!("{what}: dof is {dof}, the tree has {} coordinates", tree.dof()),
        ));
    }
    Ok(())
}

/// A point impulse on a body of a mechanism.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_mechanism_impulse_t {
    /// Index of the struck body in the tree.
    pub body: usize,
    /// The struck point in the body frame B (m).
    pub point: mech_vec3_t,
    /// The impulse S, world frame (N·s).
    pub impulse: mech_vec3_t,
}

/// The response of a mechanism to point impulses (7.115–7.117).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_mechanism_response_t {
    /// Kinetic energy before, ½ q̇ᵀ A q̇ (J).
    pub energy_before: f64,
    /// ΔT = Q_S·(q̇ + ½ Δq̇) (J).
    pub energy_change: f64,
    /// Normwise backward error of the solve A Δq̇ = Q_S.
    pub backward_error: f64,
}

/// Lagrange's impulse equations A(q) Δq̇ = Σ J_kᵀ S_k (7.115–7.117) for the tree at the state
/// of mech_tree_set_state, with `bodies` = one mass-properties value per body (body frame;
/// mass ≥ 0). Writes Δq̇ (`dof` doubles) and the energy report. MECH_STATUS_NOT_POSITIVE_DEFINITE
/// when A is singular (a rod or point mass whose spin has a coordinate, a massless leaf);
/// MECH_STATUS_INVALID_ARGUMENT for a body index out of range; MECH_STATUS_BAD_DIMENSION for a
/// wrong `body_count` or `dof`.
///
/// # Safety
/// `tree` must be a live handle; `bodies` must point to `body_count` readable values,
/// `impulses` to `impulse_count` readable values (NULL allowed when the count is 0),
/// `delta_q_dot` to `dof` writable doubles, `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_impulse_mechanism_apply(
    tree: *mut mech_tree_t,
    bodies: *const mech_mass_properties_t,
    body_count: usize,
    impulses: *const mech_mechanism_impulse_t,
    impulse_count: usize,
    delta_q_dot: *mut f64,
    dof: usize,
    out: *mut mech_mechanism_response_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { tree_mut(tree) }?;
        // SAFETY: caller's contract.
        let raw = unsafe { read_slice(impulses, impulse_count, "impulses") }?;
        let out = Out::new(out, "out")?;
        let (kt, ws) = built(t)?;
        check_dof(kt, dof, "delta_q_dot")?;
        let dest = OutSlice::new(delta_q_dot, dof, "delta_q_dot")?;
        let mut list = Vec::with_capacity(raw.len());
        for (i, s) in raw.iter().enumerate() {
            finite(&s.point, &format!("impulses[{i}].point"))?;
            finite(&s.impulse, &format!("impulses[{i}].impulse"))?;
            list.push(PointImpulse {
                point: BodyPoint {
                    body: s.body,
                    p_bq: s.point.into(),
                },
                s_w: s.impulse.into(),
            });
        }
        // SAFETY: caller's contract.
        let inertia = unsafe { tree_inertia(kt, ws, bodies, body_count) }?;
        let q_dot = ws.q_dot().to_vec();
        let r = apply_point_impulses(kt, ws, &inertia, &q_dot, &list)?;
        let value = mech_mechanism_response_t {
            energy_before: r.energy_before,
            energy_change: r.energy_change,
            backward_error: r.backward_error,
        };
        // SAFETY: caller's contract.
        unsafe {
            dest.write(&r.delta_q_dot);
            out.write(value);
        }
        Ok(())
    })
}

/// A contact of a mechanism with the environment or between two of its bodies.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_mechanism_contact_t {
    /// Index of the body that receives the impulse +P.
    pub body: usize,
    /// The contact point on `body`, body frame (m).
    pub point: mech_vec3_t,
    /// Index of the other body (receives −P), or −1 for the static environment.
    pub other_body: i64,
    /// The contact point on the other body, its body frame (m); ignored for the environment.
    pub other_point: mech_vec3_t,
    /// Unit normal (world) from the environment / other body into `body` (|n| = 1 within 1e-9).
    pub normal: mech_vec3_t,
    /// Coefficient of restitution e ∈ [0, 1].
    pub restitution: f64,
    /// Coulomb friction coefficient f ≥ 0 (+INFINITY: no slip).
    pub friction: f64,
    /// A MECH_RESTITUTION_* value (used when a single contact is resolved; several contacts use
    /// Poisson's rule, see mech_impulse_mechanism_contacts).
    pub law: mech_restitution_law_t,
}

/// Accuracy and budget of a mechanism impact; pass NULL for the defaults.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_multi_contact_options_t {
    /// Relative complementarity tolerance of the simultaneous model (> 0; default 1e-10).
    pub tolerance: f64,
    /// Maximum Gauss–Seidel sweeps per phase (≥ 1; default 10000).
    pub max_iterations: u64,
    /// Relative tolerance of the single-contact process (> 0; default 1e-10).
    pub process_tolerance: f64,
}

/// The outcome at one contact of a mechanism impact (world frame).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_mechanism_contact_result_t {
    /// Total impulse P on `body` (the other body receives −P) (N·s).
    pub impulse: mech_vec3_t,
    /// Normal impulse P·n ≥ 0 (N·s).
    pub normal_impulse: f64,
    /// Tangential (friction) impulse (N·s).
    pub tangential_impulse: mech_vec3_t,
    /// Normal impulse at the end of compression (N·s).
    pub compression_impulse: f64,
    /// Relative velocity of the contact before the impact (m/s).
    pub relative_velocity_before: mech_vec3_t,
    /// Relative velocity after the impact, u⁻ + Σ W P (m/s).
    pub relative_velocity_after: mech_vec3_t,
    /// A MECH_CONTACT_* value.
    pub mode: mech_contact_mode_t,
}

/// The report of a mechanism impact.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_mechanism_impact_t {
    /// Kinetic energy before, ½ q̇ᵀ A q̇ (J).
    pub energy_before: f64,
    /// ΔT = P·(u⁻ + ½ W P) (J); never positive for several contacts (energy guard).
    pub energy_change: f64,
    /// Largest complementarity residual over contacts (m/s); 0 for the single-contact process.
    pub complementarity_residual: f64,
    /// Impulse error of the single-contact process (N·s); 0 for several contacts.
    pub integration_error: f64,
    /// Factor applied to the restitution impulses by the energy guard (1: untouched).
    pub restitution_scale: f64,
    /// Gauss–Seidel sweeps (several contacts) or process steps (one contact).
    pub iterations: u64,
    /// Numerical rank of the 3m × 3m Delassus matrix W.
    pub delassus_rank: u64,
    /// 1 when the residual met the tolerance, 0 when the sweep budget ran out.
    pub converged: i32,
    /// 1 when the simultaneous multi-contact model was used, 0 for the single-contact process.
    pub simultaneous: i32,
}

/// Reads and validates C contacts.
fn contacts_from_c(raw: &[mech_mechanism_contact_t]) -> Result<Vec<MechanismContact>, FfiError> {
    let mut list = Vec::with_capacity(raw.len());
    for (i, c) in raw.iter().enumerate() {
        finite(&c.point, &format!("contacts[{i}].point"))?;
        finite(&c.other_point, &format!("contacts[{i}].other_point"))?;
        finite(&c.normal, &format!("contacts[{i}].normal"))?;
        finite(&c.restitution, &format!("contacts[{i}].restitution"))?;
        let law = enum_value::<RestitutionLaw>(c.law, &format!("contacts[{i}].law"))?;
        let law = ContactLaw::new(c.restitution, c.friction, law).map_err(|e| {
            FfiError::from(ImpulseError::InContact {
                contact: i,
                source: Box::new(e),
            })
        })?;
        let other = match c.other_body {
            -1 => None,
            b if b >= 0 => Some(BodyPoint {
                body: b as usize,
                p_bq: c.other_point.into(),
            }),
            b => {
                return Err(FfiError::new(
                    MECH_STATUS_INVALID_ARGUMENT,
                    format!("contacts[{i}].other_body must be a body index or -1, got {b}"),
                ));
            }
        };
        list.push(MechanismContact {
            point: BodyPoint {
                body: c.body,
                p_bq: c.point.into(),
            },
            other,
            normal_w: c.normal.into(),
            law,
        });
    }
    Ok(list)
}

/// Resolves an impact of the mechanism `tree` (at the state of mech_tree_set_state; `bodies`
/// one mass-properties value per body) at `contact_count` contacts. One contact: the
/// impulse-parameterised process with the contact's restitution law (as
/// mech_impulse_resolve_contact, on W = J A⁻¹ Jᵀ). Several contacts: the simultaneous
/// two-phase model (inelastic Signorini–Coulomb compression, then Poisson restitution with
/// friction, energy-guarded so that ΔT ≤ 0) solved by projected block Gauss–Seidel from zero
/// in contact order; see the Rust docs of mechanica_impulse::multi_contact. `options` may be
/// NULL for the defaults. Writes one result per contact, Δq̇ (`dof` doubles) and the report.
/// MECH_STATUS_SINGULAR when an approaching contact cannot move along its normal;
/// MECH_STATUS_NOT_POSITIVE_DEFINITE for a singular mass matrix; MECH_STATUS_NOT_CONVERGED for
/// a frictional jam of the single-contact process (an unconverged simultaneous solve is
/// reported by `converged` = 0, not an error).
///
/// # Safety
/// `tree` must be a live handle; `bodies` must point to `body_count` readable values,
/// `contacts` to `contact_count` readable values, `options` be NULL or readable, `results` point
/// to `contact_count` writable values, `delta_q_dot` to `dof` writable doubles, `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_impulse_mechanism_contacts(
    tree: *mut mech_tree_t,
    bodies: *const mech_mass_properties_t,
    body_count: usize,
    contacts: *const mech_mechanism_contact_t,
    contact_count: usize,
    options: *const mech_multi_contact_options_t,
    results: *mut mech_mechanism_contact_result_t,
    delta_q_dot: *mut f64,
    dof: usize,
    out: *mut mech_mechanism_impact_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { tree_mut(tree) }?;
        // SAFETY: caller's contract.
        let raw = unsafe { read_slice(contacts, contact_count, "contacts") }?;
        let mut opts = MultiContactOptions::default();
        if !options.is_null() {
            // SAFETY: caller's contract.
            let o = unsafe { read(options, "options") }?;
            finite(&o.tolerance, "options.tolerance")?;
            finite(&o.process_tolerance, "options.process_tolerance")?;
            if o.tolerance <= 0.0 || o.process_tolerance <= 0.0 || o.max_iterations == 0 {
                return Err(FfiError::new(
                    MECH_STATUS_INVALID_ARGUMENT,
                    "options: tolerances must be positive and max_iterations at least 1",
                ));
            }
            opts.tolerance = o.tolerance;
            opts.max_iterations = usize::try_from(o.max_iterations).unwrap_or(usize::MAX);
            opts.process.tolerance = o.process_tolerance;
        }
        let out = Out::new(out, "out")?;
        let results = OutSlice::new(results, contact_count, "results")?;
        let (kt, ws) = built(t)?;
        check_dof(kt, dof, "delta_q_dot")?;
        let dest = OutSlice::new(delta_q_dot, dof, "delta_q_dot")?;
        let list = contacts_from_c(raw)?;
        // SAFETY: caller's contract.
        let inertia = unsafe { tree_inertia(kt, ws, bodies, body_count) }?;
        let q_dot = ws.q_dot().to_vec();
        let r = resolve_contacts(kt, ws, &inertia, &q_dot, &list, &opts)?;
        let per_contact: Vec<mech_mechanism_contact_result_t> = r
            .contacts
            .iter()
            .map(|c| mech_mechanism_contact_result_t {
                impulse: c.impulse_w.into(),
                normal_impulse: c.normal_impulse,
                tangential_impulse: c.tangential_impulse_w.into(),
                compression_impulse: c.compression_impulse,
                relative_velocity_before: c.u_before_w.into(),
                relative_velocity_after: c.u_after_w.into(),
                mode: mode_to_c(c.mode),
            })
            .collect();
        let value = mech_mechanism_impact_t {
            energy_before: r.energy_before,
            energy_change: r.energy_change,
            complementarity_residual: r.complementarity_residual,
            integration_error: r.integration_error,
            restitution_scale: r.restitution_scale,
            iterations: r.iterations as u64,
            delassus_rank: r.delassus_rank as u64,
            converged: i32::from(r.converged),
            simultaneous: i32::from(r.model == ImpactModel::Simultaneous),
        };
        // SAFETY: caller's contract.
        unsafe {
            results.write(&per_contact);
            dest.write(&r.delta_q_dot);
            out.write(value);
        }
        Ok(())
    })
}

/// The contact-space (Delassus) matrix W = J A⁻¹ Jᵀ of `contact_count` contacts of the
/// mechanism at the state of mech_tree_set_state, into `delassus` (column-major, `rows` × `rows`
/// with rows = 3·contact_count; rows 3i, 3i+1, 3i+2 are the tangents t₁, t₂ and the normal of
/// contact i), its numerical rank into `rank_out`, and the contact frames (columns t₁, t₂, n;
/// world) into `frames` (`contact_count` matrices). The restitution and friction of the contacts
/// are validated but not used.
///
/// # Safety
/// `tree` must be a live handle; `bodies` must point to `body_count` readable values,
/// `contacts` to `contact_count` readable values, `delassus` to rows² writable doubles,
/// `frames` to `contact_count` writable matrices, `rank_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_impulse_mechanism_delassus(
    tree: *mut mech_tree_t,
    bodies: *const mech_mass_properties_t,
    body_count: usize,
    contacts: *const mech_mechanism_contact_t,
    contact_count: usize,
    delassus: *mut f64,
    rows: usize,
    frames: *mut mech_mat3_t,
    rank_out: *mut usize,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { tree_mut(tree) }?;
        // SAFETY: caller's contract.
        let raw = unsafe { read_slice(contacts, contact_count, "contacts") }?;
        let expected = 3 * contact_count;
        if rows != expected {
            return Err(FfiError::new(
                MECH_STATUS_BAD_DIMENSION,
                format!("rows must be 3·contact_count = {expected}, got {rows}"),
            ));
        }
        let size = square_len(rows, "delassus")?;
        let dest = OutSlice::new(delassus, size, "delassus")?;
        let frames_out = OutSlice::new(frames, contact_count, "frames")?;
        let rank_out = Out::new(rank_out, "rank_out")?;
        let (kt, ws) = built(t)?;
        let list = contacts_from_c(raw)?;
        // SAFETY: caller's contract.
        let inertia = unsafe { tree_inertia(kt, ws, bodies, body_count) }?;
        let q_dot = ws.q_dot().to_vec();
        let space = ContactSpace::new(kt, ws, &inertia, &q_dot, &list)?;
        let frame_values: Vec<mech_mat3_t> = (0..contact_count)
            .map(|i| space.frame(i).copied().unwrap_or_else(Matrix3::identity).into())
            .collect();
        // SAFETY: caller's contract.
        unsafe {
            dest.write(space.delassus());
            frames_out.write(&frame_values);
            rank_out.write(space.rank());
        }
        Ok(())
    })
}
