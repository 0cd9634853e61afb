//! Tests of the quadratic eigensolver against closed forms evaluated in double-double from the
//! stored coefficients (single oscillators, proportional damping on graded spring trees,
//! gyroscopes), the condensed symmetric pencil (massless coordinates), and an independent
//! double-double residual (random non-symmetric C).

use super::*;
use crate::dd::{self, Dd};
use crate::dense::scaling::{exponent, times_power_of_two};
use crate::testing::graded::{GradedFamily, Shape, SplitMix, spring_tree, tree_pencil_spectrum};

const UNIT_ROUNDOFF: f64 = f64::EPSILON / 2.0;

/// √x in double-double (one Newton step from the double root), 0 for x ≤ 0.
fn dd_sqrt(x: Dd) -> Dd {
    if x.hi <= 0.0 {
        return Dd::of(0.0);
    }
    let root = Dd::of(x.hi.sqrt());
    root.plus(x.minus(root.times(root)).over(Dd::of(2.0 * x.hi.sqrt())))
}

/// The roots of p s² + q s + r (p > 0, q ≥ 0, r > 0), discriminant and root in double-double,
/// the real pair without cancellation (s₂ = r/(p s₁)); each within a few units of roundoff.
fn quadratic_roots(p: Dd, q: Dd, r: Dd) -> [c64; 2] {
    assert!(p.hi > 0.0 && q.hi >= 0.0 && r.hi > 0.0);
    let discriminant = q.times(q).minus(Dd::of(4.0).times(p).times(r));
    let two_p = Dd::of(2.0).times(p);
    if discriminant.hi >= 0.0 {
        let s1 = Dd::of(0.0).minus(q).minus(dd_sqrt(discriminant)).over(two_p);
        let s2 = r.over(p.times(s1));
        [c64::new(s1.to_f64(), 0.0), c64::new(s2.to_f64(), 0.0)]
    } else {
        let re = Dd::of(0.0).minus(q).over(two_p).to_f64();
        let im = dd_sqrt(Dd::of(0.0).minus(discriminant)).over(two_p).to_f64();
        [c64::new(re, im), c64::new(re, -im)]
    }
}

/// Every finite reported eigenvalue lies within its bound (plus `slack`, the reference's own
/// uncertainty) of a reference root, and every reference root within a reported bound.
fn assert_contained(modes: &QuadraticModes, reference: &[c64], slack: impl Fn(&QuadraticEigenvalue, c64) -> f64, context: &str) {
    let finite: Vec<&QuadraticEigenvalue> = modes.eigenvalues.iter().filter(|e| e.s.is_some()).collect();
    assert_eq!(finite.len(), reference.len(), "{context}: {modes:#?}\nreference {reference:?}");
    let near = |e: &QuadraticEigenvalue, z: c64| e.s.is_some_and(|s| (s - z).norm() <= e.error_bound + slack(e, z));
    for e in &finite {
        assert!(
            reference.iter().any(|&z| near(e, z)),
            "{context}: {e:?} contains none of {reference:?}"
        );
    }
    for &z in reference {
        assert!(finite.iter().any(|e| near(e, z)), "{context}: {z} is in no bound of {finite:#?}");
    }
}

fn solve_dense(a: &Mat<f64>, c: &Mat<f64>, b: &Mat<f64>, vectors: bool) -> QuadraticModes {
    quadratic_modes(a.as_ref(), c.as_ref(), b.as_ref(), &QuadraticOptions { vectors }).expect("quadratic solve")
}

fn scalar(v: f64) -> Mat<f64> {
    Mat::from_fn(1, 1, |_, _| v)
}

/// m s² + c s + k: ζ = 10^(j/4), j = −24..24 (1e-6 to 1e6, 1 included), m and k at random
/// over 1e-150..1e150. The reference is the closed form of the stored m, c, k after the exact
/// substitution s = 2^g t and division by 2^e, in double-double.
#[test]
fn single_oscillators_match_the_closed_form_from_zeta_1e_minus_6_to_1e6() {
    let mut rng = SplitMix::new(0x05c1_11a7);
    for j in -24..=24 {
        let zeta = 10f64.powf(f64::from(j) / 4.0);
        for _ in 0..6 {
            let m = 10f64.powf(rng.uniform(-150.0, 150.0));
            let k = 10f64.powf(rng.uniform(-150.0, 150.0));
            let c = 2.0 * zeta * (m * k).sqrt();
            let context = format!("m {m:e}, c {c:e}, k {k:e}, ζ {zeta:e}");
            let result = solve_dense(&scalar(m), &scalar(c), &scalar(k), false);
            let g = ((k.log2() - m.log2()) / 2.0).round() as i32;
            let e = exponent(k);
            let t = quadratic_roots(
                Dd::of(times_power_of_two(m, 2 * g - e)),
                Dd::of(times_power_of_two(c, g - e)),
                Dd::of(times_power_of_two(k, -e)),
            );
            let reference = t.map(|t| c64::new(times_power_of_two(t.re, g), times_power_of_two(t.im, g)));
            assert_contained(&result, &reference, |_, z| 4.0 * UNIT_ROUNDOFF * z.norm(), &context);
            assert_eq!(result.modes.len(), 1, "{context}");
            let mode = &result.modes[0];
            let expected = if zeta <= 0.5 {
                Some(QuadraticModeKind::Underdamped)
            } else if zeta >= 2.0 {
                Some(QuadraticModeKind::Overdamped)
            } else {
                None
            };
            if let Some(kind) = expected {
                assert_eq!(mode.kind, kind, "{context}: {result:#?}");
            }
            check_frequency_and_ratio(&result, (k / m).sqrt(), zeta, &context);
        }
    }
}

/// ω_n and ζ of the only mode against √(k/m) and the ζ the damping was built from, within the
/// first-order propagation of the eigenvalue bounds (ω_n = √(s₁s₂), ζ = −(s₁ + s₂)/(2ω_n)) plus
/// the rounding of the inputs.
fn check_frequency_and_ratio(result: &QuadraticModes, omega: f64, zeta: f64, context: &str) {
    let mode = &result.modes[0];
    let relative: f64 = mode
        .eigenvalues
        .iter()
        .map(|&i| {
            let e = &result.eigenvalues[i];
            e.error_bound / e.s.map_or(f64::INFINITY, |s| s.norm())
        })
        .sum();
    let omega_n = mode.natural_frequency.expect("finite mode");
    assert!(
        (omega_n - omega).abs() <= omega * (relative / 2.0 + 8.0 * UNIT_ROUNDOFF),
        "{context}: ω_n {omega_n:e} vs {omega:e}, relative bound {relative:e}"
    );
    let ratio = mode.damping_ratio.expect("ω_n > 0");
    // Δ(s₁ + s₂) ≤ r₁ + r₂ and Δω_n/ω_n ≤ relative/2; the stored c carries ζ to within 8u.
    let sum_bound: f64 = mode.eigenvalues.iter().map(|&i| result.eigenvalues[i].error_bound).sum();
    let allowance = sum_bound / (2.0 * omega_n) + zeta * (relative / 2.0 + 8.0 * UNIT_ROUNDOFF);
    assert!(
        (ratio - zeta).abs() <= allowance,
        "{context}: ζ {ratio:e} vs {zeta:e}, allowance {allowance:e}"
    );
}
