//! The Lie-group integrators of the free rigid body (`free_body::LieIntegrator`) against the
//! exact solution `TorqueFreeBody` (an independent closed form): the order of each method, R on
//! SO(3) and |L| over long runs, the honesty of the error estimate over a random family, and
//! typed errors for bad input.

mod common;

use common::Rng;
use mechanica_dynamics::DynamicsError;
use mechanica_dynamics::free_body::{LieIntegrator, LieMethod, MAX_LIE_STEPS, TorqueFreeBody};
use mechanica_kinematics::rotation::log_map;
use nalgebra::{Matrix3, Rotation3, Vector3};
use proptest::prelude::*;

/// A free-body problem.
#[derive(Debug, Clone)]
struct Case {
    moments: Vector3<f64>,
    omega0: Vector3<f64>,
    r0: Rotation3<f64>,
}

/// Sorted moments in [0.5, 5] that obey the triangle inequality.
fn sorted_moments(rng: &mut Rng) -> [f64; 3] {
    loop {
        let mut m = [rng.uniform(0.5, 5.0), rng.uniform(0.5, 5.0), rng.uniform(0.5, 5.0)];
        m.sort_by(f64::total_cmp);
        if m[2] <= m[0] + m[1] {
            return m;
        }
    }
}

/// The sorted case turned by a cyclic permutation of the axes (the frame stays right-handed).
fn permuted(rng: &mut Rng, sorted: [f64; 3], omega: Vector3<f64>) -> Case {
    let shift = rng.below(3);
    let cyclic = |v: [f64; 3]| Vector3::new(v[shift % 3], v[(shift + 1) % 3], v[(shift + 2) % 3]);
    Case {
        moments: cyclic(sorted),
        omega0: cyclic([omega.x, omega.y, omega.z]),
        r0: rng.rotation(),
    }
}

/// ω(0) at relative distance `delta` from the separatrix (the sign of delta picks the side).
fn near_separatrix(rng: &mut Rng, delta: f64, scale: f64) -> Case {
    let m = sorted_moments(rng);
    let w1 = rng.uniform(0.3, 1.0) * scale;
    let w2 = rng.uniform(-0.5, 0.5) * scale;
    let ratio = m[0] * (m[1] - m[0]) * (1.0 + delta) / (m[2] * (m[2] - m[1]) * (1.0 - delta));
    let w3 = w1 * ratio.sqrt() * if rng.below(2) == 0 { 1.0 } else { -1.0 };
    permuted(rng, m, Vector3::new(w1, w2, w3))
}

/// Two moments equal to a relative 1e-8..1e-4.
fn near_axisymmetric(rng: &mut Rng, scale: f64) -> Case {
    let base = rng.uniform(1.0, 3.0);
    let split = base * 10f64.powf(rng.uniform(-8.0, -4.0));
    let other = rng.uniform(0.6 * base, 1.9 * base);
    let mut m = [base, base + split, other];
    m.sort_by(f64::total_cmp);
    let omega = rng.vector(scale);
    permuted(rng, m, omega)
}

/// A body of every kind: generic, near-axisymmetric, near the separatrix; |ω| scaled by 0.1..10.
fn random_case(rng: &mut Rng) -> Case {
    let scale = 10f64.powf(rng.uniform(-1.0, 1.0));
    match rng.below(3) {
        0 => {
            let m = sorted_moments(rng);
            let omega = rng.vector(scale);
            permuted(rng, m, omega)
        }
        1 => near_axisymmetric(rng, scale),
        _ => {
            let delta = 10f64.powf(rng.uniform(-6.0, -2.0)) * if rng.below(2) == 0 { 1.0 } else { -1.0 };
            near_separatrix(rng, delta, scale)
        }
    }
}

/// The fastest rate of the motion: |ω| times the spread of the moments.
fn rate(case: &Case) -> f64 {
    case.omega0.norm() * case.moments.max() / case.moments.min()
}

