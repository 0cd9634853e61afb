//! Constrained motion: RATTLE (M.17) and the projected methods (M.19) on a pendulum written as
//! a free point held by a rod, against the revolute pendulum integrated without constraints
//! (an independent formulation), and on random four-bar linkages (Grashof and not, masses over
//! four decades): constraint drift at rounding level, second-order convergence of RATTLE,
//! bounded energy, honest error estimates, typed failures.

mod common;

use common::{Rng, distance, pendulum};
use mechanica_dynamics::{ConstrainedDynamics, Constraint, Dynamics};
use mechanica_kinematics::tree::{Joint, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mechanism::{Anchor, Mechanism};
use mechanica_motion::{Method, MotionError, Options, Simulation, StepFailure, Trajectory};
use nalgebra::{Isometry3, Matrix3, Translation3, Vector2, Vector3};

const U: f64 = f64::EPSILON;

fn quiet() -> Options {
    Options {
        estimate_error: false,
        ..Options::default()
    }
}

/// A point mass m moving in the yz-plane on two prismatic joints (y, then z; the carriage of
/// the first is massless), held at distance l from the origin by a rod, gravity g along −z.
fn point_pendulum(m: f64, l: f64, g: f64) -> ConstrainedDynamics {
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Prismatic { axis: Vector3::y() }, Isometry3::identity());
    builder.add_body(Some(0), Joint::Prismatic { axis: Vector3::z() }, Isometry3::identity());
    let tree = builder.build().expect("tree");
    let carriage = MassProperties::ZERO;
    let bob = MassProperties::point(m, Vector3::zeros()).expect("bob");
    let mut mechanism = Mechanism::new(tree, vec![carriage, bob]).expect("mechanism");
    mechanism.set_gravity(Vector3::new(0.0, 0.0, -g)).expect("gravity");
    let mut constrained = ConstrainedDynamics::new(Dynamics::new(mechanism).expect("dynamics"));
    let rod = Constraint::Distance {
        a: Anchor {
            body: Some(1),
            point: Vector3::zeros(),
        },
        b: Anchor {
            body: None,
            point: Vector3::zeros(),
        },
        length: l,
    };
    constrained.add_constraint("rod", rod).expect("rod");
    constrained
}

/// The point pendulum's (q, q̇) for the revolute pendulum's (θ, θ̇): the bob at
/// (l sin θ, −l cos θ) in (y, z).
fn point_state(l: f64, theta: f64, rate: f64) -> (Vec<f64>, Vec<f64>) {
    (
        vec![l * theta.sin(), -l * theta.cos()],
        vec![l * rate * theta.cos(), l * rate * theta.sin()],
    )
}

/// A random pendulum: mass, length and g over decades, amplitude up to 2.5 rad.
struct PendulumCase {
    m: f64,
    l: f64,
    g: f64,
    theta: f64,
    rate: f64,
}

impl PendulumCase {
    fn random(rng: &mut Rng) -> Self {
        let (l, g) = (rng.decades(-1.0, 1.0), rng.decades(0.0, 1.5));
        Self {
            m: rng.decades(-2.0, 2.0),
            l,
            g,
            theta: rng.uniform(-2.5, 2.5),
            rate: rng.uniform(-0.5, 0.5) * (g / l).sqrt(),
        }
    }

    /// √(l/g), the time scale.
    fn period_scale(&self) -> f64 {
        (self.l / self.g).sqrt()
    }

    /// The revolute pendulum's motion as the point's (y, z) at the samples of `run_times`,
    /// by Dormand–Prince at rtol 1e-12 without constraints.
    fn reference(&self, t_end: f64, interval: f64) -> Vec<Vec<f64>> {
        let method = Method::DormandPrince {
            rtol: 1e-12,
            atol: 1e-14,
        };
        let simulation = Simulation::new(pendulum(self.m, self.l, self.g), method, quiet()).expect("simulation");
        let run = simulation
            .run(&[self.theta], &[self.rate], t_end, interval)
            .expect("reference");
        run.samples
            .iter()
            .map(|s| point_state(self.l, s.q[0], s.q_dot[0]).0)
            .collect()
    }

