//! Inputs at the ends of the double range: every fallible function either returns finite
//! results that match an independent reference, or a typed error; never NaN or ∞ with Ok.

use mechanica_kinematics::KinematicsError;
use mechanica_kinematics::euler::{AngularVelocityFrame, EulerSequence, angular_velocity_from_euler_rates};
use mechanica_kinematics::nalgebra::{Isometry3, Matrix3, Rotation3, Unit, Vector3};
use mechanica_kinematics::relative_motion::{RelativeMotion, decompose};
use mechanica_kinematics::rigid_motion::RigidMotion;
use mechanica_kinematics::rotation::{
    QuaternionNorm, ROTATION_VECTOR_LIMIT, angular_velocity_from_rate, exp_map, orthonormalize_matrix,
    quaternion_from_matrix, right_jacobian, right_jacobian_rate, rotation_from_axis_angle, rotation_from_matrix, skew,
    unit_quaternion,
};
use mechanica_kinematics::tree::{Joint, TreeBuilder};
use proptest::prelude::*;

const EPS: f64 = f64::EPSILON;

/// (θ, sin θ, cos θ) for exact doubles θ, sin and cos computed with mpmath at 1200 bits and
/// rounded to double: an independent reference for the reduction modulo 2π.
const HUGE_ANGLES: [(f64, f64, f64); 14] = [
    (1e308, 0.4533964905016491, -0.8913089376870335),
    (9007199254740992.0, -0.848925964814655, -0.5285117844130887),
    (1.7976931348623157e308, 0.004961954789184062, -0.9999876894265599),
    (-3.3e250, -0.6859873026970635, -0.727613510414978),
    (-9.520212367363202e179, 0.8591289709426937, 0.5117591340532655),
    (4.001240185129651e88, -0.5202715014956442, -0.854000916118635),
    (-2.625098147605817e115, 0.49701498008442313, -0.8677419602460633),
    (-2.0676639435965898e209, -0.2965457005658898, -0.955018663417572),
    (1.4965387229650766e190, -0.23653163821999904, -0.9716237873379611),
    (2.049869944704978e177, 0.9892313301242902, -0.14636043010502392),
    (-2.198825884885293e67, -0.025094839409939666, 0.9996850749285944),
    (-3.0373728639074706e272, -0.6844635664131051, -0.7290470672412398),
    (-4.316102459969944e159, 0.7828674959482176, -0.6221884632390474),
    (-2.951703437921352e104, 0.9906914205689847, -0.13612681297601484),
];

/// Reported case and family: the rotation by a huge angle about a coordinate axis is the
/// exact rotation of that double, to a few ulps of the mpmath reference.
#[test]
fn huge_angles_are_reduced_exactly() {
    for (theta, s, c) in HUGE_ANGLES {
        for axis in 0..3 {
            let r = rotation_from_axis_angle(&Vector3::ith(axis, 1.0), theta).expect("finite angle");
            let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
            let m = r.matrix();
            for (got, want) in [(m[(i, i)], c), (m[(j, j)], c), (m[(j, i)], s), (m[(i, j)], -s)] {
                assert!((got - want).abs() <= 4.0 * EPS, "θ = {theta:e}: {got} vs {want}");
            }
            assert_eq!(m[(axis, axis)], 1.0);
        }
    }
}

/// Reported case: a rotation vector with 1e308 components (|φ| = 1.7e308) used to give a NaN
/// matrix; one rounding of |φ| is then ~1e292 rad, so the rotation is undetermined and refused.
#[test]
fn rotation_vectors_beyond_the_limit_are_refused() {
    for phi in [
        Vector3::repeat(1e308),
        Vector3::new(f64::MAX, 0.0, -f64::MAX),
        Vector3::new(0.0, 2.0 * ROTATION_VECTOR_LIMIT, 0.0),
    ] {
        assert!(matches!(
            exp_map(&phi),
            Err(KinematicsError::RotationAngleUnresolved { .. })
        ));
    }
    assert!(exp_map(&Vector3::new(0.0, 0.0, ROTATION_VECTOR_LIMIT)).is_ok());
}

