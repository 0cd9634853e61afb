//! The mechanism analyses of a scene (equilibrium, stability, modes, free response), run only
//! when the scene asks for them.

pub(crate) mod records;

use crate::mode_record::{BodyMotion, ModeRecord};
use crate::plots::{EnergyBalance, PlotData, ResponseSeries};
use crate::report::{Step, timed_step};
use crate::scene::Scene;
use crate::scene_run::{Model, coordinate_names};
use mechanica::impulse::{
    BodyPoint, ContactLaw, ContactMode, ImpactOptions, MechanismContact, MechanismInertia, RestitutionLaw,
    resolve_single_contact,
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
use records::{
    ContactModeName, EquilibriumRecord, FoundEquilibrium, GyroscopicRecord, ImpactLawRecord, ImpactRecord,
    MechanismRecord, ModalAccuracy, ModesRecord, MultiStartRecord, ResponseRecord, StabilityRecord, SturmStatus,
    Verdict,
};

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

/// The typed verdict of `stability`.
pub(crate) fn stability_record(stability: &Stability) -> StabilityRecord {
    match *stability {
        Stability::Stable => StabilityRecord {
            verdict: Verdict::Stable,
            unstable_directions: 0,
            max_growth_rate: None,
            zero_modes: 0,
            undecided_modes: 0,
        },
        Stability::Unstable {
            directions,
            max_growth_rate,
        } => StabilityRecord {
            verdict: Verdict::Unstable,
            unstable_directions: directions,
            max_growth_rate: Some(max_growth_rate),
            zero_modes: 0,
            undecided_modes: 0,
        },
        Stability::Marginal { zero_modes } => StabilityRecord {
            verdict: Verdict::Marginal,
            unstable_directions: 0,
            max_growth_rate: None,
            zero_modes,
            undecided_modes: 0,
        },
        Stability::Undecided {
            undecided_modes,
            zero_modes,
        } => StabilityRecord {
            verdict: Verdict::Undecided,
            unstable_directions: 0,
            max_growth_rate: None,
            zero_modes,
            undecided_modes,
        },
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
    let names = coordinate_names(model);
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
        let mut step = timed_step("equilibrium: Newton on grad U* (8.74)", || {
            equilibrium_search(&mut mechanism, &mut q, &mut locked, &options, &names)
        })?;
        if !spec.starts.is_empty() {
            let starts: Vec<Vec<f64>> = spec.starts.iter().map(|s| s.get_ref().clone()).collect();
            let multi = equilibria_from_starts(&mut mechanism, &q, &starts, &options)?;
            if let crate::report::Record::Equilibrium(r) = &mut step.record {
                r.multi_start = Some(multi);
            }
        }
        steps.push(step);
    }
    let Some(spec) = &analyses.modes else { return Ok(()) };
    let bodies: Vec<String> = scene.bodies.iter().map(|b| b.name.get_ref().clone()).collect();
    let (step, modes) = modes_step(&mut mechanism, &q, &locked, spec, &names, &bodies)?;
    steps.push(step);
    record_mode_plots(&modes, &recentred(&mechanism, &q), &bodies, scene.gravity, plots);
    if let Some(response) = &analyses.response {
        steps.push(response_step(&modes, response.get_ref(), plots, &names)?);
    }
    Ok(())
}

/// The timed step building the scene's mechanism, and the mechanism.
fn build_step(scene: &Scene, model: &Model) -> Result<(Step, Mechanism), String> {
    let mut built = None;
    let step = timed_step("build: mechanism (potentials, frame)", || {
        let mechanism = build_mechanism(scene, model)?;
        let record = MechanismRecord {
            potentials: mechanism.potentials().len(),
        };
        built = Some(mechanism);
        Ok::<_, String>(record)
    })?;
    let mechanism = built.ok_or("internal: mechanism not built")?;
    Ok((step, mechanism))
}

/// The equilibrium search from `q`: on success `q` becomes the equilibrium and `locked` the
/// coordinates resting on a joint limit there.
fn equilibrium_search(
    mechanism: &mut Mechanism,
    q: &mut Vec<f64>,
    locked: &mut Vec<usize>,
    options: &EquilibriumOptions,
    names: &[String],
) -> Result<EquilibriumRecord, String> {
    let recentred = mechanism.has_rotation_vectors();
    let eq = find_equilibrium(mechanism, q, options).map_err(|e| e.to_string())?;
    let record = EquilibriumRecord {
        coordinates: names.to_vec(),
        q: eq.q.clone(),
        gradient_norm: eq.gradient_norm,
        tolerance: eq.tolerance,
        iterations: eq.iterations,
        last_step: eq.last_step,
        potential: eq.potential,
        locked: named(names, &eq.at_limit),
        recentred,
        multi_start: None,
    };
    *q = eq.q;
    *locked = eq.at_limit;
    Ok(record)
}

/// The names of the coordinates `indices`.
fn named(names: &[String], indices: &[usize]) -> Vec<String> {
    indices
        .iter()
        .map(|&k| names.get(k).cloned().unwrap_or_else(|| format!("q[{k}]")))
        .collect()
}

/// Searches from `q` and every further start; each distinct equilibrium found (apart by more
/// than 1e-8 in some coordinate) with its stability.
fn equilibria_from_starts(
    mechanism: &mut Mechanism,
    q: &[f64],
    further_starts: &[Vec<f64>],
    options: &EquilibriumOptions,
) -> Result<MultiStartRecord, String> {
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
    let equilibria = found
        .into_iter()
        .map(|eq| {
            let modes = mechanism_modes(&mut mechanism.clone(), &eq, &SolveOptions::default());
            FoundEquilibrium {
                q: eq,
                stability: modes.as_ref().ok().map(|m| stability_record(&m.stability)),
                stability_error: modes.err().map(|e| e.to_string()),
            }
        })
        .collect();
    Ok(MultiStartRecord {
        starts: starts.len(),
        failed,
        equilibria,
    })
}

/// The timed modes at `q` with the `locked` coordinates held fixed, with the stability, the
/// gyroscopic problem, and a warning when `q` is not an equilibrium; and the modes.
fn modes_step(
    mechanism: &mut Mechanism,
    q: &[f64],
    locked: &[usize],
    spec: &crate::scene::ModesSpec,
    names: &[String],
    bodies: &[String],
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
        let record = modes_record(&m, names, &named(names, locked), bodies);
        modes = Some(m);
        Ok::<_, String>(record)
    })?;
    let modes = modes.ok_or("internal: modes missing")?;
    check_finite_modes(&modes, &step.title)?;
    if modes.gradient_norm > 1e-6 * modes.stiffness_matrix.norm_l2().max(1.0) {
        step.warnings.push(format!(
            "warning: |grad U*| = {:.2e} at this configuration: it is not an equilibrium; the modes are those of the linearisation",
            modes.gradient_norm
        ));
    }
    Ok((step, modes))
}

