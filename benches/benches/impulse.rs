//! Criterion benchmarks: impulse dynamics.
//!
//! - `impulse_contact/*`: one two-body point impact, end to end (mobility assembly, impact
//!   process, both body responses): a frictionless contact as the baseline, a frictional
//!   contact whose slip halts and sticks (closed-form segments), and a 3-D swerving slip
//!   integrated at the default tolerance 1e-10 (timings: docs/benchmarks.md).
//! - `impulse_swerve`: error against run time of the swerving-slip integration over the
//!   tolerance, written to `target/reports/impulse_swerve.csv` and `.svg`. The error is
//!   measured against a tolerance-1e-14 run; the reported error estimate is listed beside it.
//! - `impulse_mechanism/*`: a humanoid-like tree of 14 bodies (free torso, head, four limbs of
//!   three spherical joints each: 45 DOF) landing on hands and feet, 4 frictional contacts:
//!   `mass_matrix_and_factor` (A(q) by CRBA and its Cholesky), `resolve_4_contacts` (J, W =
//!   J A⁻¹ Jᵀ and the simultaneous frictional impact, given the factor), `end_to_end` (both),
//!   and `single_contact` (one foot, the impulse process on W).

use criterion::{Criterion, criterion_group, criterion_main};
use mechanica::impulse::{
    BodyPoint, ContactLaw, ImpactOptions, MechanismContact, MechanismInertia, MultiContactOptions, RestitutionLaw,
    RigidBody, TwoBodyImpact, resolve_contact, resolve_contacts, resolve_single_contact,
};
use mechanica::kinematics::nalgebra::{Isometry3, Matrix3, Rotation3, Vector3};
use mechanica::kinematics::tree::{Joint, KinematicTree, TreeBuilder, Workspace};
use mechanica::mass::MassProperties;
use mechanica::mass::mechanism::TreeMass;
use mechanica_benches::work_precision::{Panel, Series, WorkPoint, write_work_precision};
use mechanica_benches::write_csv;
use std::hint::black_box;
use std::time::Instant;

/// A free body whose inertia is rotated about z only: with velocities in the xy plane and
/// spin about z the impact is planar (its slip cannot swerve), the common case of a 3-D
/// simulator's contact between boxes lying on their faces.
fn body(mass: f64, p: Vector3<f64>, v: Vector3<f64>, w: Vector3<f64>) -> RigidBody {
    let r = Rotation3::from_euler_angles(0.0, 0.0, 0.8);
    let j = r.matrix() * Matrix3::from_diagonal(&Vector3::new(0.2, 0.5, 0.7)) * r.matrix().transpose();
    RigidBody::from_inverse(1.0 / mass, &j.try_inverse().unwrap_or_else(Matrix3::identity), p, v, w)
        .expect("valid body")
}

/// The tilted rod of the tests: its slip swerves in 3-D before halting.
fn swerving_rod() -> (RigidBody, RigidBody) {
    let axis = Vector3::new(0.6, 0.5, 0.3).normalize();
    let j = (Matrix3::identity() - axis * axis.transpose()) / 12.0;
    let w = Vector3::new(0.3, 0.0, 0.2);
    let w = w - axis * w.dot(&axis);
    let rod =
        RigidBody::from_inverse(1.0, &pseudo_inverse(&j), axis * 0.5, Vector3::new(0.4, -1.0, -0.7), w).expect("rod");
    (RigidBody::fixed(Vector3::zeros()).expect("ground"), rod)
}

fn pseudo_inverse(j: &Matrix3<f64>) -> Matrix3<f64> {
    j.pseudo_inverse(1e-12).unwrap_or_else(|_| Matrix3::zeros())
}

fn swerve(tolerance: f64) -> TwoBodyImpact {
    let (ground, rod) = swerving_rod();
    let law = ContactLaw::new(0.8, 0.25, RestitutionLaw::Stronge).expect("law");
    let options = ImpactOptions {
        tolerance,
        ..ImpactOptions::default()
    };
    resolve_contact(&ground, &rod, &Vector3::zeros(), &Vector3::y(), &law, &options).expect("impact")
}

