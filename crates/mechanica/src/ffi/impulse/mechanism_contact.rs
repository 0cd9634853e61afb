//! Impacts of a mechanism at one or several contacts, and its contact-space (Delassus) matrix.

use super::mechanism::tree_inertia;
use super::{mech_contact_mode_t, mech_restitution_law_t, mode_to_c};
use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::c_enum::enum_value;
use crate::ffi::handle::Handle;
use crate::ffi::kinematics::{check_dof, mech_tree_t};
use crate::ffi::mass::mech_mass_properties_t;
use crate::ffi::status::*;
use crate::ffi::types::*;
use crate::ffi::validate::*;
use mechanica_impulse::{
    BodyPoint, ContactLaw, ContactSpace, ImpactModel, ImpulseError, MechanismContact, MultiContactOptions,
    RestitutionLaw, resolve_contacts,
};
use mechanica_kinematics::nalgebra::Matrix3;

/// A contact of a mechanism with the environment or between two of its bodies.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_mechanism_contact_t {
    /// Index of the body that receives the impulse +P.
    pub body: usize,
    /// The contact point on `body`, body frame (m).
    pub point: mech_vec3_t,
    /// Index of the other body (receives −P), or −1 for the static environment.
    pub other_body: i64,
    /// The contact point on the other body, its body frame (m); ignored for the environment.
    pub other_point: mech_vec3_t,
    /// Unit normal (world) from the environment / other body into `body` (|n| = 1 within 1e-9).
    pub normal: mech_vec3_t,
    /// Coefficient of restitution e ∈ [0, 1].
    pub restitution: f64,
    /// Coulomb friction coefficient f ≥ 0 (+INFINITY: no slip).
    pub friction: f64,
    /// A MECH_RESTITUTION_* value (used when a single contact is resolved; several contacts use
    /// Poisson's rule, see mech_impulse_mechanism_contacts).
    pub law: mech_restitution_law_t,
}

/// Accuracy and budget of a mechanism impact. A NULL options pointer means the defaults, which
/// mech_multi_contact_options_default writes (tolerance 1e-10, 10000 sweeps, process tolerance
/// 1e-10).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_multi_contact_options_t {
    /// Relative complementarity tolerance of the simultaneous model (> 0; default 1e-10).
    pub tolerance: f64,
    /// Maximum Gauss–Seidel sweeps per phase (≥ 1; default 10000).
    pub max_iterations: u64,
    /// Relative tolerance of the single-contact process (0 < tolerance ≤ 1e-2; default 1e-10).
    pub process_tolerance: f64,
}

impl From<&MultiContactOptions> for mech_multi_contact_options_t {
    fn from(o: &MultiContactOptions) -> Self {
        Self {
            tolerance: o.tolerance,
            max_iterations: o.max_iterations as u64,
            process_tolerance: o.process.tolerance,
        }
    }
}

/// Writes the default options of a mechanism impact (those a NULL options pointer selects) to
/// `options_out`.
///
/// Errors: none beyond the pointer checks.
///
/// # Safety
/// `options_out` must point to a writable mech_multi_contact_options_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_multi_contact_options_default(
    options_out: *mut mech_multi_contact_options_t,
) -> mech_status_t {
    boundary(|| {
        let out = Out::new(options_out, "options_out")?;
        // SAFETY: caller's contract.
        unsafe { out.write((&MultiContactOptions::default()).into()) };
        Ok(())
    })
}

/// The Rust options of a C options pointer: the defaults for NULL; NON_FINITE or
/// INVALID_ARGUMENT for a tolerance that is not a positive number or no sweep allowed.
///
/// # Safety
/// A non-NULL, aligned `options` must point to a readable mech_multi_contact_options_t.
unsafe fn read_options(options: *const mech_multi_contact_options_t) -> Result<MultiContactOptions, FfiError> {
    let mut opts = MultiContactOptions::default();
    if options.is_null() {
        return Ok(opts);
    }
    // SAFETY: caller's contract.
    let o = unsafe { read(options, "options") }?;
    finite(&o.tolerance, "options.tolerance")?;
    finite(&o.process_tolerance, "options.process_tolerance")?;
    if o.tolerance <= 0.0 || o.process_tolerance <= 0.0 || o.max_iterations == 0 {
        return Err(FfiError::new(
            MECH_STATUS_INVALID_ARGUMENT,
            "options: tolerances must be positive and max_iterations at least 1",
        ));
    }
    opts.tolerance = o.tolerance;
    opts.max_iterations = usize::try_from(o.max_iterations).unwrap_or(usize::MAX);
    opts.process.tolerance = o.process_tolerance;
    Ok(opts)
}