proptest! {
    /// exp(θ n) against the rotation by θ about n (nalgebra's own formula), over 600 orders of
    /// magnitude of θ up to 1e3: they agree to the rounding of θ n, about (1 + θ) u.
    #[test]
    fn exp_agrees_with_axis_angle_at_every_scale(
        x in -1.0..1.0f64, y in -1.0..1.0f64, z in -1.0..1.0f64, exponent in -300.0..3.0f64,
    ) {
        let n = Vector3::new(x, y, z);
        prop_assume!(n.norm() > 0.1);
        let n = n.normalize();
        let theta = 10f64.powf(exponent);
        let r = exp_map(&(n * theta)).expect("within the limit");
        let reference = Rotation3::from_axis_angle(&Unit::new_normalize(n), theta);
        prop_assert!((r.matrix() - reference.matrix()).norm() <= 16.0 * EPS * (1.0 + theta));
        let m = r.matrix();
        prop_assert!((m.transpose() * m - Matrix3::identity()).norm() <= 16.0 * EPS);
    }

    /// The right Jacobian from θ = 2 up to the limit against its defining formula evaluated
    /// directly (accurate there, since 1 − cos θ and θ − sin θ do not cancel).
    #[test]
    fn the_right_jacobian_is_finite_and_exact_for_large_angles(
        x in -1.0..1.0f64, y in -1.0..1.0f64, z in -1.0..1.0f64, exponent in 0.31..15.0f64,
    ) {
        let n = Vector3::new(x, y, z);
        prop_assume!(n.norm() > 0.1);
        let theta = 10f64.powf(exponent);
        let phi = n.normalize() * theta;
        let th = phi.norm();
        let k = skew(&phi);
        let direct = Matrix3::identity() - k * ((1.0 - th.cos()) / (th * th)) + k * k * ((th - th.sin()) / (th * th * th));
        prop_assert!((right_jacobian(&phi) - direct).norm() <= 64.0 * EPS * direct.norm());
    }

    /// dJ_r/dt from θ = 2 to 100 (the unit-axis branch) against central differences of J_r
    /// along φ(t) = φ + t φ̇: truncation of order h² and rounding of order u/h, both below 1e-7.
    #[test]
    fn the_right_jacobian_rate_matches_differences_for_large_angles(
        x in -1.0..1.0f64, y in -1.0..1.0f64, z in -1.0..1.0f64, theta in 2.0..100.0f64,
        a in -1.0..1.0f64, b in -1.0..1.0f64, c in -1.0..1.0f64,
    ) {
        let n = Vector3::new(x, y, z);
        prop_assume!(n.norm() > 0.1);
        let phi = n.normalize() * theta;
        let phi_dot = Vector3::new(a, b, c);
        let h = 1e-5;
        let fd = (right_jacobian(&(phi + phi_dot * h)) - right_jacobian(&(phi - phi_dot * h))) / (2.0 * h);
        prop_assert!((right_jacobian_rate(&phi, &phi_dot) - fd).norm() <= 1e-7);
    }

    /// A multiple s R of a rotation, s over the whole range: the polar factor is R and the
    /// correction |s − 1|·√3; beyond f64::MAX the correction is a typed error.
    #[test]
    fn orthonormalize_works_at_every_scale(a in -3.0..3.0f64, b in -3.0..3.0f64, c in -3.0..3.0f64, exponent in -300.0..308.0f64) {
        let r = Rotation3::from_scaled_axis(Vector3::new(a, b, c));
        let s = 10f64.powf(exponent);
        let fixed = orthonormalize_matrix(&(r.matrix() * s)).expect("finite correction");
        prop_assert!((fixed.rotation.matrix() - r.matrix()).norm() <= 16.0 * EPS);
        let expected = (s - 1.0).abs() * 3f64.sqrt();
        prop_assert!((fixed.correction - expected).abs() <= 16.0 * EPS * (expected + s));
    }

    /// Matrices U diag(s) Vᵀ with det > 0 whose singular values span up to 300 decades (nearly
    /// singular, or with entries of very different sizes): the result, when one is given, is a
    /// proper rotation to rounding (never a reflection, never NaN), and it is U Vᵀ when the
    /// singular values are well separated from zero.
    #[test]
    fn orthonormalize_never_returns_a_reflection(
        a in -3.0..3.0f64, b in -3.0..3.0f64, c in -3.0..3.0f64,
        d in -3.0..3.0f64, e in -3.0..3.0f64, f in -3.0..3.0f64,
        e1 in -150.0..150.0f64, e2 in -150.0..150.0f64, e3 in -150.0..150.0f64,
    ) {
        let u = Rotation3::from_scaled_axis(Vector3::new(a, b, c));
        let v = Rotation3::from_scaled_axis(Vector3::new(d, e, f));
        let s = Vector3::new(10f64.powf(e1), 10f64.powf(e2), 10f64.powf(e3));
        let m = u.matrix() * Matrix3::from_diagonal(&s) * v.matrix().transpose();
        if let Ok(fixed) = orthonormalize_matrix(&m) {
            let r = fixed.rotation.matrix();
            prop_assert!((r.transpose() * r - Matrix3::identity()).norm() <= 64.0 * EPS);
            prop_assert!(r.determinant() > 0.0);
            let spread = s.max() / s.min();
            if spread < 1e6 {
                let exact = u.matrix() * v.matrix().transpose();
                prop_assert!((r - exact).norm() <= 1e-9, "{r} vs {exact}");
            }
        }
    }

    /// Normalising a quaternion of any finite size gives the same unit quaternion as its
    /// exactly rescaled copy (down to 2⁻¹⁰¹⁸, where the rescaled components are still normal
    /// numbers; below, they have lost bits, but still normalise).
    #[test]
    fn quaternions_of_any_size_normalise(w in -1.0..1.0f64, x in -1.0..1.0f64, y in -1.0..1.0f64, z in -1.0..1.0f64, k in -1018i32..1020) {
        prop_assume!(w.abs().max(x.abs()).max(y.abs()).max(z.abs()) > 0.1);
        let s = 2f64.powi(k);
        let big = unit_quaternion(w * s, x * s, y * s, z * s, QuaternionNorm::Normalize).expect("non-zero");
        let unit = unit_quaternion(w, x, y, z, QuaternionNorm::Normalize).expect("non-zero");
        prop_assert!((big.coords - unit.coords).norm() <= 4.0 * EPS);
        let t = 2f64.powi(-1066);
        let tiny = unit_quaternion(w * t, x * t, y * t, z * t, QuaternionNorm::Normalize).expect("non-zero");
        prop_assert!((tiny.norm() - 1.0).abs() <= 4.0 * EPS);
    }

    /// A rotation scaled by s ≠ 1 (up to f64::MAX, where RᵀR − I is ∞ − ∞ = NaN) is not a
    /// rotation; the rotation itself (s = 1) is accepted and gives back its unit quaternion.
    #[test]
    fn scaled_rotations_are_refused_at_every_scale(a in -3.0..3.0f64, b in -3.0..3.0f64, c in -3.0..3.0f64, exponent in 1.0..308.3f64, shrink in any::<bool>()) {
        let r = Rotation3::from_scaled_axis(Vector3::new(a, b, c));
        let s = if shrink { 10f64.powf(-exponent) } else { 10f64.powf(exponent).min(f64::MAX) };
        let scaled = r.matrix() * s;
        prop_assert!(rotation_from_matrix(&scaled).is_err(), "accepted {scaled:?}");
        prop_assert!(quaternion_from_matrix(&scaled).is_err());
        let q = quaternion_from_matrix(r.matrix()).expect("a rotation");
        prop_assert!((q.to_rotation_matrix().matrix() - r.matrix()).norm() <= 8.0 * EPS);
    }

    /// ω from Ṙ = s [ω̂]× R for s up to 1e307: ω = s ω̂ to rounding.
    #[test]
    fn angular_velocity_from_huge_rates(a in -3.0..3.0f64, b in -3.0..3.0f64, c in -3.0..3.0f64, exponent in 280.0..307.0f64) {
        let r = Rotation3::from_scaled_axis(Vector3::new(a, b, c));
        let w = Vector3::new(c, a, b) * 10f64.powf(exponent);
        let r_dot = skew(&w) * r.matrix();
        let got = angular_velocity_from_rate(&r, &r_dot).expect("representable");
        prop_assert!((got - w).norm() <= 16.0 * EPS * w.norm());
    }
}

