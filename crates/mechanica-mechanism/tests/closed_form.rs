//! Equilibria, stability and modes of mechanisms with closed-form answers (§8f–g).

mod common;

use common::{G, pendulum_chain};
use mechanica_kinematics::tree::{Joint, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mass::primitives::{Amount, cylinder};
use mechanica_mechanism::potentials::{JointSpring, PointSpring};
use mechanica_mechanism::{
    Anchor, EquilibriumOptions, Mechanism, MechanismError, RotatingFrame, Seek, Stability, find_equilibria,
    find_equilibrium, mechanism_modes,
};
use mechanica_modal::{ModeKind, SolveOptions};
use nalgebra::{Isometry3, Unit, Vector3};

/// Every computed ω² must be within its own reported bound of the exact value (and the bound
/// must be honest, i.e. small).
fn assert_within_bounds(modes: &mechanica_mechanism::MechanismModes, exact: &[f64]) {
    assert_eq!(modes.solution.modes.len(), exact.len());
    for (mode, &w2) in modes.solution.modes.iter().zip(exact) {
        let error = (mode.omega_sq - w2).abs();
        assert!(
            error <= mode.error_bound.max(4.0 * f64::EPSILON * w2.abs()),
            "ω² = {} vs exact {w2}: error {error:.2e} exceeds its bound {:.2e}",
            mode.omega_sq,
            mode.error_bound
        );
        assert!(
            error <= 1e-12 * w2.abs().max(1e-300),
            "ω² = {} vs exact {w2}",
            mode.omega_sq
        );
    }
}

#[test]
fn double_pendulum_has_omega_sq_l_over_g_equal_two_minus_and_plus_root_two() {
    let (m, l) = (1.3, 0.7);
    let mut mechanism = pendulum_chain(2, m, l);
    let eq = find_equilibrium(&mut mechanism, &[0.4, -0.3], &EquilibriumOptions::default()).expect("equilibrium");
    assert!(eq.q.iter().all(|q| q.abs() < 1e-12), "hanging equilibrium: {:?}", eq.q);
    assert!(eq.gradient_norm <= eq.tolerance);
    let modes = mechanism_modes(&mut mechanism, &eq.q, &SolveOptions::default()).expect("modes");
    let s = 2f64.sqrt();
    assert_within_bounds(&modes, &[(2.0 - s) * G / l, (2.0 + s) * G / l]);
    assert_eq!(modes.stability, Stability::Stable);
}

#[test]
fn triple_pendulum_matches_the_roots_of_its_characteristic_cubic() {
    let (m, l) = (0.9, 1.1);
    let mut mechanism = pendulum_chain(3, m, l);
    let modes = mechanism_modes(&mut mechanism, &[0.0; 3], &SolveOptions::default()).expect("modes");
    // μ = ω² l / g solves μ³ − 9μ² + 18μ − 6 = 0: Newton from brackets of its three roots.
    let mut roots = Vec::new();
    for start in [0.3, 2.0, 6.5] {
        let mut mu: f64 = start;
        for _ in 0..50 {
            mu -= (((mu - 9.0) * mu + 18.0) * mu - 6.0) / ((3.0 * mu - 18.0) * mu + 18.0);
        }
        assert!((((mu - 9.0) * mu + 18.0) * mu - 6.0).abs() < 1e-12);
        roots.push(mu);
    }
    roots.sort_by(f64::total_cmp);
    let exact: Vec<f64> = roots.iter().map(|mu| mu * G / l).collect();
    assert_within_bounds(&modes, &exact);
}

/// n unit masses on prismatic joints along x, joined to each other and to two walls by unit
/// springs: the fixed–fixed chain, ω²_k = 4 sin²(kπ/(2(n+1))).
#[test]
fn spring_mass_chain_built_as_a_mechanism_matches_the_matrix_closed_form() {
    let n = 6;
    let spacing = 1.0;
    let mut builder = TreeBuilder::new();
    let mut root = None;
    for i in 0..n {
        // A massless base body carries every slider so that the tree has a single root.
        if i == 0 {
            root = Some(builder.add_body(None, Joint::Fixed, Isometry3::identity()));
        }
        builder.add_body(
            root,
            Joint::Prismatic { axis: Vector3::x() },
            Isometry3::translation((i + 1) as f64 * spacing, 0.0, 0.0),
        );
    }
    let tree = builder.build().expect("tree");
    let mut bodies = vec![MassProperties::point(1.0, Vector3::zeros()).expect("mass"); n + 1];
    bodies[0] = MassProperties::ZERO;
    let mut mechanism = Mechanism::new(tree, bodies).expect("mechanism");
    let ground = |x: f64| Anchor {
        body: None,
        point: Vector3::new(x, 0.0, 0.0),
    };
    let slider = |i: usize| Anchor {
        body: Some(i + 1),
        point: Vector3::zeros(),
    };
    let spring = |a, b| PointSpring {
        a,
        b,
        stiffness: 1.0,
        rest_length: spacing,
    };
    mechanism.add_potential(spring(ground(0.0), slider(0))).expect("wall");
    for i in 0..n - 1 {
        mechanism
            .add_potential(spring(slider(i), slider(i + 1)))
            .expect("spring");
    }
    mechanism
        .add_potential(spring(slider(n - 1), ground((n + 1) as f64 * spacing)))
        .expect("wall");
    let modes = mechanism_modes(&mut mechanism, &vec![0.0; n], &SolveOptions::default()).expect("modes");
    assert_within_bounds(&modes, &mechanica_modal::testing::fixed_chain_omega_sq(n));
    // Effective masses along x sum to the moving mass when every mode is kept.
    let sum: f64 = modes.effective_masses.iter().map(|e| e[0]).sum();
    assert!((sum - n as f64).abs() <= 1e-12 * n as f64, "Σ m_eff = {sum}");
}

#[test]
fn inverted_pendulum_is_found_and_classified_unstable() {
    let l = 0.5;
    let mut mechanism = pendulum_chain(1, 2.0, l);
    let eq = find_equilibrium(&mut mechanism, &[2.9], &EquilibriumOptions::default()).expect("equilibrium");
    assert!((eq.q[0] - std::f64::consts::PI).abs() < 1e-12, "upright: {:?}", eq.q);
    let modes = mechanism_modes(&mut mechanism, &eq.q, &SolveOptions::default()).expect("modes");
    match modes.stability {
        Stability::Unstable {
            directions,
            max_growth_rate,
        } => {
            assert_eq!(directions, 1);
            let exact = (G / l).sqrt();
            assert!(
                (max_growth_rate - exact).abs() <= 1e-12 * exact,
                "γ = {max_growth_rate} vs {exact}"
            );
        }
        other => panic!("inverted pendulum classified {other:?}"),
    }
    // The hanging and the upright equilibria from several starts, nothing else.
    let starts: Vec<Vec<f64>> = (-3..=3).map(|k| vec![0.45 * k as f64]).collect();
    let (found, _) = find_equilibria(&mut mechanism, &starts, &EquilibriumOptions::default()).expect("search");
    for eq in &found {
        let wrapped = eq.q[0].rem_euclid(2.0 * std::f64::consts::PI);
        assert!(
            wrapped < 1e-9
                || (wrapped - std::f64::consts::PI).abs() < 1e-9
                || (wrapped - 2.0 * std::f64::consts::PI).abs() < 1e-9
        );
    }
}

/// A bead of mass m on a hoop of radius R turning at Ω about its vertical diameter:
/// U* = −mgR cos θ − ½ mΩ²R² sin²θ. Below Ω² = g/R the bottom is stable with
/// ω² = g/R − Ω²; above, the bottom is unstable and θ* = arccos(g/(Ω²R)) is stable with
/// ω² = Ω² sin²θ*.
#[test]
fn bead_on_a_rotating_hoop_bifurcates_at_the_critical_speed() {
    let (m, r) = (0.2, 0.4);
    let critical = (G / r).sqrt();
    for &ratio in &[0.5, 0.9, 1.1, 1.5, 3.0] {
        let rate = ratio * critical;
        let mut mechanism = pendulum_chain(1, m, r);
        mechanism
            .set_rotating_frame(Some(RotatingFrame {
                axis: Unit::new_normalize(Vector3::z()),
                rate,
            }))
            .expect("rotation");
        let bottom = mechanism_modes(&mut mechanism, &[0.0], &SolveOptions::default()).expect("modes");
        let seek_minimum = EquilibriumOptions {
            seek: Seek::Minimum,
            ..EquilibriumOptions::default()
        };
        let eq = find_equilibrium(&mut mechanism, &[0.3], &seek_minimum).expect("equilibrium");
        let modes = mechanism_modes(&mut mechanism, &eq.q, &SolveOptions::default()).expect("modes");
        if ratio < 1.0 {
            assert!(
                eq.q[0].abs() < 1e-10,
                "below critical speed the bead returns to the bottom: {:?}",
                eq.q
            );
            let exact = G / r - rate * rate;
            assert!((modes.solution.modes[0].omega_sq - exact).abs() <= 1e-12 * exact);
            assert_eq!(modes.stability, Stability::Stable);
        } else {
            assert!(matches!(bottom.stability, Stability::Unstable { directions: 1, .. }));
            let theta = (G / (rate * rate * r)).acos();
            assert!((eq.q[0] - theta).abs() <= 1e-10, "θ* = {} vs {theta}", eq.q[0]);
            let exact = rate * rate * theta.sin().powi(2);
            assert!((modes.solution.modes[0].omega_sq - exact).abs() <= 1e-10 * exact);
            assert_eq!(modes.stability, Stability::Stable);
        }
    }
}

/// A solid cylinder hanging from a spherical joint: a compound pendulum in two directions
/// (a double ω² = m g d / I_pivot) and a free spin about its axis (a zero mode): marginal.
#[test]
fn spherical_compound_pendulum_has_a_double_frequency_and_a_zero_mode() {
    let (radius, length, mass) = (0.05, 0.8, 3.0);
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Spherical, Isometry3::identity());
    let tree = builder.build().expect("tree");
    let mut body = cylinder(radius, length, Amount::Mass(mass)).expect("cylinder");
    body.p_oc = Vector3::new(0.0, 0.0, -length / 2.0);
    let mut mechanism = Mechanism::new(tree, vec![body]).expect("mechanism");
    mechanism.set_gravity(Vector3::new(0.0, 0.0, -G)).expect("gravity");
    let eq = find_equilibrium(&mut mechanism, &[0.2, -0.1, 0.3], &EquilibriumOptions::default()).expect("eq");
    let modes = mechanism_modes(&mut mechanism, &eq.q, &SolveOptions::default()).expect("modes");
    let d = length / 2.0;
    let i_pivot = mass * (radius * radius / 4.0 + length * length / 12.0) + mass * d * d;
    let pendulum = mass * G * d / i_pivot;
    assert!(
        matches!(modes.solution.modes[0].kind, ModeKind::Zero),
        "{:?}",
        modes.solution.modes
    );
    for mode in &modes.solution.modes[1..] {
        assert!(
            (mode.omega_sq - pendulum).abs() <= 1e-12 * pendulum,
            "{} vs {pendulum}",
            mode.omega_sq
        );
    }
    assert_eq!(modes.solution.groups.last().map(|g| g.multiplicity), Some(2));
    assert_eq!(modes.stability, Stability::Marginal { zero_modes: 1 });
}

