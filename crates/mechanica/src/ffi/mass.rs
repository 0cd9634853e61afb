//! C entry points of the mass-properties crate.

use super::boundary::{FfiError, boundary};
use super::kinematics::{built, mech_tree_t, tree_mut};
use super::status::*;
use super::types::*;
use super::validate::*;
use mechanica_kinematics::nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};
use mechanica_kinematics::rotation::{self, QuaternionNorm};
use mechanica_mass::mechanism::{DragField, EnergySplit, SplitBuffers, TreeMass};
use mechanica_mass::mesh::{
    DegeneratePolicy, InsideOutPolicy, MeshModel, MeshOptions, MeshTopology, OpenMeshPolicy, TopologySource,
};
use mechanica_mass::validity::{self, InertiaClass, InertiaIssue, ValidityTolerance};
use mechanica_mass::{Amount, MassError, MassProperties, primitives};

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
        let status = match &error {
            MassError::NonFinite { .. } | MassError::NonFiniteVertex { .. } => MECH_STATUS_NON_FINITE,
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

/// The Rust value of C mass properties, without any check.
fn raw_properties(m: &mech_mass_properties_t) -> MassProperties {
    MassProperties {
        mass: m.mass,
        p_oc: m.center_of_mass.into(),
        inertia_c: Matrix3::from(m.inertia_about_com),
    }
}

/// Reads C mass properties for computation: every number finite and the mass positive (the
/// tensor itself is not checked; see mech_mass_check).
///
/// # Safety
/// A non-NULL `ptr` must point to a readable mech_mass_properties_t.
unsafe fn read_properties(ptr: *const mech_mass_properties_t, what: &str) -> Result<MassProperties, FfiError> {
    // SAFETY: caller's contract.
    let m = unsafe { read(ptr, what) }?;
    finite(&m.mass, &format!("{what}.mass"))?;
    finite(&m.center_of_mass, &format!("{what}.center_of_mass"))?;
    finite(&m.inertia_about_com, &format!("{what}.inertia_about_com"))?;
    if m.mass <= 0.0 {
        return Err(FfiError::new(
            MECH_STATUS_INVALID_ARGUMENT,
            format!("{what}.mass must be positive, got {}", m.mass),
        ));
    }
    Ok(raw_properties(&m))
}

/// Reads a finite vector.
///
/// # Safety
/// A non-NULL `ptr` must point to a readable mech_vec3_t.
unsafe fn read_vec3(ptr: *const mech_vec3_t, what: &str) -> Result<Vector3<f64>, FfiError> {
    // SAFETY: caller's contract.
    let v = unsafe { read(ptr, what) }?;
    finite(&v, what)?;
    Ok(v.into())
}

/// A rigid motion from a unit quaternion (|‖q‖ − 1| ≤ 1e-12) and a translation.
fn pose(q: &mech_quat_t, t: &mech_vec3_t) -> Result<Isometry3<f64>, FfiError> {
    finite(q, "rotation")?;
    finite(t, "translation")?;
    let unit: UnitQuaternion<f64> = rotation::unit_quaternion(q.w, q.x, q.y, q.z, QuaternionNorm::RequireUnit)?;
    Ok(Isometry3::from_parts(Translation3::from(Vector3::from(*t)), unit))
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
        let (props, a) = unsafe { (read_properties(properties, "properties")?, read_vec3(point, "point")?) };
        let out = Out::new(inertia_out, "inertia_out")?;
        let j = props.inertia_about(&a);
        // SAFETY: caller's contract.
        unsafe { out.write(j.into()) };
        Ok(())
    })
}

/// Kinds of primitive bodies for mech_mass_primitive. Each lists its `dimensions` (metres) and
/// the frame it is built in; "centred" means the origin is the centre of mass.
pub type mech_primitive_t = i32;
/// Point mass at the origin; 0 dimensions.
pub const MECH_PRIMITIVE_POINT: mech_primitive_t = 0;
/// Thin rod along z, centred; {length}; density per metre.
pub const MECH_PRIMITIVE_ROD: mech_primitive_t = 1;
/// Rectangular lamina in the xy plane, centred; {size_x, size_y}; density per m².
pub const MECH_PRIMITIVE_RECTANGLE_LAMINA: mech_primitive_t = 2;
/// Disc lamina in the xy plane, centred; {radius}; density per m².
pub const MECH_PRIMITIVE_DISC_LAMINA: mech_primitive_t = 3;
/// Solid sphere, centred; {radius}.
pub const MECH_PRIMITIVE_SPHERE: mech_primitive_t = 4;
/// Solid ellipsoid, centred; {semi-axis x, semi-axis y, semi-axis z}.
pub const MECH_PRIMITIVE_ELLIPSOID: mech_primitive_t = 5;
/// Solid box, centred; {size_x, size_y, size_z}.
pub const MECH_PRIMITIVE_BOX: mech_primitive_t = 6;
/// Solid cylinder along z, centred; {radius, height}.
pub const MECH_PRIMITIVE_CYLINDER: mech_primitive_t = 7;
/// Solid cone, base centre at the origin, apex at (0, 0, height); {radius, height}.
pub const MECH_PRIMITIVE_CONE: mech_primitive_t = 8;
/// Solid capsule along z, centred; {radius, cylinder length}.
pub const MECH_PRIMITIVE_CAPSULE: mech_primitive_t = 9;
/// Solid torus around z, centred; {ring radius, tube radius ≤ ring radius}.
pub const MECH_PRIMITIVE_TORUS: mech_primitive_t = 10;
/// Solid hemisphere, flat face centred at the origin, dome towards +z; {radius}.
pub const MECH_PRIMITIVE_HEMISPHERE: mech_primitive_t = 11;

