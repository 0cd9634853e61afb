//! C entry points of the dynamics crate: a dynamics handle made from a mechanism (its gravity,
//! rotating frame and potentials), with dampers and charged points added to it; inverse
//! dynamics (τ, its split, joint reactions), forward dynamics (q̈ with its accuracy report) and
//! the mass matrix, and the damped modes about a configuration, into caller buffers; holonomic
//! constraints added to the handle and the forward dynamics with their multipliers; the
//! torque-free rigid body, exact and integrated.

use super::boundary::{FfiError, boundary};
use super::handle::Handle;
use super::mechanism::mech_mechanism_t;
use super::status::*;
use super::validate::*;
use mechanica_dynamics::{ConstrainedDynamics, Dynamics, DynamicsError};

mod constraints;
mod damped;
mod forward;
mod free_body;
mod inverse;
mod loads;

pub use constraints::*;
pub use damped::*;
pub use forward::*;
pub use free_body::*;
pub use inverse::*;
pub use loads::*;

impl From<DynamicsError> for FfiError {
    fn from(error: DynamicsError) -> Self {
        let status = match &error {
            DynamicsError::Mechanism(e) => return FfiError::from(e.clone()),
            DynamicsError::Kinematics(e) => return FfiError::from(e.clone()),
            DynamicsError::Mass(e) => return FfiError::from(e.clone()),
            DynamicsError::Modal(e) => return FfiError::from(e.clone()),
            DynamicsError::WrongLength { .. } => MECH_STATUS_BAD_DIMENSION,
            DynamicsError::NonFiniteInput { .. } => MECH_STATUS_NON_FINITE,
            DynamicsError::NonFiniteResult { .. } => MECH_STATUS_OUT_OF_RANGE,
            DynamicsError::SingularArticulatedInertia { .. }
            | DynamicsError::SingularMassMatrix { .. }
            | DynamicsError::RedundantConstraint { .. }
            | DynamicsError::Dissipation { .. } => MECH_STATUS_SINGULAR,
            DynamicsError::NotConverged { .. } => MECH_STATUS_NOT_CONVERGED,
            DynamicsError::OutOfRange { .. }
            | DynamicsError::NoSuchBody { .. }
            | DynamicsError::NoSuchCoordinate { .. } => MECH_STATUS_INVALID_ARGUMENT,
            // A variant added after this layer was written: its message still says what was wrong.
            _ => MECH_STATUS_INVALID_ARGUMENT,
        };
        FfiError::new(status, error.to_string())
    }
}

/// The dynamics of a mechanism (opaque): a copy of the mechanism (tree, bodies, gravity,
/// rotating frame, potentials) with its dampers and charged points, its holonomic constraints
/// (used only by mech_dynamics_forward_constrained), and the working storage of its recursions.
/// Created by mech_dynamics_create, freed by mech_dynamics_destroy.
pub struct mech_dynamics_t {
    constrained: ConstrainedDynamics,
}

impl Handle for mech_dynamics_t {}

impl mech_dynamics_t {
    /// The dynamics without its constraints (read by the other C modules).
    #[allow(dead_code)]
    pub(crate) fn dynamics(&self) -> &Dynamics {
        self.constrained.dynamics()
    }

    /// The dynamics with its constraints (read by the motion module).
    pub(crate) fn constrained(&self) -> &ConstrainedDynamics {
        &self.constrained
    }
}

/// Borrows the dynamics behind a handle for evaluating or changing it (NULL_POINTER,
/// MISALIGNED_POINTER).
///
/// # Safety
/// As [`Handle::borrow_mut`].
unsafe fn dynamics_mut<'a>(handle: *mut mech_dynamics_t) -> Result<&'a mut Dynamics, FfiError> {
    // SAFETY: caller's contract.
    unsafe { mech_dynamics_t::borrow_mut(handle, "dynamics") }.map(|h| h.constrained.dynamics_mut())
}

