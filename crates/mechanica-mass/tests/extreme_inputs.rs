//! Mass properties at the ends of the double range: exact scaling laws as the reference
//! (sizes and masses scaled by powers of two scale moments exactly by m·λ²), typed errors
//! where a result is not representable, and principal axes of any finite tensor.

use mechanica_kinematics::nalgebra::{Matrix3, Rotation3, Vector3};
use mechanica_mass::primitives::{self, Amount};
use mechanica_mass::principal::principal_axes;
use mechanica_mass::validity::{InertiaIssue, ValidityTolerance, check};
use mechanica_mass::{MassError, MassProperties};
use proptest::prelude::*;

type Primitive = fn(&[f64], Amount) -> Result<MassProperties, MassError>;

/// 2^e for any e the doubles can hold (subnormal results included), exactly.
fn pow2(e: i32) -> f64 {
    2f64.powi(e / 2) * 2f64.powi(e - e / 2)
}

/// Every primitive with dimensions of order one (the torus tube below its ring radius).
fn primitives() -> Vec<(&'static str, Primitive, Vec<f64>, i32)> {
    // (name, constructor, dimensions, dimension count of its measure: 1 line, 2 area, 3 volume)
    vec![
        ("rod", |d, a| primitives::rod(d[0], a), vec![1.3], 1),
        (
            "rectangle",
            |d, a| primitives::rectangle_lamina(d[0], d[1], a),
            vec![0.7, 1.9],
            2,
        ),
        ("disc", |d, a| primitives::disc_lamina(d[0], a), vec![0.8], 2),
        ("sphere", |d, a| primitives::sphere(d[0], a), vec![1.1], 3),
        (
            "ellipsoid",
            |d, a| primitives::ellipsoid(d[0], d[1], d[2], a),
            vec![0.5, 1.2, 2.0],
            3,
        ),
        (
            "box",
            |d, a| primitives::solid_box(d[0], d[1], d[2], a),
            vec![0.3, 1.7, 0.9],
            3,
        ),
        (
            "cylinder",
            |d, a| primitives::cylinder(d[0], d[1], a),
            vec![0.7, 2.5],
            3,
        ),
        ("cone", |d, a| primitives::cone(d[0], d[1], a), vec![0.5, 1.0], 3),
        ("capsule", |d, a| primitives::capsule(d[0], d[1], a), vec![0.7, 1.1], 3),
        ("torus", |d, a| primitives::torus(d[0], d[1], a), vec![2.0, 0.6], 3),
        ("hemisphere", |d, a| primitives::hemisphere(d[0], a), vec![1.3], 3),
    ]
}

