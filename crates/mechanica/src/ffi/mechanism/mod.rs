//! C entry points of the mechanism crate: a mechanism handle made from a finalized tree and
//! per-body mass properties, loads (gravity, rotating frame, springs, forces, limits), U* with
//! its exact gradient and Hessian, equilibrium search, stability and modes into caller buffers.

use super::boundary::{FfiError, boundary};
use super::handle::Handle;
use super::kinematics::mech_tree_t;
use super::mass::mech_mass_properties_t;
use super::status::*;
use super::validate::*;
use mechanica_mass::MassProperties;
use mechanica_mechanism::{Mechanism, MechanismError};

mod equilibrium;
mod loads;
mod modes;

pub use equilibrium::*;
pub use loads::*;
pub use modes::*;

impl From<MechanismError> for FfiError {
    fn from(error: MechanismError) -> Self {
        let status = match &error {
            MechanismError::Kinematics(e) => return FfiError::from(e.clone()),
            MechanismError::Mass(e) => return FfiError::from(e.clone()),
            MechanismError::Modal(e) => return FfiError::from(e.clone()),
            MechanismError::NonFinite { .. } => MECH_STATUS_NON_FINITE,
            MechanismError::WrongLength { .. } => MECH_STATUS_BAD_DIMENSION,
            MechanismError::NoEquilibrium { .. } => MECH_STATUS_NOT_CONVERGED,
            MechanismError::Numerical(_) => MECH_STATUS_NOT_CONVERGED,
            MechanismError::ZeroLengthSpring { .. } => MECH_STATUS_SINGULAR,
            MechanismError::NoSuchBody { .. }
            | MechanismError::NoSuchCoordinate { .. }
            | MechanismError::OutOfRange { .. }
            | MechanismError::NotRebased { .. }
            | MechanismError::GravityNotAlongAxis { .. }
            | MechanismError::BadLimits { .. }
            | MechanismError::Potential { .. } => MECH_STATUS_INVALID_ARGUMENT,
            // A variant added after this layer was written: its message still says what was wrong.
            _ => MECH_STATUS_INVALID_ARGUMENT,
        };
        FfiError::new(status, error.to_string())
    }
}

/// A mechanism (opaque): a copy of a finalized tree with body mass properties and loads.
/// Created by mech_mechanism_create, freed by mech_mechanism_destroy.
pub struct mech_mechanism_t {
    pub(crate) mechanism: Mechanism,
    /// The link, joint and coordinate names of a mechanism read from URDF (or made from such
    /// a tree).
    #[cfg(feature = "urdf")]
    pub(crate) names: Option<std::sync::Arc<crate::ffi::urdf::UrdfNames>>,
}

impl Handle for mech_mechanism_t {}

impl mech_mechanism_t {
    /// The mechanism behind the handle.
    pub(crate) fn mechanism(&self) -> &Mechanism {
        &self.mechanism
    }
}

/// Borrows the mechanism behind a handle for changing it (NULL_POINTER, MISALIGNED_POINTER).
///
/// # Safety
/// As [`Handle::borrow_mut`].
unsafe fn mechanism_mut<'a>(handle: *mut mech_mechanism_t) -> Result<&'a mut Mechanism, FfiError> {
    // SAFETY: caller's contract.
    unsafe { mech_mechanism_t::borrow_mut(handle, "mechanism") }.map(|h| &mut h.mechanism)
}

/// Reads `n` coordinates, checked finite (NON_FINITE) and of the mechanism's length
/// (BAD_DIMENSION).
///
/// # Safety
/// `q` must point to `n` readable doubles.
unsafe fn read_q<'a>(mechanism: &Mechanism, q: *const f64, n: usize, what: &str) -> Result<&'a [f64], FfiError> {
    if n != mechanism.dof() {
        return Err(FfiError::new(
            MECH_STATUS_BAD_DIMENSION,
            format!("{what}: the mechanism has {} coordinates, got {n}", mechanism.dof()),
        ));
    }
    // SAFETY: caller's contract.
    let q = unsafe { read_slice(q, n, what) }?;
    finite(q, what)?;
    Ok(q)
}

/// Creates a mechanism from a finalized tree (copied: later changes to the tree, or its
/// destruction, do not affect it) and one mass-properties value per body (`n_bodies` of them,
/// each in the body's frame, in body order), and writes its handle to `*mechanism_out`. The
/// caller owns the handle and frees it with mech_mechanism_destroy. The mechanism starts
/// without loads.
///
/// Errors: MECH_STATUS_INVALID_ARGUMENT when the tree is not finalized or a body's properties
/// are not those of a real body (mass ≤ 0 or an invalid tensor; the message names the body),
/// except MECH_STATUS_NOT_POSITIVE_DEFINITE for a tensor that is not positive semidefinite or
/// breaks the triangle inequality and MECH_STATUS_NON_FINITE for a NaN or infinite entry;
/// MECH_STATUS_BAD_DIMENSION when `n_bodies` is not the tree's body count.
///
/// # Safety
/// `tree` must be a live tree handle, `bodies` must point to `n_bodies` readable values and
/// `mechanism_out` to a writable pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_create(
    tree: *mut mech_tree_t,
    bodies: *const mech_mass_properties_t,
    n_bodies: usize,
    mechanism_out: *mut *mut mech_mechanism_t,
) -> mech_status_t {
    boundary(|| {
        let out = Out::new(mechanism_out, "mechanism_out")?;
        // SAFETY: caller's contract.
        let tree_handle = unsafe { mech_tree_t::borrow_mut(tree, "tree") }?;
        #[cfg(feature = "urdf")]
        let names = tree_handle.names.clone();
        let (tree, _) = tree_handle.built()?;
        // SAFETY: caller's contract.
        let raw = unsafe { read_slice(bodies, n_bodies, "bodies") }?;
        let mut masses = Vec::with_capacity(raw.len());
        for (i, m) in raw.iter().enumerate() {
            let properties =
                MassProperties::new(m.mass, m.center_of_mass.into(), m.inertia_about_com.into()).map_err(|e| {
                    FfiError::new(
                        FfiError::from(e).status,
                        format!("bodies[{i}]: invalid mass properties"),
                    )
                })?;
            masses.push(properties);
        }
        let mechanism = mech_mechanism_t {
            mechanism: Mechanism::new(tree.clone(), masses)?,
            #[cfg(feature = "urdf")]
            names,
        };
        // SAFETY: caller's contract.
        unsafe { out.write(mechanism.into_raw()) };
        Ok(())
    })
}

/// Frees a mechanism. NULL is accepted and ignored.
///
/// # Safety
/// `mechanism` must be NULL or a live handle from mech_mechanism_create, not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_destroy(mechanism: *mut mech_mechanism_t) {
    // SAFETY: caller's contract.
    unsafe { mech_mechanism_t::destroy(mechanism) }
}

/// Writes the number of coordinates of the mechanism (the tree's dof) to `*dof_out`.
///
/// Errors: none beyond the pointer checks.
///
/// # Safety
/// `mechanism` must be a live handle and `dof_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_dof(mechanism: *mut mech_mechanism_t, dof_out: *mut usize) -> mech_status_t {
    boundary(|| {
        let out = Out::new(dof_out, "dof_out")?;
        // SAFETY: caller's contract.
        let m = unsafe { mech_mechanism_t::borrow(mechanism, "mechanism") }?;
        // SAFETY: caller's contract.
        unsafe { out.write(m.mechanism.dof()) };
        Ok(())
    })
}
