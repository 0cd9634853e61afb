//! The recursions against each other and against independent quantities, on random trees of
//! every joint type with masses graded over twelve decades:
//! - RNEA: τ(q̈) − τ(0) = A q̈, with A from the mass crate's composite-rigid-body recursion;
//! - ABA inverts RNEA, and agrees with CRBA + Cholesky within the reported estimates;
//! - the split τ(0) = c + g − Σ Q;
//! - each joint carries on its own coordinates the power of the wrench it transmits;
//! - every body's momentum theorems (7.15), (7.22) balance its joint reactions.

mod common;

use common::{Rng, norm_inf, random_mechanism, random_state};
use mechanica_dynamics::{Dynamics, State};
use nalgebra::Vector3;
use proptest::prelude::*;

fn dynamics_with_gravity(seed: u64, bodies: usize, grading: f64, chain: bool) -> (Dynamics, Rng) {
    let mut rng = Rng::new(seed);
    let mut mechanism = random_mechanism(&mut rng, bodies, grading, chain);
    mechanism
        .set_gravity(Vector3::new(0.3, -9.81, 1.2))
        .expect("finite gravity");
    (Dynamics::new(mechanism).expect("dynamics"), rng)
}

/// τ(q̈) − τ(0) = A q̈ within the rounding estimates of both evaluations and of A q̈.
fn check_rnea_against_mass_matrix(dynamics: &mut Dynamics, rng: &mut Rng) {
    let (q, q_dot, q_ddot) = random_state(rng, dynamics.mechanism());
    let n = q.len();
    let state = State::new(&q, &q_dot);
    let full = dynamics.inverse_dynamics(&state, &q_ddot).expect("rnea");
    let bias = dynamics.inverse_dynamics(&state, &vec![0.0; n]).expect("rnea at rest");
    let a = dynamics.mass_matrix(&q).expect("mass matrix");
    for k in 0..n {
        let a_qdd: f64 = (0..n).map(|l| a[(k, l)] * q_ddot[l]).sum();
        let a_size: f64 = (0..n).map(|l| (a[(k, l)] * q_ddot[l]).abs()).sum();
        let tolerance = full.error_estimate[k] + bias.error_estimate[k] + 64.0 * n as f64 * f64::EPSILON * a_size;
        let difference = (full.tau[k] - bias.tau[k] - a_qdd).abs();
        assert!(
            difference <= tolerance,
            "coordinate {k}: τ(q̈) − τ(0) − A q̈ = {difference:e} > {tolerance:e}"
        );
    }
}

/// τ(0) = c + g − Σ Q, and S_kᵀ W_i = τ_k + (the joint's own loads).
fn check_split_and_joint_power(dynamics: &mut Dynamics, rng: &mut Rng) {
    let (q, q_dot, q_ddot) = random_state(rng, dynamics.mechanism());
    let state = State::new(&q, &q_dot);
    let result = dynamics.inverse_dynamics(&state, &vec![0.0; q.len()]).expect("rnea");
    for k in 0..q.len() {
        let loads: f64 = result.loads.iter().map(|l| l.force[k]).sum();
        let split = result.velocity_product[k] + result.gravity[k] - loads;
        assert!(
            (result.tau[k] - split).abs() <= 2.0 * result.error_estimate[k],
            "coordinate {k}: τ(0) = {} but c + g − ΣQ = {split}",
            result.tau[k]
        );
    }
    let result = dynamics.inverse_dynamics(&state, &q_ddot).expect("rnea");
    let tree = dynamics.tree().clone();
    for reaction in &result.reactions {
        for k in tree.dof_range(reaction.body) {
            let (w, v) = dynamics.workspace().motion_column(k).expect("column");
            let power = reaction.wrench.power(&w, &v);
            assert!(
                (power - result.tau[k]).abs() <= 2.0 * result.error_estimate[k],
                "coordinate {k}: the joint's wrench has power {power} on its column, τ = {}",
                result.tau[k]
            );
        }
    }
}