fn single_contact(c: &mut Criterion) {
    let b1 = body(
        2.0,
        Vector3::new(0.0, -0.4, 0.0),
        Vector3::new(0.1, 0.8, 0.0),
        Vector3::new(0.0, 0.0, 1.0),
    );
    let b2 = body(
        3.0,
        Vector3::new(0.1, 0.5, 0.0),
        Vector3::new(0.6, -1.0, 0.0),
        Vector3::new(0.0, 0.0, -2.0),
    );
    let point = Vector3::new(0.05, 0.0, 0.0);
    let options = ImpactOptions::default();
    let smooth = ContactLaw::new(0.5, 0.0, RestitutionLaw::Stronge).expect("law");
    let rough = ContactLaw::new(0.5, 0.8, RestitutionLaw::Stronge).expect("law");
    let sample = resolve_contact(&b1, &b2, &point, &Vector3::y(), &rough, &options).expect("impact");
    println!(
        "impulse_contact/frictional: mode {:?}, steps {}, error {:e}",
        sample.contact.mode, sample.contact.steps, sample.contact.integration_error
    );
    let mut group = c.benchmark_group("impulse_contact");
    group.bench_function("frictionless", |b| {
        b.iter(|| resolve_contact(black_box(&b1), black_box(&b2), &point, &Vector3::y(), &smooth, &options))
    });
    group.bench_function("frictional", |b| {
        b.iter(|| resolve_contact(black_box(&b1), black_box(&b2), &point, &Vector3::y(), &rough, &options))
    });
    let (ground, rod) = swerving_rod();
    let law = ContactLaw::new(0.8, 0.25, RestitutionLaw::Stronge).expect("law");
    group.bench_function("swerving_3d", |b| {
        b.iter(|| {
            resolve_contact(
                black_box(&ground),
                black_box(&rod),
                &Vector3::zeros(),
                &Vector3::y(),
                &law,
                &options,
            )
        })
    });
    group.finish();
}

fn swerve_series(_c: &mut Criterion) {
    let reference = swerve(1e-14).contact.impulse_w;
    let mut rows = Vec::new();
    let mut measured = Vec::new();
    let mut estimated = Vec::new();
    for k in 2..=13 {
        let tolerance = 10f64.powi(-k);
        let result = swerve(tolerance);
        // Time by repetition for ≥ 20 ms: a report, not an assertion.
        let start = Instant::now();
        let mut runs = 0u32;
        while start.elapsed().as_secs_f64() < 0.02 {
            black_box(swerve(black_box(tolerance)));
            runs += 1;
        }
        let seconds = start.elapsed().as_secs_f64() / f64::from(runs);
        let error = (result.contact.impulse_w - reference).norm();
        rows.push(vec![
            format!("{tolerance:e}"),
            format!("{seconds:e}"),
            format!("{error:e}"),
            format!("{:e}", result.contact.integration_error),
            result.contact.steps.to_string(),
        ]);
        let point = |error| WorkPoint {
            order: tolerance,
            seconds,
            error,
        };
        measured.push(point(error));
        estimated.push(point(result.contact.integration_error));
    }
    let header = ["tolerance", "seconds", "impulse_error", "reported_error", "steps"];
    match write_csv("impulse_swerve", &header, &rows) {
        Ok(path) => println!("wrote {}", path.display()),
        Err(e) => eprintln!("impulse_swerve.csv: {e}"),
    }
    let panel = Panel {
        title: "3-D swerving slip, tolerance 1e-2 to 1e-13".into(),
        series: vec![Series {
            label: "adaptive contact integration".into(),
            points: measured,
            bound: estimated,
        }],
    };
    let title = "Impulse of a 3-D swerving slip: |P − P_ref| (N·s) and the reported estimate against run time";
    if let Err(e) = write_work_precision("impulse_swerve", title, "impulse error (N·s)", &[panel]) {
        eprintln!("impulse_swerve.svg: {e}");
    }
}