/// How the `amount` argument of mech_mass_primitive and mech_mass_mesh is read.
pub type mech_amount_t = i32;
/// `amount` is the total mass in kg.
pub const MECH_AMOUNT_MASS: mech_amount_t = 0;
/// `amount` is the density: kg/m for rods, kg/m² for laminae and shells, kg/m³ for solids.
pub const MECH_AMOUNT_DENSITY: mech_amount_t = 1;

#[derive(Clone, Copy)]
enum Primitive {
    Point,
    Rod,
    RectangleLamina,
    DiscLamina,
    Sphere,
    Ellipsoid,
    Box,
    Cylinder,
    Cone,
    Capsule,
    Torus,
    Hemisphere,
}

impl CEnum for Primitive {
    fn from_c(raw: i32) -> Option<Self> {
        Some(match raw {
            MECH_PRIMITIVE_POINT => Self::Point,
            MECH_PRIMITIVE_ROD => Self::Rod,
            MECH_PRIMITIVE_RECTANGLE_LAMINA => Self::RectangleLamina,
            MECH_PRIMITIVE_DISC_LAMINA => Self::DiscLamina,
            MECH_PRIMITIVE_SPHERE => Self::Sphere,
            MECH_PRIMITIVE_ELLIPSOID => Self::Ellipsoid,
            MECH_PRIMITIVE_BOX => Self::Box,
            MECH_PRIMITIVE_CYLINDER => Self::Cylinder,
            MECH_PRIMITIVE_CONE => Self::Cone,
            MECH_PRIMITIVE_CAPSULE => Self::Capsule,
            MECH_PRIMITIVE_TORUS => Self::Torus,
            MECH_PRIMITIVE_HEMISPHERE => Self::Hemisphere,
            _ => return None,
        })
    }
}

impl Primitive {
    fn dimension_count(self) -> usize {
        match self {
            Self::Point => 0,
            Self::Rod | Self::DiscLamina | Self::Sphere | Self::Hemisphere => 1,
            Self::RectangleLamina | Self::Cylinder | Self::Cone | Self::Capsule | Self::Torus => 2,
            Self::Ellipsoid | Self::Box => 3,
        }
    }

    fn build(self, d: &[f64], amount: Amount) -> Result<MassProperties, MassError> {
        match self {
            Self::Point => primitives::point(amount),
            Self::Rod => primitives::rod(d[0], amount),
            Self::RectangleLamina => primitives::rectangle_lamina(d[0], d[1], amount),
            Self::DiscLamina => primitives::disc_lamina(d[0], amount),
            Self::Sphere => primitives::sphere(d[0], amount),
            Self::Ellipsoid => primitives::ellipsoid(d[0], d[1], d[2], amount),
            Self::Box => primitives::solid_box(d[0], d[1], d[2], amount),
            Self::Cylinder => primitives::cylinder(d[0], d[1], amount),
            Self::Cone => primitives::cone(d[0], d[1], amount),
            Self::Capsule => primitives::capsule(d[0], d[1], amount),
            Self::Torus => primitives::torus(d[0], d[1], amount),
            Self::Hemisphere => primitives::hemisphere(d[0], amount),
        }
    }
}

#[derive(Clone, Copy)]
enum AmountKind {
    Mass,
    Density,
}

impl CEnum for AmountKind {
    fn from_c(raw: i32) -> Option<Self> {
        match raw {
            MECH_AMOUNT_MASS => Some(Self::Mass),
            MECH_AMOUNT_DENSITY => Some(Self::Density),
            _ => None,
        }
    }
}

fn amount_of(kind: mech_amount_t, value: f64) -> Result<Amount, FfiError> {
    let kind: AmountKind = enum_value(kind, "amount_kind")?;
    finite(&value, "amount")?;
    Ok(match kind {
        AmountKind::Mass => Amount::Mass(value),
        AmountKind::Density => Amount::Density(value),
    })
}