    fn run(&self, method: Method, options: Options, t_end: f64, interval: f64) -> Trajectory {
        let (q0, v0) = point_state(self.l, self.theta, self.rate);
        let simulation =
            Simulation::constrained(point_pendulum(self.m, self.l, self.g), method, options).expect("simulation");
        simulation.run(&q0, &v0, t_end, interval).expect("run")
    }
}

/// The largest position error of a run against the reference, relative to l.
fn position_error(run: &Trajectory, reference: &[Vec<f64>], l: f64) -> f64 {
    run.samples
        .iter()
        .zip(reference)
        .fold(0.0f64, |m, (s, r)| m.max(distance(&s.q, r)))
        / l
}

/// RATTLE, RK4 and Dormand–Prince with projection follow the revolute pendulum, RATTLE to its
/// own error estimate, and keep ‖f‖ and ‖J q̇‖ at rounding level.
#[test]
fn point_pendulum_follows_the_revolute_pendulum() {
    let mut rng = Rng::new(11);
    for case in 0..12 {
        let p = PendulumCase::random(&mut rng);
        let (t_end, interval) = (10.0 * p.period_scale(), p.period_scale());
        let reference = p.reference(t_end, interval);
        let h = 0.01 * p.period_scale();
        let rattle = p.run(Method::Rattle { step: h }, Options::default(), t_end, interval);
        let error = position_error(&rattle, &reference, p.l);
        assert!(error < 1e-2, "case {case}: RATTLE error {error:e}");
        for (sample, r) in rattle.samples.iter().zip(&reference) {
            let estimate = sample.error.expect("estimate").q;
            let truth = distance(&sample.q, r);
            assert!(
                truth <= estimate,
                "case {case} t = {}: error {truth:e} > estimate {estimate:e}",
                sample.t
            );
        }
        let drift = rattle.monitors.constraints;
        let speed = p.rate.abs() * p.l + (2.0 * p.g * p.l * 2.0).sqrt();
        assert!(
            drift.max_position <= 256.0 * U * p.l,
            "case {case}: ‖f‖ {:e}",
            drift.max_position
        );
        assert!(
            drift.max_velocity <= 256.0 * U * speed,
            "case {case}: ‖J q̇‖ {:e}",
            drift.max_velocity
        );
        for method in [
            Method::Rk4 { step: h },
            Method::DormandPrince {
                rtol: 1e-10,
                atol: 1e-12 * p.l,
            },
        ] {
            let run = p.run(method, quiet(), t_end, interval);
            let error = position_error(&run, &reference, p.l);
            assert!(error < 1e-6, "case {case} {method:?}: error {error:e}");
            let drift = run.monitors.constraints;
            assert!(
                drift.max_position <= 256.0 * U * p.l,
                "case {case} {method:?}: ‖f‖ {:e}",
                drift.max_position
            );
            assert!(
                drift.max_velocity <= 256.0 * U * speed,
                "case {case} {method:?}: ‖J q̇‖ {:e}",
                drift.max_velocity
            );
        }
    }
}

/// RATTLE's error on the point pendulum at t = 10√(l/g) falls by 4 when the step halves.
#[test]
fn rattle_is_second_order_on_the_point_pendulum() {
    let mut rng = Rng::new(23);
    for case in 0..6 {
        let p = PendulumCase::random(&mut rng);
        let t_end = 10.0 * p.period_scale();
        let reference = p.reference(t_end, t_end);
        let errors: Vec<f64> = [0.02, 0.01, 0.005, 0.0025]
            .iter()
            .map(|f| {
                let run = p.run(
                    Method::Rattle {
                        step: f * p.period_scale(),
                    },
                    quiet(),
                    t_end,
                    t_end,
                );
                position_error(&run, &reference, p.l)
            })
            .collect();
        for pair in errors.windows(2) {
            let order = (pair[0] / pair[1]).log2();
            assert!(
                (1.8..=2.2).contains(&order),
                "case {case}: errors {errors:?}, order {order}"
            );
        }
    }
}

/// A four-bar linkage: crank OB (a), coupler BC (b), rocker CD (c), ground pivots O and
/// D = (d, 0, 0), a chain of revolute joints about z closed by a pin at D (two in-plane
/// equations), uniform bars, gravity −g along y.
struct FourBar {
    lengths: [f64; 3],
    d: f64,
    masses: [f64; 3],
    g: f64,
    q: Vec<f64>,
    q_dot: Vec<f64>,
}

