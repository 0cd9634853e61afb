//! Agreement with Pinocchio (C++, an independent implementation of the same recursions) on three
//! real robots: UR5 (6 revolute joints), Panda (7 revolute + 2 prismatic) and Talos (free
//! flyer + 44 revolute joints, nv = 50), with the models and 10 random states per robot read from
//! tools/dynamics_pinocchio_reference.json, written by tools/dynamics_pinocchio_reference.py
//! (see its docstring for the model description and for the mapping of Pinocchio's free flyer
//! to mechanica's free joint, which that script checks by Lagrange's equations). Pinocchio is
//! not run here.
//!
//! Each check is norm-wise per state, relative to the reference's ∞-norm:
//! - RNEA: ‖τ − τ_pin‖∞ ≤ 1e-12 ‖τ_pin‖∞ (τ_pin = pin.rnea(q, v, a), gravity included);
//! - ABA: ‖q̈ − q̈_pin‖∞ ≤ 1e-12 ‖q̈_pin‖∞ (q̈_pin = pin.aba(q, v, τ)), or, where A(q) is too
//!   ill-conditioned for any two backward-stable solvers to agree that closely, within the
//!   perturbation bound ‖A⁻¹‖∞ (‖r‖∞ + ‖r_pin‖∞ + ρ) of the two residuals r = τ − RNEA(q̈)
//!   (ρ the rounding estimate of the RNEA that evaluates them): q̈ − q̈_pin = A⁻¹(r − r_pin);
//! - the mass matrix: max |A − A_pin| ≤ 1e-12 max |A_pin| (A_pin = pin.crba(q));
//! - the articulated-body recursion against CRBA + Cholesky (both mechanica's), 1e-12 relative.

use mechanica_dynamics::{Dynamics, State};
use mechanica_kinematics::tree::{Joint, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mechanism::Mechanism;
use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};
use serde_json::Value;

const RELATIVE: f64 = 1e-12;

/// One body of the neutral model: its joint, placement X_PJ and mass properties.
struct BodySpec {
    parent: Option<usize>,
    joint: Joint,
    placement: Isometry3<f64>,
    mass: MassProperties,
}

/// One reference state, in mechanica's coordinates.
struct Reference {
    q: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    tau: Vec<f64>,
    rnea: Vec<f64>,
    aba: Vec<f64>,
    crba: Vec<f64>,
    base_rotation: Option<Matrix3<f64>>,
}

struct Robot {
    name: String,
    nv: usize,
    gravity: Vector3<f64>,
    bodies: Vec<BodySpec>,
    states: Vec<Reference>,
}

fn numbers(value: &Value, key: &str) -> Vec<f64> {
    value[key]
        .as_array()
        .unwrap_or_else(|| panic!("`{key}` is not an array"))
        .iter()
        .map(|x| x.as_f64().expect("a number"))
        .collect()
}

fn vector3(value: &Value, key: &str) -> Vector3<f64> {
    Vector3::from_column_slice(&numbers(value, key))
}

fn matrix3(value: &Value, key: &str) -> Matrix3<f64> {
    Matrix3::from_row_slice(&numbers(value, key))
}

fn body_spec(value: &Value) -> BodySpec {
    let joint = match value["type"].as_str().expect("joint type") {
        "revolute" => Joint::Revolute {
            axis: vector3(value, "axis"),
        },
        "prismatic" => Joint::Prismatic {
            axis: vector3(value, "axis"),
        },
        "free" => Joint::Free,
        other => panic!("joint type {other} is not in the reference's vocabulary"),
    };
    let rotation = Rotation3::from_matrix_unchecked(matrix3(value, "rotation"));
    let placement = Isometry3::from_parts(
        Translation3::from(vector3(value, "translation")),
        UnitQuaternion::from_rotation_matrix(&rotation),
    );
    let mass = value["mass"].as_f64().expect("mass");
    BodySpec {
        parent: value["parent"].as_u64().map(|p| p as usize),
        joint,
        placement,
        mass: MassProperties::new(mass, vector3(value, "com"), matrix3(value, "inertia")).expect("valid body"),
    }
}

