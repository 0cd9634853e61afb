//! The dynamics step of a scene with `[[constraint]]` tables: q0 and q̇ projected onto
//! f(q) = 0 and J q̇ = 0, the forward dynamics with Lagrange multipliers (the KKT system of
//! FM 4.61) and the reactions of every constraint, and on request the constrained equilibrium
//! (FM 4.83–4.86).

pub(crate) mod records;

use crate::report::{Step, timed_step};
use crate::scene::{ConstraintSpec, DynamicsSpec, Scene};
use crate::scene_run::{Model, coordinate_names};
use mechanica::dynamics::{
    ConstrainedDynamics, ConstrainedEquilibriumOptions, ConstrainedForward, Constraint, ConstraintReaction, Dynamics,
    ProjectionOptions, State,
};
use mechanica::kinematics::nalgebra::Vector3;
use mechanica::mechanism::Anchor;
use records::{ConstrainedEquilibriumRecord, ConstrainedForwardRecord, ConstraintReactionRecord, ProjectionRecord};

/// The state of a scene with constraints: coordinates, velocities and applied forces.
pub struct StartState {
    /// q0 of the scene (before projection).
    pub q: Vec<f64>,
    /// q̇ of the scene (before projection).
    pub q_dot: Vec<f64>,
    /// Applied generalized forces τ.
    pub tau: Vec<f64>,
}

/// Runs the constrained dynamics steps on `dynamics` (the scene's mechanism and dampers).
pub fn run(
    scene: &Scene,
    model: &Model,
    dynamics: Dynamics,
    spec: &DynamicsSpec,
    start: StartState,
    steps: &mut Vec<Step>,
) -> Result<(), String> {
    let mut constrained = build(scene, model, dynamics)?;
    let names = coordinate_names(model);
    let mut state = None;
    steps.push(timed_step(
        "constraints: q0 and q̇ projected onto f(q) = 0 and J q̇ = 0 (least kinetic metric)",
        || {
            let record = project(&mut constrained, &start, &names)?;
            state = Some((record.q.clone(), record.q_dot.clone()));
            Ok::<_, String>(record)
        },
    )?);
    let (q, q_dot) = state.ok_or("internal: projected state missing")?;
    steps.push(timed_step(
        "dynamics: forward q̈ and multipliers λ from [A Jᵀ; J 0] (FM 4.61)",
        || {
            let result = constrained
                .forward_dynamics(&State::new(&q, &q_dot), &start.tau)
                .map_err(|e| format!("analyses.dynamics: constrained forward dynamics: {e}"))?;
            Ok::<_, String>(forward_record(&constrained, &result, &names))
        },
    )?);
    if spec.equilibrium {
        steps.push(timed_step(
            "equilibrium: ∇U + Jᵀλ = 0, f(q) = 0 near q0 (FM 4.83–4.86)",
            || equilibrium_record(&mut constrained, &q, &names),
        )?);
    }
    Ok(())
}

/// The scene's constraints on `dynamics`, named as in the scene.
pub(crate) fn build(scene: &Scene, model: &Model, dynamics: Dynamics) -> Result<ConstrainedDynamics, String> {
    let mut constrained = ConstrainedDynamics::new(dynamics);
    for (i, spec) in scene.constraints.iter().enumerate() {
        let name = spec.name.clone().unwrap_or_else(|| format!("constraint[{i}]"));
        let constraint = constraint_of(scene, model, spec).map_err(|e| format!("constraint[{i}]: {e}"))?;
        constrained
            .add_constraint(name, constraint)
            .map_err(|e| format!("constraint[{i}]: {e}"))?;
    }
    Ok(constrained)
}

