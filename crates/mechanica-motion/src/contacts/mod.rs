//! Unilateral contacts during a run, and the impacts at their closing (theory (M.21)–(M.23)).
//!
//! A [`UnilateralContact`] is a body point against a plane of the environment, or against a
//! point of another body, with the world normal n and the impact law of the impulse crate. Its
//! gap is g(q) = n·(x(q) − x_other(q)) − offset (x_other = 0 for the environment, so the
//! plane is n·x = offset), and the motion must keep g ≥ 0 (M.21). The run is event driven:
//! - between impacts the equations of motion are integrated as without contacts;
//! - a step whose end has a gap ≤ 0, or whose cubic Hermite gap dips below zero with a true
//!   gap ≤ 0 at the dip, is cut back to the first zero of the gap, located by the Illinois
//!   method on re-integrated partial steps ([`locate`], (M.22));
//! - there the velocities jump, q̇⁺ = q̇⁻ + A⁻¹JᵀP, with P from the impulse crate: its
//!   impulse-parameterised process for one contact, the simultaneous model for several
//!   (7.115–7.117), and the run goes on from (q, q̇⁺) ([`impact`]).
//!
//! Each impact is reported as an [`ImpactEvent`]: the energy H just before and after it and the
//! drift of H over the segment of free motion that ended there, so that what the impact law
//! dissipates is told apart from what the integrator adds (M.23). A contact that stays closed
//! after its impact (resting or sliding contact, impacts accumulating in finite time) ends the
//! run with [`crate::StepFailure::SustainedContact`]: neither is modelled.

mod gap;
pub(crate) mod impact;
pub(crate) mod locate;
pub(crate) mod run;

use crate::error::MotionError;
use mechanica_dynamics::ConstrainedDynamics;
use mechanica_impulse::{ContactLaw, ContactMode, MechanismContact};
use nalgebra::Vector3;

/// The largest departure of a contact normal's length from 1 that is accepted.
pub const NORMAL_LENGTH_TOLERANCE: f64 = 1e-9;

/// A unilateral contact of a mechanism (module docs). World frame W of the tree.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnilateralContact {
    /// The body point, the other body point (`None`: the environment), the unit normal n into
    /// the point's body, and the impact law.
    pub contact: MechanismContact,
    /// The gap at which the contact closes, m: g = n·(x − x_other) − offset.
    pub offset: f64,
}

/// One impact of a run, at a located contact event.
#[derive(Debug, Clone, PartialEq)]
pub struct ImpactEvent {
    /// The time of the impact, s.
    pub t: f64,
    /// The contacts that took part (indices into the simulation's contacts).
    pub contacts: Vec<usize>,
    /// The smallest gap of those contacts at the impact, m (≤ 0 within the location
    /// tolerance: the penetration left by locating the event).
    pub gap: f64,
    /// The largest approach speed −ġ⁻ of those contacts, m/s.
    pub approach_speed: f64,
    /// The impulse of each contact (world components, N·s), in the order of `contacts`.
    pub impulses: Vec<Vector3<f64>>,
    /// The contact mode of each contact at the end of the impact.
    pub modes: Vec<ContactMode>,
    /// The kinetic energy T⁻ = ½ q̇⁻ᵀ A q̇⁻ just before the impact (J): the scale of the loss.
    pub kinetic_energy_before: f64,
    /// H just before the impact (J).
    pub energy_before: f64,
    /// H just after the impact (J); H⁺ − H⁻ = ΔT, the work of the impulses.
    pub energy_after: f64,
    /// H⁻ minus H at the start of the free segment that ends at this impact (after the
    /// previous impact, or at t = 0), J: the integrator's drift over that segment.
    pub segment_drift: f64,
    /// The impact's own error report: the process's impulse error (N·s), or the simultaneous
    /// model's complementarity residual (m/s).
    pub impulse_error: f64,
    /// q̇⁻ (reporting chart).
    pub q_dot_before: Vec<f64>,
    /// q̇⁺ (reporting chart).
    pub q_dot_after: Vec<f64>,
}

impl ImpactEvent {
    /// The energy the impact dissipated, H⁻ − H⁺ (J; ≥ 0 for a dissipative law).
    pub fn energy_lost(&self) -> f64 {
        self.energy_before - self.energy_after
    }
}

/// Ok when every contact names existing bodies with finite points, a unit normal (within
/// [`NORMAL_LENGTH_TOLERANCE`]), a valid law and a finite offset, and the mechanism has no
/// holonomic constraints, no rotating frame and no prescribed base motion (the impact map of
/// (7.117) is that of a free tree on a fixed base).
pub(crate) fn validate(contacts: &[UnilateralContact], model: &ConstrainedDynamics) -> Result<(), MotionError> {
    if contacts.is_empty() {
        return Ok(());
    }
    let dynamics = model.dynamics();
    let setting = if !model.constraints().is_empty() {
        Some("the mechanism has holonomic constraints")
    } else if dynamics.mechanism().rotating_frame().is_some() {
        Some("the mechanism is in a rotating frame")
    } else if dynamics.has_base_motion() {
        Some("the mechanism has a prescribed base motion")
    } else {
        None
    };
    if let Some(reason) = setting {
        return Err(invalid(
            0,
            format!("{reason}; contacts need a free tree on a fixed base"),
        ));
    }
    let bodies = dynamics.tree().body_count();
    for (index, c) in contacts.iter().enumerate() {
        check_contact(c, bodies).map_err(|reason| invalid(index, reason))?;
    }
    Ok(())
}

fn invalid(index: usize, reason: String) -> MotionError {
    MotionError::InvalidContact { index, reason }
}

fn check_contact(c: &UnilateralContact, bodies: usize) -> Result<(), String> {
    let m = &c.contact;
    let points = std::iter::once(&m.point).chain(m.other.as_ref());
    for point in points {
        if point.body >= bodies {
            return Err(format!("body {} does not exist (the tree has {bodies})", point.body));
        }
        if !point.p_bq.iter().all(|x| x.is_finite()) {
            return Err(format!("the point on body {} is not finite", point.body));
        }
    }
    let length = m.normal_w.norm();
    if (length - 1.0).abs() > NORMAL_LENGTH_TOLERANCE || length.is_nan() {
        return Err(format!("the normal must be a unit vector, its length is {length}"));
    }
    if !c.offset.is_finite() {
        return Err(format!("the offset {} is not finite", c.offset));
    }
    ContactLaw::new(m.law.restitution, m.law.friction, m.law.law)
        .map(|_| ())
        .map_err(|e| e.to_string())
}
