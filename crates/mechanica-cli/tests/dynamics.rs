//! The `dynamics` analysis of `mechanica run`: forward and inverse dynamics, joint reactions and
//! dampers against closed forms, and located errors for bad dynamics input.

use std::path::PathBuf;
mod common;
use common::{mechanica, numbers, step, values};

/// The generalized force of the first load of the inverse dynamics whose name starts with `name`.
fn load(json: &serde_json::Value, name: &str) -> Vec<f64> {
    let loads = step(json, "inverse_dynamics")["loads"].as_array().expect("loads");
    let load = loads
        .iter()
        .find(|l| l["name"].as_str().is_some_and(|n| n.starts_with(name)))
        .unwrap_or_else(|| panic!("no load {name} in {loads:?}"));
    numbers(&load["force"])
}

/// The force and moment of the reaction at `joint`, six numbers.
fn reaction_at(json: &serde_json::Value, joint: &str) -> Vec<f64> {
    let reactions = step(json, "inverse_dynamics")["reactions"]
        .as_array()
        .expect("reactions");
    let reaction = reactions
        .iter()
        .find(|r| r["joint"] == joint)
        .unwrap_or_else(|| panic!("no reaction at {joint} in {reactions:?}"));
    let mut out = numbers(&reaction["force"]);
    out.extend(numbers(&reaction["moment"]));
    out
}

fn scene_file(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mechanica-dynamics-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch dir");
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).expect("write scene");
    path
}

/// Runs a scene and returns its JSON report.
fn run_json(name: &str, text: &str) -> serde_json::Value {
    let path = scene_file(name, text);
    let (ok, out, err) = mechanica(&["run", path.to_str().expect("path"), "--json"]);
    assert!(ok, "{err}");
    serde_json::from_str(&out).expect("JSON report")
}

fn close(got: f64, exact: f64, tolerance: f64) {
    assert!(
        (got - exact).abs() <= tolerance,
        "{got} vs {exact} (tolerance {tolerance:e})"
    );
}

const G: f64 = 9.81;

/// A point mass m on a rod of length l, hinged about y at the origin, with a joint damper.
fn pendulum(m: f64, l: f64, theta: f64, rate: f64, tau: f64, c: f64, frame: &str) -> String {
    format!(
        r#"title = "damped pendulum"
gravity = [0.0, 0.0, -{G:?}]
[[body]]
name = "bob"
primitive = {{ shape = "point", mass = {m:?} }}
offset = [0.0, 0.0, -{l:?}]
[[joint]]
name = "hinge"
type = "revolute"
parent = "ground"
child = "bob"
axis = [0.0, 1.0, 0.0]
q0 = [{theta:?}]
qd0 = [{rate:?}]
[[joint_damper]]
joint = "hinge"
damping = {c:?}
[analyses]
dynamics = {{ tau = [{tau:?}], frame = "{frame}" }}
"#
    )
}

/// θ̈ = (τ − m g l sin θ − c θ̇) / (m l²); the inverse dynamics at that θ̈ gives back τ with
/// g = m g l sin θ and the damper's Q = −c θ̇; the pivot's reaction is m (ẍ_C − g) in the world
/// and, in the body frame, (−m (l θ̈ + g sin θ), 0, m (l θ̇² + g cos θ)).
#[test]
fn a_damped_pendulum_matches_its_closed_forms_in_every_frame() {
    let cases = [
        (1.3, 0.7, 0.4, -1.2, 0.8, 0.3),
        (0.2, 2.5, -2.9, 3.0, -0.05, 1.5),
        (5.0, 0.1, 1.6, 0.0, 2.0, 0.0),
    ];
    for (m, l, theta, rate, tau, c) in cases {
        let (s, co) = (f64::sin(theta), f64::cos(theta));
        let accel = (tau - m * G * l * s - c * rate) / (m * l * l);
        let scale = G / l + accel.abs();
        let world = run_json("pendulum_world", &pendulum(m, l, theta, rate, tau, c, "world"));
        close(values(&world, "forward_dynamics", "q_ddot")[0], accel, 1e-13 * scale);
        close(
            values(&world, "inverse_dynamics", "tau")[0],
            tau,
            1e-13 * m * G * l + 1e-15,
        );
        close(
            values(&world, "inverse_dynamics", "gravity")[0],
            m * G * l * s,
            1e-13 * m * G * l,
        );
        close(load(&world, "joint damper")[0], -c * rate, 1e-15 * (1.0 + c));
        close(
            values(&world, "forward_dynamics", "dissipation")[0],
            0.5 * c * rate * rate,
            1e-15,
        );
        // ẍ_C of x_C = (−l sin θ, 0, −l cos θ).
        let ax = -l * co * accel + l * s * rate * rate;
        let az = l * s * accel + l * co * rate * rate;
        let force_scale = m * (G + l * (accel.abs() + rate * rate));
        let reaction = reaction_at(&world, "hinge");
        close(reaction[0], m * ax, 1e-13 * force_scale);
        close(reaction[1], 0.0, 1e-13 * force_scale);
        close(reaction[2], m * (az + G), 1e-13 * force_scale);
        // The moment about the hinge along its axis is what the hinge applies: τ and the damper.
        close(reaction[4], tau - c * rate, 1e-12 * force_scale * l);
        let body = run_json("pendulum_body", &pendulum(m, l, theta, rate, tau, c, "body"));
        let reaction = reaction_at(&body, "hinge");
        close(reaction[0], -m * (l * accel + G * s), 1e-13 * force_scale);
        close(reaction[2], m * (l * rate * rate + G * co), 1e-13 * force_scale);
    }
}