/// The outcome at one contact of a mechanism impact (world frame).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_mechanism_contact_result_t {
    /// Total impulse P on `body` (the other body receives −P) (N·s).
    pub impulse: mech_vec3_t,
    /// Normal impulse P·n ≥ 0 (N·s).
    pub normal_impulse: f64,
    /// Tangential (friction) impulse (N·s).
    pub tangential_impulse: mech_vec3_t,
    /// Normal impulse at the end of compression (N·s).
    pub compression_impulse: f64,
    /// Relative velocity of the contact before the impact (m/s).
    pub relative_velocity_before: mech_vec3_t,
    /// Relative velocity after the impact, u⁻ + Σ W P (m/s).
    pub relative_velocity_after: mech_vec3_t,
    /// A MECH_CONTACT_* value.
    pub mode: mech_contact_mode_t,
}

/// The report of a mechanism impact.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_mechanism_impact_t {
    /// Kinetic energy before, ½ q̇ᵀ A q̇ (J).
    pub energy_before: f64,
    /// ΔT = P·(u⁻ + ½ W P) (J); never positive for several contacts (energy guard).
    pub energy_change: f64,
    /// Largest complementarity residual over contacts (m/s); 0 for the single-contact process.
    pub complementarity_residual: f64,
    /// Error bound of the single-contact process's impulse (N·s, see
    /// mech_impact_result_t::integration_error); 0 for several contacts.
    pub integration_error: f64,
    /// Factor applied to the restitution impulses by the energy guard (1: untouched).
    pub restitution_scale: f64,
    /// Gauss–Seidel sweeps (several contacts) or process steps (one contact).
    pub iterations: u64,
    /// Numerical rank of the 3m × 3m Delassus matrix W.
    pub delassus_rank: u64,
    /// 1 when the residual met the tolerance, 0 when the sweep budget ran out.
    pub converged: i32,
    /// 1 when the simultaneous multi-contact model was used, 0 for the single-contact process.
    pub simultaneous: i32,
}

/// Reads and validates C contacts (the messages name the contact).
pub(crate) fn contacts_from_c(raw: &[mech_mechanism_contact_t]) -> Result<Vec<MechanismContact>, FfiError> {
    let mut list = Vec::with_capacity(raw.len());
    for (i, c) in raw.iter().enumerate() {
        finite(&c.point, &format!("contacts[{i}].point"))?;
        finite(&c.other_point, &format!("contacts[{i}].other_point"))?;
        finite(&c.normal, &format!("contacts[{i}].normal"))?;
        finite(&c.restitution, &format!("contacts[{i}].restitution"))?;
        let law: RestitutionLaw = enum_value(c.law, &format!("contacts[{i}].law"))?;
        let law = ContactLaw::new(c.restitution, c.friction, law).map_err(|e| {
            FfiError::from(ImpulseError::InContact {
                contact: i,
                source: Box::new(e),
            })
        })?;
        let other = match c.other_body {
            -1 => None,
            b if b >= 0 => Some(BodyPoint {
                body: b as usize,
                p_bq: c.other_point.into(),
            }),
            b => {
                return Err(FfiError::new(
                    MECH_STATUS_INVALID_ARGUMENT,
                    format!("contacts[{i}].other_body must be a body index or -1, got {b}"),
                ));
            }
        };
        list.push(MechanismContact {
            point: BodyPoint {
                body: c.body,
                p_bq: c.point.into(),
            },
            other,
            normal_w: c.normal.into(),
            law,
        });
    }
    Ok(list)
}

