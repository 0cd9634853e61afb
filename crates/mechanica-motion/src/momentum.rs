//! The linear and angular momentum of a whole mechanism (M.15)–(M.16), the first integrals
//! that the monitors follow beside H and the cyclic momenta.
//!
//! Both are sums over the bodies of (3.4) and (3.12) with (3.6), with each body's centre velocity
//! and angular velocity from the tree's velocity recursion. They are taken in the mechanism's
//! frame W with its base at rest: for a prescribed base motion or a rotating frame they are
//! the momenta relative to that frame, which are not first integrals.

use crate::error::{MotionError, StepFailure};
use mechanica_dynamics::DynamicsError;
use mechanica_kinematics::tree::{KinematicTree, Workspace};
use mechanica_mass::MassProperties;
use mechanica_mechanism::Mechanism;
use nalgebra::Vector3;

/// The momenta of a whole mechanism at one state, world components (frame W of the tree).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SystemMomentum {
    /// P = Σ mᵢ vᵢ (M.15), kg·m/s: vᵢ is the velocity of body i's centre of mass.
    pub linear: Vector3<f64>,
    /// L = Σ (J_c,i ωᵢ + cᵢ × mᵢ vᵢ) about the origin of W (M.16), kg·m²/s.
    pub angular: Vector3<f64>,
}

/// P and L (M.15)–(M.16) of `mechanism` at (q, q̇) (charts of the mechanism as given).
/// Fails with [`MotionError::WrongLength`] or [`MotionError::NonFiniteInput`] for a bad
/// state, and with [`MotionError::Dynamics`] when the kinematics cannot be evaluated.
pub fn system_momentum(mechanism: &Mechanism, q: &[f64], q_dot: &[f64]) -> Result<SystemMomentum, MotionError> {
    let n = mechanism.dof();
    crate::error::check_vector(q, n, "q")?;
    crate::error::check_vector(q_dot, n, "q_dot")?;
    let mut ws = mechanism.tree().workspace();
    momentum_into(mechanism.tree(), mechanism.bodies(), &mut ws, q, q_dot).map_err(|cause| match cause {
        StepFailure::Dynamics(e) => MotionError::Dynamics(e),
        _ => MotionError::NonFiniteResult { what: "momentum" },
    })
}

/// P and L with the workspace `ws` of `tree` (base at rest), `bodies` in body frames.
pub(crate) fn momentum_into(
    tree: &KinematicTree,
    bodies: &[MassProperties],
    ws: &mut Workspace,
    q: &[f64],
    q_dot: &[f64],
) -> Result<SystemMomentum, StepFailure> {
    let kinematics = |e| StepFailure::Dynamics(DynamicsError::from(e));
    tree.update_positions(ws, q).map_err(kinematics)?;
    tree.update_velocities(ws, q_dot).map_err(kinematics)?;
    let mut linear = Vector3::zeros();
    let mut angular = Vector3::zeros();
    for (i, body) in bodies.iter().enumerate() {
        let rotation = ws.rotation(i).map_err(kinematics)?;
        let centre = ws.point_position(i, &body.p_oc).map_err(kinematics)?;
        let v_c = ws.point_velocity(i, &body.p_oc).map_err(kinematics)?;
        let omega = ws.angular_velocity(i).map_err(kinematics)?;
        let world = MassProperties {
            mass: body.mass,
            p_oc: centre,
            inertia_c: rotation.matrix() * body.inertia_c * rotation.matrix().transpose(),
        };
        linear += world.linear_momentum(&v_c);
        angular += world.angular_momentum_about(&Vector3::zeros(), &v_c, &omega);
    }
    if linear.iter().chain(angular.iter()).any(|x| !x.is_finite()) {
        return Err(StepFailure::NonFinite { what: "momentum" });
    }
    Ok(SystemMomentum { linear, angular })
}
