//! The mechanism analyses of a scene (equilibrium, stability, modes, free response), run only
//! when the scene asks for them.

use crate::plots::{EnergyBalance, ModeShape, PlotData, ResponseSeries};
use crate::report::{Step, timed_step};
use crate::scene::Scene;
use crate::scene_run::{Model, quantity};
use mechanica::impulse::{
    BodyPoint, ContactLaw, ImpactOptions, MechanismContact, MechanismInertia, RestitutionLaw, resolve_single_contact,
};
use mechanica::kinematics::nalgebra::{Unit, Vector3};
use mechanica::mass::mechanism::TreeMass;
use mechanica::mechanism::potentials::{ConstantForce, JointSpring, PointSpring};
use mechanica::mechanism::{
    Anchor, EquilibriumOptions, Mechanism, MechanismModes, RotatingFrame, Seek, Stability, find_equilibria,
    find_equilibrium, mechanism_modes, mechanism_modes_with_locks,
};
use mechanica::modal::response::FreeResponse;
use mechanica::modal::{ModeKind, PencilProblem, Selection, SolveOptions};

/// Builds the mechanism of a scene: tree, masses, gravity, rotating frame, springs, forces,
/// limits.
pub fn build_mechanism(scene: &Scene, model: &Model) -> Result<Mechanism, String> {
    let text = |e: &dyn std::fmt::Display| e.to_string();
    let mut mechanism = Mechanism::new(model.tree.clone(), model.bodies.clone()).map_err(|e| text(&e))?;
    if let Some(g) = scene.gravity {
        mechanism.set_gravity(Vector3::from(g)).map_err(|e| text(&e))?;
    }
    if let Some(frame) = &scene.rotating_frame {
        mechanism
            .set_rotating_frame(Some(RotatingFrame {
                axis: Unit::new_normalize(Vector3::from(*frame.axis.get_ref())),
                rate: frame.rate,
            }))
            .map_err(|e| format!("rotating_frame: {e}"))?;
    }
    let body_index = |name: &str| scene.bodies.iter().position(|b| b.name.get_ref() == name);
    let anchor = |name: &str, point: [f64; 3]| Anchor {
        body: if name == "ground" { None } else { body_index(name) },
        point: Vector3::from(point),
    };
    for (i, spring) in scene.joint_springs.iter().enumerate() {
        let body = model
            .joint_body
            .iter()
            .find(|(n, _)| n == spring.joint.get_ref())
            .map(|(_, b)| *b)
            .ok_or_else(|| format!("joint_spring[{i}]: no joint \"{}\"", spring.joint.get_ref()))?;
        let range = model.tree.dof_range(body);
        let coordinate = *spring.coordinate.get_ref();
        if coordinate >= range.len() {
            return Err(format!(
                "joint_spring[{i}].coordinate: the joint has {} coordinates, got index {coordinate}",
                range.len(),
            ));
        }
        mechanism
            .add_potential(JointSpring {
                coordinate: range.start + coordinate,
                stiffness: spring.stiffness,
                rest: spring.rest,
            })
            .map_err(|e| format!("joint_spring[{i}]: {e}"))?;
    }
    for (i, spring) in scene.springs.iter().enumerate() {
        mechanism
            .add_potential(PointSpring {
                a: anchor(spring.a.get_ref(), spring.a_point),
                b: anchor(spring.b.get_ref(), spring.b_point),
                stiffness: spring.stiffness,
                rest_length: spring.rest_length,
            })
            .map_err(|e| format!("spring[{i}]: {e}"))?;
    }
    for (i, force) in scene.forces.iter().enumerate() {
        let body = body_index(force.body.get_ref()).ok_or_else(|| format!("force[{i}]: unknown body"))?;
        mechanism
            .add_potential(ConstantForce {
                body,
                point: Vector3::from(force.point),
                force: Vector3::from(force.force),
            })
            .map_err(|e| format!("force[{i}]: {e}"))?;
    }
    for (k, limit) in model.limits.iter().enumerate() {
        if let Some([lower, upper]) = limit {
            mechanism.set_limits(k, *lower, *upper).map_err(|e| text(&e))?;
        }
    }
    Ok(mechanism)
}