/// Each freed body obeys K = m ẍ_C and M_C = J_C ω̇ + ω × J_C ω with its weight, its joint's
/// reaction and the reactions of its children's joints (7.33–7.36); ẍ_C from the kinematics
/// crate's point acceleration, not from the recursion's own formula.
fn check_reactions_balance_bodies(dynamics: &mut Dynamics, rng: &mut Rng) {
    let (q, q_dot, q_ddot) = random_state(rng, dynamics.mechanism());
    let state = State::new(&q, &q_dot);
    let result = dynamics.inverse_dynamics(&state, &q_ddot).expect("rnea");
    let tree = dynamics.tree().clone();
    let bodies = dynamics.mechanism().bodies().to_vec();
    let g = dynamics.mechanism().gravity();
    let ws = dynamics.workspace();
    for i in 0..tree.body_count() {
        let x_c = ws.point_position(i, &bodies[i].p_oc).expect("centre");
        let a_c = ws.point_acceleration(i, &bodies[i].p_oc).expect("acceleration");
        let r = ws.rotation(i).expect("rotation");
        let j_c = r.matrix() * bodies[i].inertia_c * r.matrix().transpose();
        let (w, wd) = (
            ws.angular_velocity(i).expect("ω"),
            ws.angular_acceleration(i).expect("ω̇"),
        );
        let momentum_rate = a_c * bodies[i].mass;
        let angular_rate = j_c * wd + w.cross(&(j_c * w));
        // Loads on body i about its centre: weight, own joint's reaction, children's reactions.
        let mut force = g * bodies[i].mass + result.reactions[i].wrench.force;
        let o_i = ws.position(i).expect("origin");
        let mut moment = result.reactions[i].wrench.moment + (o_i - x_c).cross(&result.reactions[i].wrench.force);
        // Rounding scale: every term's size, and the transmitted wrenches of the whole subtree
        // (each W carries the rounding of everything summed into it).
        let mut size = (g * bodies[i].mass).norm() + momentum_rate.norm() + j_c.norm() * (wd.norm() + w.norm_squared());
        for c in (0..tree.body_count()).filter(|&c| tree.parent(c) == Some(i)) {
            let reaction = result.reactions[c].wrench;
            let o_c = ws.position(c).expect("child origin");
            force -= reaction.force;
            moment -= reaction.moment + (o_c - x_c).cross(&reaction.force);
        }
        for b in (0..tree.body_count()).filter(|&b| tree.is_ancestor_or_self(i, b)) {
            let reaction = result.reactions[b].wrench;
            let lever = (ws.position(b).expect("origin") - x_c).norm();
            size += reaction.force.norm() * (1.0 + lever) + reaction.moment.norm();
        }
        let tolerance = 64.0 * (tree.body_count() as f64 + 4.0) * f64::EPSILON * size;
        assert!(
            (force - momentum_rate).norm() <= tolerance,
            "body {i}: K − m ẍ_C = {:e}",
            (force - momentum_rate).norm()
        );
        assert!(
            (moment - angular_rate).norm() <= tolerance,
            "body {i}: M_C − Ḋ_C = {:e}",
            (moment - angular_rate).norm()
        );
    }
}

/// ABA(RNEA(q̈)) = q̈ and ABA agrees with CRBA + Cholesky, each within κ(A)-based estimates.
fn check_aba(dynamics: &mut Dynamics, rng: &mut Rng) {
    let (q, q_dot, q_ddot) = random_state(rng, dynamics.mechanism());
    let state = State::new(&q, &q_dot);
    let tau = dynamics.inverse_dynamics(&state, &q_ddot).expect("rnea").tau;
    let aba = dynamics.forward_dynamics(&state, &tau).expect("forward dynamics");
    let crba = dynamics.forward_dynamics_crba(&state, &tau).expect("crba");
    let mut fast = vec![0.0; q.len()];
    dynamics.aba_into(&q, &q_dot, &tau, &mut fast).expect("aba_into");
    let estimate = crba.error_estimate.expect("estimate");
    let condition = crba.condition.expect("condition");
    let size = norm_inf(&q_ddot);
    // Both routes solve the same equations; their difference and their distance to the q̈ that
    // produced τ are bounded by κ(A) times their backward errors.
    // The τ that RNEA returned carries its own rounding, so the q̈ it belongs to differs from the
    // q̈ it was computed from by up to one more error estimate.
    let allowance = 3.0 * estimate + condition * aba.backward_error * size;
    let aba_error: Vec<f64> = aba.q_ddot.iter().zip(&q_ddot).map(|(a, b)| a - b).collect();
    let routes: Vec<f64> = aba.q_ddot.iter().zip(&crba.q_ddot).map(|(a, b)| a - b).collect();
    assert!(
        norm_inf(&aba_error) <= allowance,
        "ABA(RNEA(q̈)) − q̈ = {:e} > {allowance:e} (κ = {condition:e}, η = {:e})",
        norm_inf(&aba_error),
        aba.backward_error
    );
    assert!(
        norm_inf(&routes) <= allowance,
        "ABA − CRBA = {:e} > {allowance:e}",
        norm_inf(&routes)
    );
    assert!(
        aba.backward_error < 1e-13,
        "forward dynamics backward error {:e}",
        aba.backward_error
    );
    // The bare recursion: its backward error grows with the grading (module docs of
    // `forward`), so it is held to κ(A) times the mass ratio's rounding.
    let fast_error: Vec<f64> = fast.iter().zip(&q_ddot).map(|(a, b)| a - b).collect();
    let ratio = mass_ratio(dynamics);
    let fast_allowance = allowance + condition * ratio * 64.0 * f64::EPSILON * size;
    assert!(
        norm_inf(&fast_error) <= fast_allowance,
        "aba_into − q̈ = {:e} > {fast_allowance:e}",
        norm_inf(&fast_error)
    );
}

