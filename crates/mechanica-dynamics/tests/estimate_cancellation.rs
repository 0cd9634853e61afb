//! The rounding estimate of `inverse_dynamics` where joint accelerations cancel at a heavy body.
//!
//! When q̈ nearly annuls a heavy body's acceleration (J q̈ ≈ 0 with Σ|J_k||q̈_k| large), the
//! body's computed acceleration is small but carries the rounding of the cancelled terms, times
//! the body's mass; an estimate scaled by the computed accelerations misses it by their ratio.
//! The cases and their 50-digit reference τ (mpmath, validated there by closed forms and by
//! Lagrange's equations) are read from tools/dynamics_cancellation_reference.json, written by
//! tools/dynamics_cancellation_reference.py (see its docstring for the family: 24 random chains
//! and trees of 4–8 revolute and prismatic joints, one body 1e4–1e8 times heavier than the
//! others, q̈ = s × a null vector of its 6 × p or 3 × p Jacobian + a small part, s = 1e2…1e8).
//!
//! Every input is a double given as its shortest decimal string and parsed here by the
//! correctly rounded `str::parse`, so the test builds the reference's model exactly; the joint
//! axes and placements that the builder keeps are checked bit for bit (the script chose axes that
//! `scaling::unit` leaves unchanged and rotations whose quaternion-to-matrix conversion is exact).
//!
//! Asserted per coordinate, with no slack: |τ_k − τ_ref,k| ≤ error_estimate_k. The reference
//! is τ_ref = hi + lo (its error below 1e-50 of max|τ|); (τ_k − hi) − lo is formed in f64 and is
//! off from the true difference by at most about 2u of itself, which moves the ratio by 1e-15
//! relative, not by any amount the estimate must cover.
//!
//! With the estimate scaled by the computed body accelerations (before the magnitudes were
//! summed from the terms), 12 of the 24 cases failed, by up to 2.3e6; they are the cases whose
//! heavy body has its whole spatial acceleration cancelled (6 × p null space). Where only the
//! centre of mass's acceleration cancels (3 × p), the heavy body's uncancelled ω̇ kept that
//! estimate large enough; those cases guard the rest of the estimate.

mod common;

use mechanica_dynamics::{Dynamics, State};
use mechanica_kinematics::tree::{Joint, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mechanism::Mechanism;
use nalgebra::{Isometry3, Matrix3, Quaternion, Translation3, UnitQuaternion, Vector3};
use serde_json::Value;

/// Least Σ_k |J_k||q̈_k| / |a_C| at the heavy body's centre of mass for a case to count as
/// cancelling (the script draws cases whose exact ratio is at least 1e4).
const CANCELLATION: f64 = 1e3;

/// Least ratio of the heavy body's mass to every other body's.
const HEAVY: f64 = 1e4;

fn double(value: &Value) -> f64 {
    let text = value.as_str().expect("a double written as a string");
    text.parse().unwrap_or_else(|e| panic!("`{text}`: {e}"))
}

fn doubles(value: &Value, key: &str) -> Vec<f64> {
    value[key]
        .as_array()
        .unwrap_or_else(|| panic!("`{key}` is not an array"))
        .iter()
        .map(double)
        .collect()
}

fn vector3(value: &Value, key: &str) -> Vector3<f64> {
    Vector3::from_column_slice(&doubles(value, key))
}

fn matrix3(value: &Value, key: &str) -> Matrix3<f64> {
    Matrix3::from_row_slice(&doubles(value, key))
}

/// One body: its parent, joint (with the axis as written), placement X_PJ (with the exact
/// R_PJ the quaternion stands for) and mass properties.
struct Body {
    parent: Option<usize>,
    joint: Joint,
    axis: Vector3<f64>,
    placement: Isometry3<f64>,
    rotation: Matrix3<f64>,
    mass: MassProperties,
}

struct Case {
    name: String,
    heavy: usize,
    bodies: Vec<Body>,
    gravity: Vector3<f64>,
    q: Vec<f64>,
    q_dot: Vec<f64>,
    q_ddot: Vec<f64>,
    tau_hi: Vec<f64>,
    tau_lo: Vec<f64>,
}

fn body(value: &Value) -> Body {
    let axis = vector3(value, "axis");
    let joint = match value["type"].as_str().expect("joint type") {
        "revolute" => Joint::Revolute { axis },
        "prismatic" => Joint::Prismatic { axis },
        other => panic!("joint type {other} is not in the reference's vocabulary"),
    };
    let [w, x, y, z] = doubles(value, "quaternion")[..] else {
        panic!("a quaternion has four entries")
    };
    let placement = Isometry3::from_parts(
        Translation3::from(vector3(value, "translation")),
        UnitQuaternion::new_unchecked(Quaternion::new(w, x, y, z)),
    );
    let mass = MassProperties::new(double(&value["mass"]), vector3(value, "com"), matrix3(value, "inertia"))
        .expect("valid body");
    Body {
        parent: value["parent"].as_u64().map(|p| p as usize),
        joint,
        axis,
        placement,
        rotation: matrix3(value, "rotation"),
        mass,
    }
}

fn cases() -> Vec<Case> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tools/dynamics_cancellation_reference.json"
    );
    let text = std::fs::read_to_string(path).expect("the committed reference file");
    let document: Value = serde_json::from_str(&text).expect("valid JSON");
    document["cases"]
        .as_array()
        .expect("cases")
        .iter()
        .map(|c| {
            let case = Case {
                name: c["name"].as_str().expect("name").to_string(),
                heavy: c["heavy"].as_u64().expect("heavy body") as usize,
                bodies: c["bodies"].as_array().expect("bodies").iter().map(body).collect(),
                gravity: vector3(c, "gravity"),
                q: doubles(c, "q"),
                q_dot: doubles(c, "q_dot"),
                q_ddot: doubles(c, "q_ddot"),
                tau_hi: doubles(c, "tau_hi"),
                tau_lo: doubles(c, "tau_lo"),
            };
            // hi is the 50-digit value rounded to f64 (both parsers round correctly).
            for (text, hi) in c["tau"].as_array().expect("tau").iter().zip(&case.tau_hi) {
                let parsed: f64 = text.as_str().expect("tau digits").parse().expect("tau");
                assert_eq!(parsed, *hi, "{}: tau_hi", case.name);
            }
            case
        })
        .collect()
}

