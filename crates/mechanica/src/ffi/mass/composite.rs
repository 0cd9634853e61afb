//! Moving bodies between frames, composing several bodies into one, and removing material.

use super::{mech_mass_properties_t, pose, read_properties};
use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::status::*;
use crate::ffi::types::*;
use crate::ffi::validate::*;
use mechanica_mass::MassProperties;

/// The body `properties` after the rigid motion x ↦ R x + t, with R from the unit quaternion
/// `rotation` (|‖q‖ − 1| ≤ 1e-12) and t = `translation` (m): the centre moves and the tensor
/// becomes R J Rᵀ. Equivalently, re-expresses properties given in a body frame B in the frame F
/// in which B has this pose. Written to `out`.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_INVALID_ARGUMENT for
/// a mass ≤ 0, a tensor not symmetric within 1e-9·Σ|J_kk| or a non-unit quaternion; MECH_STATUS_OUT_OF_RANGE when the result overflows.
///
/// # Safety
/// All pointers must be readable (inputs) or writable (`out`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mass_transform(
    properties: *const mech_mass_properties_t,
    rotation: *const mech_quat_t,
    translation: *const mech_vec3_t,
    out: *mut mech_mass_properties_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let props = unsafe { read_properties(properties, "properties") }?;
        // SAFETY: caller's contract.
        let (q, t) = unsafe { (read(rotation, "rotation")?, read(translation, "translation")?) };
        let out = Out::new(out, "out")?;
        let moved = props.transformed(&pose(&q, &t)?);
        finite_result(&mech_mass_properties_t::from(moved), "transformed mass properties")?;
        // SAFETY: caller's contract.
        unsafe { out.write(moved.into()) };
        Ok(())
    })
}

/// The mass properties of the union of `count` ≥ 1 bodies, written to `out`: body i is
/// `parts[i]` moved by the rigid motion (`rotations[i]`, `translations[i]`) as in
/// mech_mass_transform. Pass NULL for both `rotations` and `translations` when the parts are
/// already in one frame. The total mass, the mass-weighted centre (1.24) and the sum of the
/// central tensors moved to the common centre by Steiner's theorem (3.27–3.29).
///
/// Errors: MECH_STATUS_BAD_DIMENSION for count = 0; MECH_STATUS_NULL_POINTER when only one of
/// `rotations` and `translations` is NULL; MECH_STATUS_NON_FINITE; MECH_STATUS_INVALID_ARGUMENT
/// for a part with mass ≤ 0 or an asymmetric tensor (the message names it) or a non-unit quaternion;
/// MECH_STATUS_OUT_OF_RANGE when the total mass, centre or tensor overflows.
///
/// # Safety
/// `parts` (and, when non-NULL, `rotations` and `translations`) must point to `count` readable
/// values and `out` to a writable mech_mass_properties_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mass_combine(
    parts: *const mech_mass_properties_t,
    rotations: *const mech_quat_t,
    translations: *const mech_vec3_t,
    count: usize,
    out: *mut mech_mass_properties_t,
) -> mech_status_t {
    boundary(|| {
        if count == 0 {
            return Err(FfiError::new(MECH_STATUS_BAD_DIMENSION, "count is 0"));
        }
        // SAFETY: caller's contract.
        let raw = unsafe { read_slice(parts, count, "parts") }?;
        let out = Out::new(out, "out")?;
        let poses = match (rotations.is_null(), translations.is_null()) {
            (true, true) => None,
            (false, false) => {
                // SAFETY: caller's contract.
                let qs = unsafe { read_slice(rotations, count, "rotations") }?;
                // SAFETY: caller's contract.
                let ts = unsafe { read_slice(translations, count, "translations") }?;
                Some((qs, ts))
            }
            (true, false) => return Err(FfiError::new(MECH_STATUS_NULL_POINTER, "rotations is NULL")),
            (false, true) => return Err(FfiError::new(MECH_STATUS_NULL_POINTER, "translations is NULL")),
        };
        let mut placed = Vec::with_capacity(count);
        for (i, part) in raw.iter().enumerate() {
            // SAFETY: `part` is a reference into a slice we were given.
            let p = unsafe { read_properties(part, &format!("parts[{i}]")) }?;
            placed.push(match poses {
                Some((qs, ts)) => p.transformed(&pose(&qs[i], &ts[i])?),
                None => p,
            });
        }
        let sum = MassProperties::sum(&placed)?;
        // SAFETY: caller's contract.
        unsafe { out.write(sum.into()) };
        Ok(())
    })
}

/// The body `body` with the material `hole` (same frame) removed, written to `out`: the inverse
/// of mech_mass_combine.
///
/// Errors: MECH_STATUS_NON_FINITE; MECH_STATUS_INVALID_ARGUMENT for a mass ≤ 0, an asymmetric tensor or a hole at
/// least as heavy as the body; MECH_STATUS_NOT_POSITIVE_DEFINITE or
/// MECH_STATUS_INVALID_ARGUMENT when the remainder is not a valid body (a hole that does not fit
/// inside); MECH_STATUS_OUT_OF_RANGE when the remainder overflows.
///
/// # Safety
/// `body` and `hole` must be readable and `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mass_subtract(
    body: *const mech_mass_properties_t,
    hole: *const mech_mass_properties_t,
    out: *mut mech_mass_properties_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let (b, h) = unsafe { (read_properties(body, "body")?, read_properties(hole, "hole")?) };
        let out = Out::new(out, "out")?;
        let rest = b.subtract(&h)?;
        // SAFETY: caller's contract.
        unsafe { out.write(rest.into()) };
        Ok(())
    })
}
