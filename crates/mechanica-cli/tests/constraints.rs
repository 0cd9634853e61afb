//! Scene constraints (`[[constraint]]`) in `mechanica run`: the forward dynamics with
//! multipliers, the projection onto the constraints and the constrained equilibrium, against
//! closed forms of a parallelogram four-bar and a locked double pendulum, over families of
//! random parameters; and located errors for bad constraint tables.

use std::path::PathBuf;
mod common;
use common::{mechanica, numbers, step, values};

const G: f64 = 9.81;

fn scene_file(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mechanica-constraints-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch dir");
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).expect("write scene");
    path
}

fn run(name: &str, text: &str) -> (bool, String, String) {
    let path = scene_file(name, text);
    mechanica(&["run", path.to_str().expect("path"), "--json"])
}

fn run_json(name: &str, text: &str) -> serde_json::Value {
    let (ok, out, err) = run(name, text);
    assert!(ok, "{err}");
    serde_json::from_str(&out).expect("JSON report")
}

/// A small deterministic generator for parameter families (xorshift64*).
struct Random(u64);

impl Random {
    fn uniform(&mut self, low: f64, high: f64) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let bits = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11;
        low + (high - low) * (bits as f64 / (1u64 << 53) as f64)
    }
}

/// The four-bar's parameters (its two ground pivots sit on a fixed body "frame", the tree's one
/// root): point masses m at distance a on the crank and the rocker, M on
/// the coupler; links of length l; ground link and coupler of length d.
#[derive(Debug, Clone, Copy)]
struct FourBar {
    m: f64,
    big_m: f64,
    a: f64,
    l: f64,
    d: f64,
}

impl FourBar {
    fn random(random: &mut Random) -> Self {
        let l = random.uniform(0.2, 2.0);
        Self {
            m: 10f64.powf(random.uniform(-2.0, 2.0)),
            big_m: 10f64.powf(random.uniform(-2.0, 2.0)),
            a: l * random.uniform(0.1, 1.0),
            l,
            d: random.uniform(0.3, 3.0),
        }
    }

    /// The scene with q0 = `q0`, velocities `qd0` and `extra` tables appended.
    fn scene(&self, q0: [f64; 3], qd0: [f64; 3], extra: &str) -> String {
        let Self { m, big_m, a, l, d } = *self;
        let half = d / 2.0;
        format!(
            r#"title = "parallelogram four-bar"
gravity = [0.0, 0.0, -{G:?}]
[[body]]
name = "frame"
primitive = {{ shape = "point", mass = 1.0 }}
[[joint]]
name = "frame_fixing"
type = "fixed"
parent = "ground"
child = "frame"
[[body]]
name = "crank"
primitive = {{ shape = "point", mass = {m:?} }}
offset = [0.0, 0.0, -{a:?}]
[[body]]
name = "coupler"
primitive = {{ shape = "point", mass = {big_m:?} }}
offset = [{half:?}, 0.0, 0.0]
[[body]]
name = "rocker"
primitive = {{ shape = "point", mass = {m:?} }}
offset = [0.0, 0.0, -{a:?}]
[[joint]]
name = "crank_pivot"
type = "revolute"
parent = "frame"
child = "crank"
axis = [0.0, 1.0, 0.0]
q0 = [{:?}]
qd0 = [{:?}]
[[joint]]
name = "crank_coupler"
type = "revolute"
parent = "crank"
child = "coupler"
axis = [0.0, 1.0, 0.0]
origin = [0.0, 0.0, -{l:?}]
q0 = [{:?}]
qd0 = [{:?}]
[[joint]]
name = "rocker_pivot"
type = "revolute"
parent = "frame"
child = "rocker"
axis = [0.0, 1.0, 0.0]
origin = [{d:?}, 0.0, 0.0]
q0 = [{:?}]
qd0 = [{:?}]
[[constraint]]
name = "closure"
kind = "points"
a = "coupler"
a_point = [{d:?}, 0.0, 0.0]
b = "rocker"
b_point = [0.0, 0.0, -{l:?}]
directions = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
{extra}"#,
            q0[0], qd0[0], q0[1], qd0[1], q0[2], qd0[2]
        )
    }