/// The closed-form mass properties of a primitive body `kind` (a mech_primitive_t) with
/// `dimension_count` dimensions at `dimensions` (as listed for each MECH_PRIMITIVE_* value),
/// and `amount` read as a mass or a density according to `amount_kind` (a mech_amount_t).
/// Rods, laminae and points have semidefinite inertia, which is valid.
///
/// Errors: BAD_ENUM for unknown `kind` or `amount_kind`, BAD_DIMENSION when
/// `dimension_count` is not the count of `kind`, NON_FINITE, INVALID_ARGUMENT for a
/// non-positive dimension, mass or density, or a torus tube radius above its ring radius.
///
/// # Safety
/// `dimensions` must point to `dimension_count` readable doubles (it may be NULL when the count
/// is 0) and `out` to a writable mech_mass_properties_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mass_primitive(
    kind: mech_primitive_t,
    dimensions: *const f64,
    dimension_count: usize,
    amount_kind: mech_amount_t,
    amount: f64,
    out: *mut mech_mass_properties_t,
) -> mech_status_t {
    boundary(|| {
        let kind: Primitive = enum_value(kind, "kind")?;
        // SAFETY: caller's contract.
        let dims = unsafe { read_slice(dimensions, dimension_count, "dimensions") }?;
        let out = Out::new(out, "out")?;
        if dims.len() != kind.dimension_count() {
            return Err(FfiError::new(
                MECH_STATUS_BAD_DIMENSION,
                format!(
                    "dimension_count is {}, this primitive takes {}",
                    dims.len(),
                    kind.dimension_count()
                ),
            ));
        }
        finite(dims, "dimensions")?;
        let props = kind.build(dims, amount_of(amount_kind, amount)?)?;
        // SAFETY: caller's contract.
        unsafe { out.write(props.into()) };
        Ok(())
    })
}

/// The same body after the rigid motion x ↦ R x + t with R from the unit quaternion
/// `rotation` (|‖q‖ − 1| ≤ 1e-12) and t = `translation`: the centre moves, the tensor becomes
/// R J Rᵀ. Equivalently, re-expresses properties given in a body frame B in the frame F in
/// which B has this pose.
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
        // SAFETY: caller's contract.
        unsafe { out.write(moved.into()) };
        Ok(())
    })
}

/// The mass properties of the union of `count` ≥ 1 bodies: body i is `parts[i]` moved by the
/// rigid motion (`rotations[i]`, `translations[i]`) as in mech_mass_transform. Pass NULL for
/// both `rotations` and `translations` when the parts are already in one frame (passing only one
/// of them NULL is an error). Steiner's theorem (3.27–3.29) sums the tensors about the common
/// centre.
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

/// The body `body` with the material `hole` (same frame) removed. Fails with
/// INVALID_ARGUMENT when the hole is at least as heavy as the body, and with
/// NOT_POSITIVE_DEFINITE or INVALID_ARGUMENT when the remainder is not a valid body (a hole
/// that does not fit inside).
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

/// The moment of inertia (e, J_A e) about the line through `point` with direction `direction`
/// (any non-zero length; normalised internally), syllabus 3.22–3.23 and 3.30.
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

/// Principal moments I₁ ≤ I₂ ≤ I₃ of the central tensor (3.20–3.21) and the principal axes as
/// the columns of a right-handed rotation matrix R (column-major) with J = R diag(I) Rᵀ.
/// Repeated moments (relative gap ≤ 1e-10) give a canonical frame: the identity for three equal
/// moments; the exact symmetry axis and the coordinate axis least aligned with it for two.
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
/// Not valid (see the issue flags).
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
    /// Eigenvalues of the symmetric part of the tensor, ascending (zeros when non-finite).
    pub moments: mech_vec3_t,
}