/// An error when a finite mode's ω² or error bound is not a finite number.
fn check_finite_modes(modes: &MechanismModes, analysis: &str) -> Result<(), String> {
    let finite = |m: &&mechanica::modal::Mode| m.omega_sq.is_finite() && m.error_bound.is_finite();
    let massive = |m: &&mechanica::modal::Mode| !matches!(m.kind, ModeKind::Infinite);
    match modes.solution.modes.iter().filter(massive).find(|m| !finite(m)) {
        Some(mode) => Err(crate::report::NonFiniteResult {
            analysis: analysis.into(),
            quantity: "ω² of a finite mode or its error bound".into(),
            value: if mode.omega_sq.is_finite() {
                mode.error_bound
            } else {
                mode.omega_sq
            },
        }
        .to_string()),
        None => Ok(()),
    }
}

/// The typed modes of `m`: every mode with its shape, effective masses and body motions.
fn modes_record(m: &MechanismModes, names: &[String], locked: &[String], bodies: &[String]) -> ModesRecord {
    let solution = &m.solution;
    let records = solution
        .modes
        .iter()
        .enumerate()
        .map(|(k, mode)| {
            let shape = solution
                .vectors
                .as_ref()
                .filter(|x| k < x.ncols())
                .map(|x| (0..x.nrows()).map(|r| x[(r, k)]).collect());
            let mut record = ModeRecord::new(mode, &solution.groups, shape);
            record.effective_mass = m.effective_masses.get(k).copied();
            record.bodies = m.body_displacements.get(k).map(|motions| {
                motions
                    .iter()
                    .zip(bodies)
                    .map(|(d, body)| BodyMotion {
                        body: body.clone(),
                        translation: d.translation.into(),
                        rotation: d.rotation.into(),
                    })
                    .collect()
            });
            record
        })
        .collect();
    let accuracy = &solution.accuracy;
    ModesRecord {
        coordinates: names.to_vec(),
        locked: locked.to_vec(),
        idle: named(names, &m.idle),
        stability: stability_record(&m.stability),
        modes: records,
        accuracy: ModalAccuracy {
            max_bound: solution.modes.iter().map(|mode| mode.error_bound).fold(0.0, f64::max),
            max_backward_error: accuracy.max_backward_error,
            orthogonality_error: accuracy.orthogonality_error,
            sturm_check: match &accuracy.inertia_check {
                Some(c) if c.consistent => SturmStatus::Consistent,
                Some(_) => SturmStatus::Inconsistent,
                None => SturmStatus::NotRun,
            },
        },
        gradient_norm: m.gradient_norm,
        total_mass: m.total_mass,
        gyroscopic: m.gyroscopic.as_ref().map(|g| GyroscopicRecord {
            eigenvalues: g.eigenvalues.iter().map(|&(re, im)| [re, im]).collect(),
            backward_errors: g.backward_errors.clone(),
            max_real_part: g.max_real_part,
            real_part_bound: g.real_part_bound,
            stable: g.stable,
        }),
    }
}