    /// θ̈ of the parallelogram: T = ½(2 m a² + M l²) θ̇², U = −g cos θ (2 m a + M l).
    fn angular_acceleration(&self, theta: f64) -> f64 {
        let Self { m, big_m, a, l, .. } = *self;
        -G * theta.sin() * (2.0 * m * a + big_m * l) / (2.0 * m * a * a + big_m * l * l)
    }
}

fn close(got: f64, exact: f64, tolerance: f64, what: &str) {
    assert!(
        (got - exact).abs() <= tolerance,
        "{what}: {got} vs {exact} (tolerance {tolerance:e})"
    );
}

/// On the parallelogram (θ, −θ, θ) the loop moves as one degree of freedom with the closed-form
/// θ̈, whatever the velocity; the loop's drift is at rounding level.
#[test]
fn a_parallelogram_four_bar_accelerates_as_its_closed_form() {
    let mut random = Random(0x9e37_79b9_7f4a_7c15);
    for case in 0..12 {
        let linkage = FourBar::random(&mut random);
        let theta = random.uniform(-1.4, 1.4);
        let omega = random.uniform(-3.0, 3.0);
        let scene = linkage.scene(
            [theta, -theta, theta],
            [omega, -omega, omega],
            "[analyses]\ndynamics = {}\n",
        );
        let json = run_json(&format!("fourbar{case}"), &scene);
        let q_ddot = values(&json, "constrained_dynamics", "q_ddot");
        let alpha = linkage.angular_acceleration(theta);
        let scale = G / linkage.a + omega * omega;
        for (k, sign) in [1.0, -1.0, 1.0].iter().enumerate() {
            close(
                q_ddot[k],
                sign * alpha,
                1e-11 * scale,
                &format!("case {case} {linkage:?}: q̈[{k}]"),
            );
        }
        let drift = values(&json, "constrained_dynamics", "position_drift");
        assert!(drift[0] <= 1e-13 * linkage.d, "case {case}: ‖f‖ = {}", drift[0]);
    }
}

/// A start off the loop is projected onto it: the projected q closes the loop (checked from
/// the linkage's own geometry, not the solver's residual) and stays near the start.
#[test]
fn a_start_off_the_loop_is_projected_onto_it() {
    let mut random = Random(0x2545_f491_4f6c_dd1d);
    for case in 0..8 {
        let linkage = FourBar::random(&mut random);
        let theta = random.uniform(-1.0, 1.0);
        let q0 = [
            theta,
            -theta + random.uniform(-0.05, 0.05),
            theta + random.uniform(-0.05, 0.05),
        ];
        let json = run_json(
            &format!("projection{case}"),
            &linkage.scene(q0, [0.0; 3], "[analyses]\ndynamics = {}\n"),
        );
        let q = values(&json, "constraint_projection", "q");
        let FourBar { l, d, .. } = linkage;
        // Coupler end: crank tip + R_y(q0 + q1) (d, 0, 0); rocker tip: (d, 0, 0) + R_y(q2) (0, 0, −l).
        let coupler_angle = q[0] + q[1];
        let coupler_end = [
            -l * q[0].sin() + d * coupler_angle.cos(),
            -l * q[0].cos() - d * coupler_angle.sin(),
        ];
        let rocker_end = [d - l * q[2].sin(), -l * q[2].cos()];
        let gap = (coupler_end[0] - rocker_end[0]).hypot(coupler_end[1] - rocker_end[1]);
        assert!(gap <= 1e-12 * (l + d), "case {case}: the loop is open by {gap}");
        let moved: f64 = q.iter().zip(&q0).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(moved < 0.2, "case {case}: the projection moved {moved}");
    }
}