proptest! {
    /// Parts whose masses are subnormal (k·2⁻¹⁰⁷⁴, k up to 1000) combine to the centre
    /// Σ kᵢ cᵢ / Σ kᵢ, and subtracting a part gives the others' centre back, to rounding: the
    /// weights are the masses over a power of two, so a mass of 5e-324 weighs 1, not 0 or 2.
    #[test]
    fn subnormal_masses_weigh_their_full_value(
        counts in proptest::collection::vec(1u32..1000, 2..6),
        centres in proptest::collection::vec(proptest::array::uniform3(-2.0f64..2.0), 6),
    ) {
        let tiny = f64::from_bits(1);
        let parts: Vec<MassProperties> = counts
            .iter()
            .zip(&centres)
            .map(|(k, c)| MassProperties::new(*k as f64 * tiny, Vector3::from(*c), Matrix3::identity()).expect("valid part"))
            .collect();
        let weighted = |parts: &[MassProperties]| {
            let total: f64 = parts.iter().map(|p| p.mass / tiny).sum();
            parts.iter().map(|p| p.p_oc * (p.mass / tiny)).sum::<Vector3<f64>>() / total
        };
        let sum = MassProperties::sum(&parts).expect("sum");
        prop_assert!((sum.p_oc - weighted(&parts)).amax() <= 1e-14, "{} vs {}", sum.p_oc, weighted(&parts));
        let rest = sum.subtract(&parts[0]).expect("rest");
        let want = weighted(&parts[1..]);
        prop_assert!((rest.p_oc - want).amax() <= 1e-11, "{} vs {}", rest.p_oc, want);
    }

    /// T(2^a m, 2^b v, 2^c ω, 2^d J) = 2^(a+2b) ½ m v² + 2^(d+2c) ½ ωᵀJω for a body of order
    /// one: the energy of a scaled body is the scaled energy (to a few ulps) whenever each
    /// term is a normal number, although |v|², ω² or J ω may underflow or overflow on the way
    /// (a 1e70 kg body at 1e-160 m/s has T = 1e-250, which a plain ½ m v·v returns as 0).
    #[test]
    fn kinetic_energy_is_homogeneous_over_the_range(
        e_v in -1000i32..1000, b in -1000i32..1000, e_w in -1000i32..1000, c in -1000i32..1000,
        v in proptest::array::uniform3(-1.0f64..1.0), w in proptest::array::uniform3(-1.0f64..1.0),
        moments in proptest::array::uniform3(0.6f64..1.0), axis in proptest::array::uniform3(-3.0f64..3.0),
    ) {
        let (v, w) = (Vector3::from(v), Vector3::from(w));
        let r = Rotation3::from_scaled_axis(Vector3::from(axis));
        let j = r.matrix() * Matrix3::from_diagonal(&Vector3::from(moments)) * r.matrix().transpose();
        let (t_v, t_w) = (0.5 * 0.7 * v.norm_squared(), 0.5 * w.dot(&(j * w)));
        let scale = |x: f64, e: i32| x * pow2(e / 2) * pow2(e - e / 2);
        let (a, d) = (e_v - 2 * b, e_w - 2 * c);
        prop_assume!((-1020..=1020).contains(&a) && (-1020..=1020).contains(&d));
        let (want_v, want_w) = (scale(t_v, e_v), scale(t_w, e_w));
        let normal = |x: f64| x == 0.0 || (x.abs() >= f64::MIN_POSITIVE && x.is_finite());
        prop_assume!(normal(want_v) && normal(want_w) && (want_v + want_w).is_finite());
        let body = MassProperties::new(0.7 * pow2(a), Vector3::zeros(), j * pow2(d)).expect("valid body");
        let got = body.kinetic_energy(&(v * pow2(b)), &(w * pow2(c)));
        let want = want_v + want_w;
        prop_assert!((got - want).abs() <= 1e-14 * want, "T = {:e}, want {:e}", got, want);
    }

    /// Dimensions scaled by λ = 2^k and the mass by 2^j: the moments are exactly 2^(j+2k) times
    /// those of the unit body (up to the few roundings of the closed form), or a typed error
    /// naming the moment when that is not representable.
    #[test]
    fn primitives_by_mass_scale_exactly_or_fail_typed(k in -560i32..560, j in -600i32..600, which in 0..11usize) {
        let (name, build, dims, _) = primitives()[which].clone();
        let unit = build(&dims, Amount::Mass(1.0)).expect("unit body");
        let lambda = pow2(k);
        let scaled: Vec<f64> = dims.iter().map(|d| d * lambda).collect();
        // unit·2^(j+2k), rounded once.
        let expected = unit.inertia_c.map(|x| x * pow2((j + 2 * k) / 2) * pow2(j + 2 * k - (j + 2 * k) / 2));
        match build(&scaled, Amount::Mass(2f64.powi(j))) {
            Ok(p) => {
                prop_assert!(expected.iter().all(|x| x.is_finite()), "{name}: Ok for an overflowing moment");
                for (got, want) in p.inertia_c.iter().zip(expected.iter()) {
                    // Subnormal results keep an absolute accuracy of a few smallest doubles.
                    prop_assert!((got - want).abs() <= 16.0 * f64::EPSILON * want.abs() + 1e-320, "{name}: {got} vs {want}");
                }
                prop_assert!((p.p_oc - unit.p_oc * lambda).norm() <= 4.0 * f64::EPSILON * (unit.p_oc * lambda).norm());
            }
            Err(MassError::NonFiniteResult { quantity }) => {
                prop_assert!(quantity.ends_with("moment of inertia"), "{name}: {quantity}");
                prop_assert!(expected.iter().any(|x| !x.is_finite()) || expected.amax() > 0.5 * f64::MAX, "{name}: {expected}");
            }
            Err(other) => prop_assert!(false, "{name}: {other}"),
        }
    }

    /// By density: m = ρ λ^d V₁ exactly, or MassUnderflow / NonFiniteResult("mass").
    #[test]
    fn primitives_by_density_scale_exactly_or_fail_typed(k in -400i32..400, j in -600i32..600, which in 0..11usize) {
        let (name, build, dims, dim) = primitives()[which].clone();
        let unit = build(&dims, Amount::Density(1.0)).expect("unit body");
        let lambda = pow2(k);
        let scaled: Vec<f64> = dims.iter().map(|d| d * lambda).collect();
        let e = j + dim * k;
        let mass = unit.mass * pow2(e / 2) * pow2(e - e / 2);
        match build(&scaled, Amount::Density(2f64.powi(j))) {
            Ok(p) => prop_assert!((p.mass - mass).abs() <= 8.0 * f64::EPSILON * mass + 1e-320, "{name}: {} vs {mass}", p.mass),
            Err(MassError::MassUnderflow { .. }) => prop_assert!(mass < 1e-300, "{name}: {mass}"),
            Err(MassError::NonFiniteResult { quantity: "mass" }) => prop_assert!(mass > 1e300, "{name}: {mass}"),
            Err(MassError::NonFiniteResult { quantity }) => prop_assert!(quantity.ends_with("moment of inertia")),
            Err(other) => prop_assert!(false, "{name}: {other}"),
        }
    }

    /// J = s R diag(I) Rᵀ for s over the whole range: the principal moments are s·I sorted,
    /// the axes those of R, whatever the scale.
    #[test]
    fn principal_axes_of_any_finite_tensor(
        a in -3.0..3.0f64, b in -3.0..3.0f64, c in -3.0..3.0f64,
        i1 in 0.1..1.0f64, i2 in 0.1..1.0f64, k in -1000i32..1000,
    ) {
        let r = Rotation3::from_scaled_axis(Vector3::new(a, b, c));
        let moments = Vector3::new(i1, i2, i1 + i2);
        let s = 2f64.powi(k);
        let j = r.matrix() * Matrix3::from_diagonal(&moments) * r.matrix().transpose() * s;
        let j = j * 0.5 + j.transpose() * 0.5;
        let p = principal_axes(&j).expect("representable moments");
        let mut sorted = [i1, i2, i1 + i2];
        sorted.sort_by(f64::total_cmp);
        for (got, want) in p.moments.iter().zip(sorted) {
            prop_assert!((got - want * s).abs() <= 1e-13 * (i1 + i2) * s, "{got} vs {}", want * s);
        }
        prop_assert!(p.relative_residual <= 1e-12);
        let class = check(&MassProperties { mass: 1.0, p_oc: Vector3::zeros(), inertia_c: j }, &ValidityTolerance::default())
            .map(|report| report.class);
        let unit_class = check(&MassProperties { mass: 1.0, p_oc: Vector3::zeros(), inertia_c: j / s }, &ValidityTolerance::default())
            .map(|report| report.class);
        prop_assert_eq!(class, unit_class);
    }
}

