//! C entry points of the mass-properties crate.

use super::boundary::{FfiError, boundary};
use super::status::*;
use super::types::*;
use super::validate::*;
use mechanica_kinematics::nalgebra::{Matrix3, Vector3};
use mechanica_mass::{MassError, MassProperties};

/// Mass properties: mass (kg), centre of mass (m, in the body's reference frame) and the
/// inertia tensor about the centre of mass (kg·m², same frame).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_mass_properties_t {
    /// Total mass.
    pub mass: f64,
    /// Centre of mass.
    pub center_of_mass: mech_vec3_t,
    /// Inertia tensor about the centre of mass, column-major.
    pub inertia_about_com: mech_mat3_t,
}

impl From<MassError> for FfiError {
    fn from(error: MassError) -> Self {
        let status = match error {
            MassError::NonFinite { .. } => MECH_STATUS_NON_FINITE,
            MassError::NonPositiveMass(_) => MECH_STATUS_INVALID_ARGUMENT,
        };
        FfiError::new(status, error.to_string())
    }
}

impl From<MassProperties> for mech_mass_properties_t {
    fn from(m: MassProperties) -> Self {
        Self {
            mass: m.mass,
            center_of_mass: m.p_oc.into(),
            inertia_about_com: m.inertia_c.into(),
        }
    }
}

/// The mass properties of a point mass `mass` at `position` (zero central inertia).
///
/// # Safety
/// `position` must point to a readable mech_vec3_t and `out` to a writable mech_mass_properties_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mass_point(
    mass: f64,
    position: *const mech_vec3_t,
    out: *mut mech_mass_properties_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let p = unsafe { read(position, "position") }?;
        let out = Out::new(out, "out")?;
        let props = MassProperties::point(mass, Vector3::from(p))?;
        // SAFETY: caller's contract.
        unsafe { out.write(props.into()) };
        Ok(())
    })
}

/// The inertia tensor of `properties` about the point `point` (same frame), by Steiner's
/// theorem (syllabus 3.27–3.29).
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
        let (m, a) = unsafe { (read(properties, "properties")?, read(point, "point")?) };
        let out = Out::new(inertia_out, "inertia_out")?;
        finite(&m.mass, "properties.mass")?;
        finite(&m.center_of_mass, "properties.center_of_mass")?;
        finite(&m.inertia_about_com, "properties.inertia_about_com")?;
        finite(&a, "point")?;
        let mut props = MassProperties::point(m.mass, m.center_of_mass.into())?;
        props.inertia_c = Matrix3::from(m.inertia_about_com);
        let j = props.inertia_about(&Vector3::from(a));
        // SAFETY: caller's contract.
        unsafe { out.write(j.into()) };
        Ok(())
    })
}
