//! Holonomic constraints f(q) = 0 added to a dynamics handle, and the forward dynamics with
//! Lagrange multipliers: [A Jᵀ; J 0] [q̈; λ] = [τ + Q − h; γ] (FM 4.61, λ of the opposite sign:
//! a rod's λ is its tension). The constraints act only in mech_dynamics_forward_constrained;
//! every other mech_dynamics_* function ignores them.

use super::{mech_dynamics_t, read_state};
use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::handle::Handle;
use crate::ffi::mechanism::anchor;
use crate::ffi::status::*;
use crate::ffi::types::mech_vec3_t;
use crate::ffi::validate::*;
use mechanica_dynamics::{ConstrainedDynamics, Constraint, State};

/// The drift and accuracy report of mech_dynamics_forward_constrained.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_constrained_report_t {
    /// ‖f(q)‖₂, how far q is from the constraint manifold (mixed units when the equations mix
    /// lengths and angles).
    pub position_drift: f64,
    /// ‖J(q) q̇‖₂, how far q̇ is from the constraints' tangent space.
    pub velocity_drift: f64,
    /// The row-wise backward error η of the KKT solve: each residual of
    /// [τ + Q − h − A q̈ − Jᵀλ; γ − J q̈] against the size of the terms of its row. The error of
    /// q̈ and λ is roughly η times the conditioning of the KKT matrix, about κ(A)·κ(J A⁻¹ Jᵀ).
    pub backward_error: f64,
}

/// Borrows the constrained dynamics behind a handle (NULL_POINTER, MISALIGNED_POINTER).
///
/// # Safety
/// As [`crate::ffi::handle::Handle::borrow_mut`].
unsafe fn constrained_mut<'a>(handle: *mut mech_dynamics_t) -> Result<&'a mut ConstrainedDynamics, FfiError> {
    // SAFETY: caller's contract.
    unsafe { mech_dynamics_t::borrow_mut(handle, "dynamics") }.map(|h| &mut h.constrained)
}

/// Adds `constraint` under a name that says which function added it, and writes its index to
/// the optional `index_out`.
///
/// # Safety
/// `dynamics` a live handle; `index_out` NULL or writable.
unsafe fn add(
    dynamics: *mut mech_dynamics_t,
    index_out: *mut usize,
    function: &str,
    constraint: impl FnOnce() -> Result<Constraint, FfiError>,
) -> mech_status_t {
    boundary(|| {
        let out = Out::optional(index_out, "index_out")?;
        // SAFETY: caller's contract.
        let c = unsafe { constrained_mut(dynamics) }?;
        let index = c.add_constraint(format!("added by {function}"), constraint()?)?;
        if let Some(out) = out {
            // SAFETY: caller's contract.
            unsafe { out.write(index) };
        }
        Ok(())
    })
}

/// Adds the constraint that the point `point_a` of body `body_a` and `point_b` of `body_b`
/// (body coordinates, m; MECH_GROUND and base-frame coordinates for the ground) coincide along
/// each of the `direction_count` (1 to 3) world directions `directions`: one equation
/// f_r = d_r·(x_a − x_b) per direction, the directions normalised. Three independent
/// directions close a loop with a ball joint; a planar loop closed by a pin needs only the two
/// in-plane ones (the third would be redundant). Writes the constraint's index (0, 1, … in the
/// order constraints are added) to `*index_out` (may be NULL).
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_INVALID_ARGUMENT for
/// a direction count outside 1..3, a zero direction, a body index below MECH_GROUND or out of
/// range. Dependent directions are found by mech_dynamics_forward_constrained
/// (MECH_STATUS_SINGULAR).
///
/// # Safety
/// `dynamics` must be a live handle; `directions` must point to `direction_count` readable
/// vectors; `index_out` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_dynamics_add_point_constraint(
    dynamics: *mut mech_dynamics_t,
    body_a: i64,
    point_a: mech_vec3_t,
    body_b: i64,
    point_b: mech_vec3_t,
    directions: *const mech_vec3_t,
    direction_count: usize,
    index_out: *mut usize,
) -> mech_status_t {
    let build = || {
        if !(1..=3).contains(&direction_count) {
            return Err(FfiError::new(
                MECH_STATUS_INVALID_ARGUMENT,
                format!("direction_count must be 1, 2 or 3, got {direction_count}"),
            ));
        }
        // SAFETY: caller's contract.
        let directions = unsafe { read_slice(directions, direction_count, "directions") }?;
        finite(&point_a, "point_a")?;
        finite(&point_b, "point_b")?;
        for d in directions {
            finite(d, "directions")?;
        }
        Ok(Constraint::PointsCoincide {
            a: anchor(body_a, point_a)?,
            b: anchor(body_b, point_b)?,
            directions: directions.iter().map(|&d| d.into()).collect(),
        })
    };
    // SAFETY: caller's contract.
    unsafe { add(dynamics, index_out, "mech_dynamics_add_point_constraint", build) }
}