/// (attitude angle, relative ω error) of (R, ω) against the exact state at t.
fn true_error(case: &Case, t: f64, rotation: &Rotation3<f64>, omega: &Vector3<f64>) -> (f64, f64) {
    let exact = TorqueFreeBody::new(case.moments, case.omega0, case.r0).expect("a valid body");
    let (r, w) = exact.state_at(t).expect("the exact state");
    (
        log_map(&(r.transpose() * rotation)).norm(),
        (omega - w).norm() / w.norm(),
    )
}

fn worst_true_error(case: &Case, method: LieMethod, t: f64, steps: f64) -> f64 {
    let integrator = LieIntegrator::new(case.moments, method).expect("valid moments");
    let solution = integrator
        .integrate(&case.r0, &case.omega0, t, t / steps)
        .expect("a run");
    let (attitude, omega) = true_error(case, t, &solution.rotation, &solution.omega);
    attitude.max(omega)
}

/// The observed order: the median of log₂(e(n)/e(2n)) over the first three halvings in the
/// asymptotic range, where a step spans at most a quarter radian of the fastest rate and the
/// error over two radians is below 1e-3 for orders up to 4 and 1e-6 above (the terms after the
/// leading one of an order-8 composition still weigh at 1e-3). Halvings whose finer run is at
/// rounding level (1e-12) are left out; None when none is left. The median keeps one ratio
/// distorted by a sign change of the error's leading term from deciding the order.
fn observed_order(case: &Case, method: LieMethod) -> Option<f64> {
    let t = 2.0 / rate(case);
    let asymptotic = if method.order() > 4 { 1e-6 } else { 1e-3 };
    let mut steps = 8.0;
    let mut coarse = worst_true_error(case, method, t, steps);
    while coarse >= asymptotic {
        steps *= 2.0;
        coarse = worst_true_error(case, method, t, steps);
    }
    let mut orders = Vec::new();
    for _ in 0..3 {
        steps *= 2.0;
        let fine = worst_true_error(case, method, t, steps);
        if fine <= 1e-12 {
            break;
        }
        orders.push((coarse / fine).log2());
        coarse = fine;
    }
    orders.sort_by(f64::total_cmp);
    orders.get(orders.len() / 2).copied()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Halving the step divides the error by 2ᵖ, p the method's order (within ±0.6 for the
    /// median order of [`observed_order`]; higher-order terms and rounding blur it).
    #[test]
    fn each_method_converges_with_its_order(seed in any::<u64>(), which in 0usize..5) {
        let mut rng = Rng::new(seed);
        let m = sorted_moments(&mut rng);
        let omega = rng.vector(1.0);
        let case = permuted(&mut rng, m, omega);
        let method = LieMethod::ALL[which];
        if let Some(order) = observed_order(&case, method) {
            let p = f64::from(method.order());
            prop_assert!((order - p).abs() <= 0.6, "{method:?}: observed order {order} for {case:?}");
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2))]

    /// The estimate bounds the true error of the reported run (attitude and ω) for at least
    /// 97.5% of a family of 600 random bodies (generic, near-axisymmetric, 1e-6..1e-2 from the
    /// separatrix), methods, durations (0.5..5 radians of the fastest rate, times 1..20) and
    /// steps. (The misses, 0 to 7 per 600 over 15 families, are runs of order 6 and 8 at the
    /// rounding level, 1e-13..1e-10, whose three runs share the amplified rounding of the
    /// initial state.)
    #[test]
    fn the_error_estimate_bounds_the_true_error(seed in any::<u64>()) {
        let mut rng = Rng::new(seed);
        let mut honest = 0;
        let mut report = Vec::new();
        for _ in 0..600 {
            let case = random_case(&mut rng);
            let method = LieMethod::ALL[rng.below(5)];
            let t = rng.uniform(0.5, 5.0) * rng.uniform(1.0, 20.0) / rate(&case);
            let radians_per_step = 10f64.powf(rng.uniform(-2.0, -0.5));
            let step = radians_per_step / rate(&case);
            let integrator = LieIntegrator::new(case.moments, method).expect("valid moments");
            let estimate = integrator.integrate_with_estimate(&case.r0, &case.omega0, t, step).expect("a run");
            let solution = &estimate.solution;
            let (attitude, omega) = true_error(&case, t, &solution.rotation, &solution.omega);
            if attitude <= estimate.attitude_error && omega <= estimate.omega_error {
                honest += 1;
            } else {
                report.push((method, attitude, estimate.attitude_error, omega, estimate.omega_error));
            }
        }
        prop_assert!(honest >= 585, "{honest} of 600 honest; failures {report:?}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4))]

    /// Steps far too long for the motion (0.3..2 rad of the fastest rate per step, over 5..60
    /// radians): wherever the runs lose the phase, the estimate is the largest error there can
    /// be, so every estimate bounds the true error, with no exception allowed.
    #[test]
    fn estimates_of_runs_that_lose_the_phase_still_bound_the_error(seed in any::<u64>()) {
        let mut rng = Rng::new(seed);
        let mut saturated = 0;
        for _ in 0..100 {
            let case = random_case(&mut rng);
            let method = LieMethod::ALL[rng.below(5)];
            let t = rng.uniform(5.0, 60.0) / rate(&case);
            let step = 10f64.powf(rng.uniform(-0.5, 0.3)) / rate(&case);
            let integrator = LieIntegrator::new(case.moments, method).expect("valid moments");
            let estimate = integrator.integrate_with_estimate(&case.r0, &case.omega0, t, step).expect("a run");
            let solution = &estimate.solution;
            let (attitude, omega) = true_error(&case, t, &solution.rotation, &solution.omega);
            prop_assert!(
                attitude <= estimate.attitude_error && omega <= estimate.omega_error,
                "{method:?} {case:?} t {t} step {step}: true ({attitude:e}, {omega:e}), \
                 estimate ({:e}, {:e})",
                estimate.attitude_error,
                estimate.omega_error
            );
            saturated += usize::from(estimate.attitude_error >= std::f64::consts::PI);
        }
        prop_assert!(saturated >= 10, "only {saturated} of 100 runs lost the phase: the family is too easy");
    }
}

/// ‖RᵀR − I‖ (max entry).
fn orthonormality_defect(r: &Rotation3<f64>) -> f64 {
    (r.matrix().transpose() * r.matrix() - Matrix3::identity()).amax()
}

/// Over 200 000 steps (a few hundred periods) R stays orthonormal to n·ε without being
/// renormalised, and for the splittings |L| = |R I ω| keeps its initial value to n·ε.
#[test]
fn rotation_stays_on_so3_and_momentum_norm_is_conserved() {
    let mut rng = Rng::new(17);
    let steps = 200_000u64;
    let allowance = steps as f64 * f64::EPSILON;
    for method in LieMethod::ALL {
        let case = random_case(&mut rng);
        let t = 2000.0 / rate(&case);
        let integrator = LieIntegrator::new(case.moments, method).expect("valid moments");
        let solution = integrator
            .integrate(&case.r0, &case.omega0, t, t / steps as f64)
            .expect("a run");
        assert_eq!(solution.steps, steps);
        let defect = orthonormality_defect(&solution.rotation);
        assert!(
            defect <= allowance,
            "{method:?}: ‖RᵀR − I‖ = {defect:e} > n·ε = {allowance:e}"
        );
        if method != LieMethod::Rkmk4 {
            let start = case.moments.component_mul(&case.omega0).norm();
            let end = case.moments.component_mul(&solution.omega).norm();
            let drift = (end - start).abs() / start;
            assert!(drift <= allowance, "{method:?}: |L| drifted by {drift:e}");
        }
    }
}

/// The order-6 and order-8 splittings reach 1e-9 against the exact solution over 20 periods
/// of random bodies with 20 steps per radian of the fastest rate, and a steady rotation about a principal axis is
/// reproduced to rounding.
#[test]
fn high_order_splittings_match_the_exact_solution() {
    let mut rng = Rng::new(5);
    for _ in 0..6 {
        let m = sorted_moments(&mut rng);
        let omega = rng.vector(1.0);
        let case = permuted(&mut rng, m, omega);
        let body = TorqueFreeBody::new(case.moments, case.omega0, case.r0).expect("a valid body");
        let Some(period) = body.period() else { continue };
        for method in [LieMethod::Splitting6, LieMethod::Splitting8] {
            let t = 20.0 * period;
            let error = worst_true_error(&case, method, t, (t * rate(&case) * 20.0).ceil());
            assert!(error < 1e-9, "{method:?}: error {error:e} for {case:?}");
        }
    }
    let case = Case {
        moments: Vector3::new(1.0, 2.0, 3.0),
        omega0: Vector3::new(0.0, 0.0, 1.3),
        r0: Rotation3::new(Vector3::new(0.1, 0.2, 0.3)),
    };
    for method in LieMethod::ALL {
        let error = worst_true_error(&case, method, 50.0, 500.0);
        assert!(error < 1e-13, "{method:?}: steady rotation error {error:e}");
    }
}

/// The estimate of `integrate_to_tolerance` meets the tolerance and the true error does too.
#[test]
fn integration_to_a_tolerance_meets_it() {
    let mut rng = Rng::new(11);
    for tolerance in [1e-6, 1e-9] {
        let case = near_separatrix(&mut rng, 1e-3, 1.0);
        let t = 200.0 / rate(&case);
        let integrator = LieIntegrator::new(case.moments, LieMethod::Splitting6).expect("valid moments");
        let estimate = integrator
            .integrate_to_tolerance(&case.r0, &case.omega0, t, t / 16.0, tolerance)
            .expect("converges");
        assert!(estimate.attitude_error <= tolerance && estimate.omega_error <= tolerance);
        let (attitude, omega) = true_error(&case, t, &estimate.solution.rotation, &estimate.solution.omega);
        assert!(
            attitude <= tolerance && omega <= tolerance,
            "true errors {attitude:e}, {omega:e}"
        );
    }
}

/// A tolerance below what rounding allows ends with `NotConverged` once the estimate stops
/// falling, long before the cap of 2³⁰ steps, and the residual it reports is above the
/// tolerance.
#[test]
fn tolerances_below_the_rounding_floor_end_as_not_converged() {
    let mut rng = Rng::new(5);
    for method in [LieMethod::Rkmk4, LieMethod::Splitting6] {
        let case = near_separatrix(&mut rng, 1e-3, 1.0);
        let t = 200.0 / rate(&case);
        let integrator = LieIntegrator::new(case.moments, method).expect("valid moments");
        match integrator.integrate_to_tolerance(&case.r0, &case.omega0, t, t / 2000.0, 1e-17) {
            Err(DynamicsError::NotConverged {
                iterations, residual, ..
            }) => {
                assert!(residual > 1e-17, "{method:?}: residual {residual:e}");
                assert!(iterations < 22, "{method:?}: {iterations} doublings");
            }
            other => panic!("{method:?}: expected NotConverged, got {other:?}"),
        }
    }
}

fn out_of_range(result: Result<impl std::fmt::Debug, DynamicsError>, expected_what: &str) {
    match result {
        Err(DynamicsError::OutOfRange { what, .. }) => assert!(what.contains(expected_what), "{what}"),
        other => panic!("expected OutOfRange for {expected_what}, got {other:?}"),
    }
}

#[test]
fn bad_moments_are_typed_errors() {
    let method = LieMethod::Splitting6;
    for bad in [0.0, -1.0] {
        out_of_range(
            LieIntegrator::new(Vector3::new(1.0, bad, 2.0), method),
            "principal moment",
        );
    }
    for bad in [f64::NAN, f64::INFINITY] {
        assert!(matches!(
            LieIntegrator::new(Vector3::new(1.0, 2.0, bad), method),
            Err(DynamicsError::NonFiniteInput { .. })
        ));
    }
    out_of_range(
        LieIntegrator::new(Vector3::new(1.0, 1.0, 2.5), method),
        "triangle inequality",
    );
    assert!(
        LieIntegrator::new(Vector3::new(1.0, 1.5, 2.5), method).is_ok(),
        "a lamina is a body"
    );
}

#[test]
fn bad_steps_durations_tolerances_and_states_are_typed_errors() {
    let integrator = LieIntegrator::new(Vector3::new(1.0, 2.0, 2.5), LieMethod::Rkmk4).expect("valid moments");
    let (r0, w0) = (Rotation3::identity(), Vector3::new(0.1, 0.2, 0.3));
    for step in [0.0, -0.1] {
        out_of_range(integrator.integrate(&r0, &w0, 1.0, step), "step");
        out_of_range(integrator.integrate_with_estimate(&r0, &w0, 1.0, step), "step");
    }
    out_of_range(integrator.integrate(&r0, &w0, -1.0, 0.1), "duration");
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert!(matches!(
            integrator.integrate(&r0, &w0, 1.0, bad),
            Err(DynamicsError::NonFiniteInput { .. })
        ));
        assert!(matches!(
            integrator.integrate(&r0, &w0, bad, 0.1),
            Err(DynamicsError::NonFiniteInput { .. })
        ));
        assert!(matches!(
            integrator.integrate(&r0, &Vector3::new(0.0, bad, 0.0), 1.0, 0.1),
            Err(DynamicsError::NonFiniteInput { .. })
        ));
        assert!(matches!(
            integrator.integrate_to_tolerance(&r0, &w0, 1.0, 0.1, bad),
            Err(DynamicsError::NonFiniteInput { .. })
        ));
    }
    for tolerance in [0.0, -1e-9] {
        out_of_range(
            integrator.integrate_to_tolerance(&r0, &w0, 1.0, 0.1, tolerance),
            "tolerance",
        );
    }
    let over_cap = MAX_LIE_STEPS as f64 * 1.5;
    for result in [
        integrator.integrate(&r0, &w0, over_cap, 1.0).map(|s| s.steps),
        integrator.integrate(&r0, &w0, 1.0, f64::MIN_POSITIVE).map(|s| s.steps),
        integrator
            .integrate_with_estimate(&r0, &w0, MAX_LIE_STEPS as f64 * 0.75, 1.0)
            .map(|s| s.solution.steps),
    ] {
        assert!(
            matches!(result, Err(DynamicsError::TooManySteps { cap: MAX_LIE_STEPS, .. })),
            "{result:?}"
        );
    }
    let skewed = Rotation3::from_matrix_unchecked(Matrix3::new(1.0, 1e-6, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0));
    out_of_range(integrator.integrate(&skewed, &w0, 1.0, 0.1), "R(0)");
    let reflection = Rotation3::from_matrix_unchecked(Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0)));
    out_of_range(integrator.integrate(&reflection, &w0, 1.0, 0.1), "R(0)");
    let zero = integrator.integrate(&r0, &w0, 0.0, 0.1).expect("an empty run");
    assert_eq!((zero.steps, zero.omega), (0, w0));
}

/// A step so large that the rotation angle per step overflows is a typed error, not a NaN.
#[test]
fn overflowing_states_are_typed_errors() {
    let integrator = LieIntegrator::new(Vector3::new(1.0, 2.0, 2.5), LieMethod::Rkmk4).expect("valid moments");
    let result = integrator.integrate(&Rotation3::identity(), &Vector3::new(1e200, 1e200, 1e200), 1e3, 1.0);
    assert!(result.is_err(), "{result:?}");
}