/// A copy of `mechanism` with its charts re-centred at `q`, as the modes at `q` were computed
/// (`MechanismModes::q` names poses in these charts).
fn recentred(mechanism: &Mechanism, q: &[f64]) -> Mechanism {
    let mut copy = mechanism.clone();
    if copy.has_rotation_vectors() {
        // A failure leaves the copy as it was; the figures then fail to draw, nothing else.
        let _ = copy.rebase(&mut q.to_vec());
    }
    copy
}

/// Puts the spectrum and the first six modes drawn on the mechanism into the plot data (the
/// mechanism in the charts the modes were computed in: re-centred at `modes.q`).
fn record_mode_plots(
    modes: &MechanismModes,
    mechanism: &Mechanism,
    names: &[String],
    gravity: Option<[f64; 3]>,
    plots: &mut PlotData,
) {
    let solution = &modes.solution;
    plots.spectrum = solution
        .modes
        .iter()
        .map(|m| crate::spectrum_plot::SpectrumPoint {
            omega_sq: m.omega_sq,
            bound: m.error_bound,
            kind: crate::mode_record::ModeKindName::of(m.kind).as_str().to_string(),
        })
        .collect();
    let Some(x) = &solution.vectors else { return };
    let (tree, bodies) = (mechanism.tree(), mechanism.bodies());
    // Without a skeleton (forward kinematics failing at q) there is nothing to draw on.
    let Ok(skeleton) = crate::mode_shape::skeleton(tree, bodies, names, &modes.q, gravity) else {
        return;
    };
    let figures = (0..x.ncols().min(solution.modes.len()).min(6))
        .map(|k| {
            let shape: Vec<f64> = (0..x.nrows()).map(|r| x[(r, k)]).collect();
            let record = ModeRecord::new(&solution.modes[k], &solution.groups, None);
            crate::mode_shape::figure(tree, bodies, &modes.q, &skeleton, k + 1, &record, &shape)
        })
        .collect();
    plots.shapes = Some(crate::mode_shape::ModeShapes {
        skeleton,
        modes: figures,
    });
}