/// A slider of mass m along x, at x = q, with a damper to a ground point (x0, 0, h): on the
/// full relative velocity q̈ = (τ − c v)/m; as a dashpot along the line only the rate along it
/// resists, q̈ = (τ − c v (q − x0)²/((q − x0)² + h²))/m.
#[test]
fn point_dampers_and_dashpots_resist_the_relative_velocity() {
    let (m, q, v, tau, c, x0, h) = (2.0, 0.3, -1.7, 0.4, 0.9, -0.5, 0.6);
    for axial in [false, true] {
        let text = format!(
            r#"title = "damped slider"
[[body]]
name = "slider"
primitive = {{ shape = "box", size = [0.1, 0.1, 0.1], mass = {m:?} }}
[[joint]]
name = "rail"
type = "prismatic"
parent = "ground"
child = "slider"
axis = [1.0, 0.0, 0.0]
q0 = [{q:?}]
[[damper]]
a = "slider"
b = "ground"
b_point = [{x0:?}, 0.0, {h:?}]
damping = {c:?}
axial = {axial}
[analyses]
dynamics = {{ q_dot = [{v:?}], tau = [{tau:?}], q_ddot = [0.0] }}
"#
        );
        let json = run_json("slider", &text);
        let d = q - x0;
        let along = if axial { d * d / (d * d + h * h) } else { 1.0 };
        let expected = (tau - c * v * along) / m;
        close(values(&json, "forward_dynamics", "q_ddot")[0], expected, 1e-14);
        // At the given q̈ = 0 the inverse dynamics needs τ = −Q = c v (fraction along the line).
        close(values(&json, "inverse_dynamics", "tau")[0], c * v * along, 1e-14);
        let dissipation = 0.5 * c * v * v * along;
        close(values(&json, "forward_dynamics", "dissipation")[0], dissipation, 1e-15);
    }
}

#[test]
fn bad_dynamics_input_gives_located_errors() {
    let base = pendulum(1.0, 1.0, 0.3, 0.0, 0.0, 0.5, "world");
    let cases = [
        (
            base.replace("damping = 0.5", "damping = -0.5"),
            "joint_damper[0].damping",
            "damping = -0.5",
            "≥ 0",
        ),
        (
            base.replace("damping = 0.5", "damping = nan"),
            "joint_damper[0].damping",
            "damping = nan",
            "finite",
        ),
        (
            base.replace(
                "[analyses]",
                "[[damper]]\na = \"bob\"\nb = \"ground\"\ndamping = -2.0\n\n[analyses]",
            ),
            "damper[0].damping",
            "damping = -2.0",
            "≥ 0",
        ),
        (
            base.replace("joint = \"hinge\"", "joint = \"hing\""),
            "joint_damper[0].joint",
            "joint = \"hing\"",
            "no joint",
        ),
        (
            base.replace("damping = 0.5", "damping = 0.5\ncoordinate = 1"),
            "joint_damper[0].coordinate",
            "coordinate = 1",
            "which has 1",
        ),
        (
            base.replace("tau = [0.0]", "tau = [0.0, 1.0]"),
            "analyses.dynamics.tau",
            "dynamics =",
            "2 values",
        ),
        (
            base.replace("frame = \"world\"", "frame = \"sideways\""),
            "analyses.dynamics.frame",
            "dynamics =",
            "sideways",
        ),
        (
            base.replace("tau = [0.0]", "tau = [0.0], q_dot = [inf]"),
            "analyses.dynamics.q_dot",
            "dynamics =",
            "finite",
        ),
    ];
    for (i, (text, field, line_of, says)) in cases.iter().enumerate() {
        let path = scene_file(&format!("bad{i}"), text);
        let (ok, out, err) = mechanica(&["run", path.to_str().expect("path")]);
        assert!(!ok, "{field}: accepted:\n{out}");
        let line = text
            .lines()
            .position(|l| l.contains(line_of))
            .map(|i| i + 1)
            .expect("line");
        let located = format!("{}:{line}:", path.display());
        assert!(err.contains(&located), "{field}: {err} (expected {located})");
        assert!(err.contains(&format!("field {field}")), "{field}: {err}");
        assert!(err.contains(says), "{field}: {err}");
    }
}