/// With a joint spring k (θ − r) on the crank, the equilibrium of the parallelogram solves
/// k (θ − r) + g sin θ (2 m a + M l) = 0, found here by bisection.
#[test]
fn the_constrained_equilibrium_balances_the_spring_and_gravity() {
    let mut random = Random(0x0123_4567_89ab_cdef);
    for case in 0..6 {
        let linkage = FourBar::random(&mut random);
        let weight = G * (2.0 * linkage.m * linkage.a + linkage.big_m * linkage.l);
        let k = weight * random.uniform(1.5, 20.0);
        let rest = random.uniform(-1.0, 1.0);
        let balance = |t: f64| k * (t - rest) + weight * t.sin();
        let (mut low, mut high) = (-std::f64::consts::PI, std::f64::consts::PI);
        for _ in 0..200 {
            let mid = 0.5 * (low + high);
            if balance(mid) > 0.0 { high = mid } else { low = mid }
        }
        let spring = format!(
            "[[joint_spring]]\njoint = \"crank_pivot\"\nstiffness = {k:?}\nrest = {rest:?}\n\
             [analyses]\ndynamics = {{ equilibrium = true }}\n"
        );
        let json = run_json(
            &format!("equilibrium{case}"),
            &linkage.scene([0.1, -0.1, 0.1], [0.0; 3], &spring),
        );
        let q = values(&json, "constrained_equilibrium", "q");
        let theta = 0.5 * (low + high);
        for (k_index, sign) in [1.0, -1.0, 1.0].iter().enumerate() {
            close(q[k_index], sign * theta, 1e-9, &format!("case {case}: q[{k_index}]"));
        }
    }
}

/// A double pendulum of point masses with its elbow locked straight swings as one rigid
/// pendulum; the lock's generalized force is the elbow torque m₂ l₂ (L θ̈ + g sin θ).
#[test]
fn a_locked_elbow_carries_the_closed_form_torque() {
    let mut random = Random(0x5851_f42d_4c95_7f2d);
    for case in 0..10 {
        let (m1, m2) = (
            10f64.powf(random.uniform(-2.0, 2.0)),
            10f64.powf(random.uniform(-2.0, 2.0)),
        );
        let (l1, l2) = (random.uniform(0.1, 2.0), random.uniform(0.1, 2.0));
        let (theta, omega) = (random.uniform(-2.5, 2.5), random.uniform(-3.0, 3.0));
        let scene = format!(
            r#"title = "locked double pendulum"
gravity = [0.0, 0.0, -{G:?}]
[[body]]
name = "upper"
primitive = {{ shape = "point", mass = {m1:?} }}
offset = [0.0, 0.0, -{l1:?}]
[[body]]
name = "lower"
primitive = {{ shape = "point", mass = {m2:?} }}
offset = [0.0, 0.0, -{l2:?}]
[[joint]]
name = "shoulder"
type = "revolute"
parent = "ground"
child = "upper"
axis = [0.0, 1.0, 0.0]
q0 = [{theta:?}]
qd0 = [{omega:?}]
[[joint]]
name = "elbow"
type = "revolute"
parent = "upper"
child = "lower"
axis = [0.0, 1.0, 0.0]
origin = [0.0, 0.0, -{l1:?}]
[[constraint]]
kind = "coordinate"
joint = "elbow"
[analyses]
dynamics = {{}}
"#
        );
        let json = run_json(&format!("locked{case}"), &scene);
        let reach = l1 + l2;
        let alpha = -G * theta.sin() * (m1 * l1 + m2 * reach) / (m1 * l1 * l1 + m2 * reach * reach);
        let q_ddot = values(&json, "constrained_dynamics", "q_ddot");
        let scale = G / l1.min(l2) + omega * omega;
        close(q_ddot[0], alpha, 1e-11 * scale, &format!("case {case}: θ̈"));
        close(q_ddot[1], 0.0, 1e-11 * scale, &format!("case {case}: elbow"));
        let torque = m2 * l2 * (reach * alpha + G * theta.sin());
        let reaction = &step(&json, "constrained_dynamics")["reactions"][0];
        assert_eq!(reaction["constraint"], "constraint[0]");
        let lock = numbers(&reaction["generalized_force"]);
        let torque_scale = m2 * l2 * (reach * scale + G);
        close(
            lock[1],
            torque,
            1e-11 * torque_scale,
            &format!("case {case}: lock torque"),
        );
        close(
            lock[0],
            0.0,
            1e-11 * torque_scale,
            &format!("case {case}: shoulder share"),
        );
    }
}

