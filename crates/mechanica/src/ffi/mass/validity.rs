//! Whether mass properties could belong to a real body (issue flags and the body's class), and
//! the repair of a slightly invalid inertia tensor.

use super::{check_finite_properties, mech_mass_properties_t, raw_properties};
use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::status::*;
use crate::ffi::types::*;
use crate::ffi::validate::*;
use mechanica_kinematics::nalgebra::{Matrix3, Vector3};
use mechanica_kinematics::scaling::power_of_two_above;
use mechanica_mass::MassError;
use mechanica_mass::validity::{self, InertiaClass, InertiaIssue, ValidityTolerance};

/// Bit flags of mech_mass_validity_t.issues: what is wrong with mass properties.
pub type mech_mass_issue_t = u32;
/// The mass, centre or a tensor entry is NaN or infinite.
pub const MECH_MASS_ISSUE_NON_FINITE: mech_mass_issue_t = 1;
/// The mass is negative.
pub const MECH_MASS_ISSUE_NEGATIVE_MASS: mech_mass_issue_t = 2;
/// The mass is zero but the inertia is not.
pub const MECH_MASS_ISSUE_ZERO_MASS_WITH_INERTIA: mech_mass_issue_t = 4;
/// The tensor is not symmetric.
pub const MECH_MASS_ISSUE_NOT_SYMMETRIC: mech_mass_issue_t = 8;
/// The tensor has a negative eigenvalue.
pub const MECH_MASS_ISSUE_NOT_POSITIVE_SEMIDEFINITE: mech_mass_issue_t = 16;
/// The principal moments violate I₁ + I₂ ≥ I₃.
pub const MECH_MASS_ISSUE_TRIANGLE_INEQUALITY: mech_mass_issue_t = 32;

/// The kind of body valid mass properties describe.
pub type mech_inertia_class_t = i32;
/// Not valid (see the MECH_MASS_ISSUE_* flags in mech_mass_validity_t.issues).
pub const MECH_INERTIA_INVALID: mech_inertia_class_t = 0;
/// A body with extent in three directions (positive definite, strict triangle inequality).
pub const MECH_INERTIA_SOLID: mech_inertia_class_t = 1;
/// All mass in a plane: I₁ + I₂ = I₃ (laminae, flat shells).
pub const MECH_INERTIA_PLANAR: mech_inertia_class_t = 2;
/// All mass on a line: one zero moment (rods). Semidefinite and valid.
pub const MECH_INERTIA_LINEAR: mech_inertia_class_t = 3;
/// A point mass: zero central inertia. Valid.
pub const MECH_INERTIA_POINT: mech_inertia_class_t = 4;

/// The result of mech_mass_check.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_mass_validity_t {
    /// OR of MECH_MASS_ISSUE_* flags; 0 when the properties are valid.
    pub issues: mech_mass_issue_t,
    /// A mech_inertia_class_t: MECH_INERTIA_INVALID when `issues` ≠ 0.
    pub inertia_class: mech_inertia_class_t,
    /// Eigenvalues of the symmetric part of the tensor (kg·m²), ascending (zeros when
    /// non-finite).
    pub moments: mech_vec3_t,
}

/// The C class of a valid body.
fn class_to_c(class: InertiaClass) -> mech_inertia_class_t {
    match class {
        InertiaClass::Solid => MECH_INERTIA_SOLID,
        InertiaClass::Planar => MECH_INERTIA_PLANAR,
        InertiaClass::Linear => MECH_INERTIA_LINEAR,
        InertiaClass::Point => MECH_INERTIA_POINT,
    }
}

/// The C flag of an issue.
fn issue_to_c(issue: &InertiaIssue) -> mech_mass_issue_t {
    match issue {
        InertiaIssue::NonFinite { .. } => MECH_MASS_ISSUE_NON_FINITE,
        InertiaIssue::NegativeMass(_) => MECH_MASS_ISSUE_NEGATIVE_MASS,
        InertiaIssue::ZeroMassWithInertia => MECH_MASS_ISSUE_ZERO_MASS_WITH_INERTIA,
        InertiaIssue::NotSymmetric { .. } => MECH_MASS_ISSUE_NOT_SYMMETRIC,
        InertiaIssue::NotPositiveSemidefinite { .. } => MECH_MASS_ISSUE_NOT_POSITIVE_SEMIDEFINITE,
        InertiaIssue::TriangleInequality { .. } => MECH_MASS_ISSUE_TRIANGLE_INEQUALITY,
    }
}

