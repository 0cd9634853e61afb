//! Loads that only the dynamics sees: Rayleigh dampers (FM 4.62–4.66) and charges in uniform
//! electromagnetic fields (a velocity-dependent potential, FM 4.90).

use super::{dynamics_mut, mech_dynamics_t};
use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::mechanism::anchor;
use crate::ffi::status::*;
use crate::ffi::types::mech_vec3_t;
use crate::ffi::validate::*;
use mechanica_dynamics::{ChargedPoint, Damper, UniformFields};
use std::sync::Arc;

/// Writes a new load's index to an optional `index_out`.
///
/// # Safety
/// A non-NULL `out` must be writable.
unsafe fn write_index(out: Option<Out<usize>>, index: usize) {
    if let Some(out) = out {
        // SAFETY: caller's contract.
        unsafe { out.write(index) };
    }
}

/// Fails with INVALID_ARGUMENT unless the damping coefficient is ≥ 0 (NON_FINITE for NaN, ±∞).
fn check_coefficient(c: f64) -> Result<(), FfiError> {
    finite(&c, "c")?;
    if c < 0.0 {
        return Err(FfiError::new(
            MECH_STATUS_INVALID_ARGUMENT,
            format!("the damping coefficient c must be ≥ 0, got {c}"),
        ));
    }
    Ok(())
}

/// Adds a damper on coordinate `coordinate`: the dissipation function D = ½ c q̇_k² and the
/// generalized force Q_k = −c q̇_k (c in N·m·s/rad for an angle, N·s/m for a length). Writes the
/// damper's index (0, 1, … in the order dampers are added) to `*index_out` (may be NULL).
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite c; MECH_STATUS_INVALID_ARGUMENT for
/// c < 0 or a coordinate ≥ n.
///
/// # Safety
/// `dynamics` must be a live handle; `index_out` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_dynamics_add_joint_damper(
    dynamics: *mut mech_dynamics_t,
    coordinate: usize,
    c: f64,
    index_out: *mut usize,
) -> mech_status_t {
    boundary(|| {
        let out = Out::optional(index_out, "index_out")?;
        // SAFETY: caller's contract.
        let d = unsafe { dynamics_mut(dynamics) }?;
        check_coefficient(c)?;
        let index = d.add_damper(Damper::Joint {
            coordinate,
            coefficient: c,
        })?;
        // SAFETY: caller's contract.
        unsafe { write_index(out, index) };
        Ok(())
    })
}

/// Adds a linear damper between the point `point_a` of body `body_a` and `point_b` of `body_b`
/// (body coordinates, m; MECH_GROUND and base-frame coordinates for the ground). With
/// v = ẋ_a − ẋ_b the relative velocity of the points: `axial` = 0 resists all of it,
/// D = ½ c |v|², force −c v on a and +c v on b (FM 4.62); `axial` = 1 only its component along
/// the line between the points, D = ½ c (e·v)² with e = (x_a − x_b)/|x_a − x_b| (a dashpot; an
/// evaluation where the points meet fails with MECH_STATUS_SINGULAR). c in N·s/m. Writes the
/// damper's index to `*index_out` (may be NULL).
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_INVALID_ARGUMENT for
/// c < 0, `axial` other than 0 or 1, a body index below MECH_GROUND or out of range.
///
/// # Safety
/// `dynamics` must be a live handle; `index_out` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_dynamics_add_point_damper(
    dynamics: *mut mech_dynamics_t,
    body_a: i64,
    point_a: mech_vec3_t,
    body_b: i64,
    point_b: mech_vec3_t,
    c: f64,
    axial: i32,
    index_out: *mut usize,
) -> mech_status_t {
    boundary(|| {
        let out = Out::optional(index_out, "index_out")?;
        // SAFETY: caller's contract.
        let d = unsafe { dynamics_mut(dynamics) }?;
        finite(&point_a, "point_a")?;
        finite(&point_b, "point_b")?;
        check_coefficient(c)?;
        let (a, b) = (anchor(body_a, point_a)?, anchor(body_b, point_b)?);
        let damper = match axial {
            0 => Damper::Points { a, b, coefficient: c },
            1 => Damper::Dashpot { a, b, coefficient: c },
            other => {
                return Err(FfiError::new(
                    MECH_STATUS_INVALID_ARGUMENT,
                    format!("axial must be 0 or 1, got {other}"),
                ));
            }
        };
        let index = d.add_damper(damper)?;
        // SAFETY: caller's contract.
        unsafe { write_index(out, index) };
        Ok(())
    })
}

/// Adds a charge `charge` (C) at the point `point` (body coordinates, m) of body `body`, in the
/// uniform static fields E = `electric` (V/m) and B = `magnetic` (T), base-frame components.
/// Its velocity-dependent potential U = e (φ − ẋ·𝐀) (FM 4.105, gauge φ = −E·x, 𝐀 = ½ B × x)
/// gives the Lorentz force e (E + ẋ × B) at the point, ẋ its velocity (with a rotating frame,
/// in the inertial frame that coincides with the base frame at the instant). Writes the potential's index (0, 1, … in the order charges are added) to
/// `*index_out` (may be NULL).
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_INVALID_ARGUMENT for
/// a body out of range.
///
/// # Safety
/// `dynamics` must be a live handle; `index_out` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_dynamics_add_charged_point(
    dynamics: *mut mech_dynamics_t,
    body: usize,
    point: mech_vec3_t,
    charge: f64,
    electric: mech_vec3_t,
    magnetic: mech_vec3_t,
    index_out: *mut usize,
) -> mech_status_t {
    boundary(|| {
        let out = Out::optional(index_out, "index_out")?;
        // SAFETY: caller's contract.
        let d = unsafe { dynamics_mut(dynamics) }?;
        finite(&point, "point")?;
        finite(&charge, "charge")?;
        finite(&electric, "electric")?;
        finite(&magnetic, "magnetic")?;
        let field = UniformFields {
            electric: electric.into(),
            magnetic: magnetic.into(),
        };
        let index = d.add_velocity_potential(ChargedPoint {
            body,
            point: point.into(),
            charge,
            field: Arc::new(field),
        })?;
        // SAFETY: caller's contract.
        unsafe { write_index(out, index) };
        Ok(())
    })
}