#[test]
fn joint_limits_stop_the_search_and_are_reported() {
    let mut mechanism = pendulum_chain(1, 1.0, 1.0);
    mechanism
        .add_potential(JointSpring {
            coordinate: 0,
            stiffness: 100.0,
            rest: 2.0,
        })
        .expect("spring");
    mechanism.set_limits(0, 0.5, 1.0).expect("limits");
    let eq = find_equilibrium(&mut mechanism, &[0.7], &EquilibriumOptions::default()).expect("equilibrium");
    assert_eq!(eq.at_limit, vec![0]);
    assert_eq!(eq.q[0], 1.0);
    assert!(matches!(
        mechanism.set_limits(0, 1.0, 0.0),
        Err(MechanismError::BadLimits { .. })
    ));
}

#[test]
fn a_search_that_cannot_converge_reports_its_best_point() {
    // A constant torque on a free wheel: grad U* = −Q everywhere, no equilibrium.
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Revolute { axis: Vector3::z() }, Isometry3::identity());
    let tree = builder.build().expect("tree");
    let body = cylinder(0.1, 0.02, Amount::Mass(1.0)).expect("wheel");
    let mut mechanism = Mechanism::new(tree, vec![body]).expect("mechanism");
    mechanism
        .add_potential(mechanica_mechanism::potentials::GeneralizedForce {
            coordinate: 0,
            value: 2.0,
        })
        .expect("torque");
    match find_equilibrium(
        &mut mechanism,
        &[0.0],
        &EquilibriumOptions {
            max_iterations: 10,
            ..EquilibriumOptions::default()
        },
    ) {
        Err(MechanismError::NoEquilibrium {
            gradient_norm, best_q, ..
        }) => {
            assert!((gradient_norm - 2.0).abs() < 1e-12);
            assert_eq!(best_q.len(), 1);
        }
        other => panic!("expected NoEquilibrium, got {other:?}"),
    }
}

