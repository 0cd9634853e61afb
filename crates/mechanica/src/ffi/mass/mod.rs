//! C entry points of the mass-properties crate: primitives, composition, inertia queries,
//! momenta, validity, triangle meshes, and the mass matrix of a kinematic tree.

use super::boundary::FfiError;
use super::status::*;
use super::types::*;
use super::validate::*;
use mechanica_kinematics::nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};
use mechanica_kinematics::rotation::{self, QuaternionNorm};
use mechanica_mass::validity::InertiaIssue;
use mechanica_mass::{MassError, MassProperties};

mod composite;
mod inertia;
mod mesh;
mod momentum;
mod primitives;
mod tree;
mod validity;

pub use composite::*;
pub use inertia::*;
pub use mesh::*;
pub use momentum::*;
pub use primitives::*;
pub use tree::*;
pub use validity::*;

/// Mass properties of a body: mass (kg), centre of mass (m, in the body's reference frame) and
/// the inertia tensor about the centre of mass (kg·m², same frame).
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
        let status = match &error {
            MassError::NonFinite { .. } | MassError::NonFiniteVertex { .. } => MECH_STATUS_NON_FINITE,
            MassError::NonFiniteResult { .. } | MassError::MassUnderflow { .. } => MECH_STATUS_OUT_OF_RANGE,
            MassError::TooManyVertices(_) | MassError::TooManyTriangles(_) | MassError::WrongLength { .. } => {
                MECH_STATUS_BAD_DIMENSION
            }
            MassError::Kinematics(e) => return FfiError::from(e.clone()),
            MassError::Body { error: inner, .. } => FfiError::from((**inner).clone()).status,
            MassError::InvalidInertia(issues)
                if issues.iter().any(|i| {
                    matches!(
                        i,
                        InertiaIssue::NotPositiveSemidefinite { .. } | InertiaIssue::TriangleInequality { .. }
                    )
                }) =>
            {
                MECH_STATUS_NOT_POSITIVE_DEFINITE
            }
            MassError::Io(_) => MECH_STATUS_IO_ERROR,
            MassError::Parse(_) => MECH_STATUS_PARSE_ERROR,
            MassError::NonPositiveMass(_)
            | MassError::NonPositiveDensity(_)
            | MassError::NonPositiveDimension { .. }
            | MassError::InconsistentDimensions(_)
            | MassError::ZeroDirection(_)
            | MassError::NonPositiveTotalMass(_)
            | MassError::InvalidInertia(_)
            | MassError::EmptyMesh
            | MassError::IndexOutOfRange { .. }
            | MassError::DegenerateTriangles { .. }
            | MassError::OpenMesh { .. }
            | MassError::InconsistentOrientation { .. }
            | MassError::InsideOut { .. }
            | MassError::ZeroVolume { .. } => MECH_STATUS_INVALID_ARGUMENT,
            // A variant added after this layer was written: its message still says what was wrong.
            _ => MECH_STATUS_INVALID_ARGUMENT,
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

impl Finite for mech_mass_properties_t {
    fn first_non_finite(&self) -> Option<f64> {
        self.mass
            .first_non_finite()
            .or_else(|| self.center_of_mass.first_non_finite())
            .or_else(|| self.inertia_about_com.first_non_finite())
    }
}

/// The Rust value of C mass properties, without any check.
pub(crate) fn raw_properties(m: &mech_mass_properties_t) -> MassProperties {
    MassProperties {
        mass: m.mass,
        p_oc: m.center_of_mass.into(),
        inertia_c: Matrix3::from(m.inertia_about_com),
    }
}

/// Fails with NON_FINITE, naming `what.mass`, `what.center_of_mass` or `what.inertia_about_com`,
/// unless every number of `m` is finite.
pub(crate) fn check_finite_properties(m: &mech_mass_properties_t, what: &str) -> Result<(), FfiError> {
    finite(&m.mass, &format!("{what}.mass"))?;
    finite(&m.center_of_mass, &format!("{what}.center_of_mass"))?;
    finite(&m.inertia_about_com, &format!("{what}.inertia_about_com"))
}

/// Reads C mass properties for computation: every number finite, the mass positive and the
/// tensor symmetric within the validity tolerance |J_ij − J_ji| ≤ 1e-9·Σ|J_kk| (its other
/// properties are not checked; see mech_mass_check).
///
/// # Safety
/// A non-NULL, aligned `ptr` must point to a readable mech_mass_properties_t.
unsafe fn read_properties(ptr: *const mech_mass_properties_t, what: &str) -> Result<MassProperties, FfiError> {
    // SAFETY: caller's contract.
    let m = unsafe { read(ptr, what) }?;
    check_finite_properties(&m, what)?;
    if m.mass <= 0.0 {
        return Err(FfiError::new(
            MECH_STATUS_INVALID_ARGUMENT,
            format!("{what}.mass must be positive, got {}", m.mass),
        ));
    }
    let props = raw_properties(&m);
    mechanica_mass::principal::require_symmetric(&props.inertia_c)?;
    Ok(props)
}

/// A rigid motion from a unit quaternion (|‖q‖ − 1| ≤ 1e-12) and a translation.
fn pose(q: &mech_quat_t, t: &mech_vec3_t) -> Result<Isometry3<f64>, FfiError> {
    finite(q, "rotation")?;
    finite(t, "translation")?;
    let unit: UnitQuaternion<f64> = rotation::unit_quaternion(q.w, q.x, q.y, q.z, QuaternionNorm::RequireUnit)?;
    Ok(Isometry3::from_parts(Translation3::from(Vector3::from(*t)), unit))
}
