//! Simulations with unilateral contacts (theory (M.21)–(M.23)): every closing of a contact's
//! gap is located and resolved as an impact by the impulse crate's laws, and each impact is
//! reported with the energy it dissipated beside the integrator's drift over the free motion
//! before it.

use super::{InitialValues, mech_motion_options_t, mech_simulation_t, start};
use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::dynamics::mech_dynamics_t;
use crate::ffi::handle::Handle;
use crate::ffi::impulse::{contacts_from_c, mech_contact_mode_t, mech_mechanism_contact_t, mode_to_c};
use crate::ffi::status::*;
use crate::ffi::types::mech_vec3_t;
use crate::ffi::validate::*;
use mechanica_dynamics::ConstrainedDynamics;
use mechanica_motion::{ImpactEvent, UnilateralContact};

/// A unilateral contact of a simulation: a body point against the plane n·x = offset of the
/// environment (`contact.other_body` = −1), or against a point of another body. Its gap
/// g = n·(x − x_other) − offset (m) must stay ≥ 0; `contact.normal` (world, unit) points from
/// the plane or the other body into `contact.body`, and `contact.restitution`, `friction` and
/// `law` give the impact law (one contact: that law; several at once: the simultaneous model).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct mech_motion_contact_t {
    /// The body points, normal and impact law.
    pub contact: mech_mechanism_contact_t,
    /// The gap at which the contact closes, m.
    pub offset: f64,
}

/// One impact of a simulation with contacts (world frame, SI units).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_motion_impact_t {
    /// The time of the impact, s.
    pub t: f64,
    /// How many contacts took part (their indices: mech_simulation_impact_contacts).
    pub contact_count: usize,
    /// The smallest gap of those contacts at the impact, m: ≤ 0, the penetration left by
    /// locating the event to its tolerance.
    pub gap: f64,
    /// The largest approach speed −ġ of those contacts before the impact, m/s.
    pub approach_speed: f64,
    /// The kinetic energy ½ q̇ᵀA q̇ just before the impact, J (the scale of the loss).
    pub kinetic_energy_before: f64,
    /// H just before the impact, J.
    pub energy_before: f64,
    /// H just after the impact, J.
    pub energy_after: f64,
    /// energy_before − energy_after, J (≥ 0 for a dissipative law).
    pub energy_lost: f64,
    /// H just before this impact minus H just after the previous one (or at t = 0), J: the
    /// integrator's drift over the free motion that ended here (or the work of dampers and
    /// applied forces there).
    pub segment_drift: f64,
    /// The impact's own error report: the single-contact process's impulse error (N·s) or the
    /// simultaneous model's complementarity residual (m/s).
    pub impulse_error: f64,
}

/// Creates a simulation of a copy of `dynamics` with the `contact_count` unilateral contacts
/// `contacts` (the other arguments are those of mech_simulation_create). The initial state
/// may touch a contact (gap ≤ 0) only if it opens from there.
///
/// Errors: those of mech_simulation_create; MECH_STATUS_INVALID_ARGUMENT for a contact that
/// names a missing body, has a normal that is not a unit vector (within 1e-9), a non-finite
/// point or offset, or an invalid law, and for a dynamics with holonomic constraints, a
/// rotating frame or a prescribed base motion. During mech_simulation_advance: a contact that
/// stays closed after its impact (resting or sliding contact), impacts that accumulate
/// faster than t can resolve, or more than 100 000 impacts stop the integration with
/// MECH_STATUS_NOT_CONVERGED at the start of the step (mech_last_error says which).
///
/// # Safety
/// As mech_simulation_create; `contacts` must point to `contact_count` readable
/// mech_motion_contact_t (it may be NULL when `contact_count` is 0).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_simulation_create_with_contacts(
    dynamics: *const mech_dynamics_t,
    options: *const mech_motion_options_t,
    contacts: *const mech_motion_contact_t,
    contact_count: usize,
    q0: *const f64,
    q_dot0: *const f64,
    tau: *const f64,
    n: usize,
    simulation_out: *mut *mut mech_simulation_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let d = unsafe { mech_dynamics_t::borrow(dynamics, "dynamics") }?.dynamics();
        // SAFETY: caller's contract.
        let raw = unsafe { read_slice(contacts, contact_count, "contacts") }?;
        let list = unilateral_from_c(raw)?;
        let model = ConstrainedDynamics::new(d.clone());
        let initial: InitialValues = (q0, q_dot0, tau, n);
        // SAFETY: caller's contract.
        unsafe { start(model, list, options, initial, simulation_out) }
    })
}

/// The motion crate's contacts from their C form (validated against the mechanism when the
/// simulation is created).
fn unilateral_from_c(raw: &[mech_motion_contact_t]) -> Result<Vec<UnilateralContact>, FfiError> {
    let laws: Vec<mech_mechanism_contact_t> = raw.iter().map(|c| c.contact).collect();
    let contacts = contacts_from_c(&laws)?;
    raw.iter()
        .zip(contacts)
        .enumerate()
        .map(|(i, (c, contact))| {
            finite(&c.offset, &format!("contacts[{i}].offset"))?;
            Ok(UnilateralContact {
                contact,
                offset: c.offset,
            })
        })
        .collect()
}

/// The impact `index` of the simulation, or INVALID_ARGUMENT naming the count.
fn impact_at(s: &mech_simulation_t, index: usize) -> Result<&ImpactEvent, FfiError> {
    let impacts = s.stepper.impacts();
    impacts.get(index).ok_or_else(|| {
        FfiError::new(
            MECH_STATUS_INVALID_ARGUMENT,
            format!(
                "impact {index} does not exist (the simulation has had {})",
                impacts.len()
            ),
        )
    })
}

