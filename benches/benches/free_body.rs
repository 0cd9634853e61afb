//! Criterion benchmark: the free rigid body integrated by the Lie–Poisson splitting of order 6
//! (`free_body::LieIntegrator`, `LieMethod::Splitting6`, the fastest method to that error) over 100 periods of the problem of
//! crates/mechanica-dynamics/examples/free_body_work_precision.rs (moments (1, 2, 3), ω(0) at
//! relative distance 1e-3 from the separatrix), with the number of steps at which the
//! work-precision run (tools/free_body_work_precision.csv) reaches an attitude error ≤ 1e-10
//! against the exact solution. Before timing, the bench checks that error against
//! `TorqueFreeBody` and prints it.

use criterion::Criterion;
use mechanica::kinematics::nalgebra::{Rotation3, Vector3};
use mechanica::kinematics::rotation::log_map;
use mechanica_dynamics::free_body::{LieIntegrator, LieMethod, TorqueFreeBody};
use std::hint::black_box;
use std::time::Duration;

/// Steps over the 100 periods (from tools/free_body_work_precision.csv).
const STEPS: f64 = 90_950.0;

fn problem() -> (Vector3<f64>, Vector3<f64>, Rotation3<f64>) {
    let moments = Vector3::new(1.0, 2.0, 3.0);
    let (w1, w2, delta): (f64, f64, f64) = (0.8, 0.1, 1e-3);
    let ratio =
        moments.x * (moments.y - moments.x) * (1.0 + delta) / (moments.z * (moments.z - moments.y) * (1.0 - delta));
    let omega0 = Vector3::new(w1, w2, w1 * ratio.sqrt());
    (moments, omega0, Rotation3::new(Vector3::new(0.3, -0.5, 0.8)))
}

fn main() {
    let (moments, omega0, r0) = problem();
    let body = TorqueFreeBody::new(moments, omega0, r0).expect("a valid body");
    let duration = 100.0 * body.period().expect("an elliptic motion");
    let (r_exact, _) = body.state_at(duration).expect("the exact state");
    let integrator = LieIntegrator::new(moments, LieMethod::Splitting6).expect("valid moments");
    let step = duration / STEPS;
    let solution = integrator.integrate(&r0, &omega0, duration, step).expect("a run");
    let error = log_map(&(r_exact.transpose() * solution.rotation)).norm();
    println!(
        "# Splitting6, {} steps over 100 periods: attitude error {error:.2e}",
        solution.steps
    );
    let mut c = Criterion::default()
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(5))
        .sample_size(20)
        .configure_from_args();
    c.bench_function("free_body/splitting6_100_periods_1e-10", |b| {
        b.iter(|| integrator.integrate(black_box(&r0), black_box(&omega0), duration, step))
    });
    c.final_summary();
}
