//! A search for a minimum (`Seek::Minimum`) that starts on a stationary point which is not one
//! (an inverted pendulum, a chain with links standing up) must leave it along the negative
//! curvature and end at a minimum, while a search for any stationary point stays there.

use mechanica_kinematics::tree::{Joint, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mechanism::{EquilibriumOptions, Mechanism, Seek, Stability, find_equilibrium, mechanism_modes};
use mechanica_modal::SolveOptions;
use nalgebra::{Isometry3, Vector3};
use proptest::prelude::*;
use std::f64::consts::PI;

const G: f64 = 9.81;

/// A planar chain of point masses `m_i` on massless links `l_i`, hinges about y, hanging
/// along −z at q = 0, gravity −g z.
fn chain(links: &[(f64, f64)]) -> Mechanism {
    let mut builder = TreeBuilder::new();
    let mut previous = 0.0;
    for (i, &(_, l)) in links.iter().enumerate() {
        let placement = Isometry3::translation(0.0, 0.0, -previous);
        builder.add_body(i.checked_sub(1), Joint::Revolute { axis: Vector3::y() }, placement);
        previous = l;
    }
    let bodies = links
        .iter()
        .map(|&(m, l)| MassProperties::point(m, Vector3::new(0.0, 0.0, -l)).expect("point"))
        .collect();
    let mut mechanism = Mechanism::new(builder.build().expect("chain"), bodies).expect("mechanism");
    mechanism.set_gravity(Vector3::new(0.0, 0.0, -G)).expect("gravity");
    mechanism
}

/// U* of the chain hanging straight down: −g Σ m_i (l_1 + … + l_i).
fn hanging_potential(links: &[(f64, f64)]) -> f64 {
    let mut depth = 0.0;
    links
        .iter()
        .map(|&(m, l)| {
            depth += l;
            -m * G * depth
        })
        .sum()
}

fn options(seek: Seek) -> EquilibriumOptions {
    EquilibriumOptions {
        seek,
        max_iterations: 200,
        ..EquilibriumOptions::default()
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Every configuration with all links vertical (each relative angle 0 or π) is stationary;
    /// only the one hanging straight down is a minimum. From any other, the minimum search
    /// reaches U* of the hanging chain, with every mode oscillatory; the stationary search
    /// stays where it started.
    #[test]
    fn a_minimum_search_leaves_stationary_points_that_are_not_minima(
        links in proptest::collection::vec((-1.0..1.0_f64, -1.0..0.5_f64), 1..6),
        flips in proptest::collection::vec(any::<bool>(), 6),
    ) {
        let links: Vec<(f64, f64)> = links.iter().map(|&(m, l)| (10f64.powf(m), 10f64.powf(l))).collect();
        let n = links.len();
        let mut start: Vec<f64> = flips[..n].iter().map(|&f| if f { PI } else { 0.0 }).collect();
        if start.iter().all(|&q| q == 0.0) {
            start[n - 1] = PI;
        }
        let mut mechanism = chain(&links);
        let stay = find_equilibrium(&mut mechanism, &start, &options(Seek::Stationary)).expect("stationary");
        prop_assert_eq!(stay.iterations, 0);
        prop_assert_eq!(&stay.q, &start);

        let eq = find_equilibrium(&mut mechanism, &start, &options(Seek::Minimum)).expect("minimum");
        prop_assert!(eq.gradient_norm <= eq.tolerance);
        let lowest = hanging_potential(&links);
        prop_assert!(
            (eq.potential - lowest).abs() <= 1e-12 * lowest.abs(),
            "U* = {} vs the hanging chain's {lowest} at q = {:?}",
            eq.potential,
            eq.q
        );
        let modes = mechanism_modes(&mut mechanism, &eq.q, &SolveOptions::default()).expect("modes");
        prop_assert_eq!(modes.stability, Stability::Stable);
    }
}

/// The double pendulum balanced upside down: the minimum search ends hanging, where
/// ω² l/g = 2 ∓ √2, the negatives of the inverted pendulum's.
#[test]
fn the_inverted_double_pendulum_falls_to_its_hanging_position() {
    let (m, l) = (1.3, 0.7);
    let mut mechanism = chain(&[(m, l), (m, l)]);
    let eq = find_equilibrium(&mut mechanism, &[PI, 0.0], &options(Seek::Minimum)).expect("minimum");
    let folded = |angle: f64| (angle + PI).rem_euclid(2.0 * PI) - PI;
    assert!(
        folded(eq.q[0]).abs() < 1e-9 && folded(eq.q[1]).abs() < 1e-9,
        "{:?}",
        eq.q
    );
    let modes = mechanism_modes(&mut mechanism, &eq.q, &SolveOptions::default()).expect("modes");
    assert_eq!(modes.solution.modes.len(), 2);
    let s = 2f64.sqrt();
    for (mode, exact) in modes.solution.modes.iter().zip([(2.0 - s) * G / l, (2.0 + s) * G / l]) {
        assert!(
            (mode.omega_sq - exact).abs() <= 1e-12 * exact,
            "{} vs {exact}",
            mode.omega_sq
        );
    }
}

/// A minimum search with nothing left to move: every coordinate resting on a limit that the
/// gradient pushes against, or no coordinate at all. The search returns the point (the
/// reduced Hessian is empty) instead of decomposing an empty matrix.
#[test]
fn a_minimum_search_with_no_free_coordinate_returns_its_point() {
    let mut pendulum = chain(&[(1.0, 1.0)]);
    pendulum.set_limits(0, 0.5, 1.0).expect("limits");
    let eq = find_equilibrium(&mut pendulum, &[0.7], &options(Seek::Minimum)).expect("minimum");
    assert_eq!(eq.q, vec![0.5]);
    assert_eq!(eq.at_limit, vec![0]);

    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Fixed, Isometry3::identity());
    let bodies = vec![MassProperties::point(2.0, Vector3::new(0.3, 0.0, -1.0)).expect("point")];
    let mut rigid = Mechanism::new(builder.build().expect("tree"), bodies).expect("mechanism");
    rigid.set_gravity(Vector3::new(0.0, 0.0, -G)).expect("gravity");
    let eq = find_equilibrium(&mut rigid, &[], &options(Seek::Minimum)).expect("minimum");
    assert!(eq.q.is_empty() && eq.iterations == 0);
}