/// Resolves an impact of the mechanism `tree` (at the state of mech_tree_set_state; `bodies`
/// one mass-properties value per body, body frame) at `contact_count` contacts. One contact:
/// the impulse-parameterised process with the contact's restitution law (as
/// mech_impulse_resolve_contact, on W = J A⁻¹ Jᵀ). Several contacts: the simultaneous
/// two-phase model (inelastic Signorini–Coulomb compression, then Poisson restitution with
/// friction, energy-guarded so that ΔT ≤ 0) solved by projected block Gauss–Seidel from zero
/// in contact order. `options` may be NULL for the defaults (see
/// mech_multi_contact_options_default). Writes one result per contact into `results` (world
/// frame), the jump Δq̇ (`dof` doubles) into `delta_q_dot` and the report, with its residual or
/// integration error, into `out`.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_BAD_ENUM for an
/// unknown law; MECH_STATUS_BAD_DIMENSION for a wrong `body_count` or `dof`;
/// MECH_STATUS_INVALID_ARGUMENT for bad options, a contact law out of range, a body index out
/// of range, or a tree that is not finalized or has no state; MECH_STATUS_SINGULAR when an
/// approaching contact cannot move along its normal; MECH_STATUS_NOT_POSITIVE_DEFINITE for a
/// singular mass matrix; MECH_STATUS_NOT_CONVERGED for a frictional jam of the single-contact
/// process, a self-locking contact under Newton's or Stronge's law included (an unconverged
/// simultaneous solve is reported by `converged` = 0, not an error); MECH_STATUS_OUT_OF_RANGE
/// when an impulse, velocity or energy overflows.
///
/// # Safety
/// `tree` must be a live handle; `bodies` must point to `body_count` readable values,
/// `contacts` to `contact_count` readable values, `options` be NULL or readable, `results` point
/// to `contact_count` writable values, `delta_q_dot` to `dof` writable doubles, `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_impulse_mechanism_contacts(
    tree: *mut mech_tree_t,
    bodies: *const mech_mass_properties_t,
    body_count: usize,
    contacts: *const mech_mechanism_contact_t,
    contact_count: usize,
    options: *const mech_multi_contact_options_t,
    results: *mut mech_mechanism_contact_result_t,
    delta_q_dot: *mut f64,
    dof: usize,
    out: *mut mech_mechanism_impact_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { mech_tree_t::borrow_mut(tree, "tree") }?;
        // SAFETY: caller's contract.
        let raw = unsafe { read_slice(contacts, contact_count, "contacts") }?;
        // SAFETY: caller's contract.
        let opts = unsafe { read_options(options) }?;
        let out = Out::new(out, "out")?;
        let results = OutSlice::new(results, contact_count, "results")?;
        let (kt, ws) = t.built()?;
        check_dof(kt, dof, "delta_q_dot")?;
        let dest = OutSlice::new(delta_q_dot, dof, "delta_q_dot")?;
        let list = contacts_from_c(raw)?;
        // SAFETY: caller's contract.
        let inertia = unsafe { tree_inertia(kt, ws, bodies, body_count) }?;
        ws.check_velocities()?; // the velocities of mech_tree_set_state must be in place
        let q_dot = ws.q_dot().to_vec();
        let r = resolve_contacts(kt, ws, &inertia, &q_dot, &list, &opts)?;
        let per_contact: Vec<mech_mechanism_contact_result_t> = r
            .contacts
            .iter()
            .map(|c| mech_mechanism_contact_result_t {
                impulse: c.impulse_w.into(),
                normal_impulse: c.normal_impulse,
                tangential_impulse: c.tangential_impulse_w.into(),
                compression_impulse: c.compression_impulse,
                relative_velocity_before: c.u_before_w.into(),
                relative_velocity_after: c.u_after_w.into(),
                mode: mode_to_c(c.mode),
            })
            .collect();
        let value = mech_mechanism_impact_t {
            energy_before: r.energy_before,
            energy_change: r.energy_change,
            complementarity_residual: r.complementarity_residual,
            integration_error: r.integration_error,
            restitution_scale: r.restitution_scale,
            iterations: r.iterations as u64,
            delassus_rank: r.delassus_rank as u64,
            converged: i32::from(r.converged),
            simultaneous: i32::from(r.model == ImpactModel::Simultaneous),
        };
        // SAFETY: caller's contract.
        unsafe {
            results.write(&per_contact);
            dest.write(&r.delta_q_dot);
            out.write(value);
        }
        Ok(())
    })
}