#[test]
fn overflowing_results_are_typed_errors() {
    // ṘRᵀ with Ṙ of entries ±f64::MAX and R the eighth turn about z: Ω₁₀ = −Ω₀₁ = √2·MAX.
    let r = Rotation3::from_axis_angle(&Vector3::z_axis(), std::f64::consts::FRAC_PI_4);
    let m = f64::MAX;
    let r_dot = Matrix3::new(-m, -m, 0.0, m, -m, 0.0, 0.0, 0.0, 0.0);
    assert!(matches!(
        angular_velocity_from_rate(&r, &r_dot),
        Err(KinematicsError::NonFiniteResult { .. })
    ));
    // ω = E·rates with proper Euler angles at b = 0: ω_z = ȧ + ċ = 2e308.
    let rates = [1e308, 0.0, 1e308];
    assert!(matches!(
        angular_velocity_from_euler_rates(EulerSequence::Zyz, &[0.0; 3], &rates, AngularVelocityFrame::Fixed),
        Err(KinematicsError::NonFiniteResult { .. })
    ));
    // …while a large but representable result comes out exactly.
    let omega = angular_velocity_from_euler_rates(
        EulerSequence::Zyz,
        &[0.0; 3],
        &[1e308, 0.0, 0.0],
        AngularVelocityFrame::Fixed,
    )
    .expect("representable");
    assert_eq!(omega, Vector3::new(0.0, 0.0, 1e308));
    // Relative motion: a relative position of 1e308 in a frame 1e308 away.
    let frame = RigidMotion::new(
        Rotation3::identity(),
        Vector3::new(1e308, 0.0, 0.0),
        Vector3::zeros(),
        Vector3::zeros(),
        Vector3::zeros(),
        Vector3::zeros(),
    )
    .expect("finite");
    let rel = RelativeMotion {
        xi: Vector3::new(1e308, 0.0, 0.0),
        xi_dot: Vector3::zeros(),
        xi_ddot: Vector3::zeros(),
    };
    assert!(matches!(
        decompose(&frame, &rel),
        Err(KinematicsError::NonFiniteResult { quantity: "position" })
    ));
}

