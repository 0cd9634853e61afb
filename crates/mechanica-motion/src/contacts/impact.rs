//! The impact at a located event: q̇⁺ = q̇⁻ + A⁻¹JᵀP with P from the impulse crate
//! (7.115–7.117), the energy before and after it, and its [`ImpactEvent`] record.

use super::gap::Gap;
use super::{ImpactEvent, UnilateralContact};
use crate::error::StepFailure;
use crate::integrator::{Integrator, Point};
use mechanica_dynamics::DynamicsError;
use mechanica_impulse::{MechanismContact, MechanismInertia, MultiContactOptions, resolve_contacts};

/// Resolves the impact of the contacts `hitting` (closing, with gaps `gaps`) at the state
/// reached by `run`, applies the velocity jump to `run` and restarts its monitors' reference
/// there. `segment_start` is H after the previous impact (or at t = 0).
pub(crate) fn resolve(
    run: &mut Integrator,
    contacts: &[UnilateralContact],
    (hitting, gaps): (&[usize], &[Gap]),
    segment_start: f64,
) -> Result<ImpactEvent, StepFailure> {
    let point = run.point();
    let n = point.q.len();
    let mass = run.system_mut().mass_matrix(&point.q)?;
    let inertia = MechanismInertia::from_mass_matrix(n, mass.as_slice().to_vec())
        .map_err(|e| StepFailure::Impact(Box::new(e)))?;
    let tree = run.system().dynamics().tree();
    let kinematics = |e| StepFailure::Dynamics(DynamicsError::Kinematics(e));
    let mut ws = tree.workspace();
    tree.update_positions(&mut ws, &point.q).map_err(kinematics)?;
    tree.update_velocities(&mut ws, &point.q_dot).map_err(kinematics)?;
    let list: Vec<MechanismContact> = hitting.iter().map(|&i| contacts[i].contact).collect();
    let options = MultiContactOptions::default();
    let impact = resolve_contacts(tree, &ws, &inertia, &point.q_dot, &list, &options)
        .map_err(|e| StepFailure::Impact(Box::new(e)))?;
    if !impact.converged {
        return Err(StepFailure::NotConverged {
            what: "simultaneous impact",
            iterations: impact.iterations,
            correction: impact.complementarity_residual,
        });
    }
    let before = run.system_mut().measure(&point.q, &point.q_dot)?;
    run.jump_velocity(&impact.q_dot_after);
    let after = run.system_mut().measure(&point.q, &impact.q_dot_after)?;
    if let Some(tracker) = run.tracker_mut() {
        tracker.rebase(&after);
    }
    let reported_before = run.report(&point)?;
    let reported_after = run.report(&Point {
        q_dot: impact.q_dot_after.clone(),
        ..point.clone()
    })?;
    Ok(ImpactEvent {
        t: point.t,
        contacts: hitting.to_vec(),
        gap: hitting.iter().map(|&i| gaps[i].value).fold(f64::INFINITY, f64::min),
        approach_speed: hitting.iter().map(|&i| -gaps[i].rate).fold(0.0, f64::max),
        impulses: impact.contacts.iter().map(|c| c.impulse_w).collect(),
        modes: impact.contacts.iter().map(|c| c.mode).collect(),
        kinetic_energy_before: impact.energy_before,
        energy_before: before.energy,
        energy_after: after.energy,
        segment_drift: before.energy - segment_start,
        impulse_error: impact.integration_error.max(impact.complementarity_residual),
        q_dot_before: reported_before.q_dot,
        q_dot_after: reported_after.q_dot,
    })
}