/// The humanoid-like tree: torso (free), head, two arms and two legs of three bodies each.
/// Returns the tree, its workspace at a crouched landing pose, the body masses, q̇ and the
/// four contacts (hands and feet on the floor, f = 0.6, e = 0.2).
fn humanoid() -> (KinematicTree, Workspace, TreeMass, Vec<f64>, Vec<MechanismContact>) {
    let mut builder = TreeBuilder::new();
    let mut bodies = Vec::new();
    let link = |mass: f64, length: f64| {
        let r = 0.05_f64;
        let (ia, it) = (0.5 * mass * r * r, mass * (3.0 * r * r + length * length) / 12.0);
        MassProperties {
            mass,
            p_oc: Vector3::new(0.0, -0.5 * length, 0.0),
            inertia_c: Matrix3::from_diagonal(&Vector3::new(it, ia, it)),
        }
    };
    let torso = builder.add_body(None, Joint::Free, Isometry3::identity());
    bodies.push(MassProperties {
        mass: 30.0,
        p_oc: Vector3::zeros(),
        inertia_c: Matrix3::from_diagonal(&Vector3::new(1.2, 0.6, 1.0)),
    });
    builder.add_body(Some(torso), Joint::Spherical, Isometry3::translation(0.0, 0.3, 0.0));
    bodies.push(MassProperties {
        mass: 5.0,
        p_oc: Vector3::new(0.0, 0.12, 0.0),
        inertia_c: Matrix3::identity() * 0.03,
    });
    let mut ends = Vec::new();
    for (x, y, lengths, masses) in [
        (0.2, 0.25, [0.3, 0.28, 0.08], [2.5, 1.5, 0.5]),
        (-0.2, 0.25, [0.3, 0.28, 0.08], [2.5, 1.5, 0.5]),
        (0.1, -0.3, [0.45, 0.42, 0.1], [8.0, 4.0, 1.2]),
        (-0.1, -0.3, [0.45, 0.42, 0.1], [8.0, 4.0, 1.2]),
    ] {
        let mut parent = torso;
        let mut offset = Vector3::new(x, y, 0.0);
        for k in 0..3 {
            parent = builder.add_body(
                Some(parent),
                Joint::Spherical,
                Isometry3::translation(offset.x, offset.y, offset.z),
            );
            bodies.push(link(masses[k], lengths[k]));
            offset = Vector3::new(0.0, -lengths[k], 0.0);
        }
        ends.push((parent, offset));
    }
    let tree = builder.build().expect("humanoid");
    let n = tree.dof();
    let q: Vec<f64> = (0..n)
        .map(|k| {
            if k < 6 {
                [0.0, 1.0, 0.0, 0.3, 0.0, 0.0][k]
            } else {
                0.25 * ((k as f64) * 0.9).sin()
            }
        })
        .collect();
    let q_dot: Vec<f64> = (0..n)
        .map(|k| if k == 1 { -2.0 } else { 0.3 * ((k as f64) * 1.3).cos() })
        .collect();
    let mut ws = tree.workspace();
    tree.update_positions(&mut ws, &q).expect("q");
    let mass = TreeMass::new(&tree, bodies).expect("mass");
    let law = ContactLaw::new(0.2, 0.6, RestitutionLaw::Stronge).expect("law");
    let contacts = ends
        .iter()
        .map(|&(body, p_bq)| MechanismContact {
            point: BodyPoint { body, p_bq },
            other: None,
            normal_w: Vector3::y(),
            law,
        })
        .collect();
    (tree, ws, mass, q_dot, contacts)
}

fn mechanism_contacts(c: &mut Criterion) {
    let (tree, ws, mut mass, q_dot, contacts) = humanoid();
    let inertia = MechanismInertia::new(&tree, &ws, &mut mass).expect("inertia");
    let options = MultiContactOptions::default();
    let sample = resolve_contacts(&tree, &ws, &inertia, &q_dot, &contacts, &options).expect("impact");
    println!(
        "impulse_mechanism: dof {}, contacts {}, sweeps {}, residual {:e} m/s, converged {}, rank {}, ΔT {:.4} J of T {:.4} J, modes {:?}",
        tree.dof(),
        contacts.len(),
        sample.iterations,
        sample.complementarity_residual,
        sample.converged,
        sample.delassus_rank,
        sample.energy_change,
        sample.energy_before,
        sample.contacts.iter().map(|c| c.mode).collect::<Vec<_>>()
    );
    let mut group = c.benchmark_group("impulse_mechanism");
    group.bench_function("mass_matrix_and_factor", |b| {
        b.iter(|| MechanismInertia::new(black_box(&tree), black_box(&ws), &mut mass))
    });
    group.bench_function("resolve_4_contacts", |b| {
        b.iter(|| {
            resolve_contacts(
                black_box(&tree),
                black_box(&ws),
                &inertia,
                black_box(&q_dot),
                &contacts,
                &options,
            )
        })
    });
    group.bench_function("end_to_end", |b| {
        b.iter(|| {
            let inertia = MechanismInertia::new(black_box(&tree), black_box(&ws), &mut mass).expect("inertia");
            resolve_contacts(&tree, &ws, &inertia, black_box(&q_dot), &contacts, &options)
        })
    });
    let process = ImpactOptions::default();
    group.bench_function("single_contact", |b| {
        b.iter(|| {
            resolve_single_contact(
                black_box(&tree),
                black_box(&ws),
                &inertia,
                black_box(&q_dot),
                &contacts[2],
                &process,
            )
        })
    });
    group.finish();
}

criterion_group!(benches, single_contact, mechanism_contacts, swerve_series);
criterion_main!(benches);
