//! The dynamics step of a scene with `[[constraint]]` tables: q0 and q̇ projected onto
//! f(q) = 0 and J q̇ = 0, the forward dynamics with Lagrange multipliers (the KKT system of
//! FM 4.61) and the reactions of every constraint, and on request the constrained equilibrium
//! (FM 4.83–4.86).

use crate::report::{Quantity, Step, timed_step};
use crate::scene::{ConstraintSpec, DynamicsSpec, Scene};
use crate::scene_run::{Model, quantity};
use mechanica::dynamics::{
    ConstrainedDynamics, ConstrainedEquilibriumOptions, ConstrainedForward, Constraint, ConstraintReaction, Dynamics,
    ProjectionOptions, State,
};
use mechanica::kinematics::nalgebra::Vector3;
use mechanica::mechanism::Anchor;

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
    let mut state = None;
    steps.push(timed_step(
        "constraints: q0 and q̇ projected onto f(q) = 0 and J q̇ = 0 (least kinetic metric)",
        || {
            let (quantities, q, q_dot) = project(&mut constrained, &start)?;
            state = Some((q, q_dot));
            Ok::<_, String>(quantities)
        },
    )?);
    let (q, q_dot) = state.ok_or("internal: projected state missing")?;
    steps.push(timed_step(
        "dynamics: forward q̈ and multipliers λ from [A Jᵀ; J 0] (FM 4.61)",
        || {
            let result = constrained
                .forward_dynamics(&State::new(&q, &q_dot), &start.tau)
                .map_err(|e| format!("analyses.dynamics: constrained forward dynamics: {e}"))?;
            Ok::<_, String>(forward_quantities(&constrained, &result))
        },
    )?);
    if spec.equilibrium {
        steps.push(timed_step(
            "equilibrium: ∇U + Jᵀλ = 0, f(q) = 0 near q0 (FM 4.83–4.86)",
            || equilibrium_quantities(&mut constrained, &q),
        )?);
    }
    Ok(())
}

/// The scene's constraints on `dynamics`, named as in the scene.
fn build(scene: &Scene, model: &Model, dynamics: Dynamics) -> Result<ConstrainedDynamics, String> {
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

/// The report of a projection, the projected q and the projected q̇.
type Projected = (Vec<Quantity>, Vec<f64>, Vec<f64>);

/// The projected (q, q̇) with what the projection moved and what is left.
fn project(constrained: &mut ConstrainedDynamics, start: &StartState) -> Result<Projected, String> {
    let positions = constrained
        .project_positions(&start.q, &ProjectionOptions::default())
        .map_err(|e| format!("analyses.dynamics: q0 cannot be brought onto the constraints: {e}"))?;
    let velocities = constrained
        .project_velocities(&positions.q, &start.q_dot)
        .map_err(|e| format!("analyses.dynamics: velocity projection: {e}"))?;
    let moved: f64 = positions.q.iter().zip(&start.q).map(|(a, b)| (a - b).powi(2)).sum();
    let quantities = vec![
        quantity("q on the constraints", positions.q.clone(), "rad | m", None),
        quantity(
            "‖q − q0‖₂, ‖f(q)‖₂",
            vec![moved.sqrt(), positions.residual],
            "",
            Some(format!(
                "{} Gauss–Newton iteration(s); tolerance on ‖f‖₂ {:.1e}",
                positions.iterations, positions.tolerance
            )),
        ),
        quantity("q̇ with J q̇ = 0", velocities.q_dot.clone(), "rad/s | m/s", None),
        quantity(
            "‖J q̇‖₂ before, after",
            vec![velocities.removed, velocities.residual],
            "m/s | rad/s",
            None,
        ),
    ];
    Ok((quantities, positions.q, velocities.q_dot))
}

fn forward_quantities(constrained: &ConstrainedDynamics, result: &ConstrainedForward) -> Vec<Quantity> {
    let accuracy = format!(
        "backward error {:.1e}; κ(A) = {:.2e}, κ(J A⁻¹ Jᵀ) = {:.2e}",
        result.backward_error, result.mass_condition, result.schur_condition
    );
    let mut out = vec![
        quantity(
            "q̈ (constrained forward dynamics)",
            result.q_ddot.clone(),
            "rad/s² | m/s²",
            Some(accuracy),
        ),
        quantity(
            "λ (one per constraint equation)",
            result.multipliers.clone(),
            "N | N·m",
            None,
        ),
        quantity(
            "drift ‖f(q)‖₂, ‖J q̇‖₂",
            vec![result.position_drift, result.velocity_drift],
            "",
            None,
        ),
    ];
    out.extend(reaction_quantities(constrained, &result.reactions));
    out
}

/// Per constraint: the force on its first point and the generalized force −Jᵢᵀλᵢ.
fn reaction_quantities(constrained: &ConstrainedDynamics, reactions: &[ConstraintReaction]) -> Vec<Quantity> {
    let mut out = Vec::with_capacity(2 * reactions.len());
    for reaction in reactions {
        let name = constrained.constraint_name(reaction.constraint).unwrap_or("?");
        if reaction.point.is_some() {
            out.push(quantity(
                &format!("reaction of \"{name}\": force on its first point (world)"),
                reaction.force.iter().copied().collect(),
                "N",
                None,
            ));
        }
        out.push(quantity(
            &format!("reaction of \"{name}\": generalized force −Jᵀλ"),
            reaction.generalized_force.clone(),
            "N·m | N",
            None,
        ));
    }
    out
}

fn equilibrium_quantities(constrained: &mut ConstrainedDynamics, q: &[f64]) -> Result<Vec<Quantity>, String> {
    let result = constrained
        .equilibrium(q, &ConstrainedEquilibriumOptions::default())
        .map_err(|e| format!("analyses.dynamics: constrained equilibrium: {e}"))?;
    let accuracy = format!(
        "‖∇U + Jᵀλ‖₂ = {:.1e} ≤ {:.1e}, ‖f‖₂ = {:.1e} ≤ {:.1e}; {} Newton iteration(s)",
        result.stationarity,
        result.stationarity_tolerance,
        result.constraint_norm,
        result.constraint_tolerance,
        result.iterations
    );
    let mut out = vec![
        quantity(
            "q at the constrained equilibrium",
            result.q.clone(),
            "rad | m",
            Some(accuracy),
        ),
        quantity("U at the equilibrium", vec![result.potential], "J", None),
        quantity("λ at the equilibrium", result.multipliers.clone(), "N | N·m", None),
    ];
    out.extend(reaction_quantities(constrained, &result.reactions));
    Ok(out)
}
