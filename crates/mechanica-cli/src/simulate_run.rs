//! The `simulate` step of a scene: the motion from (q0, qd0) integrated to t_end by the chosen
//! method of `mechanica-motion` (docs/theory.md, "Integration in time"), with the global error
//! estimate of its companion run (M.12)–(M.13) and the drift of the energy or Jacobi integral
//! (M.1)–(M.2); the trajectory optionally written as CSV and JSON, and plotted with `--plot`.
//! A scene with `[[constraint]]` tables is simulated with its constraints kept (RATTLE (M.17),
//! or projection after each step (M.19)), and the constraint drift (M.20) is reported.

mod record;

use crate::plots::{PlotData, SimulationSeries};
use crate::report::{Step, timed_step};
use crate::scene::{Scene, SimulateSpec};
use crate::scene_run::Model;
use mechanica::impulse::{BodyPoint, ContactLaw, MechanismContact};
use mechanica::kinematics::nalgebra::Vector3;
use mechanica::motion::{
    Forcing, ImpactEvent, Invariant, Method, MotionError, Options, Simulation, Trajectory, UnilateralContact,
};
pub use record::SimulateRecord;
use record::{ConstraintRecord, ImpactEventRecord, InvariantName, MethodName, MonitorRecord};
use std::path::Path;

/// Runs the simulation when the scene asks for it.
pub fn run(
    scene: &Scene,
    file: &Path,
    model: &Model,
    steps: &mut Vec<Step>,
    plots: &mut PlotData,
) -> Result<(), String> {
    let Some(spec) = &scene.analyses.simulate else {
        return Ok(());
    };
    let dynamics = crate::dynamics_run::build_dynamics(scene, model)?;
    let options = Options {
        forcing: spec
            .tau
            .as_ref()
            .map_or(Forcing::None, |tau| Forcing::Constant(tau.get_ref().clone())),
        estimate_error: spec.estimate_error.unwrap_or(true),
        max_steps: spec.step_limit(),
        ..Options::default()
    };
    let method = method_of(spec);
    let constrained = crate::constraint_run::build(scene, model, dynamics)?;
    let simulation = Simulation::constrained(constrained, method, options)
        .and_then(|s| s.with_contacts(contacts_of(scene)?))
        .map_err(|e| format!("analyses.simulate: {e}"))?;
    let names = crate::scene_run::coordinate_names(model);
    let mut trajectory = None;
    let kept = match (scene.constraints.is_empty(), scene.contacts.is_empty()) {
        (false, _) => ", constraints kept (M.17)–(M.19)",
        (true, false) => ", impacts at the contacts located and resolved (M.21)–(M.23)",
        _ => "",
    };
    let title = format!(
        "simulate: motion from (q0, qd0) to t = {} s by {} (M.3)–(M.11){kept}, error by a companion run (M.13)",
        spec.t_end.get_ref(),
        describe(spec)
    );
    let mut step = timed_step(&title, || {
        let result = integrate(&simulation, model, spec)?;
        let mut record = summary(spec, &result, &names, !scene.constraints.is_empty());
        if !scene.contacts.is_empty() {
            record.impacts = Some(result.impacts.iter().map(|e| impact_record(scene, e)).collect());
        }
        trajectory = Some(result);
        Ok::<_, String>(record)
    })?;
    let trajectory = trajectory.ok_or("internal: trajectory missing")?;
    for (path, text) in outputs(spec, file, &trajectory, &names)? {
        std::fs::write(&path, text).map_err(|e| format!("analyses.simulate: {}: {e}", path.display()))?;
        if let crate::report::Record::Simulate(record) = &mut step.record {
            record.files.push(path.display().to_string());
        }
    }
    plots.simulation = Some(series(&trajectory, names));
    steps.push(step);
    Ok(())
}

