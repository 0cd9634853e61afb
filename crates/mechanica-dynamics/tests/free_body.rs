//! The exact torque-free motion (`free_body::TorqueFreeBody`) against independent references:
//! a classical RK4 integration of Euler's equations (7.41) and Ṙ = R[ω]× with small steps, the
//! first integrals T and L, orthonormality, and 30-digit Taylor integrations of mpmath
//! (tools/free_body_reference.py) up to 100 periods.

mod common;

use common::Rng;
use mechanica_dynamics::DynamicsError;
use mechanica_dynamics::free_body::{Regime, TorqueFreeBody, attitude_rate, euler_rates};
use nalgebra::{Matrix3, Rotation3, Vector3};

/// A body with sorted moments `sorted`, presented to the solver with its axes permuted at random
/// (a proper signed permutation, so the body frame stays right-handed).
struct Case {
    moments: Vector3<f64>,
    omega0: Vector3<f64>,
    r0: Rotation3<f64>,
}

fn permuted(rng: &mut Rng, sorted: Vector3<f64>, omega: Vector3<f64>) -> Case {
    let shift = rng.below(3);
    let cyclic = |v: Vector3<f64>| Vector3::new(v[shift % 3], v[(shift + 1) % 3], v[(shift + 2) % 3]);
    Case {
        moments: cyclic(sorted),
        omega0: cyclic(omega),
        r0: rng.rotation(),
    }
}

/// Distinct sorted moments in [0.5, 5] and a random ω of size ~1.
fn random_case(rng: &mut Rng) -> Case {
    let mut m = [rng.uniform(0.5, 5.0), rng.uniform(0.5, 5.0), rng.uniform(0.5, 5.0)];
    m.sort_by(f64::total_cmp);
    let omega = rng.vector(1.0);
    permuted(rng, Vector3::from(m), omega)
}

/// ω(0) at relative distance `delta` from the separatrix: I₃(I₃ − I₂)ω₃² − I₁(I₂ − I₁)ω₁² =
/// delta · (the sum of the two terms), with the sign of delta choosing the side.
fn near_separatrix(rng: &mut Rng, delta: f64) -> Case {
    let mut m = [rng.uniform(0.5, 5.0), rng.uniform(0.5, 5.0), rng.uniform(0.5, 5.0)];
    m.sort_by(f64::total_cmp);
    let w1 = rng.uniform(0.3, 1.0);
    let w2 = rng.uniform(-0.5, 0.5);
    let ratio = m[0] * (m[1] - m[0]) * (1.0 + delta) / (m[2] * (m[2] - m[1]) * (1.0 - delta));
    let w3 = w1 * ratio.sqrt() * if rng.below(2) == 0 { 1.0 } else { -1.0 };
    permuted(rng, Vector3::from(m), Vector3::new(w1, w2, w3))
}

fn body(case: &Case) -> TorqueFreeBody {
    TorqueFreeBody::new(case.moments, case.omega0, case.r0).expect("a valid body")
}

/// RK4 on (ω, R) with `steps` equal steps up to t.
fn rk4(case: &Case, t: f64, steps: usize) -> (Matrix3<f64>, Vector3<f64>) {
    let rhs = |w: &Vector3<f64>, r: &Matrix3<f64>| {
        let dw = euler_rates(&case.moments, w, &Vector3::zeros()).expect("a valid input");
        (dw, attitude_rate(r, w).expect("a valid input"))
    };
    let h = t / steps as f64;
    let (mut w, mut r) = (case.omega0, *case.r0.matrix());
    for _ in 0..steps {
        let (k1w, k1r) = rhs(&w, &r);
        let (k2w, k2r) = rhs(&(w + k1w * (h / 2.0)), &(r + k1r * (h / 2.0)));
        let (k3w, k3r) = rhs(&(w + k2w * (h / 2.0)), &(r + k2r * (h / 2.0)));
        let (k4w, k4r) = rhs(&(w + k3w * h), &(r + k3r * h));
        w += (k1w + k2w * 2.0 + k3w * 2.0 + k4w) * (h / 6.0);
        r += (k1r + k2r * 2.0 + k3r * 2.0 + k4r) * (h / 6.0);
    }
    (r, w)
}

/// Largest relative difference of ω and largest entry difference of R between the exact state
/// and RK4 at t, with 4000 steps per radian of the fastest rate.
fn rk4_error(case: &Case, t: f64) -> (f64, f64) {
    let rate = case.omega0.norm() * (case.moments.max() / case.moments.min());
    let steps = ((t * rate * 4000.0).ceil() as usize).max(100);
    let (r_ref, w_ref) = rk4(case, t, steps);
    let (r, w) = body(case).state_at(t).expect("a valid input");
    ((w - w_ref).norm() / w_ref.norm(), (r.matrix() - r_ref).abs().max())
}

