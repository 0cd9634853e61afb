//! Equilibria along soft directions: a body turning about an axis tilted by ε from the
//! vertical feels a gravity stiffness of order ε·m g r, 1e-7 to 1e-12 of the others (real
//! robots have such joints: a wrist about a nearly vertical axis carrying an offset hand). The
//! Newton search must take its full step there and converge quadratically, not crawl at the
//! rate ε/floor of a regularisation floor far above the soft curvature.

use mechanica_kinematics::tree::{Joint, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mechanism::{EquilibriumOptions, Mechanism, Seek, Stability, find_equilibrium, mechanism_modes};
use mechanica_modal::SolveOptions;
use nalgebra::{Isometry3, Matrix3, Unit, UnitQuaternion, Vector3};
use proptest::prelude::*;

const G: f64 = 9.81;

/// The root joint's axis: the vertical tilted by `tilt` about the horizontal direction at
/// angle `heading` from x.
fn tilted_axis(tilt: f64, heading: f64) -> Vector3<f64> {
    let about = Unit::new_normalize(Vector3::new(heading.cos(), heading.sin(), 0.0));
    UnitQuaternion::from_axis_angle(&about, tilt) * Vector3::z()
}

/// A root revolute joint about `axis` carrying a body of mass `m` with its centre at `centre`
/// (joint frame, at q = 0), then a chain of `links` hinges about horizontal axes, each a rod of
/// (mass, length, hinge direction angle) hanging along −z.
fn soft_arm(axis: Vector3<f64>, m: f64, centre: Vector3<f64>, links: &[(f64, f64, f64)]) -> Mechanism {
    let mut builder = TreeBuilder::new();
    let mut parent = builder.add_body(None, Joint::Revolute { axis }, Isometry3::identity());
    let hub = Matrix3::from_diagonal(&Vector3::new(1e-3, 1e-3, 1e-3)) * m;
    let mut bodies = vec![MassProperties::new(m, centre, hub).expect("hub")];
    let mut drop = centre;
    for &(mass, length, direction) in links {
        let hinge = Vector3::new(direction.cos(), direction.sin(), 0.0);
        parent = builder.add_body(
            Some(parent),
            Joint::Revolute { axis: hinge },
            Isometry3::translation(drop.x, drop.y, drop.z),
        );
        let moment = mass * length * length / 12.0;
        let inertia = Matrix3::from_diagonal(&Vector3::new(moment, moment, 1e-3 * moment));
        bodies.push(MassProperties::new(mass, Vector3::new(0.0, 0.0, -0.5 * length), inertia).expect("rod"));
        drop = Vector3::new(0.0, 0.0, -length);
    }
    let mut mechanism = Mechanism::new(builder.build().expect("tree"), bodies).expect("mechanism");
    mechanism.set_gravity(Vector3::new(0.0, 0.0, -G)).expect("gravity");
    mechanism
}

fn seek_minimum() -> EquilibriumOptions {
    EquilibriumOptions {
        seek: Seek::Minimum,
        max_iterations: 200,
        ..EquilibriumOptions::default()
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// One body on the tilted axis: the lowest point of its centre's circle is at
    /// θ* = atan2(−(a × c)_z, −(c − (a·c)a)_z) (the height is (a·c)a_z + cos θ (c − (a·c)a)_z
    /// + sin θ (a × c)_z), reached to within the gradient tolerance over the soft stiffness
    /// (and 1e-12 rad for the rounding of θ itself).
    #[test]
    fn a_body_on_a_nearly_vertical_axis_settles_at_its_lowest_point(
        log_tilt in -12.0..-7.0_f64,
        heading in -3.1..3.1_f64,
        log_mass in -1.0..1.0_f64,
        radius in 0.05..1.0_f64,
        drop in -1.0..1.0_f64,
        azimuth in -3.1..3.1_f64,
        start in -3.0..3.0_f64,
    ) {
        let tilt = 10f64.powf(log_tilt);
        let axis = tilted_axis(tilt, heading);
        let centre = Vector3::new(radius * azimuth.cos(), radius * azimuth.sin(), drop);
        let m = 10f64.powf(log_mass);
        let mut mechanism = soft_arm(axis, m, centre, &[]);
        let eq = find_equilibrium(&mut mechanism, &[start], &seek_minimum()).expect("converges");
        prop_assert!(eq.gradient_norm <= eq.tolerance);
        prop_assert!(eq.iterations <= 40, "{} iterations", eq.iterations);
        // (c − (a·c)a)_z = c_z (a_x² + a_y²) − a_z (a_x c_x + a_y c_y), written without the
        // cancellation of c_z − (a·c)a_z (both terms are of order ε or ε²).
        let (a, c) = (axis, centre);
        let cos_part = c.z * (a.x * a.x + a.y * a.y) - a.z * (a.x * c.x + a.y * c.y);
        let sin_part = a.x * c.y - a.y * c.x;
        let exact = (-sin_part).atan2(-cos_part);
        let stiffness = m * G * cos_part.hypot(sin_part);
        let miss = (eq.q[0] - exact + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI) - std::f64::consts::PI;
        prop_assert!(
            miss.abs() <= 4.0 * eq.tolerance / stiffness + 1e-12,
            "θ = {} vs θ* = {exact}: miss {miss:.2e}, tolerance/stiffness {:.2e}",
            eq.q[0],
            eq.tolerance / stiffness
        );
    }

    /// A chain of hinges below the soft joint: the search converges within 60 iterations
    /// and stops at a minimum (no mode unstable).
    #[test]
    fn chains_below_a_nearly_vertical_axis_converge_to_a_minimum(
        log_tilt in -12.0..-7.0_f64,
        heading in -3.1..3.1_f64,
        radius in 0.05..1.0_f64,
        links in proptest::collection::vec((-1.0..1.0_f64, -1.0..0.3_f64, -3.1..3.1_f64), 1..5),
        starts in proptest::collection::vec(-1.5..1.5_f64, 5),
    ) {
        let links: Vec<(f64, f64, f64)> = links.iter().map(|&(m, l, d)| (10f64.powf(m), 10f64.powf(l), d)).collect();
        let axis = tilted_axis(10f64.powf(log_tilt), heading);
        let mut mechanism = soft_arm(axis, 1.0, Vector3::new(radius, 0.0, -0.1), &links);
        let eq = find_equilibrium(&mut mechanism, &starts[..=links.len()], &seek_minimum()).expect("converges");
        prop_assert!(eq.gradient_norm <= eq.tolerance);
        prop_assert!(eq.iterations <= 60, "{} iterations", eq.iterations);
        let modes = mechanism_modes(&mut mechanism, &eq.q, &SolveOptions::default()).expect("modes");
        prop_assert!(!matches!(modes.stability, Stability::Unstable { .. }), "{:?}", modes.solution.modes);
    }
}