/// Checks whether `properties` could belong to a real body, and reports every problem found
/// as flags (the call itself succeeds whether or not they are valid). `relative_tolerance`
/// (≥ 0; 0 selects the default 1e-9) is relative to the trace of the tensor and decides
/// symmetry, semidefiniteness, the triangle inequality and the class (rods and laminae have
/// exact equalities, which the tolerance accepts).
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
                inertia_class: match report.class {
                    InertiaClass::Solid => MECH_INERTIA_SOLID,
                    InertiaClass::Planar => MECH_INERTIA_PLANAR,
                    InertiaClass::Linear => MECH_INERTIA_LINEAR,
                    InertiaClass::Point => MECH_INERTIA_POINT,
                },
                moments: report.moments.into(),
            },
            Err(MassError::InvalidInertia(issues)) => {
                let mut flags = 0;
                for issue in &issues {
                    flags |= match issue {
                        InertiaIssue::NonFinite { .. } => MECH_MASS_ISSUE_NON_FINITE,
                        InertiaIssue::NegativeMass(_) => MECH_MASS_ISSUE_NEGATIVE_MASS,
                        InertiaIssue::ZeroMassWithInertia => MECH_MASS_ISSUE_ZERO_MASS_WITH_INERTIA,
                        InertiaIssue::NotSymmetric { .. } => MECH_MASS_ISSUE_NOT_SYMMETRIC,
                        InertiaIssue::NotPositiveSemidefinite { .. } => MECH_MASS_ISSUE_NOT_POSITIVE_SEMIDEFINITE,
                        InertiaIssue::TriangleInequality { .. } => MECH_MASS_ISSUE_TRIANGLE_INEQUALITY,
                    };
                }
                let moments = if props.inertia_c.iter().all(|v| v.is_finite()) {
                    let mut l = ((props.inertia_c + props.inertia_c.transpose()) * 0.5).symmetric_eigenvalues();
                    l.as_mut_slice().sort_by(f64::total_cmp);
                    l.into()
                } else {
                    mech_vec3_t::default()
                };
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

/// Repairs the tensor of `properties` when mech_mass_check finds it invalid: symmetrises it,
/// clamps its principal second moments σ_k = (I_i + I_j − I_k)/2 to ≥ 0 and rebuilds
/// I_k = σ_i + σ_j (which restores semidefiniteness and the triangle inequality). Valid input is
/// copied unchanged. `relative_change_out` (may be NULL) receives ‖ΔJ‖_F/‖J‖_F. A non-finite
/// value or a negative mass cannot be repaired (INVALID_ARGUMENT / NON_FINITE).
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
        let change_out = if relative_change_out.is_null() {
            None
        } else {
            Some(Out::new(relative_change_out, "relative_change_out")?)
        };
        let tol = tolerance(relative_tolerance)?;
        finite(&m.mass, "properties.mass")?;
        finite(&m.center_of_mass, "properties.center_of_mass")?;
        finite(&m.inertia_about_com, "properties.inertia_about_com")?;
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

/// The angular momentum D_A = J₀ ω + (x₀ − a) × m v₀ (syllabus 3.5–3.7) about the point `point`
/// (fixed or moving; only its position enters) of a body whose properties are given in the
/// inertial frame at this instant, moving with centre velocity `com_velocity` and angular
/// velocity `omega` (both in that frame).
///
/// # Safety
/// The inputs must be readable and `angular_momentum_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mass_angular_momentum(
    properties: *const mech_mass_properties_t,
    point: *const mech_vec3_t,
    com_velocity: *const mech_vec3_t,
    omega: *const mech_vec3_t,
    angular_momentum_out: *mut mech_vec3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let props = unsafe { read_properties(properties, "properties") }?;
        // SAFETY: caller's contract.
        let (a, v, w) = unsafe {
            (
                read_vec3(point, "point")?,
                read_vec3(com_velocity, "com_velocity")?,
                read_vec3(omega, "omega")?,
            )
        };
        let out = Out::new(angular_momentum_out, "angular_momentum_out")?;
        let d = props.angular_momentum_about(&a, &v, &w);
        // SAFETY: caller's contract.
        unsafe { out.write(d.into()) };
        Ok(())
    })
}

/// The kinetic energy T = ½ m v₀·v₀ + ½ ω·J₀ ω (syllabus 3.37) and the momentum p = m v₀ (3.4)
/// of a body moving with centre velocity `com_velocity` and angular velocity `omega` (in the
/// frame of the properties). `momentum_out` may be NULL.
///
/// # Safety
/// The inputs must be readable, `energy_out` writable, `momentum_out` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mass_kinetic_energy(
    properties: *const mech_mass_properties_t,
    com_velocity: *const mech_vec3_t,
    omega: *const mech_vec3_t,
    energy_out: *mut f64,
    momentum_out: *mut mech_vec3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let props = unsafe { read_properties(properties, "properties") }?;
        // SAFETY: caller's contract.
        let (v, w) = unsafe { (read_vec3(com_velocity, "com_velocity")?, read_vec3(omega, "omega")?) };
        let energy = Out::new(energy_out, "energy_out")?;
        let momentum = if momentum_out.is_null() {
            None
        } else {
            Some(Out::new(momentum_out, "momentum_out")?)
        };
        let t = props.kinetic_energy(&v, &w);
        if !t.is_finite() {
            return Err(FfiError::new(
                MECH_STATUS_NON_FINITE,
                format!("kinetic energy overflows: {t}"),
            ));
        }
        // SAFETY: caller's contract.
        unsafe {
            energy.write(t);
            if let Some(p) = momentum {
                p.write(props.linear_momentum(&v).into());
            }
        }
        Ok(())
    })
}

/// The mass model of a mesh.
pub type mech_mesh_model_t = i32;
/// A closed surface bounding a solid of uniform volume density.
pub const MECH_MESH_SOLID: mech_mesh_model_t = 0;
/// A thin shell with uniform surface density (kg/m²).
pub const MECH_MESH_SHELL: mech_mesh_model_t = 1;

/// What to do with an open mesh under MECH_MESH_SOLID.
pub type mech_open_mesh_t = i32;
/// Fail with MECH_STATUS_INVALID_ARGUMENT (the message gives the boundary-edge count).
pub const MECH_OPEN_MESH_REJECT: mech_open_mesh_t = 0;
/// Fall back to the shell model; a density amount is then read as kg/m².
pub const MECH_OPEN_MESH_SHELL: mech_open_mesh_t = 1;