fn regime_of_sorted(case: &Case) -> f64 {
    let mut pairs: Vec<(f64, f64)> = (0..3).map(|i| (case.moments[i], case.omega0[i])).collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let two_t: f64 = pairs.iter().map(|(i, w)| i * w * w).sum();
    let gamma2: f64 = pairs.iter().map(|(i, w)| (i * w) * (i * w)).sum();
    gamma2 - two_t * pairs[1].0
}

#[test]
fn random_bodies_follow_euler_equations_in_both_regimes() {
    let mut rng = Rng::new(11);
    let (mut major, mut minor, mut worst) = (0, 0, (0.0_f64, 0.0_f64));
    for _ in 0..40 {
        let case = random_case(&mut rng);
        let solver = body(&case);
        let side = regime_of_sorted(&case);
        match solver.regime() {
            Regime::MajorAxis => {
                assert!(side > 0.0);
                major += 1
            }
            Regime::MinorAxis => {
                assert!(side < 0.0);
                minor += 1
            }
            other => panic!("random case classified {other:?}"),
        }
        let t = 2.3 * solver.period().expect("a finite period");
        let (dw, dr) = rk4_error(&case, t);
        worst = (worst.0.max(dw), worst.1.max(dr));
    }
    println!(
        "random bodies ({major} major-axis, {minor} minor-axis): ω {:.2e}, R {:.2e}",
        worst.0, worst.1
    );
    assert!(major >= 5 && minor >= 5);
    assert!(worst.0 < 1e-9 && worst.1 < 1e-9, "{worst:?}");
}

#[test]
fn bodies_near_and_on_the_separatrix_follow_euler_equations() {
    let mut rng = Rng::new(12);
    for delta in [1e-6, -1e-6, 1e-10, -1e-10, 0.0] {
        let mut worst = (0.0_f64, 0.0_f64);
        for _ in 0..6 {
            let case = near_separatrix(&mut rng, delta);
            let solver = body(&case);
            if delta == 0.0 {
                assert_eq!(solver.regime(), Regime::Separatrix);
            } else {
                let expected = if delta > 0.0 {
                    Regime::MajorAxis
                } else {
                    Regime::MinorAxis
                };
                assert_eq!(solver.regime(), expected, "delta {delta}");
            }
            let t = 12.0 / case.omega0.norm();
            let (dw, dr) = rk4_error(&case, t);
            worst = (worst.0.max(dw), worst.1.max(dr));
        }
        println!("separatrix distance {delta:e}: ω {:.2e}, R {:.2e}", worst.0, worst.1);
        assert!(worst.0 < 1e-8 && worst.1 < 1e-8, "{delta}: {worst:?}");
    }
}

#[test]
fn axisymmetric_spherical_and_steady_bodies_follow_euler_equations() {
    let mut rng = Rng::new(13);
    let mut worst = (0.0_f64, 0.0_f64);
    for i in 0..12 {
        let (a, b) = (rng.uniform(0.5, 5.0), rng.uniform(0.5, 5.0));
        let sorted = match i % 4 {
            0 => Vector3::new(a.min(b), a.min(b), a.max(b)),
            1 => Vector3::new(a.min(b), a.max(b), a.max(b)),
            2 => Vector3::new(a, a, a),
            _ => Vector3::new(a.min(b), 0.5 * (a + b), a.max(b)),
        };
        let omega = if i % 4 == 3 {
            Vector3::new(0.0, rng.uniform(0.5, 2.0), 0.0)
        } else {
            rng.vector(1.0)
        };
        let case = permuted(&mut rng, sorted, omega);
        let solver = body(&case);
        if i % 4 >= 2 {
            assert_eq!(solver.regime(), Regime::Steady);
        } else {
            assert_eq!(solver.modulus(), Some(0.0));
        }
        let (dw, dr) = rk4_error(&case, 20.0);
        worst = (worst.0.max(dw), worst.1.max(dr));
    }
    println!("axisymmetric, spherical, steady: ω {:.2e}, R {:.2e}", worst.0, worst.1);
    assert!(worst.0 < 1e-9 && worst.1 < 1e-9, "{worst:?}");
}