/// The scene's contacts for the library (validated by the scene: bodies exist, numbers are
/// finite, the normal is non-zero and is normalised here). Body indices are the scene's order.
fn contacts_of(scene: &Scene) -> Result<Vec<UnilateralContact>, MotionError> {
    let index = |name: &str| scene.bodies.iter().position(|b| b.name.get_ref() == name);
    let mut contacts = Vec::with_capacity(scene.contacts.len());
    for (i, spec) in scene.contacts.iter().enumerate() {
        let invalid = |reason: String| MotionError::InvalidContact { index: i, reason };
        let body = index(spec.body.get_ref()).ok_or_else(|| invalid("unknown body".into()))?;
        let other = match &spec.other {
            Some(name) => Some(BodyPoint {
                body: index(name.get_ref()).ok_or_else(|| invalid("unknown other body".into()))?,
                p_bq: Vector3::from(spec.other_point),
            }),
            None => None,
        };
        let law_kind = crate::mechanism_run::law_named(spec.law_name());
        let law = ContactLaw::new(spec.restitution(), spec.friction(), law_kind).map_err(|e| invalid(e.to_string()))?;
        // Scaled by its largest component first, so that neither 1e308 nor 1e-320 components
        // overflow or underflow the length.
        let normal = Vector3::from(*spec.normal.get_ref());
        let normal = normal / normal.amax();
        contacts.push(UnilateralContact {
            contact: MechanismContact {
                point: BodyPoint {
                    body,
                    p_bq: Vector3::from(spec.point),
                },
                other,
                normal_w: normal / normal.norm(),
                law,
            },
            offset: spec.offset,
        });
    }
    Ok(contacts)
}

/// The report's record of one impact, with the contacts named.
fn impact_record(scene: &Scene, event: &ImpactEvent) -> ImpactEventRecord {
    ImpactEventRecord {
        t: event.t,
        contacts: event
            .contacts
            .iter()
            .map(|&i| {
                scene
                    .contacts
                    .get(i)
                    .map_or_else(|| format!("contact[{i}]"), |c| c.label(i))
            })
            .collect(),
        impulses: event.impulses.iter().map(|p| [p.x, p.y, p.z]).collect(),
        modes: event
            .modes
            .iter()
            .map(|m| crate::mechanism_run::contact_mode(*m))
            .collect(),
        gap: event.gap,
        approach_speed: event.approach_speed,
        kinetic_energy_before: event.kinetic_energy_before,
        energy_before: event.energy_before,
        energy_after: event.energy_after,
        energy_lost: event.energy_lost(),
        segment_drift: event.segment_drift,
        impulse_error: event.impulse_error,
        q_dot_before: event.q_dot_before.clone(),
        q_dot_after: event.q_dot_after.clone(),
    }
}

/// The library's method for the scene's name and parameters (validated by the scene).
fn method_of(spec: &SimulateSpec) -> Method {
    let step = spec.step.as_ref().map_or(0.0, |s| *s.get_ref());
    match spec.method_name() {
        "rk4" => Method::Rk4 { step },
        "verlet" => Method::StormerVerlet { step },
        "midpoint" => Method::ImplicitMidpoint { step },
        "rattle" => Method::Rattle { step },
        _ => {
            let rtol = spec.tolerance.as_ref().map_or(1e-8, |t| *t.get_ref());
            Method::DormandPrince {
                rtol,
                atol: spec.atol.as_ref().map_or(rtol, |a| *a.get_ref()),
            }
        }
    }
}

/// The method in words, with its parameter.
fn describe(spec: &SimulateSpec) -> String {
    match method_of(spec) {
        Method::Rk4 { step } => format!("RK4 with step {step} s"),
        Method::StormerVerlet { step } => format!("Störmer–Verlet with step {step} s"),
        Method::ImplicitMidpoint { step } => format!("the implicit midpoint rule with step {step} s"),
        Method::Rattle { step } => format!("RATTLE with step {step} s"),
        Method::DormandPrince { rtol, atol } => format!("Dormand–Prince 5(4), rtol {rtol:e}, atol {atol:e}"),
        _ => "an integrator".into(),
    }
}

/// The run, with a progress bar over the samples; a failed step names the time and state.
fn integrate(simulation: &Simulation, model: &Model, spec: &SimulateSpec) -> Result<Trajectory, String> {
    let (t_end, interval) = (*spec.t_end.get_ref(), spec.interval());
    let samples = ((t_end / interval).ceil() + 1.0) as u64;
    let bar = crate::progress::bar(samples, "simulate");
    let q_dot = spec.q_dot.as_ref().map_or(&model.qd0, |v| v.get_ref());
    let result = simulation.run_observed(&model.q0, q_dot, t_end, interval, &mut |_| bar.inc(1));
    bar.finish_and_clear();
    result.map_err(|e| match e {
        MotionError::StepFailed { t, q, q_dot, cause } => format!(
            "analyses.simulate: the integration failed at t = {t} s ({cause}); last good q = {q:?}, q̇ = {q_dot:?}"
        ),
        other => format!("analyses.simulate: {other}"),
    })
}