/// What to do with an inside-out closed mesh (negative signed volume).
pub type mech_inside_out_t = i32;
/// Reverse the orientation and report `flipped` = 1.
pub const MECH_INSIDE_OUT_FLIP: mech_inside_out_t = 0;
/// Fail with MECH_STATUS_INVALID_ARGUMENT.
pub const MECH_INSIDE_OUT_REJECT: mech_inside_out_t = 1;

/// What to do with degenerate triangles (repeated indices or zero area).
pub type mech_degenerate_t = i32;
/// Count them in the report and leave them out of the integrals.
pub const MECH_DEGENERATE_SKIP: mech_degenerate_t = 0;
/// Fail with MECH_STATUS_INVALID_ARGUMENT.
pub const MECH_DEGENERATE_REJECT: mech_degenerate_t = 1;

/// Options of mech_mass_mesh. All zeros is the default: solid, reject open meshes, flip
/// inside-out meshes, skip degenerate triangles.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_mesh_options_t {
    /// A mech_mesh_model_t.
    pub model: mech_mesh_model_t,
    /// A mech_open_mesh_t.
    pub open_mesh: mech_open_mesh_t,
    /// A mech_inside_out_t.
    pub inside_out: mech_inside_out_t,
    /// A mech_degenerate_t.
    pub degenerate: mech_degenerate_t,
}

/// What mech_mass_mesh found and how accurate its integrals are.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_mesh_report_t {
    /// The model used (a mech_mesh_model_t; an open solid may fall back to a shell).
    pub model: mech_mesh_model_t,
    /// 1 when an inside-out mesh was reversed, else 0.
    pub flipped: i32,
    /// Volume (m³) for a solid, area (m²) for a shell.
    pub measure: f64,
    /// Bound on the relative rounding error of `measure`.
    pub relative_error_bound: f64,
    /// Number of triangles given.
    pub triangles: usize,
    /// Triangles skipped as degenerate.
    pub degenerate_triangles: usize,
    /// Edges used by one triangle only.
    pub boundary_edges: usize,
    /// Edges used by more than two triangles.
    pub non_manifold_edges: usize,
    /// Edges used twice in the same direction.
    pub misoriented_edges: usize,
}

macro_rules! c_enum {
    ($rust:ty, $($c:ident => $v:expr),+) => {
        impl CEnum for $rust {
            fn from_c(raw: i32) -> Option<Self> {
                match raw {
                    $($c => Some($v),)+
                    _ => None,
                }
            }
        }
    };
}
c_enum!(MeshModel, MECH_MESH_SOLID => MeshModel::Solid, MECH_MESH_SHELL => MeshModel::Shell);
c_enum!(OpenMeshPolicy, MECH_OPEN_MESH_REJECT => OpenMeshPolicy::Reject, MECH_OPEN_MESH_SHELL => OpenMeshPolicy::Shell);
c_enum!(InsideOutPolicy, MECH_INSIDE_OUT_FLIP => InsideOutPolicy::Flip, MECH_INSIDE_OUT_REJECT => InsideOutPolicy::Reject);
c_enum!(DegeneratePolicy, MECH_DEGENERATE_SKIP => DegeneratePolicy::Skip, MECH_DEGENERATE_REJECT => DegeneratePolicy::Reject);

/// Mass properties of the triangle mesh with `vertex_count` vertices (x, y, z interleaved:
/// 3·vertex_count doubles, metres) and `triangle_count` triangles (3·triangle_count vertex
/// indices, counter-clockwise seen from outside), with `amount` read as a mass or a density per
/// `amount_kind`. Closed solids use exact polynomial volume integrals relative to a point near
/// the mesh, so far-from-origin meshes keep full accuracy. `options` may be NULL for the
/// defaults; `report_out` may be NULL.
///
/// Errors: NULL_POINTER, BAD_DIMENSION (0 triangles, sizes overflowing), BAD_ENUM,
/// NON_FINITE (a vertex; the message names it), INVALID_ARGUMENT (index out of range, open,
/// misoriented, inside-out or degenerate meshes under rejecting policies, zero volume,
/// non-positive density or mass; the message says which and how many).
///
/// # Safety
/// `vertices` must point to 3·vertex_count readable doubles, `indices` to 3·triangle_count
/// readable uint32_t, `options` NULL or readable, `out` writable, `report_out` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mass_mesh(
    vertices: *const f64,
    vertex_count: usize,
    indices: *const u32,
    triangle_count: usize,
    amount_kind: mech_amount_t,
    amount: f64,
    options: *const mech_mesh_options_t,
    out: *mut mech_mass_properties_t,
    report_out: *mut mech_mesh_report_t,
) -> mech_status_t {
    // SAFETY: the caller's contract is mesh_call's.
    unsafe {
        mesh_call(
            vertices,
            vertex_count,
            indices,
            triangle_count,
            amount_kind,
            amount,
            options,
            None,
            out,
            report_out,
        )
    }
}