fn stability_note(stability: &Stability) -> String {
    match stability {
        Stability::Stable => "stable: every mode oscillates (B positive definite relative to A)".into(),
        Stability::Unstable {
            directions,
            max_growth_rate,
        } => format!("unstable: {directions} unstable direction(s), fastest growth rate {max_growth_rate:.6e} 1/s"),
        Stability::Marginal { zero_modes } => {
            format!("marginal: {zero_modes} zero mode(s) within their error bounds, none unstable")
        }
    }
}

/// Runs the requested mechanism analyses, appending steps and plot data.
pub fn run(scene: &Scene, model: &Model, steps: &mut Vec<Step>, plots: &mut PlotData) -> Result<(), String> {
    let analyses = &scene.analyses;
    if let Some(impact) = &analyses.impact {
        steps.push(impact_step(scene, model, impact, plots)?);
    }
    if analyses.equilibrium.is_none() && analyses.modes.is_none() {
        return Ok(());
    }
    let (build, mut mechanism) = build_step(scene, model)?;
    steps.push(build);
    let mut q = model.q0.clone();
    let mut locked: Vec<usize> = Vec::new();
    if let Some(spec) = &analyses.equilibrium {
        let options = EquilibriumOptions {
            seek: match spec.seek.as_ref().map(|s| s.get_ref().as_str()) {
                Some("stationary") => Seek::Stationary,
                _ => Seek::Minimum,
            },
            max_iterations: spec.max_iterations.unwrap_or(100),
            ..EquilibriumOptions::default()
        };
        let mut step = equilibrium_step(&mut mechanism, &mut q, &mut locked, &options)?;
        if !spec.starts.is_empty() {
            let starts: Vec<Vec<f64>> = spec.starts.iter().map(|s| s.get_ref().clone()).collect();
            add_equilibria_from_starts(&mut step, &mut mechanism, &q, &starts, &options)?;
        }
        steps.push(step);
    }
    let Some(spec) = &analyses.modes else { return Ok(()) };
    let (step, modes) = modes_step(&mut mechanism, &q, &locked, spec)?;
    steps.push(step);
    record_mode_plots(&modes, plots);
    if let Some(response) = &analyses.response {
        steps.push(response_step(&modes, response.get_ref(), plots)?);
    }
    Ok(())
}

/// The timed step building the scene's mechanism, and the mechanism.
fn build_step(scene: &Scene, model: &Model) -> Result<(Step, Mechanism), String> {
    let mut built = None;
    let step = timed_step("build: mechanism (potentials, frame)", || {
        let mechanism = build_mechanism(scene, model)?;
        let quantities = vec![quantity(
            "potentials",
            vec![mechanism.potentials().len() as f64],
            "",
            None,
        )];
        built = Some(mechanism);
        Ok::<_, String>(quantities)
    })?;
    let mechanism = built.ok_or("internal: mechanism not built")?;
    Ok((step, mechanism))
}

/// The timed equilibrium search from `q`: on success `q` becomes the equilibrium and `locked`
/// the coordinates resting on a joint limit there.
fn equilibrium_step(
    mechanism: &mut Mechanism,
    q: &mut Vec<f64>,
    locked: &mut Vec<usize>,
    options: &EquilibriumOptions,
) -> Result<Step, String> {
    let recentred = mechanism.has_rotation_vectors();
    let mut notes = Vec::new();
    let mut step = timed_step("equilibrium: Newton on grad U* (8.74)", || {
        let eq = find_equilibrium(mechanism, q, options).map_err(|e| e.to_string())?;
        let quantities = vec![
            quantity("q at equilibrium", eq.q.clone(), "rad | m", None),
            quantity(
                "|grad U*| at equilibrium",
                vec![eq.gradient_norm],
                "J",
                Some(format!(
                    "tolerance {:.1e}, {} Newton iterations, last step {:.1e}",
                    eq.tolerance, eq.iterations, eq.last_step
                )),
            ),
            quantity("U* at equilibrium", vec![eq.potential], "J", None),
        ];
        *q = eq.q;
        *locked = eq.at_limit;
        if recentred {
            notes.push(
                "spherical/free joints were re-centred on the equilibrium: their rotation vectors read 0 in the new chart; bodies did not move"
                    .to_string(),
            );
        }
        Ok::<_, String>(quantities)
    })?;
    step.notes.append(&mut notes);
    Ok(step)
}