/// Bad constraint tables are refused with the field named; analyses that would ignore the
/// constraints are refused too.
#[test]
fn bad_constraint_tables_are_refused_with_the_field_named() {
    let linkage = FourBar {
        m: 1.0,
        big_m: 1.0,
        a: 0.5,
        l: 1.0,
        d: 1.0,
    };
    let base = linkage.scene([0.1, -0.1, 0.1], [0.0; 3], "");
    let cases = [
        (
            "kind",
            base.replace("kind = \"points\"", "kind = \"weld\""),
            "constraint[0].kind",
        ),
        (
            "body",
            base.replace("b = \"rocker\"", "b = \"nobody\""),
            "constraint[0].b",
        ),
        (
            "field",
            base.replace("kind = \"points\"", "kind = \"points\"\nlength = 2.0"),
            "constraint[0].length",
        ),
        (
            "plane",
            base.replace("kind = \"points\"", "kind = \"plane\"")
                .replace("directions = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]\n", ""),
            "constraint[0].",
        ),
        (
            "direction",
            base.replace("[0.0, 0.0, 1.0]]", "[0.0, 0.0, 0.0]]"),
            "constraint[0].directions",
        ),
    ];
    for (name, text, field) in cases {
        let text = format!("{text}[analyses]\ndynamics = {{}}\n");
        let (ok, _, err) = run(&format!("bad_{name}"), &text);
        assert!(!ok && err.contains(field), "{name}: {err}");
    }
    let modes = format!("{base}[analyses]\nmodes = {{}}\n");
    let (ok, _, err) = run("bad_modes", &modes);
    assert!(
        !ok && err.contains("analyses.modes") && err.contains("constraints"),
        "{err}"
    );
}

/// K(k) = π / (2 AGM(1, √(1 − k²))).
fn elliptic_k(k: f64) -> f64 {
    let (mut a, mut b) = (1.0f64, (1.0 - k * k).sqrt());
    for _ in 0..40 {
        if (a - b).abs() <= 1e-16 * a {
            break;
        }
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    std::f64::consts::PI / (a + b)
}

/// `simulate` keeps the scene's constraints: the parallelogram released from rest at θ₀ swings
/// as the pendulum θ̈ = −K sin θ and is back at (θ₀, −θ₀, θ₀) after 4 K(sin(θ₀/2))/√K, by RATTLE
/// and by Dormand–Prince with projection, with the constraint drift reported at rounding level.
#[test]
fn simulate_keeps_the_constraints_of_a_scene() {
    let mut random = Random(0x5851_f42d_4c95_7f2d);
    for case in 0..6 {
        let linkage = FourBar::random(&mut random);
        let theta0 = random.uniform(0.2, 1.4);
        let rate = (-linkage.angular_acceleration(std::f64::consts::FRAC_PI_2)).sqrt();
        let period = 4.0 * elliptic_k((0.5 * theta0).sin()) / rate;
        for (method, tolerance) in [
            (format!("method = \"rattle\", step = {:?}", 2e-3 * period), 1e-4),
            ("method = \"dopri5\", tolerance = 1e-11".to_string(), 1e-7),
        ] {
            let analysis = format!(
                "[analyses]\nsimulate = {{ t_end = {period:?}, interval = {:?}, {method} }}\n",
                0.5 * period
            );
            let json = run_json(
                &format!("simulate{case}"),
                &linkage.scene([theta0, -theta0, theta0], [0.0; 3], &analysis),
            );
            let q = values(&json, "simulate", "q_end");
            for (k, sign) in [1.0, -1.0, 1.0].iter().enumerate() {
                close(
                    q[k],
                    sign * theta0,
                    tolerance * theta0,
                    &format!("case {case} {method}: q[{k}]"),
                );
            }
            let drift = &step(&json, "simulate")["constraints"];
            let position = numbers(&drift["max_position_drift"])[0];
            let velocity = numbers(&drift["max_velocity_drift"])[0];
            assert!(
                position <= 1e-13 * linkage.d,
                "case {case} {method}: ‖f‖ = {position:e}"
            );
            assert!(
                velocity <= 1e-13 * linkage.d * rate,
                "case {case} {method}: ‖J q̇‖ = {velocity:e}"
            );
        }
    }
}
