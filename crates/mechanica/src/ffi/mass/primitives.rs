//! Closed-form mass properties of point masses and primitive bodies, and the mass-or-density
//! amount they are built from.

use super::mech_mass_properties_t;
use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::c_enum::{c_enum, enum_value};
use crate::ffi::status::*;
use crate::ffi::types::*;
use crate::ffi::validate::*;
use mechanica_kinematics::nalgebra::Vector3;
use mechanica_mass::{Amount, MassError, MassProperties, primitives};

/// The mass properties of a point mass `mass` (kg) at `position` (m, in the frame of the
/// result): zero central inertia, which is valid (semidefinite). Written to `out`.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_INVALID_ARGUMENT for
/// a mass ≤ 0.
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

/// The bodies of [`mech_primitive_t`].
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

c_enum!(Primitive,
    MECH_PRIMITIVE_POINT => Primitive::Point,
    MECH_PRIMITIVE_ROD => Primitive::Rod,
    MECH_PRIMITIVE_RECTANGLE_LAMINA => Primitive::RectangleLamina,
    MECH_PRIMITIVE_DISC_LAMINA => Primitive::DiscLamina,
    MECH_PRIMITIVE_SPHERE => Primitive::Sphere,
    MECH_PRIMITIVE_ELLIPSOID => Primitive::Ellipsoid,
    MECH_PRIMITIVE_BOX => Primitive::Box,
    MECH_PRIMITIVE_CYLINDER => Primitive::Cylinder,
    MECH_PRIMITIVE_CONE => Primitive::Cone,
    MECH_PRIMITIVE_CAPSULE => Primitive::Capsule,
    MECH_PRIMITIVE_TORUS => Primitive::Torus,
    MECH_PRIMITIVE_HEMISPHERE => Primitive::Hemisphere,
);

impl Primitive {
    /// How many dimensions the body takes.
    fn dimension_count(self) -> usize {
        match self {
            Self::Point => 0,
            Self::Rod | Self::DiscLamina | Self::Sphere | Self::Hemisphere => 1,
            Self::RectangleLamina | Self::Cylinder | Self::Cone | Self::Capsule | Self::Torus => 2,
            Self::Ellipsoid | Self::Box => 3,
        }
    }

    /// The body's properties from its dimensions `d` (of [`Primitive::dimension_count`] length).
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

/// The readings of [`mech_amount_t`].
#[derive(Clone, Copy)]
enum AmountKind {
    Mass,
    Density,
}

c_enum!(AmountKind,
    MECH_AMOUNT_MASS => AmountKind::Mass,
    MECH_AMOUNT_DENSITY => AmountKind::Density,
);

/// The amount `value` read as `kind`: BAD_ENUM for an unknown kind, NON_FINITE for a NaN or
/// infinite value (its sign is checked by the body that uses it).
pub(super) fn amount_of(kind: mech_amount_t, value: f64) -> Result<Amount, FfiError> {
    let kind: AmountKind = enum_value(kind, "amount_kind")?;
    finite(&value, "amount")?;
    Ok(match kind {
        AmountKind::Mass => Amount::Mass(value),
        AmountKind::Density => Amount::Density(value),
    })
}

/// The closed-form mass properties of a primitive body `kind` (a mech_primitive_t) with
/// `dimension_count` dimensions at `dimensions` (m, as listed for each MECH_PRIMITIVE_* value),
/// and `amount` read as a mass or a density according to `amount_kind` (a mech_amount_t),
/// written to `out` in the body's own frame. Rods, laminae and points have semidefinite
/// inertia, which is valid.
///
/// Errors: MECH_STATUS_BAD_ENUM for an unknown `kind` or `amount_kind`;
/// MECH_STATUS_BAD_DIMENSION when `dimension_count` is not the count of `kind`;
/// MECH_STATUS_NON_FINITE; MECH_STATUS_INVALID_ARGUMENT for a non-positive dimension, mass or
/// density, or a torus tube radius above its ring radius; MECH_STATUS_OUT_OF_RANGE when the
/// mass or a moment of inertia is not representable (it overflows, or a mass from a density
/// underflows to zero; mech_last_error names the quantity). Masses and moments are formed as
/// products with the exponents kept apart, so that only a result that is itself out of range
/// fails.
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