fn e(phi: f64) -> Vector2<f64> {
    Vector2::new(phi.cos(), phi.sin())
}

impl FourBar {
    /// Random lengths on a scale 10^U(−1, 1), masses over four decades, a closed configuration
    /// away from the toggle positions and a crank rate on the constraint. With `grashof`, the
    /// lengths satisfy Grashof's condition s + l ≤ p + q (a link turns fully), otherwise not.
    fn random(rng: &mut Rng, grashof: bool) -> Self {
        let scale = rng.decades(-1.0, 1.0);
        loop {
            let lengths = [rng.uniform(0.3, 1.0), rng.uniform(0.5, 1.5), rng.uniform(0.5, 1.5)].map(|l| l * scale);
            let d = rng.uniform(0.5, 1.5) * scale;
            let mut all = [lengths[0], lengths[1], lengths[2], d];
            all.sort_by(f64::total_cmp);
            if (all[0] + all[3] <= all[1] + all[2]) != grashof {
                continue;
            }
            let phi1 = rng.uniform(-3.1, 3.1);
            let b_point = e(phi1) * lengths[0];
            let to_d = Vector2::new(d, 0.0) - b_point;
            let s = to_d.norm();
            let [_, b, c] = lengths;
            if s <= (b - c).abs() + 0.1 * scale || s >= b + c - 0.1 * scale {
                continue;
            }
            let unit = to_d / s;
            let along = (b * b - c * c + s * s) / (2.0 * s);
            let height = (b * b - along * along).sqrt() * if rng.uniform(0.0, 1.0) < 0.5 { 1.0 } else { -1.0 };
            let c_point = b_point + unit * along + Vector2::new(-unit.y, unit.x) * height;
            let to_c = c_point - b_point;
            let phi2 = to_c.y.atan2(to_c.x);
            let to_end = Vector2::new(d, 0.0) - c_point;
            let phi3 = to_end.y.atan2(to_end.x);
            let g = rng.uniform(1.0, 20.0);
            let rate = rng.uniform(-1.0, 1.0) * (g / scale).sqrt();
            let k2 = -lengths[0] * (phi3 - phi1).sin() / (b * (phi3 - phi2).sin());
            let k3 = -lengths[0] * (phi2 - phi1).sin() / (c * (phi2 - phi3).sin());
            return Self {
                lengths,
                d,
                masses: [0, 1, 2].map(|_| rng.decades(-2.0, 2.0)),
                g,
                q: vec![phi1, phi2 - phi1, phi3 - phi2],
                q_dot: vec![rate, (k2 - 1.0) * rate, (k3 - k2) * rate],
            };
        }
    }

    fn constrained(&self) -> ConstrainedDynamics {
        let mut builder = TreeBuilder::new();
        let z = Joint::Revolute { axis: Vector3::z() };
        builder.add_body(None, z, Isometry3::identity());
        for i in 0..2 {
            let at = Isometry3::from_parts(Translation3::new(self.lengths[i], 0.0, 0.0), Default::default());
            builder.add_body(Some(i), z, at);
        }
        let tree = builder.build().expect("tree");
        let bodies = (0..3)
            .map(|i| {
                let (m, l) = (self.masses[i], self.lengths[i]);
                let tensor =
                    Matrix3::from_diagonal(&Vector3::new(1e-3 * m * l * l, m * l * l / 12.0, m * l * l / 12.0));
                MassProperties::new(m, Vector3::new(l / 2.0, 0.0, 0.0), tensor).expect("bar")
            })
            .collect();
        let mut mechanism = Mechanism::new(tree, bodies).expect("mechanism");
        mechanism.set_gravity(Vector3::new(0.0, -self.g, 0.0)).expect("gravity");
        let mut constrained = ConstrainedDynamics::new(Dynamics::new(mechanism).expect("dynamics"));
        let pin = Constraint::PointsCoincide {
            a: Anchor {
                body: Some(2),
                point: Vector3::new(self.lengths[2], 0.0, 0.0),
            },
            b: Anchor {
                body: None,
                point: Vector3::new(self.d, 0.0, 0.0),
            },
            directions: vec![Vector3::x(), Vector3::y()],
        };
        constrained.add_constraint("pin at D", pin).expect("pin");
        constrained
    }