#[test]
fn a_tree_whose_positions_overflow_reports_it_and_keeps_no_stale_stage() {
    let mut builder = TreeBuilder::new();
    let root = builder.add_body(
        None,
        Joint::Prismatic { axis: Vector3::x() },
        Isometry3::translation(1e308, 0.0, 0.0),
    );
    builder.add_body(Some(root), Joint::Spherical, Isometry3::identity());
    let tree = builder.build().expect("valid tree");
    let mut ws = tree.workspace();
    tree.update_positions(&mut ws, &[1.0, 0.1, 0.2, 0.3])
        .expect("representable");
    assert!(matches!(
        tree.update_positions(&mut ws, &[1e308, 0.1, 0.2, 0.3]),
        Err(KinematicsError::NonFiniteResult {
            quantity: "body position"
        })
    ));
    assert!(matches!(ws.position(0), Err(KinematicsError::WorkspaceNotReady { .. })));
    assert!(matches!(
        tree.update_positions(&mut ws, &[1.0, 1e300, 0.0, 0.0]),
        Err(KinematicsError::RotationAngleUnresolved { .. })
    ));
}

/// A random tree (every joint type, 1–6 bodies, placements up to 2 m) and a random (q, q̇, q̈).
fn far_tree(seed: u64) -> (mechanica_kinematics::tree::KinematicTree, Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut state = seed | 1;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut builder = TreeBuilder::new();
    let bodies = 1 + (next() * 6.0) as usize;
    for i in 0..bodies {
        let parent = (i > 0).then(|| (next() * i as f64) as usize);
        let axis = Vector3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize();
        let joint = match (next() * 6.0) as usize {
            0 => Joint::Revolute { axis },
            1 => Joint::Prismatic { axis },
            2 => Joint::Spherical,
            3 => Joint::Free,
            4 => Joint::Planar,
            _ => Joint::Fixed,
        };
        let rotation = Rotation3::from_scaled_axis(Vector3::new(next(), next(), next()) * 3.0);
        let offset = Vector3::new(next() - 0.5, next() - 0.5, next() - 0.5) * 4.0;
        builder.add_body(parent, joint, Isometry3::from_parts(offset.into(), rotation.into()));
    }
    let tree = builder.build().expect("valid tree");
    let n = tree.dof();
    let mut sample = |scale: f64| (0..n).map(|_| (next() - 0.5) * scale).collect::<Vec<f64>>();
    let (q, q_dot, q_ddot) = (sample(2.0), sample(4.0), sample(4.0));
    (tree, q, q_dot, q_ddot)
}