fn reference(value: &Value) -> Reference {
    Reference {
        q: numbers(value, "q"),
        v: numbers(value, "v"),
        a: numbers(value, "a"),
        tau: numbers(value, "tau"),
        rnea: numbers(value, "rnea"),
        aba: numbers(value, "aba"),
        crba: numbers(value, "crba"),
        base_rotation: value.get("base_rotation").map(|_| matrix3(value, "base_rotation")),
    }
}

fn robots() -> Vec<Robot> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tools/dynamics_pinocchio_reference.json"
    );
    let text = std::fs::read_to_string(path).expect("the committed reference file");
    let document: Value = serde_json::from_str(&text).expect("valid JSON");
    document["models"]
        .as_array()
        .expect("models")
        .iter()
        .map(|m| Robot {
            name: m["name"].as_str().expect("name").to_string(),
            nv: m["nv"].as_u64().expect("nv") as usize,
            gravity: vector3(m, "gravity"),
            bodies: m["joints"].as_array().expect("joints").iter().map(body_spec).collect(),
            states: m["states"].as_array().expect("states").iter().map(reference).collect(),
        })
        .collect()
}

/// The dynamics of `robot` set up for `state`: a free joint gets R_ref = the state's base
/// rotation (rebased from φ = log R), so that the state's φ = 0 describes that orientation.
fn dynamics_for(robot: &Robot, state: &Reference) -> Dynamics {
    let mut builder = TreeBuilder::new();
    for body in &robot.bodies {
        builder.add_body(body.parent, body.joint, body.placement);
    }
    let mut tree = builder.build().expect("valid tree");
    assert_eq!(tree.dof(), robot.nv, "{}: dof", robot.name);
    if let Some(r) = state.base_rotation {
        let free = (0..tree.body_count())
            .find(|&b| tree.joint(b) == Some(&Joint::Free))
            .expect("a free joint");
        let start = tree.dof_range(free).start + 3;
        let phi = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r)).scaled_axis();
        let mut q = state.q.clone();
        q[start..start + 3].copy_from_slice(phi.as_slice());
        tree.rebase(&mut q, &mut vec![0.0; robot.nv]).expect("rebase");
        let r_ref = tree.reference_rotation(free).expect("free body");
        assert!((r_ref.matrix() - r).amax() <= 1e-15, "{}: R_ref = R_base", robot.name);
        assert_eq!(q, state.q, "{}: rebased coordinates", robot.name);
    }
    let bodies = robot.bodies.iter().map(|b| b.mass).collect();
    let mut mechanism = Mechanism::new(tree, bodies).expect("mechanism");
    mechanism.set_gravity(robot.gravity).expect("gravity");
    Dynamics::new(mechanism).expect("dynamics")
}

fn norm_inf(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |m, v| m.max(v.abs()))
}

/// ‖x − reference‖∞ / ‖reference‖∞.
fn relative_deviation(x: &[f64], reference: &[f64]) -> f64 {
    assert_eq!(x.len(), reference.len());
    let difference: Vec<f64> = x.iter().zip(reference).map(|(a, b)| a - b).collect();
    norm_inf(&difference) / norm_inf(reference)
}

/// Runs `deviation` on every state of every robot, prints the worst per robot, and asserts
/// each is within its allowance (at least [`RELATIVE`]); a failure lists the state, its
/// deviation and `note`.
fn check_all(what: &str, deviation: impl Fn(&Robot, &Reference, &mut Dynamics) -> Deviation) {
    let mut failures = Vec::new();
    for robot in robots() {
        let mut worst = 0.0f64;
        for (index, state) in robot.states.iter().enumerate() {
            let mut dynamics = dynamics_for(&robot, state);
            let Deviation {
                relative: d,
                allowed,
                note,
            } = deviation(&robot, state, &mut dynamics);
            worst = worst.max(d);
            if d.is_nan() || d > allowed.max(RELATIVE) {
                failures.push(format!(
                    "{} state {index}: {d:e} (allowed {allowed:e}) {note}",
                    robot.name
                ));
            }
        }
        println!(
            "{what}: {} (nv = {}) worst relative deviation {worst:.2e}",
            robot.name, robot.nv
        );
    }
    assert!(failures.is_empty(), "{what} beyond its allowance: {failures:?}");
}

/// A relative deviation, the allowance beyond [`RELATIVE`] that conditioning grants, and a note.
struct Deviation {
    relative: f64,
    allowed: f64,
    note: String,
}