/// As mech_mass_mesh, for a mesh whose vertices moved since an earlier call on the same
/// triangle array (a deforming body re-integrated every step): the edge-topology check, about
/// 60 % of the time of a large mesh, is skipped and its result taken from `earlier`, the
/// report of that call (its `triangles` must equal `triangle_count`). The caller vouches that
/// the triangles are unchanged; indices are still checked and an inside-out mesh is still
/// flipped or refused.
///
/// Errors: as mech_mass_mesh; NULL_POINTER when `earlier` is NULL; BAD_DIMENSION when its
/// triangle count differs.
///
/// # Safety
/// As mech_mass_mesh; `earlier` must point to a readable mech_mesh_report_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mass_mesh_same_connectivity(
    vertices: *const f64,
    vertex_count: usize,
    indices: *const u32,
    triangle_count: usize,
    amount_kind: mech_amount_t,
    amount: f64,
    options: *const mech_mesh_options_t,
    earlier: *const mech_mesh_report_t,
    out: *mut mech_mass_properties_t,
    report_out: *mut mech_mesh_report_t,
) -> mech_status_t {
    // SAFETY: the caller's contract is mesh_call's.
    unsafe {
        mesh_call(
            vertices,
            vertex_count,
            indices,
            triangle_count,
            amount_kind,
            amount,
            options,
            Some(earlier),
            out,
            report_out,
        )
    }
}

/// The body of mech_mass_mesh and mech_mass_mesh_same_connectivity; `earlier` is the report
/// whose topology is reused, if any.
///
/// # Safety
/// As mech_mass_mesh; `earlier`, when given, readable.
unsafe fn mesh_call(
    vertices: *const f64,
    vertex_count: usize,
    indices: *const u32,
    triangle_count: usize,
    amount_kind: mech_amount_t,
    amount: f64,
    options: *const mech_mesh_options_t,
    earlier: Option<*const mech_mesh_report_t>,
    out: *mut mech_mass_properties_t,
    report_out: *mut mech_mesh_report_t,
) -> mech_status_t {
    boundary(|| {
        if triangle_count == 0 {
            return Err(FfiError::new(MECH_STATUS_BAD_DIMENSION, "triangle_count is 0"));
        }
        let times3 = |n: usize, what: &str| {
            n.checked_mul(3)
                .ok_or_else(|| FfiError::new(MECH_STATUS_BAD_DIMENSION, format!("{what}: 3·{n} overflows")))
        };
        // SAFETY: caller's contract.
        let flat_v = unsafe { read_slice(vertices, times3(vertex_count, "vertex_count")?, "vertices") }?;
        // SAFETY: caller's contract.
        let flat_i = unsafe { read_slice(indices, times3(triangle_count, "triangle_count")?, "indices") }?;
        let opts = if options.is_null() {
            mech_mesh_options_t::default()
        } else {
            // SAFETY: caller's contract.
            unsafe { read(options, "options") }?
        };
        let out = Out::new(out, "out")?;
        let report = if report_out.is_null() {
            None
        } else {
            Some(Out::new(report_out, "report_out")?)
        };
        let topology = match earlier {
            None => TopologySource::Check,
            Some(ptr) => {
                // SAFETY: caller's contract.
                let e = unsafe { read(ptr, "earlier") }?;
                if e.triangles != triangle_count {
                    return Err(FfiError::new(
                        MECH_STATUS_BAD_DIMENSION,
                        format!(
                            "earlier report is for {} triangles, this call has {triangle_count}",
                            e.triangles
                        ),
                    ));
                }
                TopologySource::Known(MeshTopology {
                    boundary_edges: e.boundary_edges,
                    non_manifold_edges: e.non_manifold_edges,
                    misoriented_edges: e.misoriented_edges,
                })
            }
        };
        let options = MeshOptions {
            model: enum_value(opts.model, "options.model")?,
            open_mesh: enum_value(opts.open_mesh, "options.open_mesh")?,
            inside_out: enum_value(opts.inside_out, "options.inside_out")?,
            degenerate: enum_value(opts.degenerate, "options.degenerate")?,
            topology,
        };
        let amount = amount_of(amount_kind, amount)?;
        let (verts, _) = flat_v.as_chunks::<3>();
        let (tris, _) = flat_i.as_chunks::<3>();
        let r = mechanica_mass::mesh_mass_properties(verts, tris, amount, &options)?;
        let d = r.diagnostics;
        let rep = mech_mesh_report_t {
            model: match r.model {
                MeshModel::Solid => MECH_MESH_SOLID,
                MeshModel::Shell => MECH_MESH_SHELL,
            },
            flipped: i32::from(d.flipped),
            measure: r.measure,
            relative_error_bound: r.relative_error_bound,
            triangles: d.triangles,
            degenerate_triangles: d.degenerate_triangles,
            boundary_edges: d.topology.boundary_edges,
            non_manifold_edges: d.topology.non_manifold_edges,
            misoriented_edges: d.topology.misoriented_edges,
        };
        // SAFETY: caller's contract.
        unsafe {
            out.write(r.properties.into());
            if let Some(o) = report {
                o.write(rep);
            }
        }
        Ok(())
    })
}