/// A point mass m on a prismatic joint with a joint spring k and a joint damper c.
fn oscillator(m: f64, k: f64, c: f64) -> String {
    format!(
        r#"title = "damped oscillator"
[[body]]
name = "mass"
primitive = {{ shape = "point", mass = {m:?} }}
[[joint]]
name = "slide"
type = "prismatic"
parent = "ground"
child = "mass"
axis = [1.0, 0.0, 0.0]
q0 = [0.0]
[[joint_spring]]
joint = "slide"
stiffness = {k:?}
[[joint_damper]]
joint = "slide"
damping = {c:?}
[analyses]
dynamics = {{}}
"#
    )
}

/// ω_n = √(k/m), ζ = c/(2√(km)); below ζ = 1 a conjugate pair s = −ζω_n ± iω_n√(1−ζ²), above it
/// two real roots −ω_n(ζ ± √(ζ²−1)) with ω_n² = s₁s₂; the text report names the kind.
#[test]
fn a_damped_oscillator_has_the_closed_form_damping_ratio_and_frequency() {
    let cases = [
        (0.3, 40.0, 0.01),
        (2.5, 7.0, 0.5),
        (0.05, 900.0, 2.0),
        (12.0, 0.8, 0.25),
    ];
    for (m, k, zeta) in cases {
        let omega_n = f64::sqrt(k / m);
        let c = 2.0 * zeta * f64::sqrt(k * m);
        let scene = oscillator(m, k, c);
        let json = run_json("oscillator", &scene);
        let kind = if zeta < 1.0 { "underdamped" } else { "overdamped" };
        let mode = &step(&json, "damped_modes")["modes"][0];
        assert_eq!(mode["kind"], kind);
        let f = [
            &mode["natural_frequency"],
            &mode["damped_frequency"],
            &mode["damping_ratio"],
        ]
        .map(|v| numbers(v)[0]);
        close(f[0], omega_n, 1e-12 * omega_n);
        close(f[2], zeta, 1e-12 * (1.0 + zeta));
        let s: Vec<f64> = mode["eigenvalues"]
            .as_array()
            .expect("eigenvalues")
            .iter()
            .flat_map(|e| numbers(&e["s"]))
            .collect();
        assert_eq!(s.len(), 4, "two eigenvalues: {s:?}");
        if zeta < 1.0 {
            let omega_d = omega_n * f64::sqrt(1.0 - zeta * zeta);
            close(f[1], omega_d, 1e-12 * omega_n);
            close(s[0], -zeta * omega_n, 1e-12 * omega_n);
            close(s[1], omega_d, 1e-12 * omega_n);
            close(s[3], -omega_d, 1e-12 * omega_n);
        } else {
            let fast = -omega_n * (zeta + f64::sqrt(zeta * zeta - 1.0));
            let slow = omega_n * omega_n / fast;
            let (lo, hi) = (s[0].min(s[2]), s[0].max(s[2]));
            close(lo, fast, 1e-12 * fast.abs());
            close(hi, slow, 1e-12 * fast.abs());
            assert_eq!(f[1], 0.0);
        }
        close(values(&json, "damped_modes", "gradient_norm")[0], 0.0, 0.0);
        let path = scene_file("oscillator_text", &scene);
        let (ok, text, err) = mechanica(&["run", path.to_str().expect("path")]);
        assert!(ok, "{err}");
        assert!(text.contains(&format!("damped mode 1 ({kind})")), "{text}");
        assert!(text.contains("|Δs| ≤"), "{text}");
    }
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

/// A chain of point masses `m` on prismatic joints along x with joint springs `k`; with
/// `damping` = Some((α, β)) a damper α m_i from each mass to a ground point (full relative
/// velocity: C = α A) and a joint damper β k_i on each joint (C = β B), and the dynamics
/// analysis; the undamped modes in either case.
fn rayleigh_chain(m: &[f64], k: &[f64], damping: Option<(f64, f64)>) -> String {
    let mut text = String::from("title = \"proportionally damped chain\"\n");
    for (i, (mi, ki)) in m.iter().zip(k).enumerate() {
        let parent = if i == 0 {
            "ground".to_string()
        } else {
            format!("m{}", i - 1)
        };
        text += &format!(
            "[[body]]\nname = \"m{i}\"\nprimitive = {{ shape = \"point\", mass = {mi:?} }}\n\
             [[joint]]\nname = \"j{i}\"\ntype = \"prismatic\"\nparent = \"{parent}\"\nchild = \"m{i}\"\n\
             axis = [1.0, 0.0, 0.0]\norigin = [1.0, 0.0, 0.0]\nq0 = [0.0]\n\
             [[joint_spring]]\njoint = \"j{i}\"\nstiffness = {ki:?}\n"
        );
        if let Some((alpha, beta)) = damping {
            text += &format!(
                "[[damper]]\na = \"m{i}\"\nb = \"ground\"\nb_point = [-10.0, 3.0, 0.0]\ndamping = {:?}\n\
                 [[joint_damper]]\njoint = \"j{i}\"\ndamping = {:?}\n",
                alpha * mi,
                beta * ki
            );
        }
    }
    text += "[analyses]\nmodes = {}\n";
    if damping.is_some() {
        text += "dynamics = {}\n";
    }
    text
}

/// The closed-form roots of the undamped mode ω under C = αA + βB (2ζω = α + βω²): the pair
/// −ζω ± iω√(1−ζ²), or the real roots −ζω ∓ ω√(ζ²−1) (fast first); with |ds/dω| of each, to
/// carry the error of ω into the reference.
fn rayleigh_roots(omega: f64, alpha: f64, beta: f64) -> [([f64; 2], f64); 2] {
    let (p, dp) = (0.5 * (alpha + beta * omega * omega), beta * omega);
    let zeta = p / omega;
    if zeta < 1.0 {
        let q = omega * (1.0 - zeta * zeta).sqrt();
        let rate = dp.hypot((omega - p * dp).abs() / q);
        [([-p, q], rate), ([-p, -q], rate)]
    } else {
        let r = omega * (zeta * zeta - 1.0).sqrt();
        let fast = -(p + r);
        let slow = omega * omega / fast;
        let d_fast = dp + (p * dp - omega).abs() / r;
        let d_slow = 2.0 * omega / fast.abs() + omega * omega * d_fast / (fast * fast);
        [([fast, 0.0], d_fast), ([slow, 0.0], d_slow)]
    }
}

/// Proportional (Rayleigh) damping C = αA + βB of a chain of 2 to 5 masses: each damped mode
/// is the closed form of the undamped mode ω of the same scene (the `modes` step), within the
/// reported bounds plus the closed form's own error from the bound on ω²; α, β are drawn so
/// that the lowest mode is overdamped (ζ₁ in [1.5, 4)), and the family must show underdamped
/// modes too. No mode is within 0.15 of critical damping, where only the bounds decide.
#[test]
fn a_rayleigh_damped_chain_has_the_closed_form_modes() {
    let mut rng = Random(0x5DEE_CE66_D1CE_4E5B);
    let (mut underdamped, mut overdamped) = (0, 0);
    for trial in 0..12 {
        let n = 2 + (trial % 4);
        let m: Vec<f64> = (0..n).map(|_| 10f64.powf(rng.uniform(-1.5, 1.5))).collect();
        let k: Vec<f64> = (0..n).map(|_| 10f64.powf(rng.uniform(0.0, 3.5))).collect();
        let undamped = run_json("rayleigh_undamped", &rayleigh_chain(&m, &k, None));
        let modes = step(&undamped, "modes")["modes"].as_array().expect("modes").clone();
        assert_eq!(modes.len(), n);
        let omega_sq: Vec<f64> = modes.iter().map(|mode| numbers(&mode["omega_sq"])[0]).collect();
        let omega: Vec<f64> = omega_sq.iter().map(|w2| w2.sqrt()).collect();
        // δω from the bound on ω² (δ√x ≈ δx/(2√x)), plus the rounding of the square root.
        let d_omega: Vec<f64> = modes
            .iter()
            .zip(&omega)
            .map(|(mode, w)| numbers(&mode["bound"])[0] / (2.0 * w) + f64::EPSILON * w)
            .collect();
        let zeta = |w: f64, alpha: f64, beta: f64| 0.5 * (alpha / w + beta * w);
        let (alpha, beta) = (0..100)
            .map(|_| {
                let zeta_1 = rng.uniform(1.5, 4.0);
                let beta = 10f64.powf(rng.uniform(-3.0, -0.5)) / omega[n - 1];
                (2.0 * zeta_1 * omega[0] - beta * omega[0] * omega[0], beta)
            })
            .find(|&(alpha, beta)| alpha > 0.0 && omega.iter().all(|&w| (zeta(w, alpha, beta) - 1.0).abs() > 0.15))
            .expect("a damping away from critical");
        let json = run_json("rayleigh_damped", &rayleigh_chain(&m, &k, Some((alpha, beta))));
        // The same mechanism: the undamped modes of the damped scene are those above.
        let again: Vec<f64> = step(&json, "modes")["modes"]
            .as_array()
            .expect("modes")
            .iter()
            .map(|mode| numbers(&mode["omega_sq"])[0])
            .collect();
        assert_eq!(again, omega_sq);
        let damped = step(&json, "damped_modes")["modes"]
            .as_array()
            .expect("damped modes")
            .clone();
        assert_eq!(damped.len(), n, "one mode per undamped mode: {damped:?}");
        for (j, mode) in damped.iter().enumerate() {
            let (w, dw, z) = (omega[j], d_omega[j], zeta(omega[j], alpha, beta));
            let d_zeta = 0.5 * (beta - alpha / (w * w)).abs() * dw;
            check_rayleigh_mode(mode, w, dw, (z, d_zeta), rayleigh_roots(w, alpha, beta));
            if z < 1.0 {
                underdamped += 1;
            } else {
                overdamped += 1;
            }
        }
        assert_eq!(damped[0]["kind"], "overdamped");
    }
    assert!(
        underdamped >= 6 && overdamped >= 12,
        "{underdamped} underdamped, {overdamped} overdamped"
    );
}

/// The (s, bound, backward error) of a damped mode's eigenvalues.
fn eigenvalues_of(mode: &serde_json::Value) -> Vec<([f64; 2], f64, f64)> {
    mode["eigenvalues"]
        .as_array()
        .expect("eigenvalues")
        .iter()
        .map(|e| {
            let s = numbers(&e["s"]);
            ([s[0], s[1]], numbers(&e["bound"])[0], numbers(&e["backward_error"])[0])
        })
        .collect()
}

/// One damped mode of the Rayleigh chain against its closed-form roots: the kind, each
/// eigenvalue within its bound (plus the reference's error |ds/dω| δω and a few roundings), a
/// backward error at rounding level, and ω_n, ω_d and ζ (whose reference moves by `d_zeta`
/// with ω) within the bounds they inherit.
fn check_rayleigh_mode(
    mode: &serde_json::Value,
    omega: f64,
    d_omega: f64,
    (zeta, d_zeta): (f64, f64),
    roots: [([f64; 2], f64); 2],
) {
    let kind = if zeta < 1.0 { "underdamped" } else { "overdamped" };
    assert_eq!(mode["kind"], kind, "ζ = {zeta}: {mode}");
    let eigenvalues = eigenvalues_of(mode);
    assert_eq!(eigenvalues.len(), 2, "{mode}");
    // Real roots come in either order: match each to the nearer closed-form root.
    let swap = zeta > 1.0 && (eigenvalues[0].0[0] - roots[0].0[0]).abs() > (eigenvalues[0].0[0] - roots[1].0[0]).abs();
    let mut worst = 0f64;
    for (i, (s, bound, eta)) in eigenvalues.iter().enumerate() {
        let (exact, rate) = roots[if swap { 1 - i } else { i }];
        let error = (s[0] - exact[0]).hypot(s[1] - exact[1]);
        let allowed = bound + rate * d_omega + 8.0 * f64::EPSILON * exact[0].hypot(exact[1]);
        assert!(
            error <= allowed,
            "s = {s:?} vs {exact:?}: {error:e} > {allowed:e} (ζ = {zeta})"
        );
        // Informative bounds and a backward-stable solve (≤ 64 n u for n ≤ 5).
        assert!(*bound >= 0.0 && *bound < 1e-8 * omega * (1.0 + zeta), "bound {bound:e}");
        assert!(
            *eta >= 0.0 && *eta < 64.0 * 5.0 * f64::EPSILON,
            "backward error {eta:e}"
        );
        worst = worst.max(allowed);
    }
    // With e the largest error allowed above: |Δω_n| ≤ (1 + ζ) e (for real roots ½ Σ e/|s_i|
    // ω_n, and the slow root is ≥ ω/(2ζ)), |Δζ| ≤ (Σ e)/(2ω_n) + ζ |Δω_n|/ω_n.
    let natural = numbers(&mode["natural_frequency"])[0];
    close(
        natural,
        omega,
        (1.0 + zeta) * worst + d_omega + 8.0 * f64::EPSILON * omega,
    );
    let zeta_tolerance = worst / omega * (1.0 + zeta * (1.0 + zeta)) + d_zeta + 8.0 * f64::EPSILON * (1.0 + zeta);
    close(numbers(&mode["damping_ratio"])[0], zeta, zeta_tolerance);
    let damped_frequency = numbers(&mode["damped_frequency"])[0];
    if zeta < 1.0 {
        close(damped_frequency, roots[0].0[1], worst + 8.0 * f64::EPSILON * omega);
    } else {
        assert_eq!(damped_frequency, 0.0);
    }
}

/// Two joints through one point (yaw about z, then roll about y) carrying a point mass at
/// (0, y, 0.4): the rotation about the axis through the mass moves nothing, so A(q) is singular
/// up to rounding (iCub's neck at q = 0). Each run either refuses A as not positive definite
/// or answers by the mass-matrix route with κ∞ beyond 1/(2n·u) and no error estimate, saying
/// that no digit of q̈ is assured; never an estimate that promises digits.
#[test]
fn a_mass_matrix_singular_to_working_precision_is_said_so() {
    let mut answered = 0;
    for y in [0.3, 0.7, 1.1, 1.7, 2.3] {
        let scene = format!(
            r#"title = "neck"
gravity = [0.0, 0.0, -9.81]
[[body]]
name = "inner"
primitive = {{ shape = "point", mass = 1e-9 }}
[[body]]
name = "head"
primitive = {{ shape = "point", mass = 2.0 }}
offset = [0.0, {y:?}, 0.4]
[[joint]]
name = "yaw"
type = "revolute"
parent = "ground"
child = "inner"
axis = [0.0, 0.0, 1.0]
[[joint]]
name = "roll"
type = "revolute"
parent = "inner"
child = "head"
axis = [0.0, 1.0, 0.0]
[analyses]
dynamics = {{ tau = [0.1, 0.2] }}
"#
        );
        let path = scene_file("neck", &scene);
        let (ok, out, err) = mechanica(&["run", path.to_str().expect("path"), "--json"]);
        if !ok {
            assert!(err.contains("not positive definite"), "y = {y}: {err}");
            continue;
        }
        let json: serde_json::Value = serde_json::from_str(&out).expect("JSON report");
        let record = step(&json, "forward_dynamics");
        assert_eq!(record["method"], "mass_matrix", "y = {y}");
        let condition = record["condition"].as_f64().expect("κ∞");
        assert!(4.0 * condition * f64::EPSILON >= 0.5, "y = {y}: κ∞ = {condition:e}");
        assert!(record["error_estimate"].is_null(), "y = {y}: {record}");
        let (ok, text, _) = mechanica(&["run", path.to_str().expect("path")]);
        assert!(ok && text.contains("no digit of q̈ is assured"), "y = {y}: {text}");
        answered += 1;
    }
    assert!(answered >= 2, "only {answered} of 5 placements answered");
}