/// T, L = R I ω in space and RᵀR = 1 over 100 periods, at 200 times.
#[test]
fn energy_momentum_and_orthonormality_hold_over_100_periods() {
    let mut rng = Rng::new(14);
    let (mut energy, mut momentum, mut orthonormality) = (0.0_f64, 0.0_f64, 0.0_f64);
    let mut cases: Vec<Case> = (0..10).map(|_| random_case(&mut rng)).collect();
    cases.push(near_separatrix(&mut rng, 1e-6));
    cases.push(near_separatrix(&mut rng, -1e-10));
    for case in &cases {
        let solver = body(case);
        let period = solver.period().expect("a valid input");
        let (t0, l0) = (solver.energy(), solver.angular_momentum());
        for j in 0..=200 {
            let t = 100.0 * period * j as f64 / 200.0 + if j % 2 == 1 { 0.123 * period } else { 0.0 };
            let (r, w) = solver.state_at(t).expect("a valid input");
            let iw = case.moments.component_mul(&w);
            energy = energy.max((0.5 * w.dot(&iw) - t0).abs() / t0);
            momentum = momentum.max((r * iw - l0).norm() / l0.norm());
            orthonormality =
                orthonormality.max((r.matrix().transpose() * r.matrix() - Matrix3::identity()).abs().max());
        }
    }
    println!("over 100 periods: T {energy:.2e}, L {momentum:.2e}, RᵀR − 1 {orthonormality:.2e}");
    assert!(energy < 1e-14 && momentum < 1e-14 && orthonormality < 1e-14);
}

#[test]
fn state_at_zero_is_the_initial_state() {
    let mut rng = Rng::new(15);
    for _ in 0..20 {
        let case = random_case(&mut rng);
        let (r, w) = body(&case).state_at(0.0).expect("a valid input");
        assert!((w - case.omega0).norm() <= 1e-14 * case.omega0.norm());
        assert!((r.matrix() - case.r0.matrix()).abs().max() <= 1e-14);
    }
}

fn numbers(value: &serde_json::Value) -> Vec<f64> {
    let list = value.as_array().expect("a list");
    list.iter()
        .map(|v| v.as_str().expect("text").parse().expect("a number"))
        .collect()
}

/// The attitude and ω against mpmath's 30-digit Taylor integration at up to 100 periods.
#[test]
fn attitude_matches_the_extended_precision_integration() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tools/free_body_reference.json");
    let text = std::fs::read_to_string(path).expect("tools/free_body_reference.json is committed");
    let reference: serde_json::Value = serde_json::from_str(&text).expect("JSON");
    let mut checked = 0;
    for case in reference["cases"].as_array().expect("cases") {
        let moments = Vector3::from_vec(numbers(&case["moments"]));
        let omega0 = Vector3::from_vec(numbers(&case["omega0"]));
        let r0 = Rotation3::from_matrix_unchecked(Matrix3::from_row_slice(&numbers(&case["r0"])));
        let solver = TorqueFreeBody::new(moments, omega0, r0).expect("a valid input");
        for state in case["states"].as_array().expect("states") {
            let s = numbers(state);
            let (r, w) = solver.state_at(s[0]).expect("a valid input");
            let dw = (w - Vector3::new(s[1], s[2], s[3])).norm() / omega0.norm();
            let dr = (r.matrix() - Matrix3::from_row_slice(&s[4..13])).abs().max();
            println!("{} at t = {:.6}: ω {dw:.2e}, R {dr:.2e}", case["name"], s[0]);
            assert!(dw < 1e-12 && dr < 1e-12, "{}: {dw:e} {dr:e}", case["name"]);
            checked += 1;
        }
    }
    assert!(checked >= 12);
}

#[test]
fn bad_inputs_are_typed_errors() {
    let r0 = Rotation3::identity();
    let good = Vector3::new(1.0, 2.0, 3.0);
    assert!(matches!(
        TorqueFreeBody::new(Vector3::new(1.0, -2.0, 3.0), good, r0),
        Err(DynamicsError::OutOfRange { .. })
    ));
    assert!(matches!(
        TorqueFreeBody::new(good, Vector3::new(f64::NAN, 0.0, 0.0), r0),
        Err(DynamicsError::NonFiniteInput { .. })
    ));
    let solver = TorqueFreeBody::new(good, Vector3::new(0.1, 0.2, 0.3), r0).expect("a valid input");
    assert!(matches!(
        solver.state_at(f64::INFINITY),
        Err(DynamicsError::NonFiniteInput { .. })
    ));
    assert!(matches!(
        solver.state_at(1e308),
        Err(DynamicsError::OutOfRange { what: "time t", .. })
    ));
    let huge = TorqueFreeBody::new(good, Vector3::new(1e200, 1e200, 1e200), r0);
    assert!(matches!(huge, Err(DynamicsError::NonFiniteResult { .. })));
}