/// Searches from `q` and every further start, and adds to `step` each distinct equilibrium
/// found (apart by more than 1e-8 in some coordinate) with its stability.
fn add_equilibria_from_starts(
    step: &mut Step,
    mechanism: &mut Mechanism,
    q: &[f64],
    further_starts: &[Vec<f64>],
    options: &EquilibriumOptions,
) -> Result<(), String> {
    let mut starts = further_starts.to_vec();
    starts.insert(0, q.to_vec());
    let progress = crate::progress::bar(starts.len() as u64, "equilibria from several starts");
    let mut found = Vec::new();
    let mut failed = 0;
    for start in &starts {
        let (eqs, f) = find_equilibria(mechanism, std::slice::from_ref(start), options).map_err(|e| e.to_string())?;
        failed += f;
        for eq in eqs {
            let fresh = found
                .iter()
                .all(|other: &Vec<f64>| other.iter().zip(&eq.q).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) > 1e-8);
            if fresh {
                found.push(eq.q);
            }
        }
        progress.inc(1);
    }
    progress.finish_and_clear();
    step.notes.push(format!(
        "{} distinct equilibria from {} starts ({} did not converge)",
        found.len(),
        starts.len(),
        failed
    ));
    for (i, eq) in found.iter().enumerate() {
        step.quantities
            .push(quantity(&format!("equilibrium {i}"), eq.clone(), "rad | m", None));
        let verdict = mechanism_modes(&mut mechanism.clone(), eq, &SolveOptions::default())
            .map(|m| stability_note(&m.stability))
            .unwrap_or_else(|e| format!("stability unknown: {e}"));
        step.notes.push(format!("equilibrium {i}: {verdict}"));
    }
    Ok(())
}

/// The timed modes at `q` with the `locked` coordinates held fixed, with notes on stability,
/// the gyroscopic problem, a non-equilibrium `q` and the locks; and the modes.
fn modes_step(
    mechanism: &mut Mechanism,
    q: &[f64],
    locked: &[usize],
    spec: &crate::scene::ModesSpec,
) -> Result<(Step, MechanismModes), String> {
    let options = SolveOptions {
        selection: spec
            .lowest
            .as_ref()
            .map_or(Selection::All, |k| Selection::Lowest(*k.get_ref())),
        ..SolveOptions::default()
    };
    let mut modes: Option<MechanismModes> = None;
    let mut step = timed_step("modes: det(λA + B) = 0 at the equilibrium (8.84–8.92)", || {
        let m = mechanism_modes_with_locks(mechanism, q, locked, &options).map_err(|e| e.to_string())?;
        let quantities = mode_quantities(&m);
        modes = Some(m);
        Ok::<_, String>(quantities)
    })?;
    let modes = modes.ok_or("internal: modes missing")?;
    let finite = |m: &&mechanica::modal::Mode| m.omega_sq.is_finite() && m.error_bound.is_finite();
    let massive = |m: &&mechanica::modal::Mode| !matches!(m.kind, ModeKind::Infinite);
    if let Some(mode) = modes.solution.modes.iter().filter(massive).find(|m| !finite(m)) {
        let value = if mode.omega_sq.is_finite() {
            mode.error_bound
        } else {
            mode.omega_sq
        };
        return Err(crate::report::NonFiniteResult {
            analysis: step.analysis.clone(),
            quantity: "ω² of a finite mode or its error bound".into(),
            value,
        }
        .to_string());
    }
    step.notes.push(stability_note(&modes.stability));
    if let Some(gyro) = &modes.gyroscopic {
        step.notes.push(format!(
            "rotating frame: gyroscopic problem det(s²A + sG + B) = 0 solved; max Re s = {:.3e} (bound {:.1e}) → {}",
            gyro.max_real_part,
            gyro.real_part_bound,
            if gyro.stable {
                "stable (possibly gyroscopically stabilised)"
            } else {
                "unstable"
            }
        ));
    }
    if modes.gradient_norm > 1e-6 * modes.stiffness_matrix.norm_l2().max(1.0) {
        step.notes.push(format!(
            "warning: |grad U*| = {:.2e} at this configuration: it is not an equilibrium; the modes are those of the linearisation",
            modes.gradient_norm
        ));
    }
    if !locked.is_empty() {
        step.notes.push(format!(
            "coordinates {locked:?} rest on joint limits at the equilibrium and are held fixed for the modes"
        ));
    }
    Ok((step, modes))
}

