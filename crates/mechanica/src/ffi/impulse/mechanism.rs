//! Point impulses on a mechanism: Lagrange's impulse equations on a kinematic tree.

use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::handle::Handle;
use crate::ffi::kinematics::{check_dof, mech_tree_t};
use crate::ffi::mass::{check_finite_properties, mech_mass_properties_t, raw_properties};
use crate::ffi::status::*;
use crate::ffi::types::*;
use crate::ffi::validate::*;
use mechanica_impulse::{BodyPoint, MechanismInertia, PointImpulse, apply_point_impulses};
use mechanica_kinematics::tree::{KinematicTree, Workspace};
use mechanica_mass::mechanism::TreeMass;

/// The body mass properties of a tree from C (one per body, each in its body frame), checked
/// for finite numbers, and the factored mass matrix A(q) at the tree's current configuration.
///
/// # Safety
/// `bodies` must point to `body_count` readable values (or be NULL with body_count = 0).
pub(super) unsafe fn tree_inertia(
    tree: &KinematicTree,
    ws: &Workspace,
    bodies: *const mech_mass_properties_t,
    body_count: usize,
) -> Result<MechanismInertia, FfiError> {
    // SAFETY: caller's contract.
    let raw = unsafe { read_slice(bodies, body_count, "bodies") }?;
    let mut props = Vec::with_capacity(raw.len());
    for (i, b) in raw.iter().enumerate() {
        check_finite_properties(b, &format!("bodies[{i}]"))?;
        props.push(raw_properties(b));
    }
    let mut mass = TreeMass::new(tree, props)?;
    Ok(MechanismInertia::new(tree, ws, &mut mass)?)
}

/// A point impulse on a body of a mechanism.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_mechanism_impulse_t {
    /// Index of the struck body in the tree.
    pub body: usize,
    /// The struck point in the body frame B (m).
    pub point: mech_vec3_t,
    /// The impulse S, world frame (N·s).
    pub impulse: mech_vec3_t,
}

/// The response of a mechanism to point impulses (7.115–7.117).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_mechanism_response_t {
    /// Kinetic energy before, ½ q̇ᵀ A q̇ (J).
    pub energy_before: f64,
    /// ΔT = Q_S·(q̇ + ½ Δq̇) (J).
    pub energy_change: f64,
    /// Normwise backward error of the solve A Δq̇ = Q_S.
    pub backward_error: f64,
}

/// Checked Rust impulses of C impulses (NON_FINITE names the entry).
fn impulses_from_c(raw: &[mech_mechanism_impulse_t]) -> Result<Vec<PointImpulse>, FfiError> {
    let mut list = Vec::with_capacity(raw.len());
    for (i, s) in raw.iter().enumerate() {
        finite(&s.point, &format!("impulses[{i}].point"))?;
        finite(&s.impulse, &format!("impulses[{i}].impulse"))?;
        list.push(PointImpulse {
            point: BodyPoint {
                body: s.body,
                p_bq: s.point.into(),
            },
            s_w: s.impulse.into(),
        });
    }
    Ok(list)
}

/// Lagrange's impulse equations A(q) Δq̇ = Σ J_kᵀ S_k (7.115–7.117) for the tree at the state
/// of mech_tree_set_state, with `bodies` = one mass-properties value per body (body frame;
/// mass ≥ 0). Writes the jump of the generalized velocities Δq̇ (`dof` doubles, into
/// `delta_q_dot`) and the energy report with the backward error of the solve (into `out`).
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_NOT_POSITIVE_DEFINITE
/// when A is singular (a rod or point mass whose spin has a coordinate, a massless leaf);
/// MECH_STATUS_INVALID_ARGUMENT for a body index out of range, a tree that is not finalized or
/// has no state; MECH_STATUS_BAD_DIMENSION for a wrong `body_count` or `dof`.
///
/// # Safety
/// `tree` must be a live handle; `bodies` must point to `body_count` readable values,
/// `impulses` to `impulse_count` readable values (NULL allowed when the count is 0),
/// `delta_q_dot` to `dof` writable doubles, `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_impulse_mechanism_apply(
    tree: *mut mech_tree_t,
    bodies: *const mech_mass_properties_t,
    body_count: usize,
    impulses: *const mech_mechanism_impulse_t,
    impulse_count: usize,
    delta_q_dot: *mut f64,
    dof: usize,
    out: *mut mech_mechanism_response_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { mech_tree_t::borrow_mut(tree, "tree") }?;
        // SAFETY: caller's contract.
        let raw = unsafe { read_slice(impulses, impulse_count, "impulses") }?;
        let out = Out::new(out, "out")?;
        let (kt, ws) = t.built()?;
        check_dof(kt, dof, "delta_q_dot")?;
        let dest = OutSlice::new(delta_q_dot, dof, "delta_q_dot")?;
        let list = impulses_from_c(raw)?;
        // SAFETY: caller's contract.
        let inertia = unsafe { tree_inertia(kt, ws, bodies, body_count) }?;
        ws.check_velocities()?; // the velocities of mech_tree_set_state must be in place
        let q_dot = ws.q_dot().to_vec();
        let r = apply_point_impulses(kt, ws, &inertia, &q_dot, &list)?;
        let value = mech_mechanism_response_t {
            energy_before: r.energy_before,
            energy_change: r.energy_change,
            backward_error: r.backward_error,
        };
        // SAFETY: caller's contract.
        unsafe {
            dest.write(&r.delta_q_dot);
            out.write(value);
        }
        Ok(())
    })
}