    /// The time scale √(scale/g).
    fn time_scale(&self) -> f64 {
        (self.lengths.iter().fold(self.d, |m, l| m.max(*l)) / self.g).sqrt()
    }

    /// The largest length: the scale of f.
    fn length_scale(&self) -> f64 {
        self.lengths.iter().fold(self.d, |m, l| m.max(*l))
    }

    /// A step that resolves the motion up to `t_end`: `fraction` of the time scale and of
    /// 1/ω_max, with ω_max the fastest joint rate of the reference motion sampled at 1/100
    /// of the time scale (light cranks driven by heavy rockers turn far faster than √(g/l)).
    fn step(&self, fraction: f64, t_end: f64) -> f64 {
        let fine = four_bar_reference(self, t_end, 0.01 * self.time_scale());
        let fastest = fine
            .samples
            .iter()
            .flat_map(|s| s.q_dot.iter())
            .fold(0.0f64, |m, v| m.max(v.abs()));
        fraction * self.time_scale().min(1.0 / fastest)
    }

    fn run(&self, method: Method, options: Options, t_end: f64, interval: f64) -> Trajectory {
        let simulation = Simulation::constrained(self.constrained(), method, options).expect("simulation");
        simulation.run(&self.q, &self.q_dot, t_end, interval).expect("run")
    }
}

/// The four-bar's reference by Dormand–Prince at rtol 1e-12 with projection (M.19).
fn four_bar_reference(bar: &FourBar, t_end: f64, interval: f64) -> Trajectory {
    let method = Method::DormandPrince {
        rtol: 1e-12,
        atol: 1e-14,
    };
    bar.run(method, quiet(), t_end, interval)
}

/// The largest angle error of a run against a reference run.
fn angle_error(run: &Trajectory, reference: &Trajectory) -> f64 {
    run.samples
        .iter()
        .zip(&reference.samples)
        .fold(0.0f64, |m, (a, b)| m.max(distance(&a.q, &b.q)))
}

/// RATTLE on random four-bars: f and J q̇ stay at rounding level, the error is within the
/// estimate, and the projected Dormand–Prince run agrees with RATTLE's companion-tested path.
#[test]
fn rattle_keeps_random_four_bars_closed() {
    let mut rng = Rng::new(5);
    for case in 0..10 {
        let bar = FourBar::random(&mut rng, case % 2 == 0);
        let (t_end, interval) = (3.0 * bar.time_scale(), 0.25 * bar.time_scale());
        let reference = four_bar_reference(&bar, t_end, interval);
        let step = bar.step(0.005, t_end);
        let run = bar.run(Method::Rattle { step }, Options::default(), t_end, interval);
        let drift = run.monitors.constraints;
        let speed = bar.q_dot.iter().fold(0.0f64, |m, v| m.max(v.abs())) * bar.length_scale();
        let speed = speed.max((bar.g * bar.length_scale()).sqrt());
        assert!(
            drift.max_position <= 256.0 * U * bar.length_scale(),
            "case {case}: ‖f‖ {:e}",
            drift.max_position
        );
        assert!(
            drift.max_velocity <= 1e3 * U * speed,
            "case {case}: ‖J q̇‖ {:e}",
            drift.max_velocity
        );
        for (sample, r) in run.samples.iter().zip(&reference.samples) {
            let estimate = sample.error.expect("estimate").q;
            let truth = distance(&sample.q, &r.q);
            assert!(
                truth <= estimate,
                "case {case} t = {}: error {truth:e} > estimate {estimate:e}",
                sample.t
            );
        }
        let reference_drift = reference.monitors.constraints;
        assert!(reference_drift.max_position <= 256.0 * U * bar.length_scale());
    }
}