#[test]
fn the_reported_cases() {
    // A sphere of radius 1e308 (by mass): its moment 0.4·m·r² is not representable.
    assert_eq!(
        primitives::sphere(1e308, Amount::Mass(1.0)),
        Err(MassError::NonFiniteResult {
            quantity: "sphere moment of inertia"
        })
    );
    // A tiny sphere by density: its mass underflows, and the message says so.
    let tiny = primitives::sphere(1e-120, Amount::Density(1.0));
    assert!(matches!(tiny, Err(MassError::MassUnderflow { .. })), "{tiny:?}");
    let message = tiny.expect_err("underflow").to_string();
    assert!(
        message.contains("underflows to zero") && !message.contains("not finite"),
        "{message}"
    );
    // The principal axes of a tensor with entries of 1e308 (its moments up to 3e308 would
    // overflow; these are representable): no NaN.
    let r = Rotation3::from_scaled_axis(Vector3::new(0.3, -1.2, 0.7));
    let j = r.matrix() * Matrix3::from_diagonal(&Vector3::new(0.5e308, 0.6e308, 1.1e308)) * r.matrix().transpose();
    let j = j * 0.5 + j.transpose() * 0.5;
    let p = principal_axes(&j).expect("representable");
    assert!((p.moments - Vector3::new(0.5e308, 0.6e308, 1.1e308)).amax() <= 1e-13 * 1.1e308);
    // Moments beyond f64::MAX: a typed error, not NaN.
    // All entries MAX/2 but the diagonal MAX: the largest moment is 2·MAX.
    let mut huge = Matrix3::repeat(f64::MAX / 2.0);
    huge.fill_diagonal(f64::MAX);
    assert_eq!(
        principal_axes(&huge),
        Err(MassError::NonFiniteResult {
            quantity: "principal moments"
        })
    );
    // An asymmetric tensor is refused with the asymmetry named.
    let mut asymmetric = Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, 2.5));
    asymmetric[(0, 1)] = 1e-3;
    assert_eq!(
        principal_axes(&asymmetric),
        Err(MassError::InvalidInertia(vec![InertiaIssue::NotSymmetric {
            row: 0,
            col: 1,
            difference: 1e-3
        }]))
    );
    // Within the tolerance (1e-9 of the trace) the symmetric part is decomposed.
    asymmetric[(0, 1)] = 1e-10;
    assert!(principal_axes(&asymmetric).is_ok());
}