/// Adds the constraint that the point `point` of body `body` (body coordinates, m) stays on
/// the fixed plane n·x = `offset` (n = `normal`, base-frame components, normalised with the
/// offset divided by its length): one equation f = n·x − offset; its λ is minus the normal
/// force along n. Writes the constraint's index to `*index_out` (may be NULL).
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_INVALID_ARGUMENT for
/// a zero normal, a body index below MECH_GROUND or out of range.
///
/// # Safety
/// `dynamics` must be a live handle; `index_out` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_dynamics_add_plane_constraint(
    dynamics: *mut mech_dynamics_t,
    body: i64,
    point: mech_vec3_t,
    normal: mech_vec3_t,
    offset: f64,
    index_out: *mut usize,
) -> mech_status_t {
    let build = || {
        finite(&point, "point")?;
        finite(&normal, "normal")?;
        finite(&offset, "offset")?;
        Ok(Constraint::PointOnPlane {
            point: anchor(body, point)?,
            normal: normal.into(),
            offset,
        })
    };
    // SAFETY: caller's contract.
    unsafe { add(dynamics, index_out, "mech_dynamics_add_plane_constraint", build) }
}

/// Adds a massless rod of length `length` (m, > 0) between the point `point_a` of body
/// `body_a` and `point_b` of `body_b` (body coordinates, m; MECH_GROUND and base-frame
/// coordinates for the ground): one equation f = |x_a − x_b| − length, whose λ is the rod's
/// tension (N, positive when it pulls the points together). Writes the constraint's index to
/// `*index_out` (may be NULL).
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_INVALID_ARGUMENT for
/// length ≤ 0, a body index below MECH_GROUND or out of range.
///
/// # Safety
/// `dynamics` must be a live handle; `index_out` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_dynamics_add_distance_constraint(
    dynamics: *mut mech_dynamics_t,
    body_a: i64,
    point_a: mech_vec3_t,
    body_b: i64,
    point_b: mech_vec3_t,
    length: f64,
    index_out: *mut usize,
) -> mech_status_t {
    let build = || {
        finite(&point_a, "point_a")?;
        finite(&point_b, "point_b")?;
        finite(&length, "length")?;
        Ok(Constraint::Distance {
            a: anchor(body_a, point_a)?,
            b: anchor(body_b, point_b)?,
            length,
        })
    };
    // SAFETY: caller's contract.
    unsafe { add(dynamics, index_out, "mech_dynamics_add_distance_constraint", build) }
}

/// Adds the constraint that coordinate `coordinate` (0 ≤ coordinate < n) keeps the value
/// `value` (rad or m): one equation f = q_coordinate − value, whose λ is the generalized force
/// the lock applies with its sign reversed. Writes the constraint's index to `*index_out` (may
/// be NULL).
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite value; MECH_STATUS_INVALID_ARGUMENT for
/// a coordinate out of range.
///
/// # Safety
/// `dynamics` must be a live handle; `index_out` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_dynamics_add_coordinate_constraint(
    dynamics: *mut mech_dynamics_t,
    coordinate: usize,
    value: f64,
    index_out: *mut usize,
) -> mech_status_t {
    let build = || {
        finite(&value, "value")?;
        Ok(Constraint::Coordinate {
            index: coordinate,
            value,
        })
    };
    // SAFETY: caller's contract.
    unsafe { add(dynamics, index_out, "mech_dynamics_add_coordinate_constraint", build) }
}