/// A point mass m on two sliders (x, y) held by an isotropic zero-length spring k, seen from a
/// frame turning at Ω about z: m ẍ − 2mΩẏ + (k − mΩ²)x = 0 and its mirror. The frequencies are
/// ω₀ ∓ Ω (ω₀ = √(k/m)); beyond Ω = ω₀ the potential U* is a maximum (B negative definite) yet
/// the gyroscopic coupling keeps every mode oscillating.
#[test]
fn gyroscopic_coupling_shifts_frequencies_and_stabilises_a_potential_maximum() {
    let (m, k) = (2.0_f64, 18.0_f64);
    let omega0 = (k / m).sqrt();
    for &rate in &[0.5, 1.7, 5.0] {
        let mut builder = TreeBuilder::new();
        let carriage = builder.add_body(None, Joint::Prismatic { axis: Vector3::x() }, Isometry3::identity());
        builder.add_body(
            Some(carriage),
            Joint::Prismatic { axis: Vector3::y() },
            Isometry3::identity(),
        );
        let tree = builder.build().expect("tree");
        let massless = MassProperties::ZERO;
        let bodies = vec![massless, MassProperties::point(m, Vector3::zeros()).expect("mass")];
        let mut mechanism = Mechanism::new(tree, bodies).expect("mechanism");
        mechanism
            .set_rotating_frame(Some(RotatingFrame {
                axis: Unit::new_normalize(Vector3::z()),
                rate,
            }))
            .expect("rotation");
        mechanism
            .add_potential(PointSpring {
                a: Anchor {
                    body: Some(1),
                    point: Vector3::zeros(),
                },
                b: Anchor {
                    body: None,
                    point: Vector3::zeros(),
                },
                stiffness: k,
                rest_length: 0.0,
            })
            .expect("spring");
        let modes = mechanism_modes(&mut mechanism, &[0.0, 0.0], &SolveOptions::default()).expect("modes");
        let gyro = modes.gyroscopic.expect("rotating frame with coupling");
        let mut frequencies: Vec<f64> = gyro.eigenvalues.iter().map(|s| s.1.abs()).collect();
        frequencies.sort_by(f64::total_cmp);
        let mut expected = vec![
            (omega0 - rate).abs(),
            (omega0 - rate).abs(),
            omega0 + rate,
            omega0 + rate,
        ];
        expected.sort_by(f64::total_cmp);
        for (got, want) in frequencies.iter().zip(&expected) {
            assert!(
                (got - want).abs() <= 1e-10 * want.max(1.0),
                "Ω = {rate}: {frequencies:?} vs {expected:?}"
            );
        }
        assert!(gyro.stable, "Ω = {rate}: max Re s = {}", gyro.max_real_part);
        if rate > omega0 {
            assert!(
                matches!(modes.stability, Stability::Unstable { directions: 2, .. }),
                "{:?}",
                modes.stability
            );
        } else {
            assert_eq!(modes.stability, Stability::Stable);
        }
    }
}