/// Puts the spectrum and the first six mode shapes into the plot data.
fn record_mode_plots(modes: &MechanismModes, plots: &mut PlotData) {
    plots.spectrum = modes
        .solution
        .modes
        .iter()
        .map(|m| (m.omega_sq, matches!(m.kind, ModeKind::Oscillatory { .. })))
        .collect();
    if let Some(x) = &modes.solution.vectors {
        plots.shapes = (0..x.ncols().min(6))
            .map(|k| ModeShape {
                label: mode_label(modes, k),
                values: (0..x.nrows()).map(|r| x[(r, k)]).collect(),
            })
            .collect();
    }
}

fn mode_label(modes: &MechanismModes, k: usize) -> String {
    match modes.solution.modes[k].kind {
        ModeKind::Oscillatory { omega } => format!("mode {} — {:.4} Hz", k + 1, omega / std::f64::consts::TAU),
        ModeKind::Zero => format!("mode {} — zero", k + 1),
        ModeKind::Unstable { growth_rate } => format!("mode {} — unstable, γ = {growth_rate:.4} 1/s", k + 1),
        ModeKind::Infinite => format!("mode {} — infinite", k + 1),
        ModeKind::Undecided => format!("mode {} — undecided (ω² ± bound contains 0)", k + 1),
    }
}

/// The mode quantities that are +∞ for the infinite modes of massless directions.
pub(crate) const INFINITE_FOR_MASSLESS_MODES: [&str; 3] = [OMEGA_SQ, OMEGA, FREQUENCY];
const OMEGA_SQ: &str = "ω² (8.89: λ = −ω²)";
const OMEGA: &str = "ω";
const FREQUENCY: &str = "f = ω/2π";