/// The kinetic energy of a tree on a moving base split by powers of q̇ (syllabus 9.7–9.10).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_energy_split_t {
    /// T₀ = ½∫ρ|∂x/∂t|² dV: the energy of the base motion alone (J).
    pub t0: f64,
    /// T₁ = b·q̇ with b_k = ∫ρ ∂x/∂t·∂x/∂q_k dV (J).
    pub t1: f64,
    /// T₂ = ½ q̇ᵀ A q̇ (J).
    pub t2: f64,
    /// T = T₀ + T₁ + T₂ (J).
    pub total: f64,
}

impl From<EnergySplit> for mech_energy_split_t {
    fn from(s: EnergySplit) -> Self {
        Self {
            t0: s.t0,
            t1: s.t1,
            t2: s.t2,
            total: s.total(),
        }
    }
}

/// The per-body mass properties of a finalized tree with positions set (`bodies`: one entry per
/// body, `body_count` of them), as the recursion's state, and the tree's dof.
///
/// # Safety
/// `tree` must be a live handle; `bodies` must point to `body_count` readable entries.
unsafe fn tree_mass<'a>(
    tree: *mut mech_tree_t,
    bodies: *const mech_mass_properties_t,
    body_count: usize,
) -> Result<
    (
        TreeMass,
        &'a mechanica_kinematics::tree::KinematicTree,
        &'a mechanica_kinematics::tree::Workspace,
    ),
    FfiError,
> {
    // SAFETY: caller's contract.
    let t = unsafe { tree_mut(tree) }?;
    // SAFETY: caller's contract.
    let raw = unsafe { read_slice(bodies, body_count, "bodies") }?;
    let (kt, ws) = built(t)?;
    let props = raw.iter().map(raw_properties).collect();
    let mass = TreeMass::new(kt, props)?;
    Ok((mass, kt, ws))
}

/// Fails with BAD_DIMENSION unless the caller's `n` is the tree's dof.
fn check_dof(n: usize, dof: usize, what: &str) -> Result<(), FfiError> {
    if n == dof {
        Ok(())
    } else {
        Err(FfiError::new(
            MECH_STATUS_BAD_DIMENSION,
            format!("{what}: n = {n}, but the tree has {dof} coordinates"),
        ))
    }
}

/// The mass matrix A(q) = [α_kl] (syllabus 8.28) of a finalized tree at the coordinates of the
/// last mech_tree_set_state, by the composite-rigid-body recursion, into `a_out` (n×n doubles,
/// column-major, n = dof). `bodies` holds one mass-properties value per body (`body_count` =
/// the tree's body count), each in its own body frame; masses may be 0 (massless links).
///
/// Errors: NULL_POINTER; BAD_DIMENSION (n ≠ dof, n = 0, body_count ≠ body count); NON_FINITE
/// or INVALID_ARGUMENT (a body's numbers or negative mass; the message names the body);
/// INVALID_ARGUMENT (tree not finalized or no state set).
///
/// # Safety
/// `tree` must be a live handle; `bodies` must point to `body_count` readable entries; `a_out`
/// to n·n writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_mass_matrix(
    tree: *mut mech_tree_t,
    bodies: *const mech_mass_properties_t,
    body_count: usize,
    a_out: *mut f64,
    n: usize,
) -> mech_status_t {
    boundary(|| {
        let len = square_len(n, "n")?;
        let dest = OutSlice::new(a_out, len, "a_out")?;
        // SAFETY: caller's contract.
        let (mut mass, kt, ws) = unsafe { tree_mass(tree, bodies, body_count) }?;
        check_dof(n, kt.dof(), "a_out")?;
        let mut a = vec![0.0; len];
        mass.mass_matrix(kt, ws, &mut a)?;
        // SAFETY: caller's contract.
        unsafe { dest.write(&a) };
        Ok(())
    })
}

/// The kinetic energy T = ½ q̇ᵀ A q̇ (syllabus 8.27) and the generalized momenta ∂T/∂q̇ = A q̇
/// (`momenta_out`, n = dof doubles) of a tree on a fixed base, at the state (q, q̇) of the last
/// mech_tree_set_state. `bodies` as in mech_tree_mass_matrix. For a moving base use
/// mech_tree_energy_split.
///
/// Errors: as mech_tree_mass_matrix (n = dof is required; n = 0 is accepted for a tree without
/// coordinates).
///
/// # Safety
/// `tree` must be a live handle; `bodies` must point to `body_count` readable entries;
/// `energy_out` writable; `momenta_out` must point to n writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_kinetic_energy(
    tree: *mut mech_tree_t,
    bodies: *const mech_mass_properties_t,
    body_count: usize,
    energy_out: *mut f64,
    momenta_out: *mut f64,
    n: usize,
) -> mech_status_t {
    boundary(|| {
        let e_out = Out::new(energy_out, "energy_out")?;
        let p_out = OutSlice::new(momenta_out, n, "momenta_out")?;
        // SAFETY: caller's contract.
        let (mut mass, kt, ws) = unsafe { tree_mass(tree, bodies, body_count) }?;
        check_dof(n, kt.dof(), "momenta_out")?;
        ws.angular_velocity(0)?; // the velocities of mech_tree_set_state must be in place
        let mut a = vec![0.0; n * n];
        let mut p = vec![0.0; n];
        let t = mass.momenta_and_energy(kt, ws, ws.q_dot(), &mut a, &mut p)?;
        // SAFETY: caller's contract.
        unsafe {
            e_out.write(t);
            p_out.write(&p);
        }
        Ok(())
    })
}