/// RATTLE's observed order on random four-bars, against the projected Dormand–Prince
/// reference, lies in [1.8, 2.2] over steps h, h/2, h/4, h/8.
#[test]
fn rattle_is_second_order_on_four_bars() {
    let mut rng = Rng::new(17);
    for case in 0..6 {
        let bar = FourBar::random(&mut rng, case % 2 == 1);
        let t_end = 2.0 * bar.time_scale();
        let reference = four_bar_reference(&bar, t_end, t_end);
        let h = bar.step(0.01, t_end);
        let errors: Vec<f64> = [1.0, 0.5, 0.25, 0.125]
            .iter()
            .map(|f| {
                let method = Method::Rattle { step: f * h };
                angle_error(&bar.run(method, quiet(), t_end, t_end), &reference)
            })
            .collect();
        for pair in errors.windows(2) {
            let order = (pair[0] / pair[1]).log2();
            assert!(
                (1.8..=2.2).contains(&order),
                "case {case}: errors {errors:?}, order {order}"
            );
        }
    }
}

/// 1e5 RATTLE steps on the point pendulum: the energy error stays O(h²) and does not grow
/// (the second half of the run drifts no more than the first half allows).
#[test]
fn rattle_energy_is_bounded_over_1e5_steps() {
    let mut rng = Rng::new(31);
    let p = PendulumCase::random(&mut rng);
    let h = 0.05 * p.period_scale();
    let run = p.run(Method::Rattle { step: h }, quiet(), 1e5 * h, 100.0 * h);
    assert!(run.steps >= 100_000, "{} steps", run.steps);
    let e0 = run.monitors.initial;
    let scale = run.monitors.scale;
    let drift = |s: &[mechanica_motion::Sample]| s.iter().fold(0.0f64, |m, x| m.max((x.energy - e0).abs())) / scale;
    let half = run.samples.len() / 2;
    let (first, second) = (drift(&run.samples[..half]), drift(&run.samples[half..]));
    assert!(run.monitors.max_drift <= 0.05, "max drift {:e}", run.monitors.max_drift);
    assert!(second <= 2.0 * first, "drift grows: {first:e} then {second:e}");
    assert!(first > 0.0);
    assert!(run.monitors.constraints.max_position <= 256.0 * U * p.l);
}

/// Over 2e4 steps on random four-bars the energy error of RATTLE stays bounded while RK4
/// with projection at the same step loses energy steadily.
#[test]
fn rattle_energy_is_bounded_on_four_bars() {
    let mut rng = Rng::new(41);
    for case in 0..3 {
        let bar = FourBar::random(&mut rng, case != 1);
        let h = bar.step(0.02, 100.0 * bar.time_scale());
        let t_end = 2e4 * h;
        let run = bar.run(Method::Rattle { step: h }, quiet(), t_end, 100.0 * h);
        let e0 = run.monitors.initial;
        let scale = run.monitors.scale;
        let drift = |s: &[mechanica_motion::Sample]| s.iter().fold(0.0f64, |m, x| m.max((x.energy - e0).abs())) / scale;
        let half = run.samples.len() / 2;
        let (first, second) = (drift(&run.samples[..half]), drift(&run.samples[half..]));
        assert!(
            run.monitors.max_drift <= 0.05,
            "case {case}: max drift {:e}",
            run.monitors.max_drift
        );
        assert!(
            second <= 2.0 * first,
            "case {case}: drift grows: {first:e} then {second:e}"
        );
    }
}

/// A step far beyond the pendulum's time scale cannot meet the rod: the run stops with a typed
/// error and the last good state, which lies on the constraint.
#[test]
fn rattle_reports_a_constraint_it_cannot_meet() {
    let p = PendulumCase {
        m: 1.0,
        l: 1.0,
        g: 9.81,
        theta: 2.0,
        rate: 3.0,
    };
    let (q0, v0) = point_state(p.l, p.theta, p.rate);
    let simulation = Simulation::constrained(point_pendulum(1.0, 1.0, 9.81), Method::Rattle { step: 5.0 }, quiet())
        .expect("simulation");
    match simulation.run(&q0, &v0, 50.0, 5.0) {
        Err(MotionError::StepFailed { cause, q, t, .. }) => {
            assert!(matches!(cause, StepFailure::ConstraintNotMet { .. }), "cause {cause:?}");
            let radius = (q[0] * q[0] + q[1] * q[1]).sqrt();
            assert!(
                (radius - 1.0).abs() <= 1e-14,
                "last good state off the rod: {radius} at t = {t}"
            );
        }
        other => panic!("expected a failed step, got {other:?}"),
    }
}