fn mode_quantities(m: &MechanismModes) -> Vec<crate::report::Quantity> {
    let modes = &m.solution.modes;
    let omega: Vec<f64> = modes
        .iter()
        .map(|mode| match mode.kind {
            ModeKind::Oscillatory { omega } => omega,
            ModeKind::Infinite => f64::INFINITY,
            _ => 0.0,
        })
        .collect();
    let bound = modes.iter().map(|mode| mode.error_bound).fold(0.0, f64::max);
    let accuracy = &m.solution.accuracy;
    let mut out = vec![
        quantity(
            OMEGA_SQ,
            modes.iter().map(|mode| mode.omega_sq).collect(),
            "rad²/s²",
            Some(format!(
                "max error bound {bound:.1e}; max backward error {:.1e}; A-orthogonality error {:.1e}; Sturm check {}",
                accuracy.max_backward_error.unwrap_or(0.0),
                accuracy.orthogonality_error.unwrap_or(0.0),
                match &accuracy.inertia_check {
                    Some(c) if c.consistent => "consistent",
                    Some(_) => "INCONSISTENT",
                    None => "not run",
                }
            )),
        ),
        quantity(OMEGA, omega.clone(), "rad/s", None),
        quantity(
            FREQUENCY,
            omega.iter().map(|w| w / std::f64::consts::TAU).collect(),
            "Hz",
            None,
        ),
    ];
    for (k, masses) in m.effective_masses.iter().enumerate().take(6) {
        out.push(quantity(
            &format!("mode {} effective mass (x, y, z)", k + 1),
            masses.to_vec(),
            "kg",
            None,
        ));
    }
    for (k, bodies) in m.body_displacements.iter().enumerate().take(3) {
        for (i, d) in bodies.iter().enumerate() {
            out.push(quantity(
                &format!("mode {} body {i}: centre-of-mass translation, rotation", k + 1),
                d.translation.iter().chain(d.rotation.iter()).copied().collect(),
                "m | rad per unit amplitude",
                None,
            ));
        }
    }
    if let Some(x) = &m.solution.vectors {
        for k in 0..x.ncols().min(6) {
            out.push(quantity(
                &format!("mode {} shape in q (A-normalised)", k + 1),
                (0..x.nrows()).map(|r| x[(r, k)]).collect(),
                "",
                None,
            ));
        }
    }
    out
}

/// The free response δ(t) from the scene's initial disturbance, sampled `spec.samples` times
/// over the span (the sample count was checked against the scene limits when the scene was
/// read; the series are still allocated fallibly).
fn response_step(
    modes: &MechanismModes,
    spec: &crate::scene::ResponseSpec,
    plots: &mut PlotData,
) -> Result<Step, String> {
    let n = modes.q.len();
    timed_step("free response δ(t) by modal superposition (8.91)", || {
        if modes.mass_matrix.nrows() != n || modes.solution.modes.len() != n {
            return Err(
                "analyses.response: the free response needs every mode of every coordinate (no `lowest`, no coordinate resting on a joint limit)"
                    .to_string(),
            );
        }
        let zeros = vec![0.0; n];
        let delta0 = spec.dq0.as_ref().map_or(&zeros, |v| v.get_ref());
        let v0 = spec.v0.as_ref().map_or(&zeros, |v| v.get_ref());
        let problem = PencilProblem::new(modes.mass_matrix.as_ref(), modes.stiffness_matrix.as_ref())
            .map_err(|e| e.to_string())?;
        let response =
            FreeResponse::new(&problem, &modes.solution, delta0, v0).map_err(|e| format!("analyses.response: {e}"))?;
        let duration = *spec.duration.get_ref();
        let (series, end) = sample_response(&response, duration, *spec.samples.get_ref(), n)?;
        let fit = response.fit();
        let end_bound = response.error_bound(duration).map_err(|e| e.to_string())?;
        let quantities = vec![
            quantity(
                "δ(T) at the end of the span",
                end,
                "rad | m",
                Some(format!("error bound {end_bound:.1e}")),
            ),
            quantity(
                "initial-state fit residual (δ, δ̇)",
                vec![fit.displacement_residual, fit.velocity_residual],
                "",
                None,
            ),
        ];
        plots.response = Some(series);
        Ok(quantities)
    })
}

/// `samples` ≥ 2 equally spaced values of δ(t) over [0, `duration`] (n coordinates each), and
/// δ at the end; an error instead of an abort when the series cannot be allocated.
fn sample_response(
    response: &FreeResponse,
    duration: f64,
    samples: usize,
    n: usize,
) -> Result<(ResponseSeries, Vec<f64>), String> {
    let reserve = |v: &mut Vec<f64>| {
        v.try_reserve_exact(samples)
            .map_err(|_| format!("analyses.response.samples: cannot allocate {samples} samples"))
    };
    let mut series = ResponseSeries {
        times: Vec::new(),
        values: vec![Vec::new(); n],
    };
    reserve(&mut series.times)?;
    for values in &mut series.values {
        reserve(values)?;
    }
    let mut out = vec![0.0; n];
    for i in 0..samples {
        let t = duration * i as f64 / (samples - 1) as f64;
        response.at(t, &mut out).map_err(|e| e.to_string())?;
        series.times.push(t);
        for (k, v) in out.iter().enumerate() {
            series.values[k].push(*v);
        }
    }
    Ok((series, out))
}