/// Dimensions near f64::MAX with the smallest mass (m r² is then about 1e292): every primitive
/// either returns finite numbers, its centre of mass where the closed form puts it, or a typed
/// error. A hemisphere's centre 3r/8 was formed as 3r/8 and overflowed to ∞ above MAX/3.
#[test]
fn dimensions_near_the_largest_double_give_finite_results_or_typed_errors() {
    let tiny = f64::from_bits(1);
    for (name, build, dims, _) in primitives() {
        let largest = dims.iter().cloned().fold(0.0, f64::max);
        for top in [f64::MAX / 4.0, f64::MAX / 2.0, f64::MAX] {
            let scaled: Vec<f64> = dims.iter().map(|d| d / largest * top).collect();
            let unit = build(&dims, Amount::Mass(1.0)).expect("unit body");
            match build(&scaled, Amount::Mass(tiny)) {
                Ok(p) => {
                    assert!(p.mass == tiny, "{name}: mass {}", p.mass);
                    assert!(
                        p.p_oc.iter().chain(p.inertia_c.iter()).all(|x| x.is_finite()),
                        "{name} at {top:e}: {p:?}"
                    );
                    let centre = unit.p_oc / largest * top;
                    assert!(
                        (p.p_oc - centre).norm() <= 4.0 * f64::EPSILON * centre.norm(),
                        "{name}: {} vs {centre}",
                        p.p_oc
                    );
                }
                Err(MassError::NonFiniteResult { .. } | MassError::MassUnderflow { .. }) => {}
                Err(other) => panic!("{name} at {top:e}: {other}"),
            }
        }
    }
}

/// A tensor whose entries span 160 decades (fuzz target `abi_mass`): its repair is a physical
/// tensor (the triangle inequality holds to rounding), and the principal axes rebuild the
/// symmetric part to rounding. nalgebra's eigenvectors of such a matrix had norm 1.08.
#[test]
fn tensors_spanning_160_decades_repair_and_decompose_to_rounding() {
    let j = Matrix3::from_column_slice(&[
        -3.955078125e38,
        -3.765625e38,
        5e-324,
        5e-324,
        5e-324,
        5e-324,
        5e-324,
        6.0785776373046065e199,
        6.0785776373046065e199,
    ]);
    let props = MassProperties {
        mass: 1.0,
        p_oc: Vector3::zeros(),
        inertia_c: j,
    };
    let (repaired, _) = mechanica_mass::validity::repair(&props, &ValidityTolerance::default()).expect("repairable");
    assert!(
        check(&repaired, &ValidityTolerance::default()).is_ok(),
        "repaired tensor {:?} still fails the check",
        repaired.inertia_c
    );
    let sym = (j + j.transpose()) * 0.5;
    let axes = principal_axes(&sym).expect("symmetric");
    let rebuilt = axes.r_fp.matrix() * Matrix3::from_diagonal(&axes.moments) * axes.r_fp.matrix().transpose();
    assert!(
        (rebuilt - sym).amax() <= 1e-14 * sym.amax(),
        "R diag(I) Rᵀ = {rebuilt:?} against {sym:?}"
    );
}