fn mass_ratio(dynamics: &Dynamics) -> f64 {
    let masses = dynamics.mechanism().bodies().iter().map(|b| b.mass);
    let (lo, hi) = masses.fold((f64::INFINITY, 0.0f64), |(lo, hi), m| (lo.min(m), hi.max(m)));
    hi / lo
}

/// `mass_matrix_into` on the model's own workspace gives A(q) bit for bit as `mass_matrix`,
/// over a buffer of garbage, and leaves the next inverse dynamics unchanged (it re-evaluates
/// its state).
fn check_mass_matrix_into(dynamics: &mut Dynamics, rng: &mut Rng) {
    let (q, q_dot, q_ddot) = random_state(rng, dynamics.mechanism());
    let (q2, _, _) = random_state(rng, dynamics.mechanism());
    let n = q.len();
    let state = State::new(&q, &q_dot);
    let before = dynamics.inverse_dynamics(&state, &q_ddot).expect("rnea").tau;
    let mut into = vec![f64::NAN; n * n];
    dynamics.mass_matrix_into(&q2, &mut into).expect("mass matrix into");
    let a = dynamics.mass_matrix(&q2).expect("mass matrix");
    for k in 0..n {
        for l in 0..n {
            assert_eq!(into[k + n * l].to_bits(), a[(k, l)].to_bits(), "A[{k},{l}]");
        }
    }
    let after = dynamics.inverse_dynamics(&state, &q_ddot).expect("rnea").tau;
    assert_eq!(before, after);
    let mut wrong = vec![0.0; n * n + 1];
    assert!(dynamics.mass_matrix_into(&q2, &mut wrong).is_err());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn mass_matrix_into_matches_mass_matrix(seed in any::<u64>(), bodies in 1usize..12, chain in any::<bool>()) {
        let (mut dynamics, mut rng) = dynamics_with_gravity(seed, bodies, 12.0, chain);
        check_mass_matrix_into(&mut dynamics, &mut rng);
    }

    #[test]
    fn rnea_matches_the_mass_matrix(seed in any::<u64>(), bodies in 1usize..12, chain in any::<bool>()) {
        let (mut dynamics, mut rng) = dynamics_with_gravity(seed, bodies, 12.0, chain);
        check_rnea_against_mass_matrix(&mut dynamics, &mut rng);
    }

    #[test]
    fn bias_split_and_joint_power(seed in any::<u64>(), bodies in 1usize..12, chain in any::<bool>()) {
        let (mut dynamics, mut rng) = dynamics_with_gravity(seed, bodies, 12.0, chain);
        check_split_and_joint_power(&mut dynamics, &mut rng);
    }

    #[test]
    fn reactions_balance_every_body(seed in any::<u64>(), bodies in 1usize..12, chain in any::<bool>()) {
        let (mut dynamics, mut rng) = dynamics_with_gravity(seed, bodies, 12.0, chain);
        check_reactions_balance_bodies(&mut dynamics, &mut rng);
    }

    #[test]
    fn aba_inverts_rnea_and_matches_crba(seed in any::<u64>(), bodies in 1usize..12, chain in any::<bool>(), grading in 0.0f64..12.0) {
        let (mut dynamics, mut rng) = dynamics_with_gravity(seed, bodies, grading, chain);
        check_aba(&mut dynamics, &mut rng);
    }
}