/// Reads a vector of the mechanism's `n` coordinates: BAD_DIMENSION unless `n` is the dof,
/// NON_FINITE for a NaN or infinite entry.
///
/// # Safety
/// `values` must point to `n` readable doubles.
unsafe fn read_coordinates<'a>(
    dynamics: &Dynamics,
    values: *const f64,
    n: usize,
    what: &str,
) -> Result<&'a [f64], FfiError> {
    if n != dynamics.dof() {
        return Err(FfiError::new(
            MECH_STATUS_BAD_DIMENSION,
            format!("{what}: the mechanism has {} coordinates, got n = {n}", dynamics.dof()),
        ));
    }
    // SAFETY: caller's contract.
    let values = unsafe { read_slice(values, n, what) }?;
    finite(values, what)?;
    Ok(values)
}

/// The three coordinate vectors of a state and its rate (q, q̇ and q̈ or τ), each checked as by
/// [`read_coordinates`].
///
/// # Safety
/// Each pointer must point to `n` readable doubles.
unsafe fn read_state<'a>(
    dynamics: &Dynamics,
    [q, q_dot, third]: [*const f64; 3],
    third_name: &str,
    n: usize,
) -> Result<[&'a [f64]; 3], FfiError> {
    // SAFETY: caller's contract.
    unsafe {
        Ok([
            read_coordinates(dynamics, q, n, "q")?,
            read_coordinates(dynamics, q_dot, n, "q_dot")?,
            read_coordinates(dynamics, third, n, third_name)?,
        ])
    }
}

/// Creates the dynamics of a mechanism and writes its handle to `*dynamics_out`. The mechanism
/// is copied with its gravity, rotating frame and potentials: later changes to it, or its
/// destruction, do not affect the dynamics. The dynamics starts without dampers, charged
/// points or constraints. The caller owns the handle and frees it with mech_dynamics_destroy.
///
/// Errors: none beyond the pointer checks (MECH_STATUS_INVALID_ARGUMENT only if the mechanism's
/// rotating frame cannot be set up as the tree's base motion).
///
/// # Safety
/// `mechanism` must be a live mechanism handle and `dynamics_out` a writable pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_dynamics_create(
    mechanism: *const mech_mechanism_t,
    dynamics_out: *mut *mut mech_dynamics_t,
) -> mech_status_t {
    boundary(|| {
        let out = Out::new(dynamics_out, "dynamics_out")?;
        // SAFETY: caller's contract.
        let mechanism = unsafe { mech_mechanism_t::borrow(mechanism, "mechanism") }?;
        let handle = mech_dynamics_t {
            constrained: ConstrainedDynamics::new(Dynamics::new(mechanism.mechanism().clone())?),
        };
        // SAFETY: caller's contract.
        unsafe { out.write(handle.into_raw()) };
        Ok(())
    })
}

/// Frees a dynamics handle. NULL is accepted and ignored.
///
/// # Safety
/// `dynamics` must be NULL or a live handle from mech_dynamics_create, not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_dynamics_destroy(dynamics: *mut mech_dynamics_t) {
    // SAFETY: caller's contract.
    unsafe { mech_dynamics_t::destroy(dynamics) }
}

/// Writes the number of coordinates n (the tree's dof) to `*dof_out`: the length of every q,
/// q̇, q̈ and τ argument of the mech_dynamics_* functions.
///
/// Errors: none beyond the pointer checks.
///
/// # Safety
/// `dynamics` must be a live handle and `dof_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_dynamics_dof(dynamics: *const mech_dynamics_t, dof_out: *mut usize) -> mech_status_t {
    boundary(|| {
        let out = Out::new(dof_out, "dof_out")?;
        // SAFETY: caller's contract.
        let d = unsafe { mech_dynamics_t::borrow(dynamics, "dynamics") }?;
        // SAFETY: caller's contract.
        unsafe { out.write(d.constrained.dof()) };
        Ok(())
    })
}

/// Writes the number of bodies of the mechanism to `*bodies_out`: the number of joint
/// reactions of mech_dynamics_reactions.
///
/// Errors: none beyond the pointer checks.
///
/// # Safety
/// `dynamics` must be a live handle and `bodies_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_dynamics_body_count(
    dynamics: *const mech_dynamics_t,
    bodies_out: *mut usize,
) -> mech_status_t {
    boundary(|| {
        let out = Out::new(bodies_out, "bodies_out")?;
        // SAFETY: caller's contract.
        let d = unsafe { mech_dynamics_t::borrow(dynamics, "dynamics") }?;
        // SAFETY: caller's contract.
        unsafe { out.write(d.constrained.dynamics().tree().body_count()) };
        Ok(())
    })
}