proptest! {
    /// Moving a whole mechanism 1e6…1e28 m from the world origin (by its base) changes no point
    /// Jacobian, no
    /// Jacobian rate and no body velocity or acceleration beyond the rounding of the lever
    /// arms (a few metres): the levers are summed from relative offsets, not formed as
    /// differences of world positions (whose rounding would be 1e-16 × 1e28 = 1e12 m).
    #[test]
    fn a_mechanism_far_from_the_origin_keeps_its_jacobians(seed in any::<u64>(), exponent in 6.0f64..28.0) {
        let (tree, q, q_dot, q_ddot) = far_tree(seed);
        let n = tree.dof();
        let shift = Vector3::new(0.6, -0.48, 0.64) * 10f64.powf(exponent);
        let evaluate = |base_position: Vector3<f64>| {
            let mut ws = tree.workspace();
            let base = mechanica_kinematics::tree::BaseState { position: base_position, ..Default::default() };
            ws.set_base(base).expect("base");
            tree.update_positions(&mut ws, &q).expect("positions");
            tree.update_velocities(&mut ws, &q_dot).expect("velocities");
            tree.update_accelerations(&mut ws, &q_ddot).expect("accelerations");
            let point = Vector3::new(0.3, -0.2, 0.5);
            let mut out = Vec::new();
            for body in 0..tree.body_count() {
                let (mut j, mut jd) = (vec![0.0; 3 * n], vec![0.0; 3 * n]);
                tree.point_jacobian(&ws, body, &point, &mut j).expect("Jacobian");
                tree.point_jacobian_rate(&ws, body, &point, &mut jd).expect("Jacobian rate");
                out.extend(j);
                out.extend(jd);
                out.extend(ws.point_velocity(body, &point).expect("velocity").iter());
                out.extend(ws.point_acceleration(body, &point).expect("acceleration").iter());
            }
            out
        };
        let (near, far) = (evaluate(Vector3::zeros()), evaluate(shift));
        let scale = near.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        for (k, (a, b)) in near.iter().zip(&far).enumerate() {
            prop_assert!((a - b).abs() <= 1e-12 * scale, "entry {}: {} near, {} far ({:e} m)", k, a, b, shift.norm());
        }
    }
}
