//! Inertia queries on one body: the tensor about a point, the moment about a line, and the
//! principal axes.

use super::{mech_mass_properties_t, read_properties};
use crate::ffi::boundary::boundary;
use crate::ffi::spatial::read_vec3;
use crate::ffi::status::*;
use crate::ffi::types::*;
use crate::ffi::validate::*;

/// The inertia tensor J_A (kg·m², column-major, same frame) of `properties` about the point
/// `point` (m), by Steiner's theorem J_A = J₀ + m(|d|² I − d dᵀ), d = x₀ − a (syllabus
/// 3.27–3.29), written to `inertia_out`.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_INVALID_ARGUMENT for
/// a mass ≤ 0 or a tensor not symmetric within 1e-9·Σ|J_kk|; MECH_STATUS_OUT_OF_RANGE when an entry of J_A overflows.
///
/// # Safety
/// `properties` and `point` must be readable and `inertia_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mass_inertia_about(
    properties: *const mech_mass_properties_t,
    point: *const mech_vec3_t,
    inertia_out: *mut mech_mat3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let (props, a) = unsafe { (read_properties(properties, "properties")?, read_vec3(point, "point")?) };
        let out = Out::new(inertia_out, "inertia_out")?;
        let j = props.inertia_about(&a);
        finite_result(j.as_slice(), "inertia tensor about the point")?;
        // SAFETY: caller's contract.
        unsafe { out.write(j.into()) };
        Ok(())
    })
}

/// The moment of inertia (e, J_A e) (kg·m²) of `properties` about the line through `point` (m)
/// with direction `direction` (any non-zero length; normalised internally), syllabus 3.22–3.23
/// and 3.30, written to `moment_out`.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_INVALID_ARGUMENT for
/// a mass ≤ 0, a tensor not symmetric within 1e-9·Σ|J_kk| or a zero direction.
///
/// # Safety
/// The inputs must be readable and `moment_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mass_moment_about_line(
    properties: *const mech_mass_properties_t,
    point: *const mech_vec3_t,
    direction: *const mech_vec3_t,
    moment_out: *mut f64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let props = unsafe { read_properties(properties, "properties") }?;
        // SAFETY: caller's contract.
        let (a, e) = unsafe { (read_vec3(point, "point")?, read_vec3(direction, "direction")?) };
        let out = Out::new(moment_out, "moment_out")?;
        let i = props.moment_about_line(&a, &e)?;
        // SAFETY: caller's contract.
        unsafe { out.write(i) };
        Ok(())
    })
}

/// The principal moments I₁ ≤ I₂ ≤ I₃ (kg·m²) of the central tensor of `properties`
/// (3.20–3.21) into `moments_out` (x, y, z = I₁, I₂, I₃) and the principal axes, in the frame of
/// `properties`, as the columns of a right-handed rotation matrix R (column-major) with
/// J = R diag(I) Rᵀ into `axes_out`. Repeated moments (relative gap ≤ 1e-10) give a canonical
/// frame: the identity for three equal moments; the exact symmetry axis and the coordinate axis
/// least aligned with it for two. The tensor must be symmetric within the validity tolerance,
/// |J_ij − J_ji| ≤ 1e-9·(|J_00| + |J_11| + |J_22|); its symmetric part is decomposed, scaled
/// by a power of two, so that any finite tensor whose moments are representable works. Its
/// other validity conditions are not checked (see mech_mass_check).
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite entry; MECH_STATUS_INVALID_ARGUMENT for
/// a mass ≤ 0 or a tensor outside the symmetry tolerance; MECH_STATUS_OUT_OF_RANGE when a
/// moment exceeds the largest double.
///
/// # Safety
/// `properties` must be readable and `moments_out`, `axes_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mass_principal_axes(
    properties: *const mech_mass_properties_t,
    moments_out: *mut mech_vec3_t,
    axes_out: *mut mech_mat3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let props = unsafe { read_properties(properties, "properties") }?;
        let moments = Out::new(moments_out, "moments_out")?;
        let axes = Out::new(axes_out, "axes_out")?;
        let p = props.principal_axes()?;
        // SAFETY: caller's contract.
        unsafe {
            moments.write(p.moments.into());
            axes.write((*p.r_fp.matrix()).into());
        }
        Ok(())
    })
}