impl Deviation {
    fn plain(relative: f64) -> Self {
        Deviation {
            relative,
            allowed: RELATIVE,
            note: String::new(),
        }
    }
}

/// The deviation of our q̈ from `reference`, allowed up to ‖A⁻¹‖∞ (‖r‖∞ + ‖r_ref‖∞ + ρ) relative
/// to ‖reference‖∞, with the residuals r = τ − RNEA(q̈) of both and the RNEA's rounding ρ.
fn forward_deviation(dynamics: &mut Dynamics, state: &Reference, q_ddot: &[f64], reference: &[f64]) -> Deviation {
    let s = State::new(&state.q, &state.v);
    let mut residual = |x: &[f64]| {
        let check = dynamics.inverse_dynamics(&s, x).expect("rnea");
        let r: Vec<f64> = check.tau.iter().zip(&state.tau).map(|(a, b)| a - b).collect();
        (norm_inf(&r), norm_inf(&check.error_estimate))
    };
    let ((ours, rho_ours), (theirs, rho_theirs)) = (residual(q_ddot), residual(reference));
    let a = dynamics.mass_matrix(&state.q).expect("mass matrix");
    let n = a.nrows();
    let a_norm = (0..n)
        .map(|i| (0..n).map(|j| a[(i, j)].abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let crba = dynamics.forward_dynamics_crba(&s, &state.tau).expect("crba + Cholesky");
    let condition = crba.condition.unwrap_or(f64::NAN);
    let inverse_norm = condition / a_norm;
    let allowed = inverse_norm * (ours + theirs + rho_ours + rho_theirs) / norm_inf(reference);
    let note = format!("(residuals: ours {ours:.2e}, reference's {theirs:.2e}; κ∞(A) = {condition:.2e})");
    Deviation {
        relative: relative_deviation(q_ddot, reference),
        allowed,
        note,
    }
}

#[test]
fn rnea_matches_pinocchio() {
    check_all("rnea vs pin.rnea", |robot, state, dynamics| {
        let mut tau = vec![0.0; robot.nv];
        dynamics
            .rnea_into(&state.q, &state.v, &state.a, &mut tau)
            .expect("rnea");
        Deviation::plain(relative_deviation(&tau, &state.rnea))
    });
}

#[test]
fn inverse_dynamics_matches_pinocchio() {
    check_all("inverse_dynamics vs pin.rnea", |_, state, dynamics| {
        let result = dynamics
            .inverse_dynamics(&State::new(&state.q, &state.v), &state.a)
            .expect("inverse dynamics");
        Deviation::plain(relative_deviation(&result.tau, &state.rnea))
    });
}

#[test]
fn aba_matches_pinocchio() {
    check_all("aba vs pin.aba", |robot, state, dynamics| {
        let mut q_ddot = vec![0.0; robot.nv];
        dynamics
            .aba_into(&state.q, &state.v, &state.tau, &mut q_ddot)
            .expect("aba");
        forward_deviation(dynamics, state, &q_ddot, &state.aba)
    });
}

#[test]
fn forward_dynamics_matches_pinocchio() {
    check_all("forward_dynamics vs pin.aba", |_, state, dynamics| {
        let result = dynamics
            .forward_dynamics(&State::new(&state.q, &state.v), &state.tau)
            .expect("forward dynamics");
        forward_deviation(dynamics, state, &result.q_ddot, &state.aba)
    });
}

#[test]
fn aba_matches_crba_and_cholesky() {
    check_all("aba vs crba + Cholesky", |robot, state, dynamics| {
        let mut q_ddot = vec![0.0; robot.nv];
        dynamics
            .aba_into(&state.q, &state.v, &state.tau, &mut q_ddot)
            .expect("aba");
        let crba = dynamics
            .forward_dynamics_crba(&State::new(&state.q, &state.v), &state.tau)
            .expect("crba + Cholesky");
        forward_deviation(dynamics, state, &q_ddot, &crba.q_ddot)
    });
}

#[test]
fn mass_matrix_matches_pinocchio_crba() {
    check_all("mass matrix vs pin.crba", |robot, state, dynamics| {
        let a = dynamics.mass_matrix(&state.q).expect("mass matrix");
        let n = robot.nv;
        let ours: Vec<f64> = (0..n * n).map(|k| a[(k / n, k % n)]).collect();
        Deviation::plain(relative_deviation(&ours, &state.crba))
    });
}