/// The centre of mass of the whole tree and its Jacobian ∂x₀/∂q (3×n doubles, column-major,
/// n = dof; world components) at the coordinates of the last mech_tree_set_state.
/// `system_out` receives the mass properties of the whole system in world components (total
/// mass, centre, central inertia). `bodies` as in mech_tree_mass_matrix.
///
/// Errors: as mech_tree_mass_matrix, and INVALID_ARGUMENT when the total mass is 0.
///
/// # Safety
/// `tree` must be a live handle; `bodies` must point to `body_count` readable entries;
/// `system_out` writable; `jacobian_out` must point to 3·n writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_center_of_mass(
    tree: *mut mech_tree_t,
    bodies: *const mech_mass_properties_t,
    body_count: usize,
    system_out: *mut mech_mass_properties_t,
    jacobian_out: *mut f64,
    n: usize,
) -> mech_status_t {
    boundary(|| {
        let s_out = Out::new(system_out, "system_out")?;
        let len = n
            .checked_mul(3)
            .ok_or_else(|| FfiError::new(MECH_STATUS_BAD_DIMENSION, format!("n: 3·{n} overflows")))?;
        let j_out = OutSlice::new(jacobian_out, len, "jacobian_out")?;
        // SAFETY: caller's contract.
        let (mut mass, kt, ws) = unsafe { tree_mass(tree, bodies, body_count) }?;
        check_dof(n, kt.dof(), "jacobian_out")?;
        let mut j = vec![0.0; len];
        let system = mass.centre_of_mass(kt, ws, &mut j)?;
        // SAFETY: caller's contract.
        unsafe {
            s_out.write(system.into());
            j_out.write(&j);
        }
        Ok(())
    })
}

/// The split T = T₀ + T₁ + T₂ (syllabus 9.7–9.10) of a tree whose base moves with angular
/// velocity `base_omega` and base-origin velocity `base_velocity` (world components; the base
/// pose is the tree's, see mech_tree_set_base, whose ω₀ and v₀ these normally are; taking them
/// here keeps the split available for a base at rest in the tree's frame), so the drag velocity of a point x is ∂x/∂t = v₀ + ω₀ × (x − p₀)), at the
/// state (q, q̇) of the last mech_tree_set_state. Writes the split, b(q, t) = ∂T₁/∂q̇ into
/// `b_out` and the generalized momenta ∂T/∂q̇ = A q̇ + b into `momenta_out` (n = dof doubles
/// each). `bodies` as in mech_tree_mass_matrix.
///
/// Errors: as mech_tree_kinetic_energy, and NULL_POINTER / NON_FINITE for the base vectors.
///
/// # Safety
/// `tree` must be a live handle; `bodies` must point to `body_count` readable entries;
/// `base_omega`, `base_velocity` readable; `split_out` writable; `b_out` and `momenta_out` must
/// point to n writable doubles each.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_energy_split(
    tree: *mut mech_tree_t,
    bodies: *const mech_mass_properties_t,
    body_count: usize,
    base_omega: *const mech_vec3_t,
    base_velocity: *const mech_vec3_t,
    split_out: *mut mech_energy_split_t,
    b_out: *mut f64,
    momenta_out: *mut f64,
    n: usize,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let (omega, velocity) = unsafe {
            (
                read_vec3(base_omega, "base_omega")?,
                read_vec3(base_velocity, "base_velocity")?,
            )
        };
        let s_out = Out::new(split_out, "split_out")?;
        let b_dest = OutSlice::new(b_out, n, "b_out")?;
        let p_dest = OutSlice::new(momenta_out, n, "momenta_out")?;
        // SAFETY: caller's contract.
        let (mut mass, kt, ws) = unsafe { tree_mass(tree, bodies, body_count) }?;
        check_dof(n, kt.dof(), "b_out and momenta_out")?;
        ws.angular_velocity(0)?; // the velocities of mech_tree_set_state must be in place
        let drag = DragField {
            origin: ws.base().position,
            omega,
            velocity,
        };
        let (mut a, mut b, mut p) = (vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);
        let split = mass.energy_split(
            kt,
            ws,
            &drag,
            ws.q_dot(),
            SplitBuffers {
                mass_matrix: &mut a,
                b: &mut b,
                momenta: &mut p,
            },
        )?;
        // SAFETY: caller's contract.
        unsafe {
            s_out.write(split.into());
            b_dest.write(&b);
            p_dest.write(&p);
        }
        Ok(())
    })
}
