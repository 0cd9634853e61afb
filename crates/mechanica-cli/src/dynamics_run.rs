//! The dynamics step of a scene: at q0, the forward dynamics q̈ for the applied forces τ and the
//! inverse dynamics τ = A q̈ + c + g − Σ Q (Lagrange's equations (7.60)) with its split and the
//! joint reactions, with the scene's dampers; then the damped modes about q0
//! ([`crate::damped_run`]). A scene with constraints goes to [`crate::constraint_run`].

pub(crate) mod records;

use crate::report::{Step, timed_step};
use crate::scene::{DynamicsSpec, Scene};
use crate::scene_run::{Model, coordinate_names};
use mechanica::dynamics::{Damper, Dynamics, ForwardDynamics, ForwardMethod, Frame, InverseDynamics, State};
use mechanica::kinematics::nalgebra::Vector3;
use mechanica::mechanism::Anchor;
use records::{ForwardMethodName, ForwardRecord, InverseRecord, JointReaction, LoadRecord};

/// Runs the dynamics step when the scene asks for it.
pub fn run(scene: &Scene, model: &Model, steps: &mut Vec<Step>) -> Result<(), String> {
    let Some(spec) = &scene.analyses.dynamics else {
        return Ok(());
    };
    let mut dynamics = build_dynamics(scene, model)?;
    let n = model.q0.len();
    let vector = |values: &Option<toml::Spanned<Vec<f64>>>, default: &[f64]| {
        values
            .as_ref()
            .map_or_else(|| default.to_vec(), |v| v.get_ref().clone())
    };
    let q_dot = vector(&spec.q_dot, &model.qd0);
    let zeros = vec![0.0; n];
    let tau = vector(&spec.tau, &zeros);
    if !scene.constraints.is_empty() {
        let start = crate::constraint_run::StartState {
            q: model.q0.clone(),
            q_dot,
            tau,
        };
        return crate::constraint_run::run(scene, model, dynamics, spec, start, steps);
    }
    let state = State::new(&model.q0, &q_dot);
    let names = coordinate_names(model);
    let mut forward = None;
    steps.push(timed_step(
        "dynamics: forward q̈ = A⁻¹ (τ + Σ Q − c − g) at q0 (7.60)",
        || {
            let result = dynamics
                .forward_dynamics(&state, &tau)
                .map_err(|e| format!("analyses.dynamics: forward dynamics: {e}"))?;
            let record = forward_record(&result, &names);
            forward = Some(result);
            Ok::<_, String>(record)
        },
    )?);
    let forward = forward.ok_or("internal: forward dynamics missing")?;
    let q_ddot = vector(&spec.q_ddot, &forward.q_ddot);
    let step = timed_step(
        "dynamics: inverse τ = A q̈ + c + g − Σ Q and joint reactions (RNEA)",
        || {
            let result = dynamics
                .inverse_dynamics(&state, &q_ddot)
                .map_err(|e| format!("analyses.dynamics: inverse dynamics: {e}"))?;
            inverse_record(&dynamics, &result, &q_ddot, model, spec)
        },
    )?;
    steps.push(step);
    steps.push(crate::damped_run::step(&mut dynamics, &model.q0));
    Ok(())
}

/// The scene's mechanism (potentials, frame) with its joint and point dampers.
pub(crate) fn build_dynamics(scene: &Scene, model: &Model) -> Result<Dynamics, String> {
    let mechanism = crate::mechanism_run::build_mechanism(scene, model)?;
    let mut dynamics = Dynamics::new(mechanism).map_err(|e| format!("analyses.dynamics: {e}"))?;
    for (i, damper) in scene.joint_dampers.iter().enumerate() {
        let body = model
            .joint_body
            .iter()
            .find(|(name, _)| name == damper.joint.get_ref())
            .map(|(_, b)| *b)
            .ok_or_else(|| format!("joint_damper[{i}]: no joint \"{}\"", damper.joint.get_ref()))?;
        let coordinate = model.tree.dof_range(body).start + *damper.coordinate.get_ref();
        dynamics
            .add_damper(Damper::Joint {
                coordinate,
                coefficient: *damper.damping.get_ref(),
            })
            .map_err(|e| format!("joint_damper[{i}]: {e}"))?;
    }
    let body_index = |name: &str| scene.bodies.iter().position(|b| b.name.get_ref() == name);
    let anchor = |name: &str, point: [f64; 3]| Anchor {
        body: if name == "ground" { None } else { body_index(name) },
        point: Vector3::from(point),
    };
    for (i, damper) in scene.dampers.iter().enumerate() {
        let (a, b) = (
            anchor(damper.a.get_ref(), damper.a_point),
            anchor(damper.b.get_ref(), damper.b_point),
        );
        let coefficient = *damper.damping.get_ref();
        let element = if damper.axial {
            Damper::Dashpot { a, b, coefficient }
        } else {
            Damper::Points { a, b, coefficient }
        };
        dynamics.add_damper(element).map_err(|e| format!("damper[{i}]: {e}"))?;
    }
    Ok(dynamics)
}

fn forward_record(result: &ForwardDynamics, names: &[String]) -> ForwardRecord {
    ForwardRecord {
        coordinates: names.to_vec(),
        q_ddot: result.q_ddot.clone(),
        method: match result.method {
            ForwardMethod::ArticulatedBody => ForwardMethodName::ArticulatedBody,
            _ => ForwardMethodName::MassMatrix,
        },
        backward_error: result.backward_error,
        condition: result.condition,
        error_estimate: result.error_estimate.filter(|e| e.is_finite()),
        residual: result.residual.clone(),
        dissipation: result.dissipation,
    }
}

/// τ with its split, and one reaction per joint: the force and the moment about the joint
/// origin that the parent exerts on the body through the joint, in the requested frame.
fn inverse_record(
    dynamics: &Dynamics,
    result: &InverseDynamics,
    q_ddot: &[f64],
    model: &Model,
    spec: &DynamicsSpec,
) -> Result<InverseRecord, String> {
    let name = spec.frame.as_ref().map_or("world", |f| f.get_ref().as_str());
    let frame = match name {
        "body" => Frame::Body,
        "joint" => Frame::Joint,
        _ => Frame::World,
    };
    let mut reactions = Vec::with_capacity(result.reactions.len());
    for reaction in &result.reactions {
        let wrench = reaction
            .expressed_in(dynamics, frame)
            .map_err(|e| format!("analyses.dynamics: {e}"))?;
        let joint = model
            .joint_body
            .iter()
            .find(|(_, b)| *b == reaction.body)
            .map_or("?", |(n, _)| n.as_str());
        reactions.push(JointReaction {
            joint: joint.to_string(),
            force: wrench.force.into(),
            moment: wrench.moment.into(),
        });
    }
    Ok(InverseRecord {
        coordinates: coordinate_names(model),
        q_ddot: q_ddot.to_vec(),
        tau: result.tau.clone(),
        rounding_estimate: result.error_estimate.iter().copied().fold(0.0, f64::max),
        velocity_product: result.velocity_product.clone(),
        gravity: result.gravity.clone(),
        loads: result
            .loads
            .iter()
            .map(|load| LoadRecord {
                name: load.name.clone(),
                force: load.force.clone(),
            })
            .collect(),
        frame: name.to_string(),
        reactions,
    })
}