/// The free response δ(t) from the scene's initial disturbance, sampled `spec.samples` times
/// over the span (the sample count was checked against the scene limits when the scene was
/// read; the series are still allocated fallibly).
fn response_step(
    modes: &MechanismModes,
    spec: &crate::scene::ResponseSpec,
    plots: &mut PlotData,
    names: &[String],
) -> Result<Step, String> {
    let n = modes.q.len();
    timed_step("free response δ(t) by modal superposition (8.91)", || {
        if modes.mass_matrix.nrows() != n || modes.solution.modes.len() != n {
            return Err(
                "analyses.response: the free response needs every mode of every coordinate (no `lowest`, no coordinate resting on a joint limit, none moving no mass and feeling no force)"
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
        let (mut series, end) = sample_response(&response, duration, *spec.samples.get_ref(), n)?;
        series.names = names.to_vec();
        let fit = response.fit();
        let end_bound = response.error_bound(duration).map_err(|e| e.to_string())?;
        let record = ResponseRecord {
            coordinates: names.to_vec(),
            duration,
            samples: *spec.samples.get_ref(),
            end,
            end_bound,
            displacement_fit_residual: fit.displacement_residual,
            velocity_fit_residual: fit.velocity_residual,
        };
        plots.response = Some(series);
        Ok(record)
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
        names: Vec::new(),
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

pub(crate) fn law_named(name: &str) -> RestitutionLaw {
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
    let chosen = spec.law.as_ref().map_or("stronge", |l| l.get_ref().as_str());
    let mut step = timed_step(
        &format!("impact: body point on the ground, {chosen} law (7.115–7.117)"),
        || impact_record(scene, model, spec, chosen),
    )?;
    let mut balance = EnergyBalance {
        body: spec.body.get_ref().clone(),
        chosen: chosen.to_string(),
        laws: Vec::new(),
    };
    if let crate::report::Record::Impact(record) = &step.record {
        for law in &record.laws {
            let after = law.energy_before + law.energy_change;
            balance.laws.push((law.law.clone(), law.energy_before, after));
            if law.energy_change > 0.0 {
                step.notes.push(format!(
                    "{}: the impact GAINS energy ({:.4e} J): Kane's paradox",
                    law.law, law.energy_change
                ));
            }
        }
    }
    plots.impact = Some(balance);
    Ok(step)
}

/// The impact of the scene's body point under the `chosen` law, and the others when the scene
/// compares laws.
fn impact_record(
    scene: &Scene,
    model: &Model,
    spec: &crate::scene::ImpactSpec,
    chosen: &str,
) -> Result<ImpactRecord, String> {
    let text = |e: &dyn std::fmt::Display| format!("analyses.impact: {e}");
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
    let mut records = Vec::new();
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
        let impact = resolve_single_contact(tree, &ws, &inertia, &model.qd0, &contact, &ImpactOptions::default())
            .map_err(|e| text(&e))?;
        let outcome = impact.contacts.first().ok_or_else(|| text(&"no contact outcome"))?;
        records.push(ImpactLawRecord {
            law: name.to_string(),
            impulse: outcome.impulse_w.into(),
            integration_error: impact.integration_error,
            contact_mode: contact_mode(outcome.mode),
            q_dot_after: impact.q_dot_after.clone(),
            energy_before: impact.energy_before,
            energy_change: impact.energy_change,
        });
    }
    Ok(ImpactRecord {
        coordinates: coordinate_names(model),
        body: spec.body.get_ref().clone(),
        laws: records,
    })
}

/// The record's name of a contact mode.
pub(crate) fn contact_mode(mode: ContactMode) -> ContactModeName {
    match mode {
        ContactMode::NoImpact => ContactModeName::NoImpact,
        ContactMode::Frictionless => ContactModeName::Frictionless,
        ContactMode::Stick => ContactModeName::Stick,
        ContactMode::Slip => ContactModeName::Slip,
        ContactMode::SlipThenStick => ContactModeName::SlipThenStick,
        ContactMode::Reversed => ContactModeName::Reversed,
    }
}