fn law_named(name: &str) -> RestitutionLaw {
    match name {
        "newton" => RestitutionLaw::Newton,
        "poisson" => RestitutionLaw::Poisson,
        _ => RestitutionLaw::Stronge,
    }
}

/// One impact of a body point against the ground at (q0, qd0), by Lagrange's impulse equations
/// (7.115–7.117) and the impulse-parameterised contact process.
fn impact_step(
    scene: &Scene,
    model: &Model,
    spec: &crate::scene::ImpactSpec,
    plots: &mut PlotData,
) -> Result<Step, String> {
    let text = |e: &dyn std::fmt::Display| format!("analyses.impact: {e}");
    let chosen = spec.law.as_ref().map_or("stronge", |l| l.get_ref().as_str());
    timed_step(
        &format!("impact: body point on the ground, {chosen} law (7.115–7.117)"),
        || {
            let body = scene
                .bodies
                .iter()
                .position(|b| b.name.get_ref() == spec.body.get_ref())
                .ok_or_else(|| text(&"unknown body"))?;
            let tree = &model.tree;
            let mut ws = tree.workspace();
            tree.update_positions(&mut ws, &model.q0).map_err(|e| text(&e))?;
            tree.update_velocities(&mut ws, &model.qd0).map_err(|e| text(&e))?;
            let mut masses = TreeMass::new(tree, model.bodies.clone()).map_err(|e| text(&e))?;
            let inertia = MechanismInertia::new(tree, &ws, &mut masses).map_err(|e| text(&e))?;
            let mut laws = vec![chosen];
            if spec.compare_laws {
                laws.extend(["newton", "poisson", "stronge"].into_iter().filter(|l| *l != chosen));
            }
            let mut quantities = Vec::new();
            let mut balance = EnergyBalance { laws: Vec::new() };
            for name in laws {
                let law = ContactLaw::new(spec.restitution, spec.friction, law_named(name)).map_err(|e| text(&e))?;
                let contact = MechanismContact {
                    point: BodyPoint {
                        body,
                        p_bq: Vector3::from(spec.point),
                    },
                    other: None,
                    normal_w: Vector3::from(spec.normal),
                    law,
                };
                let impact =
                    resolve_single_contact(tree, &ws, &inertia, &model.qd0, &contact, &ImpactOptions::default())
                        .map_err(|e| text(&e))?;
                let outcome = impact.contacts.first().ok_or_else(|| text(&"no contact outcome"))?;
                let after = impact.energy_before + impact.energy_change;
                balance.laws.push((name.to_string(), impact.energy_before, after));
                let accuracy = Some(format!(
                    "integration error {:.1e} N·s, mode {:?}",
                    impact.integration_error, outcome.mode
                ));
                quantities.push(quantity(
                    &format!("{name}: impulse on the body (world)"),
                    outcome.impulse_w.iter().copied().collect(),
                    "N·s",
                    accuracy,
                ));
                quantities.push(quantity(
                    &format!("{name}: q̇ after"),
                    impact.q_dot_after.clone(),
                    "rad/s | m/s",
                    None,
                ));
                quantities.push(quantity(
                    &format!("{name}: T before, ΔT (7.107)"),
                    vec![impact.energy_before, impact.energy_change],
                    "J",
                    None,
                ));
            }
            plots.impact = Some(balance);
            Ok(quantities)
        },
    )
    .map(|mut step| {
        if let Some(impact) = &plots.impact {
            for (law, before, after) in &impact.laws {
                if after > before {
                    step.notes.push(format!(
                        "{law}: the impact GAINS energy ({:.4e} J): Kane's paradox",
                        after - before
                    ));
                }
            }
        }
        step
    })
}