/// Writes the number of impacts so far (0 for a simulation without contacts) to `*count_out`.
///
/// # Safety
/// `simulation` must be a live handle and `count_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_simulation_impact_count(
    simulation: *const mech_simulation_t,
    count_out: *mut usize,
) -> mech_status_t {
    boundary(|| {
        let out = Out::new(count_out, "count_out")?;
        // SAFETY: caller's contract.
        let s = unsafe { mech_simulation_t::borrow(simulation, "simulation") }?;
        // SAFETY: caller's contract.
        unsafe { out.write(s.stepper.impacts().len()) };
        Ok(())
    })
}

/// Writes impact `index` (0 ≤ index < mech_simulation_impact_count, in time order) to
/// `*impact_out`.
///
/// Errors: MECH_STATUS_INVALID_ARGUMENT for an index past the count.
///
/// # Safety
/// `simulation` must be a live handle and `impact_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_simulation_impact(
    simulation: *const mech_simulation_t,
    index: usize,
    impact_out: *mut mech_motion_impact_t,
) -> mech_status_t {
    boundary(|| {
        let out = Out::new(impact_out, "impact_out")?;
        // SAFETY: caller's contract.
        let s = unsafe { mech_simulation_t::borrow(simulation, "simulation") }?;
        let e = impact_at(s, index)?;
        let impact = mech_motion_impact_t {
            t: e.t,
            contact_count: e.contacts.len(),
            gap: e.gap,
            approach_speed: e.approach_speed,
            kinetic_energy_before: e.kinetic_energy_before,
            energy_before: e.energy_before,
            energy_after: e.energy_after,
            energy_lost: e.energy_lost(),
            segment_drift: e.segment_drift,
            impulse_error: e.impulse_error,
        };
        // SAFETY: caller's contract.
        unsafe { out.write(impact) };
        Ok(())
    })
}

/// Writes, for impact `index`, the indices of the contacts that took part (into the array
/// given at creation) to `contacts_out`, their impulses (world, N·s, on `contact.body`; the
/// other body receives the opposite) to `impulses_out` and their modes (MECH_CONTACT_*) to
/// `modes_out`, each `capacity` entries long; the number written is
/// mech_motion_impact_t.contact_count. Any of the three may be NULL when not wanted.
///
/// Errors: MECH_STATUS_INVALID_ARGUMENT for an index past the count;
/// MECH_STATUS_BAD_DIMENSION when `capacity` is below the contact count.
///
/// # Safety
/// `simulation` must be a live handle; the non-NULL outputs must point to `capacity`
/// writable entries.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_simulation_impact_contacts(
    simulation: *const mech_simulation_t,
    index: usize,
    capacity: usize,
    contacts_out: *mut usize,
    impulses_out: *mut mech_vec3_t,
    modes_out: *mut mech_contact_mode_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let s = unsafe { mech_simulation_t::borrow(simulation, "simulation") }?;
        let e = impact_at(s, index)?;
        let count = e.contacts.len();
        if capacity < count {
            return Err(FfiError::new(
                MECH_STATUS_BAD_DIMENSION,
                format!("impact {index} has {count} contacts, capacity is {capacity}"),
            ));
        }
        let impulses: Vec<mech_vec3_t> = e.impulses.iter().map(|p| (*p).into()).collect();
        let modes: Vec<mech_contact_mode_t> = e.modes.iter().map(|m| mode_to_c(*m)).collect();
        let contacts = OutSlice::optional(contacts_out, count, "contacts_out")?;
        let impulses_slice = OutSlice::optional(impulses_out, count, "impulses_out")?;
        let modes_slice = OutSlice::optional(modes_out, count, "modes_out")?;
        // SAFETY: caller's contract.
        unsafe {
            if let Some(out) = contacts {
                out.write(&e.contacts);
            }
            if let Some(out) = impulses_slice {
                out.write(&impulses);
            }
            if let Some(out) = modes_slice {
                out.write(&modes);
            }
        }
        Ok(())
    })
}

/// Writes q̇ just before and just after impact `index` (n values each, the charts of
/// mech_simulation_advance) to `q_dot_before_out` and `q_dot_after_out`.
///
/// Errors: MECH_STATUS_INVALID_ARGUMENT for an index past the count;
/// MECH_STATUS_BAD_DIMENSION when n is not the dof.
///
/// # Safety
/// `simulation` must be a live handle; both outputs must point to n writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_simulation_impact_velocities(
    simulation: *const mech_simulation_t,
    index: usize,
    n: usize,
    q_dot_before_out: *mut f64,
    q_dot_after_out: *mut f64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let s = unsafe { mech_simulation_t::borrow(simulation, "simulation") }?;
        let e = impact_at(s, index)?;
        let dof = e.q_dot_before.len();
        if n != dof {
            return Err(FfiError::new(
                MECH_STATUS_BAD_DIMENSION,
                format!("the mechanism has {dof} coordinates, got n = {n}"),
            ));
        }
        let before = OutSlice::new(q_dot_before_out, n, "q_dot_before_out")?;
        let after = OutSlice::new(q_dot_after_out, n, "q_dot_after_out")?;
        // SAFETY: caller's contract.
        unsafe {
            before.write(&e.q_dot_before);
            after.write(&e.q_dot_after);
        }
        Ok(())
    })
}