/// Writes the number of constraint equations m (the length of the multipliers of
/// mech_dynamics_forward_constrained) to `*count_out`: the sum over the constraints of their
/// equations (the direction count of a point constraint, 1 for the others), numbered in the
/// order the constraints were added.
///
/// Errors: none beyond the pointer checks.
///
/// # Safety
/// `dynamics` must be a live handle and `count_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_dynamics_constraint_equations(
    dynamics: *const mech_dynamics_t,
    count_out: *mut usize,
) -> mech_status_t {
    boundary(|| {
        let out = Out::new(count_out, "count_out")?;
        // SAFETY: caller's contract.
        let d = unsafe { mech_dynamics_t::borrow(dynamics, "dynamics") }?;
        // SAFETY: caller's contract.
        unsafe { out.write(d.constrained.equation_count()) };
        Ok(())
    })
}

/// Writes q̈ (n values) and the multipliers λ (m values, one per constraint equation) of the
/// constrained equations of motion [A Jᵀ; J 0] [q̈; λ] = [τ + Q − h; γ] at (`q`, `q_dot`) and
/// time `t` (s) for the applied forces `tau`, with every load of the dynamics, to `q_ddot_out`
/// and `multipliers_out`, and the drift and backward error to `*report_out` (may be NULL).
/// Solved by the mass matrix A = LLᵀ and the Schur complement J A⁻¹ Jᵀ with one step of
/// iterative refinement; J q̈ = γ holds to the rounding level, so the drift of an integrated
/// motion is the caller's to correct. With no constraints (m = 0) this is the unconstrained
/// q̈ by the mass matrix.
///
/// Errors: MECH_STATUS_BAD_DIMENSION when n is not the dof or m not the equation count;
/// MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_SINGULAR when A(q) is
/// singular, or when a constraint equation depends on the earlier ones at q (the message names
/// the constraint, its index and equation); MECH_STATUS_OUT_OF_RANGE when a result overflows.
/// Nothing is written on error.
///
/// # Safety
/// `dynamics` must be a live handle not used by another thread during the call; `q`, `q_dot`,
/// `tau` must point to n readable doubles, `q_ddot_out` to n and `multipliers_out` to m
/// writable doubles; `report_out` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_dynamics_forward_constrained(
    dynamics: *mut mech_dynamics_t,
    q: *const f64,
    q_dot: *const f64,
    tau: *const f64,
    t: f64,
    n: usize,
    m: usize,
    q_ddot_out: *mut f64,
    multipliers_out: *mut f64,
    report_out: *mut mech_constrained_report_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let c = unsafe { constrained_mut(dynamics) }?;
        // SAFETY: caller's contract.
        let [q, q_dot, tau] = unsafe { read_state(c.dynamics(), [q, q_dot, tau], "tau", n) }?;
        finite(&t, "t")?;
        let equations = c.equation_count();
        if m != equations {
            return Err(FfiError::new(
                MECH_STATUS_BAD_DIMENSION,
                format!("multipliers: the dynamics has {equations} constraint equations, got m = {m}"),
            ));
        }
        let out = OutSlice::new(q_ddot_out, n, "q_ddot_out")?;
        let multipliers = OutSlice::new(multipliers_out, m, "multipliers_out")?;
        let report = Out::optional(report_out, "report_out")?;
        let result = c.forward_dynamics(&State::new(q, q_dot).at_time(t), tau)?;
        let summary = mech_constrained_report_t {
            position_drift: result.position_drift,
            velocity_drift: result.velocity_drift,
            backward_error: result.backward_error,
        };
        let numbers = [summary.position_drift, summary.velocity_drift, summary.backward_error];
        finite_result(numbers.as_slice(), "constrained forward-dynamics report")?;
        // SAFETY: caller's contract.
        unsafe {
            out.write(&result.q_ddot);
            multipliers.write(&result.multipliers);
            if let Some(report) = report {
                report.write(summary);
            }
        }
        Ok(())
    })
}