/// Checks whether `properties` could belong to a real body and writes the verdict to
/// `validity_out`: every problem found as a flag, the class of a valid body and the moments
/// (the call itself succeeds whether or not the properties are valid). `relative_tolerance`
/// (≥ 0; 0 selects the default 1e-9) is relative to the trace of the tensor and decides
/// symmetry, semidefiniteness, the triangle inequality and the class (rods and laminae have
/// exact equalities, which the tolerance accepts).
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite `relative_tolerance`;
/// MECH_STATUS_INVALID_ARGUMENT for a negative one.
///
/// # Safety
/// `properties` must be readable and `validity_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mass_check(
    properties: *const mech_mass_properties_t,
    relative_tolerance: f64,
    validity_out: *mut mech_mass_validity_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let m = unsafe { read(properties, "properties") }?;
        let out = Out::new(validity_out, "validity_out")?;
        let tol = tolerance(relative_tolerance)?;
        let props = raw_properties(&m);
        let result = match validity::check(&props, &tol) {
            Ok(report) => mech_mass_validity_t {
                issues: 0,
                inertia_class: class_to_c(report.class),
                moments: report.moments.into(),
            },
            Err(MassError::InvalidInertia(issues)) => {
                let flags = issues.iter().fold(0, |flags, issue| flags | issue_to_c(issue));
                let moments =
                    symmetric_part_eigenvalues(&props.inertia_c).map_or_else(mech_vec3_t::default, Into::into);
                mech_mass_validity_t {
                    issues: flags,
                    inertia_class: MECH_INERTIA_INVALID,
                    moments,
                }
            }
            Err(other) => return Err(other.into()),
        };
        // SAFETY: caller's contract.
        unsafe { out.write(result) };
        Ok(())
    })
}

/// The eigenvalues of ½(J + Jᵀ), ascending, computed on J scaled by a power of two so that
/// entries near f64::MAX do not overflow the sum; None when J or an eigenvalue is not finite.
fn symmetric_part_eigenvalues(j: &Matrix3<f64>) -> Option<Vector3<f64>> {
    if !j.iter().all(|v| v.is_finite()) {
        return None;
    }
    let scale = power_of_two_above(j.amax());
    let scaled = j / scale;
    let mut l = ((scaled + scaled.transpose()) * 0.5).symmetric_eigenvalues() * scale;
    l.as_mut_slice().sort_by(f64::total_cmp);
    l.iter().all(|v| v.is_finite()).then_some(l)
}

/// The validity tolerance of a C `relative_tolerance` (0 selects the default).
fn tolerance(relative_tolerance: f64) -> Result<ValidityTolerance, FfiError> {
    finite(&relative_tolerance, "relative_tolerance")?;
    if relative_tolerance < 0.0 {
        return Err(FfiError::new(
            MECH_STATUS_INVALID_ARGUMENT,
            format!("relative_tolerance must be >= 0, got {relative_tolerance}"),
        ));
    }
    Ok(if relative_tolerance == 0.0 {
        ValidityTolerance::default()
    } else {
        ValidityTolerance {
            relative: relative_tolerance,
        }
    })
}

/// Repairs the tensor of `properties` when mech_mass_check finds it invalid, writing the result
/// to `out`: symmetrises it, clamps its principal second moments σ_k = (I_i + I_j − I_k)/2 to
/// ≥ 0 and rebuilds I_k = σ_i + σ_j (which restores semidefiniteness and the triangle
/// inequality). Valid input is copied unchanged. `relative_change_out` (may be NULL) receives
/// the size of the repair ‖ΔJ‖_F/‖J‖_F. `relative_tolerance` as in mech_mass_check.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input, which cannot be repaired;
/// MECH_STATUS_INVALID_ARGUMENT for a negative mass or `relative_tolerance`.
///
/// # Safety
/// `properties` must be readable, `out` writable, `relative_change_out` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mass_repair(
    properties: *const mech_mass_properties_t,
    relative_tolerance: f64,
    out: *mut mech_mass_properties_t,
    relative_change_out: *mut f64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let m = unsafe { read(properties, "properties") }?;
        let out = Out::new(out, "out")?;
        let change_out = Out::optional(relative_change_out, "relative_change_out")?;
        let tol = tolerance(relative_tolerance)?;
        check_finite_properties(&m, "properties")?;
        let (fixed, report) = validity::repair(&raw_properties(&m), &tol)?;
        // SAFETY: caller's contract.
        unsafe {
            out.write(fixed.into());
            if let Some(c) = change_out {
                c.write(report.relative_change);
            }
        }
        Ok(())
    })
}