/// Euler's equations with a torque M: the gyroscopic terms do no work and exert no moment on
/// |L|, so dT/dt = ω·M (7.48) and d|L|²/dt = 2 L·M, for random moments, ω and M.
#[test]
fn euler_rates_balance_power_and_momentum() {
    let mut rng = Rng::new(16);
    for _ in 0..200 {
        let scale = 10f64.powf(rng.uniform(-3.0, 3.0));
        let moments = Vector3::new(rng.uniform(0.1, 10.0), rng.uniform(0.1, 10.0), rng.uniform(0.1, 10.0)) * scale;
        let (omega, torque) = (rng.vector(3.0), rng.vector(scale));
        let rates = euler_rates(&moments, &omega, &torque).expect("a valid input");
        let i_rates = moments.component_mul(&rates);
        let momentum = moments.component_mul(&omega);
        let size = moments.max() * omega.norm() * omega.norm() * omega.norm() + torque.norm() * omega.norm();
        assert!((omega.dot(&i_rates) - omega.dot(&torque)).abs() <= 1e-14 * size);
        assert!((momentum.dot(&i_rates) - momentum.dot(&torque)).abs() <= 1e-14 * size * moments.max());
    }
}

#[test]
fn special_functions_and_rates_reject_bad_inputs() {
    use mechanica_dynamics::free_body::{carlson_rf, carlson_rj, elliptic_f, elliptic_k, elliptic_pi, jacobi_elliptic};
    let out_of_range = |r: Result<f64, DynamicsError>| matches!(r, Err(DynamicsError::OutOfRange { .. }));
    assert!(out_of_range(elliptic_k(1.0)));
    assert!(out_of_range(elliptic_k(1.5)));
    assert!(out_of_range(elliptic_pi(1.5, 0.3, 0.5)));
    assert!(out_of_range(carlson_rf(-1.0, 1.0, 1.0)));
    assert!(out_of_range(carlson_rf(0.0, 0.0, 1.0)));
    assert!(out_of_range(carlson_rj(1.0, 1.0, 1.0, -1.0)));
    assert!(matches!(
        elliptic_f(4.0, 1.0),
        Err(DynamicsError::NonFiniteResult { .. })
    ));
    assert!(matches!(
        jacobi_elliptic(f64::NAN, 0.5),
        Err(DynamicsError::NonFiniteInput { .. })
    ));
    let moments = Vector3::new(1.0, 0.0, 2.0);
    assert!(matches!(
        euler_rates(&moments, &Vector3::zeros(), &Vector3::zeros()),
        Err(DynamicsError::OutOfRange { .. })
    ));
    let torque = Vector3::new(f64::NAN, 0.0, 0.0);
    assert!(matches!(
        euler_rates(&Vector3::new(1.0, 2.0, 3.0), &Vector3::zeros(), &torque),
        Err(DynamicsError::NonFiniteInput { .. })
    ));
    assert!(matches!(
        attitude_rate(&Matrix3::identity(), &Vector3::new(f64::INFINITY, 0.0, 0.0)),
        Err(DynamicsError::NonFiniteInput { .. })
    ));
}

/// Far in time: up to 2⁵⁰ periods the state keeps the energy, the momentum and RᵀR = I (the
/// phase carries the rounding of σt, the invariants do not); beyond 2⁵² quarter periods, where
/// one ulp of σt is a quarter period, `state_at` refuses t instead of reducing a phase that is
/// rounding noise (before, the reduction ran out of its range and ω grew by 1e22).
#[test]
fn far_times_keep_the_invariants_or_are_refused() {
    let mut rng = Rng::new(16);
    for case_index in 0..30 {
        let case = random_case(&mut rng);
        let solver = body(&case);
        let period = solver.period().expect("a valid input");
        let (t0, l0) = (solver.energy(), solver.angular_momentum());
        for exponent in [20, 35, 45, 50] {
            let t = period * 2f64.powi(exponent) * rng.uniform(0.5, 1.0);
            let (r, w) = solver
                .state_at(t)
                .unwrap_or_else(|e| panic!("case {case_index}, t = {t:e}: {e}"));
            let iw = case.moments.component_mul(&w);
            assert!(
                (0.5 * w.dot(&iw) - t0).abs() <= 1e-13 * t0,
                "case {case_index}, t = {t:e}: T"
            );
            assert!(
                (r * iw - l0).norm() <= 1e-12 * l0.norm(),
                "case {case_index}, t = {t:e}: L"
            );
        }
        for far in [period * 2f64.powi(56), 4.325195312500001e34, -1e300] {
            let result = solver.state_at(far);
            assert!(
                matches!(result, Err(DynamicsError::OutOfRange { what: "time t", .. })),
                "case {case_index}, t = {far:e}: {result:?}"
            );
        }
    }
}
