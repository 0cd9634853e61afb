//! Inverse dynamics: τ = A(q) q̈ + c(q, q̇) + g(q) − Σ Q_loads (Lagrange's equations (7.60)
//! solved for the applied forces) by the recursive Newton–Euler algorithm, its split, and the
//! wrench each joint transmits.

use super::{dynamics_mut, mech_dynamics_t, read_state};
use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::c_enum::{c_enum, enum_value};
use crate::ffi::status::*;
use crate::ffi::validate::*;
use mechanica_dynamics::{Frame, State};

/// The frame in which a joint reaction is expressed (int32_t).
pub type mech_reaction_frame_t = i32;
/// World (base-frame) components.
pub const MECH_REACTION_FRAME_WORLD: mech_reaction_frame_t = 0;
/// The child body's frame (the frame its joint moves).
pub const MECH_REACTION_FRAME_BODY: mech_reaction_frame_t = 1;
/// The joint frame, fixed in the parent body (in the base for a root body's joint), in which
/// the joint's axis is given.
pub const MECH_REACTION_FRAME_JOINT: mech_reaction_frame_t = 2;

c_enum!(Frame,
    MECH_REACTION_FRAME_WORLD => Frame::World,
    MECH_REACTION_FRAME_BODY => Frame::Body,
    MECH_REACTION_FRAME_JOINT => Frame::Joint,
);

/// Writes τ (n values) for the accelerations `q_ddot` at (`q`, `q_dot`) to `tau_out`: the
/// generalized forces the actuators must apply, τ = A(q) q̈ + c(q, q̇) + g(q) − Σ Q_loads with
/// every load of the dynamics (potentials, dampers, charges) at time 0, in N or N·m per
/// coordinate, by the recursive Newton–Euler algorithm in O(n). The fast path: no split and no
/// accuracy report (see mech_dynamics_inverse).
///
/// Errors: MECH_STATUS_BAD_DIMENSION when n is not the dof; MECH_STATUS_SINGULAR when a dashpot's
/// points coincide; MECH_STATUS_OUT_OF_RANGE when τ overflows.
///
/// # Safety
/// `dynamics` must be a live handle not used by another thread during the call; `q`, `q_dot`,
/// `q_ddot` must point to n readable doubles and `tau_out` to n writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_dynamics_rnea(
    dynamics: *mut mech_dynamics_t,
    q: *const f64,
    q_dot: *const f64,
    q_ddot: *const f64,
    n: usize,
    tau_out: *mut f64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let d = unsafe { dynamics_mut(dynamics) }?;
        // SAFETY: caller's contract.
        let [q, q_dot, q_ddot] = unsafe { read_state(d, [q, q_dot, q_ddot], "q_ddot", n) }?;
        let out = OutSlice::new(tau_out, n, "tau_out")?;
        let mut tau = vec![0.0; n];
        d.rnea_into(q, q_dot, q_ddot, &mut tau)?;
        // SAFETY: caller's contract.
        unsafe { out.write(&tau) };
        Ok(())
    })
}