/// Modes of a mechanism with spherical joints at a state whose rotation vectors are not zero:
/// a cylinder on a ball joint under a spring to a ground point (the spring makes every mode
/// depend on the pose). Two identical calls give the same numbers bit for bit and leave the
/// mechanism's charts as they were (A(q₀) and U(q₀) unchanged), for random poses; before, the
/// first call re-centred the caller's mechanism, so the second read q₀ as another pose.
#[test]
fn repeated_mode_calls_with_rotation_vectors_agree_and_keep_the_charts() {
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut uniform = |lo: f64, hi: f64| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        lo + (hi - lo) * (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for case in 0..12 {
        let mut builder = TreeBuilder::new();
        builder.add_body(None, Joint::Spherical, Isometry3::identity());
        let tree = builder.build().expect("tree");
        let mut body = cylinder(0.05, 0.8, Amount::Mass(uniform(0.5, 5.0))).expect("cylinder");
        body.p_oc = Vector3::new(0.0, 0.0, -0.4);
        let mut mechanism = Mechanism::new(tree, vec![body]).expect("mechanism");
        mechanism.set_gravity(Vector3::new(0.0, 0.0, -G)).expect("gravity");
        let spring = PointSpring {
            a: Anchor {
                body: Some(0),
                point: Vector3::new(0.03, 0.0, -0.8),
            },
            b: Anchor {
                body: None,
                point: Vector3::new(uniform(-0.5, 0.5), uniform(-0.5, 0.5), -1.2),
            },
            stiffness: uniform(5.0, 500.0),
            rest_length: uniform(0.0, 0.3),
        };
        mechanism.add_potential(spring).expect("spring");
        let q0 = [uniform(-1.5, 1.5), uniform(-1.5, 1.5), uniform(-1.5, 1.5)];
        let a_before = mechanism.mass_matrix(&q0).expect("A");
        let u_before = mechanism.potential(&q0, false).expect("U").value;
        let first = mechanism_modes(&mut mechanism, &q0, &SolveOptions::default()).expect("modes");
        let second = mechanism_modes(&mut mechanism, &q0, &SolveOptions::default()).expect("modes");
        let bits = |m: &mechanica_mechanism::MechanismModes| -> Vec<u64> {
            m.solution
                .modes
                .iter()
                .flat_map(|mode| [mode.omega_sq.to_bits(), mode.error_bound.to_bits()])
                .chain([m.gradient_norm.to_bits()])
                .collect()
        };
        assert_eq!(bits(&first), bits(&second), "case {case}: the second call differs");
        let a_after = mechanism.mass_matrix(&q0).expect("A");
        assert_eq!(
            a_before, a_after,
            "case {case}: the call moved the charts (A(q₀) changed)"
        );
        let u_after = mechanism.potential(&q0, false).expect("U").value;
        assert_eq!(u_before.to_bits(), u_after.to_bits(), "case {case}: U(q₀) changed");
    }
}

/// Two sliders on separate branches of a fixed root (A = diag(m₁, m₂) exactly), the first
/// one light down to subnormal masses, with joint springs k₁, k₂: ω² = kᵢ/mᵢ. Every bound is
/// finite (or +∞) and holds; a light body's shape entries near 1e158 made the assembly
/// error 0·∞ = NaN.
#[test]
fn light_sliders_have_true_finite_bounds() {
    for m1 in [5e-324, 4.843403e-317, 1e-310, 1e-300, 1e-200, 1e-3] {
        for k1 in [0.0, 1e-310, 1e-300, 1e-290] {
            let mut builder = TreeBuilder::new();
            let root = builder.add_body(None, Joint::Fixed, Isometry3::translation(-0.3, -0.3, -0.3));
            for (axis, at) in [(Vector3::x(), 0.2), (Vector3::y(), -0.7)] {
                builder.add_body(
                    Some(root),
                    Joint::Prismatic { axis },
                    Isometry3::translation(at, 0.1, 0.0),
                );
            }
            let bodies = vec![
                MassProperties::point(4.8, Vector3::zeros()).expect("root"),
                MassProperties::point(m1, Vector3::zeros()).expect("light slider"),
                MassProperties::point(0.01, Vector3::zeros()).expect("slider"),
            ];
            let mut mechanism = Mechanism::new(builder.build().expect("tree"), bodies).expect("mechanism");
            for (coordinate, stiffness) in [(0, k1), (1, 3.0)] {
                if stiffness > 0.0 {
                    let spring = JointSpring {
                        coordinate,
                        stiffness,
                        rest: 0.0,
                    };
                    mechanism.add_potential(spring).expect("spring");
                }
            }
            let exact = [k1 / m1, 3.0 / 0.01];
            let mut sorted = exact;
            sorted.sort_by(f64::total_cmp);
            match mechanism_modes(&mut mechanism, &[0.25, -1.4], &SolveOptions::default()) {
                Ok(modes) => {
                    for mode in &modes.solution.modes {
                        assert!(
                            !mode.error_bound.is_nan() && mode.error_bound >= 0.0,
                            "m₁ {m1:e}, k₁ {k1:e}: {mode:?}"
                        );
                    }
                    assert_within_bounds(&modes, &sorted);
                }
                Err(e) => assert!(exact.iter().any(|w| *w > 1e300), "m₁ {m1:e}, k₁ {k1:e}: {e}"),
            }
        }
    }
}

/// A double pendulum (point masses m on links l, hinges about y) with massless "fingers" at its
/// tip: revolute joints about random axes carrying massless links, without springs, some
/// placed between the two pendulum bodies' coordinates in the numbering. Their rows and
/// columns of A and B are exactly zero, so the pencil of every coordinate is singular; the
/// fingers are left out (`idle`) and the pendulum's two modes are (2 ∓ √2) g/l, with zero
/// finger rows in the shapes. A finger with a joint spring moves no mass but feels a force: it
/// stays in, as an infinite mode, and the finite modes are the same.
#[test]
fn massless_joints_without_springs_are_left_out_of_the_modes() {
    let (m, l) = (1.3, 0.7);
    for (fingers, sprung) in [(1, false), (3, false), (2, true)] {
        let mut builder = TreeBuilder::new();
        let upper = builder.add_body(None, Joint::Revolute { axis: Vector3::y() }, Isometry3::identity());
        let mut bodies = vec![MassProperties::point(m, Vector3::new(0.0, 0.0, -l)).expect("point")];
        let mut parent = upper;
        for f in 0..fingers {
            let axis = Vector3::new(0.3 + f as f64, -0.5, 0.8 - f as f64).normalize();
            parent = builder.add_body(
                Some(parent),
                Joint::Revolute { axis },
                Isometry3::translation(0.0, 0.0, -l),
            );
            bodies.push(MassProperties::ZERO);
        }
        builder.add_body(
            Some(upper),
            Joint::Revolute { axis: Vector3::y() },
            Isometry3::translation(0.0, 0.0, -l),
        );
        bodies.push(MassProperties::point(m, Vector3::new(0.0, 0.0, -l)).expect("point"));
        let mut mechanism = Mechanism::new(builder.build().expect("tree"), bodies).expect("mechanism");
        mechanism.set_gravity(Vector3::new(0.0, 0.0, -G)).expect("gravity");
        if sprung {
            let spring = JointSpring {
                coordinate: 1,
                stiffness: 5.0,
                rest: 0.0,
            };
            mechanism.add_potential(spring).expect("spring");
        }
        let q = vec![0.0; fingers + 2];
        let modes = mechanism_modes(&mut mechanism, &q, &SolveOptions::default()).expect("modes");
        let expected_idle: Vec<usize> = (1..=fingers).filter(|&k| !(sprung && k == 1)).collect();
        assert_eq!(modes.idle, expected_idle, "fingers {fingers}, sprung {sprung}");
        let finite: Vec<f64> = modes
            .solution
            .modes
            .iter()
            .filter(|mode| mode.kind != ModeKind::Infinite)
            .map(|mode| mode.omega_sq)
            .collect();
        let s = 2f64.sqrt();
        let exact = [(2.0 - s) * G / l, (2.0 + s) * G / l];
        assert_eq!(finite.len(), 2, "{:?}", modes.solution.modes);
        for (got, want) in finite.iter().zip(exact) {
            assert!((got - want).abs() <= 1e-12 * want, "{got} vs {want}");
        }
        let x = modes.solution.vectors.as_ref().expect("shapes");
        assert_eq!(x.nrows(), fingers + 2);
        for &k in &expected_idle {
            assert!((0..x.ncols()).all(|c| x[(k, c)] == 0.0), "finger row {k} of the shapes");
        }
        assert_eq!(modes.stability, Stability::Stable);
    }
}