/// The contact-space (Delassus) matrix W = J A⁻¹ Jᵀ (m/(N·s)) of `contact_count` contacts of
/// the mechanism at the state of mech_tree_set_state, into `delassus` (column-major, `rows` ×
/// `rows` with rows = 3·contact_count; rows 3i, 3i+1, 3i+2 are the tangents t₁, t₂ and the
/// normal of contact i), its numerical rank into `rank_out`, and the contact frames (columns
/// t₁, t₂, n; world) into `frames` (`contact_count` matrices). The restitution and friction of
/// the contacts are validated but not used.
///
/// Errors: MECH_STATUS_BAD_DIMENSION for rows ≠ 3·contact_count or a wrong `body_count`;
/// otherwise as mech_impulse_mechanism_contacts.
///
/// # Safety
/// `tree` must be a live handle; `bodies` must point to `body_count` readable values,
/// `contacts` to `contact_count` readable values, `delassus` to rows² writable doubles,
/// `frames` to `contact_count` writable matrices, `rank_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_impulse_mechanism_delassus(
    tree: *mut mech_tree_t,
    bodies: *const mech_mass_properties_t,
    body_count: usize,
    contacts: *const mech_mechanism_contact_t,
    contact_count: usize,
    delassus: *mut f64,
    rows: usize,
    frames: *mut mech_mat3_t,
    rank_out: *mut usize,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { mech_tree_t::borrow_mut(tree, "tree") }?;
        // SAFETY: caller's contract.
        let raw = unsafe { read_slice(contacts, contact_count, "contacts") }?;
        let expected = 3 * contact_count;
        if rows != expected {
            return Err(FfiError::new(
                MECH_STATUS_BAD_DIMENSION,
                format!("rows must be 3·contact_count = {expected}, got {rows}"),
            ));
        }
        let size = square_len(rows, "delassus")?;
        let dest = OutSlice::new(delassus, size, "delassus")?;
        let frames_out = OutSlice::new(frames, contact_count, "frames")?;
        let rank_out = Out::new(rank_out, "rank_out")?;
        let (kt, ws) = t.built()?;
        let list = contacts_from_c(raw)?;
        // SAFETY: caller's contract.
        let inertia = unsafe { tree_inertia(kt, ws, bodies, body_count) }?;
        ws.check_velocities()?; // the velocities of mech_tree_set_state must be in place
        let q_dot = ws.q_dot().to_vec();
        let space = ContactSpace::new(kt, ws, &inertia, &q_dot, &list)?;
        let frame_values: Vec<mech_mat3_t> = (0..contact_count)
            .map(|i| space.frame(i).copied().unwrap_or_else(Matrix3::identity).into())
            .collect();
        // SAFETY: caller's contract.
        unsafe {
            dest.write(space.delassus());
            frames_out.write(&frame_values);
            rank_out.write(space.rank());
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_options_are_the_solver_defaults_and_are_accepted() {
        let mut written = mech_multi_contact_options_t::default();
        // SAFETY: `written` is a writable options struct.
        assert_eq!(
            unsafe { mech_multi_contact_options_default(&mut written) },
            MECH_STATUS_OK
        );
        // SAFETY: `written` is a readable options struct.
        let read_back = unsafe { read_options(&written) }.expect("the defaults are valid");
        assert_eq!(mech_multi_contact_options_t::from(&read_back), written);
        assert_eq!(written.tolerance, 1e-10);
        assert_eq!(written.max_iterations, 10_000);
        assert_eq!(written.process_tolerance, 1e-10);
    }
}
