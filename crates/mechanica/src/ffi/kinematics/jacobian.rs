//! Jacobians of a body of a kinematic tree: point and angular, and their time derivatives.

use super::tree::mech_tree_t;
use crate::ffi::boundary::boundary;
use crate::ffi::c_enum::{c_enum, enum_value};
use crate::ffi::handle::Handle;
use crate::ffi::spatial::read_vec3;
use crate::ffi::status::*;
use crate::ffi::types::*;
use crate::ffi::validate::*;
use mechanica_kinematics::nalgebra::Vector3;

/// Which Jacobian mech_tree_jacobian computes.
pub type mech_jacobian_kind_t = i32;
/// ∂x/∂q of a body point (syllabus 1.37): 3×dof.
pub const MECH_JACOBIAN_POINT: mech_jacobian_kind_t = 0;
/// ∂ω/∂q̇ of the body: 3×dof.
pub const MECH_JACOBIAN_ANGULAR: mech_jacobian_kind_t = 1;
/// d/dt of MECH_JACOBIAN_POINT along the current (q, q̇): 3×dof.
pub const MECH_JACOBIAN_POINT_RATE: mech_jacobian_kind_t = 2;
/// d/dt of MECH_JACOBIAN_ANGULAR: 3×dof.
pub const MECH_JACOBIAN_ANGULAR_RATE: mech_jacobian_kind_t = 3;

/// The kinds of [`mech_jacobian_kind_t`].
#[derive(Clone, Copy)]
enum JacobianKind {
    Point,
    Angular,
    PointRate,
    AngularRate,
}

c_enum!(JacobianKind,
    MECH_JACOBIAN_POINT => JacobianKind::Point,
    MECH_JACOBIAN_ANGULAR => JacobianKind::Angular,
    MECH_JACOBIAN_POINT_RATE => JacobianKind::PointRate,
    MECH_JACOBIAN_ANGULAR_RATE => JacobianKind::AngularRate,
);

/// A 3×dof Jacobian of `body` (`kind`: a mech_jacobian_kind_t) at the state of the last
/// mech_tree_set_state, in world components, into the caller's column-major buffer `out` of
/// `capacity` doubles (exactly 3·dof are written; column k belongs to coordinate k). `point`
/// (body coordinates, m) is used by the point kinds and ignored (may be NULL) by the angular
/// kinds.
///
/// Errors: MECH_STATUS_BAD_ENUM for an unknown `kind`; MECH_STATUS_NON_FINITE for a NaN or
/// infinite `point`; MECH_STATUS_BUFFER_TOO_SMALL when capacity < 3·dof;
/// MECH_STATUS_INVALID_ARGUMENT when the tree is not finalized, no state is set or `body` is out
/// of range.
///
/// # Safety
/// `tree` must be a live handle; `point` NULL or readable; `out` must hold `capacity` writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_jacobian(
    tree: *mut mech_tree_t,
    body: usize,
    kind: mech_jacobian_kind_t,
    point: *const mech_vec3_t,
    out: *mut f64,
    capacity: usize,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { mech_tree_t::borrow_mut(tree, "tree") }?;
        let kind: JacobianKind = enum_value(kind, "kind")?;
        let p = match kind {
            // SAFETY: caller's contract.
            JacobianKind::Point | JacobianKind::PointRate => unsafe { read_vec3(point, "point") }?,
            JacobianKind::Angular | JacobianKind::AngularRate => Vector3::zeros(),
        };
        let (kt, ws) = t.built()?;
        let len = 3 * kt.dof();
        let dest = OutSlice::buffer(out, capacity, len, "out")?;
        let mut j = vec![0.0; len];
        match kind {
            JacobianKind::Point => kt.point_jacobian(ws, body, &p, &mut j)?,
            JacobianKind::Angular => kt.angular_jacobian(ws, body, &mut j)?,
            JacobianKind::PointRate => kt.point_jacobian_rate(ws, body, &p, &mut j)?,
            JacobianKind::AngularRate => kt.angular_jacobian_rate(ws, body, &mut j)?,
        }
        // SAFETY: caller's contract.
        unsafe { dest.write(&j) };
        Ok(())
    })
}