/// The library's constraint for one validated scene table.
fn constraint_of(scene: &Scene, model: &Model, spec: &ConstraintSpec) -> Result<Constraint, String> {
    let anchor = |end: &Option<toml::Spanned<String>>, point: [f64; 3]| {
        let name = end.as_ref().map_or("ground", |n| n.get_ref().as_str());
        Anchor {
            body: scene.bodies.iter().position(|b| b.name.get_ref() == name),
            point: Vector3::from(point),
        }
    };
    let (a, b) = (anchor(&spec.a, spec.a_point), anchor(&spec.b, spec.b_point));
    Ok(match spec.kind.get_ref().as_str() {
        "points" => match &spec.directions {
            Some(directions) => Constraint::PointsCoincide {
                a,
                b,
                directions: directions.get_ref().iter().map(|d| Vector3::from(*d)).collect(),
            },
            None => Constraint::points_coincide(a, b),
        },
        "plane" => Constraint::PointOnPlane {
            point: a,
            normal: Vector3::from(*spec.normal.as_ref().ok_or("no normal")?.get_ref()),
            offset: spec.offset,
        },
        "distance" => Constraint::Distance {
            a,
            b,
            length: *spec.length.as_ref().ok_or("no length")?.get_ref(),
        },
        _ => {
            let joint = spec.joint.as_ref().ok_or("no joint")?.get_ref();
            let body = model
                .joint_body
                .iter()
                .find(|(name, _)| name == joint)
                .map(|(_, b)| *b)
                .ok_or_else(|| format!("no joint \"{joint}\""))?;
            let index = model.tree.dof_range(body).start + *spec.coordinate.get_ref();
            let value = spec.value.as_ref().map_or(model.q0[index], |v| *v.get_ref());
            Constraint::Coordinate { index, value }
        }
    })
}

/// The projected (q, q̇) with what the projection moved and what is left.
fn project(
    constrained: &mut ConstrainedDynamics,
    start: &StartState,
    names: &[String],
) -> Result<ProjectionRecord, String> {
    let positions = constrained
        .project_positions(&start.q, &ProjectionOptions::default())
        .map_err(|e| format!("analyses.dynamics: q0 cannot be brought onto the constraints: {e}"))?;
    let velocities = constrained
        .project_velocities(&positions.q, &start.q_dot)
        .map_err(|e| format!("analyses.dynamics: velocity projection: {e}"))?;
    let moved: f64 = positions.q.iter().zip(&start.q).map(|(a, b)| (a - b).powi(2)).sum();
    Ok(ProjectionRecord {
        coordinates: names.to_vec(),
        q: positions.q,
        moved: moved.sqrt(),
        constraint_residual: positions.residual,
        iterations: positions.iterations,
        tolerance: positions.tolerance,
        q_dot: velocities.q_dot,
        velocity_removed: velocities.removed,
        velocity_residual: velocities.residual,
    })
}

fn forward_record(
    constrained: &ConstrainedDynamics,
    result: &ConstrainedForward,
    names: &[String],
) -> ConstrainedForwardRecord {
    ConstrainedForwardRecord {
        coordinates: names.to_vec(),
        q_ddot: result.q_ddot.clone(),
        multipliers: result.multipliers.clone(),
        backward_error: result.backward_error,
        mass_condition: result.mass_condition,
        schur_condition: result.schur_condition,
        position_drift: result.position_drift,
        velocity_drift: result.velocity_drift,
        reactions: reaction_records(constrained, &result.reactions),
    }
}

/// Per constraint: the force on its first point and the generalized force −Jᵢᵀλᵢ.
fn reaction_records(
    constrained: &ConstrainedDynamics,
    reactions: &[ConstraintReaction],
) -> Vec<ConstraintReactionRecord> {
    reactions
        .iter()
        .map(|reaction| ConstraintReactionRecord {
            constraint: constrained
                .constraint_name(reaction.constraint)
                .unwrap_or("?")
                .to_string(),
            force: reaction.point.map(|_| reaction.force.into()),
            generalized_force: reaction.generalized_force.clone(),
        })
        .collect()
}

fn equilibrium_record(
    constrained: &mut ConstrainedDynamics,
    q: &[f64],
    names: &[String],
) -> Result<ConstrainedEquilibriumRecord, String> {
    let result = constrained
        .equilibrium(q, &ConstrainedEquilibriumOptions::default())
        .map_err(|e| format!("analyses.dynamics: constrained equilibrium: {e}"))?;
    Ok(ConstrainedEquilibriumRecord {
        coordinates: names.to_vec(),
        q: result.q.clone(),
        potential: result.potential,
        multipliers: result.multipliers.clone(),
        stationarity: result.stationarity,
        stationarity_tolerance: result.stationarity_tolerance,
        constraint_norm: result.constraint_norm,
        constraint_tolerance: result.constraint_tolerance,
        iterations: result.iterations,
        reactions: reaction_records(constrained, &result.reactions),
    })
}
