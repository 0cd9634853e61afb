//! Mass properties of a kinematic tree: the mass matrix A(q), kinetic energy and momenta, the
//! centre of mass with its Jacobian, and the energy split on a moving base.

use super::{mech_mass_properties_t, raw_properties};
use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::handle::Handle;
use crate::ffi::kinematics::{check_dof, mech_tree_t};
use crate::ffi::spatial::read_vec3;
use crate::ffi::status::*;
use crate::ffi::types::*;
use crate::ffi::validate::*;
use mechanica_kinematics::tree::{KinematicTree, Workspace};
use mechanica_mass::mechanism::{DragField, EnergySplit, SplitBuffers, TreeMass};

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

/// The body mass properties of the last mass call on a tree handle, as given and validated,
/// with the recursion's state and an output buffer: repeated calls with the same bodies skip
/// the validation and allocate nothing.
#[derive(Debug)]
pub(crate) struct TreeMassCache {
    bodies: Vec<mech_mass_properties_t>,
    mass: TreeMass,
    matrix: Vec<f64>,
}

/// The recursion's state for the per-body mass properties `bodies` (one entry per body,
/// `body_count` of them) of a finalized tree with positions set, taken from the handle's cache
/// when the bodies are the same as last time, with the tree, its workspace and a scratch
/// buffer for the mass matrix.
///
/// # Safety
/// `tree` must be a live handle; `bodies` must point to `body_count` readable entries.
unsafe fn tree_mass<'a>(
    tree: *mut mech_tree_t,
    bodies: *const mech_mass_properties_t,
    body_count: usize,
) -> Result<(&'a mut TreeMass, &'a KinematicTree, &'a Workspace, &'a mut Vec<f64>), FfiError> {
    // SAFETY: caller's contract.
    let t = unsafe { mech_tree_t::borrow_mut(tree, "tree") }?;
    // SAFETY: caller's contract.
    let raw = unsafe { read_slice(bodies, body_count, "bodies") }?;
    if t.built.is_none() {
        t.built()?; // the "not finalized" error
    }
    let Some((kt, ws)) = &t.built else {
        return unreachable_state();
    };
    let fresh = !matches!(&t.mass_cache, Some(cache) if cache.bodies.as_slice() == raw);
    if fresh {
        t.mass_cache = None;
        let props = raw.iter().map(raw_properties).collect();
        let mass = TreeMass::new(kt, props)?;
        t.mass_cache = Some(TreeMassCache {
            bodies: raw.to_vec(),
            mass,
            matrix: Vec::new(),
        });
    }
    match &mut t.mass_cache {
        Some(cache) => Ok((&mut cache.mass, kt, ws, &mut cache.matrix)),
        None => unreachable_state(),
    }
}

/// The error for a state the code above rules out (a cache just filled, a tree just checked).
fn unreachable_state<T>() -> Result<T, FfiError> {
    Err(FfiError::new(
        MECH_STATUS_PANIC,
        "internal: tree mass cache missing".to_string(),
    ))
}

/// The mass matrix A(q) = [α_kl] (syllabus 8.28) of a finalized tree at the coordinates of the
/// last mech_tree_set_state, by the composite-rigid-body recursion, into `a_out` (n×n doubles,
/// column-major, n = dof; kg, kg·m or kg·m² per the coordinates' units). `bodies` holds one
/// mass-properties value per body (`body_count` = the tree's body count), each in its own body
/// frame; masses may be 0 (massless links).
///
/// Errors: MECH_STATUS_BAD_DIMENSION (n ≠ dof, n = 0, body_count ≠ body count);
/// MECH_STATUS_NON_FINITE or MECH_STATUS_INVALID_ARGUMENT for a body's numbers or a negative
/// mass (the message names the body); MECH_STATUS_INVALID_ARGUMENT when the tree is not
/// finalized or no state is set.
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
        let (mass, kt, ws, a) = unsafe { tree_mass(tree, bodies, body_count) }?;
        check_dof(kt, n, "a_out")?;
        a.clear();
        a.resize(len, 0.0);
        mass.mass_matrix(kt, ws, a)?;
        // SAFETY: caller's contract.
        unsafe { dest.write(a) };
        Ok(())
    })
}

/// The kinetic energy T = ½ q̇ᵀ A q̇ (J, syllabus 8.27) into `energy_out` and the generalized
/// momenta ∂T/∂q̇ = A q̇ (`momenta_out`, n = dof doubles) of a tree on a fixed base, at the
/// state (q, q̇) of the last mech_tree_set_state. `bodies` as in mech_tree_mass_matrix. For a
/// moving base use mech_tree_energy_split.
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
        let (mass, kt, ws, _) = unsafe { tree_mass(tree, bodies, body_count) }?;
        check_dof(kt, n, "momenta_out")?;
        ws.check_velocities()?; // the velocities of mech_tree_set_state must be in place
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

/// The centre of mass x₀ of the whole tree and its Jacobian ∂x₀/∂q (3×n doubles into
/// `jacobian_out`, column-major, n = dof; world components) at the coordinates of the last
/// mech_tree_set_state. `system_out` receives the mass properties of the whole system in world
/// components (total mass, centre, central inertia). `bodies` as in mech_tree_mass_matrix.
///
/// Errors: as mech_tree_mass_matrix, and MECH_STATUS_INVALID_ARGUMENT when the total mass is 0.
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
        let len = product(3, n, "n")?;
        let j_out = OutSlice::new(jacobian_out, len, "jacobian_out")?;
        // SAFETY: caller's contract.
        let (mass, kt, ws, _) = unsafe { tree_mass(tree, bodies, body_count) }?;
        check_dof(kt, n, "jacobian_out")?;
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

/// The split T = T₀ + T₁ + T₂ (J, syllabus 9.7–9.10) of a tree whose base moves with angular
/// velocity `base_omega` (rad/s) and base-origin velocity `base_velocity` (m/s), both in world
/// components, so that the drag velocity of a point x is ∂x/∂t = v₀ + ω₀ × (x − p₀), at the
/// state (q, q̇) of the last mech_tree_set_state. The base pose p₀, R₀ is the tree's (see
/// mech_tree_set_base, whose ω₀ and v₀ these normally are; taking them here keeps the split
/// available for a base at rest in the tree's frame). Writes the split to `split_out`,
/// b(q, t) = ∂T₁/∂q̇ to `b_out` and the generalized momenta ∂T/∂q̇ = A q̇ + b to `momenta_out`
/// (n = dof doubles each). `bodies` as in mech_tree_mass_matrix.
///
/// Errors: as mech_tree_kinetic_energy, and MECH_STATUS_NON_FINITE for the base vectors.
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
        let (mass, kt, ws, _) = unsafe { tree_mass(tree, bodies, body_count) }?;
        check_dof(kt, n, "b_out and momenta_out")?;
        ws.check_velocities()?; // the velocities of mech_tree_set_state must be in place
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
