//! Arms whose first joint turns about the vertical through the origin, under gravity: the
//! potential does not depend on that joint, so the Hessian's first row and column are exactly
//! zero and the linearisation has an exactly zero ω² (a neutral mode), at every configuration.
//! The solver finds its shape exactly (the first coordinate alone) with a bound of the order of
//! 1e-60, while the data's resolution there is zero; the mode must be called zero, never
//! undecided, and the stability verdict must not be left open by it.

use mechanica_kinematics::tree::{Joint, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mechanism::{Mechanism, mechanism_modes};
use mechanica_modal::{ModeKind, SolveOptions};
use nalgebra::{Isometry3, Matrix3, Vector3};
use proptest::prelude::*;

/// A vertical first joint, then `links.len()` revolute joints about x, y or z (the last along
/// the link itself, like a wrist: it moves no centre of mass, so its stiffness is zero up to
/// rounding); each link a rod of the given mass and length along −z from its joint (before the
/// joints turn).
fn arm(links: &[(f64, f64, usize)]) -> Mechanism {
    let mut builder = TreeBuilder::new();
    let mut parent = Some(builder.add_body(None, Joint::Revolute { axis: Vector3::z() }, Isometry3::identity()));
    let mut bodies = vec![MassProperties::point(1.0, Vector3::new(0.1, 0.0, 0.0)).expect("hub")];
    let mut drop = 0.0;
    for &(mass, length, axis) in links {
        let axis = [Vector3::x(), Vector3::y(), Vector3::z()][axis % 3];
        parent = Some(builder.add_body(parent, Joint::Revolute { axis }, Isometry3::translation(0.0, 0.0, drop)));
        let moment = mass * length * length / 12.0;
        let inertia = Matrix3::from_diagonal(&Vector3::new(moment, moment, 1e-3 * moment));
        bodies.push(MassProperties::new(mass, Vector3::new(0.0, 0.0, -0.5 * length), inertia).expect("rod"));
        drop = -length;
    }
    let mut mechanism = Mechanism::new(builder.build().expect("tree"), bodies).expect("mechanism");
    mechanism.set_gravity(Vector3::new(0.0, 0.0, -9.81)).expect("gravity");
    mechanism
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn the_vertical_joint_gives_a_zero_mode_never_an_undecided_one(
        links in proptest::collection::vec((-1.0..1.0_f64, -1.5..0.5_f64, 0usize..3), 1..7),
        angles in proptest::collection::vec(-3.0..3.0_f64, 7),
    ) {
        let links: Vec<(f64, f64, usize)> = links.iter().map(|&(m, l, x)| (10f64.powf(m), 10f64.powf(l), x)).collect();
        let mut mechanism = arm(&links);
        let q: Vec<f64> = angles[..=links.len()].to_vec();
        let modes = mechanism_modes(&mut mechanism, &q, &SolveOptions::default()).expect("modes");
        let x = modes.solution.vectors.as_ref().expect("shapes");
        let zero_modes = modes.solution.modes.iter().filter(|m| m.kind == ModeKind::Zero).count();
        prop_assert!(zero_modes >= 1, "{:?}", modes.solution.modes);
        // The joints about vertical axes and about their loads' axes give exactly zero columns of
        // B: every mode within 1e-30 of zero is zero, none undecided.
        for mode in &modes.solution.modes {
            let tiny = mode.omega_sq.abs() + mode.error_bound <= 1e-30;
            prop_assert!(!tiny || mode.kind == ModeKind::Zero, "{:?}", mode);
        }
        // A mode whose shape is the first joint alone is the exact zero eigenpair.
        for (k, mode) in modes.solution.modes.iter().enumerate() {
            if (1..x.nrows()).all(|r| x[(r, k)] == 0.0) {
                prop_assert_eq!(mode.kind, ModeKind::Zero, "{:?}", mode);
                prop_assert!(mode.omega_sq.abs() <= mode.error_bound);
            }
        }
    }
}