/// The case's dynamics, after checking that the builder kept every axis and placement exactly.
fn dynamics_for(case: &Case) -> Dynamics {
    let mut builder = TreeBuilder::new();
    for b in &case.bodies {
        builder.add_body(b.parent, b.joint, b.placement);
    }
    let tree = builder.build().expect("valid tree");
    assert_eq!(tree.dof(), case.q.len(), "{}: dof", case.name);
    for (i, b) in case.bodies.iter().enumerate() {
        let kept = match tree.joint(i) {
            Some(Joint::Revolute { axis }) | Some(Joint::Prismatic { axis }) => *axis,
            other => panic!("{}: body {i} has joint {other:?}", case.name),
        };
        assert_eq!(kept, b.axis, "{}: body {i}'s axis as the builder keeps it", case.name);
        let (r_pj, p_pj) = tree.placement(i).expect("placement");
        assert_eq!(r_pj, b.rotation, "{}: body {i}'s R_PJ", case.name);
        assert_eq!(p_pj, b.placement.translation.vector, "{}: body {i}'s p_PJ", case.name);
    }
    let mut mechanism = Mechanism::new(tree, case.bodies.iter().map(|b| b.mass).collect()).expect("mechanism");
    mechanism.set_gravity(case.gravity).expect("gravity");
    Dynamics::new(mechanism).expect("dynamics")
}

/// Σ_k |J_k||q̈_k| / |a_C| at the heavy body's centre of mass, from the workspace of the last
/// evaluation (at the case's q̈): the factor by which the body's computed inertial force
/// m |a_C| is smaller than the m Σ_k |J_k||q̈_k| its rounding scales with.
fn cancellation(dynamics: &Dynamics, case: &Case) -> f64 {
    let (tree, ws) = (dynamics.tree(), dynamics.workspace());
    let com = case.bodies[case.heavy].mass.p_oc;
    let a_c = ws.point_acceleration(case.heavy, &com).expect("acceleration");
    let mut jacobian = vec![0.0; 3 * tree.dof()];
    tree.point_jacobian(ws, case.heavy, &com, &mut jacobian)
        .expect("point Jacobian");
    let terms: f64 = jacobian
        .chunks(3)
        .zip(&case.q_ddot)
        .map(|(column, a)| Vector3::from_column_slice(column).norm() * a.abs())
        .sum();
    terms / a_c.norm()
}

#[test]
fn estimate_covers_the_error_where_accelerations_cancel_at_a_heavy_body() {
    let cases = cases();
    assert!(cases.len() >= 20, "a family, not a single case");
    let (mut failures, mut worst) = (Vec::new(), (0.0f64, String::new()));
    for case in &cases {
        let heavy = case.bodies[case.heavy].mass.mass;
        for (i, b) in case.bodies.iter().enumerate() {
            assert!(
                i == case.heavy || heavy >= HEAVY * b.mass.mass,
                "{}: heavy body",
                case.name
            );
        }
        let mut dynamics = dynamics_for(case);
        let result = dynamics
            .inverse_dynamics(&State::new(&case.q, &case.q_dot), &case.q_ddot)
            .expect("inverse dynamics");
        let cancelled = cancellation(&dynamics, case);
        assert!(
            cancelled >= CANCELLATION,
            "{}: the heavy body's acceleration cancels only by {cancelled:.2e}",
            case.name
        );
        let mut case_worst = 0.0f64;
        for k in 0..case.q.len() {
            let error = ((result.tau[k] - case.tau_hi[k]) - case.tau_lo[k]).abs();
            let ratio = error / result.error_estimate[k];
            case_worst = case_worst.max(ratio);
            if ratio.is_nan() || ratio > 1.0 {
                failures.push(format!(
                    "{} τ_{k}: |error| {error:.3e} > estimate {:.3e} (×{ratio:.2e})",
                    case.name, result.error_estimate[k]
                ));
            }
        }
        println!(
            "{}: n = {}, cancellation {cancelled:.1e}, max|τ| {:.2e}, worst |error|/estimate {case_worst:.3e}",
            case.name,
            case.q.len(),
            common::norm_inf(&result.tau)
        );
        if case_worst > worst.0 {
            worst = (case_worst, case.name.clone());
        }
    }
    println!(
        "worst |error|/estimate over {} cases: {:.3e} ({})",
        cases.len(),
        worst.0,
        worst.1
    );
    assert!(
        failures.is_empty(),
        "error beyond the estimate in {} coordinates (worst ratio {:.3e}, {}): {failures:#?}",
        failures.len(),
        worst.0,
        worst.1
    );
}