/// The final state with its estimated error, the largest estimate over the run, the costs,
/// the monitor of the conserved quantity and, for a `constrained` scene, the constraint drift.
fn summary(spec: &SimulateSpec, trajectory: &Trajectory, names: &[String], constrained: bool) -> SimulateRecord {
    let (method, step, rtol, atol) = match method_of(spec) {
        Method::Rk4 { step } => (MethodName::Rk4, Some(step), None, None),
        Method::StormerVerlet { step } => (MethodName::Verlet, Some(step), None, None),
        Method::ImplicitMidpoint { step } => (MethodName::Midpoint, Some(step), None, None),
        Method::Rattle { step } => (MethodName::Rattle, Some(step), None, None),
        Method::DormandPrince { rtol, atol } => (MethodName::DormandPrince, None, Some(rtol), Some(atol)),
        _ => (MethodName::DormandPrince, None, None, None),
    };
    let last = trajectory.samples.last();
    let error = last.and_then(|s| s.error);
    let worst = trajectory
        .samples
        .iter()
        .filter_map(|s| s.error)
        .fold((0.0f64, 0.0f64), |(a, b), e| (a.max(e.q), b.max(e.q_dot)));
    let m = &trajectory.monitors;
    SimulateRecord {
        method,
        step,
        rtol,
        atol,
        t_end: *spec.t_end.get_ref(),
        coordinates: names.to_vec(),
        q_end: last.map_or_else(Vec::new, |s| s.q.clone()),
        q_dot_end: last.map_or_else(Vec::new, |s| s.q_dot.clone()),
        error_q_end: error.map(|e| e.q),
        error_q_dot_end: error.map(|e| e.q_dot),
        max_error_q: error.map(|_| worst.0),
        max_error_q_dot: error.map(|_| worst.1),
        steps: trajectory.steps,
        companion_steps: trajectory.companion_steps,
        monitor: MonitorRecord {
            invariant: match m.invariant {
                Invariant::JacobiIntegral => InvariantName::JacobiIntegral,
                _ => InvariantName::Energy,
            },
            initial: m.initial,
            max_drift: m.max_drift,
            last_drift: m.last_drift,
            scale: m.scale,
        },
        constraints: constrained.then_some(ConstraintRecord {
            max_position_drift: m.constraints.max_position,
            max_velocity_drift: m.constraints.max_velocity,
        }),
        impacts: None,
        files: Vec::new(),
    }
}

/// The CSV and JSON files the scene asks for, with their contents.
fn outputs(
    spec: &SimulateSpec,
    file: &Path,
    trajectory: &Trajectory,
    names: &[String],
) -> Result<Vec<(std::path::PathBuf, String)>, String> {
    let dir = file.parent().unwrap_or(Path::new("."));
    let mut out = Vec::new();
    if let Some(csv) = &spec.csv {
        out.push((dir.join(csv), crate::trajectory_file::csv(trajectory, names)));
    }
    if let Some(json) = &spec.json {
        out.push((dir.join(json), crate::trajectory_file::json(trajectory, names)?));
    }
    Ok(out)
}

/// The series of the plots: motion, energy drift and estimated error over time.
fn series(trajectory: &Trajectory, names: Vec<String>) -> SimulationSeries {
    let samples = &trajectory.samples;
    let initial = trajectory.monitors.initial;
    let scale = trajectory.monitors.scale;
    // H(0) minus the losses of the impacts up to t: what H would be without integrator drift.
    let booked = |t: f64| {
        let lost: f64 = trajectory
            .impacts
            .iter()
            .filter(|i| i.t <= t)
            .map(ImpactEvent::energy_lost)
            .sum();
        initial - lost
    };
    SimulationSeries {
        times: samples.iter().map(|s| s.t).collect(),
        coordinates: (0..names.len())
            .map(|k| samples.iter().map(|s| s.q[k]).collect())
            .collect(),
        names,
        drift: samples.iter().map(|s| (s.energy - booked(s.t)).abs() / scale).collect(),
        error_q: samples.iter().map(|s| s.error.map_or(f64::NAN, |e| e.q)).collect(),
        error_q_dot: samples.iter().map(|s| s.error.map_or(f64::NAN, |e| e.q_dot)).collect(),
    }
}