/// Writes τ (n values) for the accelerations `q_ddot` at (`q`, `q_dot`) and time `t` (s) to
/// `tau_out`, as mech_dynamics_rnea, and its parts, each n values, to the optional outputs (may
/// be NULL): `velocity_product_out` c(q, q̇), the Coriolis and centrifugal terms (with those of
/// a rotating frame), `gravity_out` g(q) = ∂U_g/∂q, the force that balances the weights, and
/// `error_estimate_out` a first-order estimate of the rounding error of each τ_k
/// (16·(d + 4)·u times the magnitudes τ_k is summed from, d the depth of the tree; an
/// estimate, not a bound). The loads' generalized force is Σ Q = A q̈ + c + g − τ.
///
/// Errors: as mech_dynamics_rnea, and MECH_STATUS_NON_FINITE for a NaN or infinite `t`.
///
/// # Safety
/// As mech_dynamics_rnea; each non-NULL optional output must point to n writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_dynamics_inverse(
    dynamics: *mut mech_dynamics_t,
    q: *const f64,
    q_dot: *const f64,
    q_ddot: *const f64,
    t: f64,
    n: usize,
    tau_out: *mut f64,
    velocity_product_out: *mut f64,
    gravity_out: *mut f64,
    error_estimate_out: *mut f64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let d = unsafe { dynamics_mut(dynamics) }?;
        // SAFETY: caller's contract.
        let [q, q_dot, q_ddot] = unsafe { read_state(d, [q, q_dot, q_ddot], "q_ddot", n) }?;
        finite(&t, "t")?;
        let tau_out = OutSlice::new(tau_out, n, "tau_out")?;
        let optional = [
            OutSlice::optional(velocity_product_out, n, "velocity_product_out")?,
            OutSlice::optional(gravity_out, n, "gravity_out")?,
            OutSlice::optional(error_estimate_out, n, "error_estimate_out")?,
        ];
        let result = d.inverse_dynamics(&State::new(q, q_dot).at_time(t), q_ddot)?;
        let parts = [
            (&result.velocity_product, "velocity-product term c(q, q̇)"),
            (&result.gravity, "gravity term g(q)"),
            (&result.error_estimate, "rounding estimate of τ"),
        ];
        for (values, what) in parts {
            finite_result(values.as_slice(), what)?;
        }
        // SAFETY: caller's contract.
        unsafe { tau_out.write(&result.tau) };
        for (out, (values, _)) in optional.into_iter().zip(parts) {
            if let Some(out) = out {
                // SAFETY: caller's contract.
                unsafe { out.write(values) };
            }
        }
        Ok(())
    })
}

/// Writes the wrench that each body's joint transmits, at (`q`, `q_dot`) with the accelerations
/// `q_ddot` (the inverse dynamics' motion, loads at time 0), to `wrenches_out`: 6 doubles per
/// body in body order, the force (N) then the moment (N·m) about the joint origin (the body
/// frame's origin), that the parent (or the ground) exerts on the body through the joint,
/// constraint reaction and actuator force together (7.33–7.36, FM 4.61). Components in `frame`
/// (a mech_reaction_frame_t). `bodies` must be the body count (mech_dynamics_body_count).
///
/// Errors: as mech_dynamics_rnea, and MECH_STATUS_BAD_ENUM for an unknown frame,
/// MECH_STATUS_BAD_DIMENSION when `bodies` is not the body count.
///
/// # Safety
/// As mech_dynamics_rnea; `wrenches_out` must point to 6·bodies writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_dynamics_reactions(
    dynamics: *mut mech_dynamics_t,
    q: *const f64,
    q_dot: *const f64,
    q_ddot: *const f64,
    n: usize,
    frame: mech_reaction_frame_t,
    bodies: usize,
    wrenches_out: *mut f64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let d = unsafe { dynamics_mut(dynamics) }?;
        // SAFETY: caller's contract.
        let [q, q_dot, q_ddot] = unsafe { read_state(d, [q, q_dot, q_ddot], "q_ddot", n) }?;
        let frame = enum_value::<Frame>(frame, "frame")?;
        let count = d.tree().body_count();
        if bodies != count {
            return Err(FfiError::new(
                MECH_STATUS_BAD_DIMENSION,
                format!("bodies: the mechanism has {count} bodies, got {bodies}"),
            ));
        }
        let out = OutSlice::new(wrenches_out, product(6, bodies, "wrenches_out")?, "wrenches_out")?;
        let result = d.inverse_dynamics(&State::new(q, q_dot), q_ddot)?;
        let mut wrenches = Vec::with_capacity(6 * count);
        for reaction in &result.reactions {
            let w = reaction.expressed_in(d, frame)?;
            wrenches.extend(w.force.iter().chain(w.moment.iter()));
        }
        finite_result(wrenches.as_slice(), "joint reaction")?;
        // SAFETY: caller's contract.
        unsafe { out.write(&wrenches) };
        Ok(())
    })
}
