//! Tests of the quadratic eigensolver against closed forms evaluated in double-double from the
//! stored coefficients (single oscillators, proportional damping on graded spring trees,
//! gyroscopes), the condensed symmetric pencil (massless coordinates), and an independent
//! double-double residual (random non-symmetric C).

use super::*;
use crate::dd::Dd;
use crate::linalg::powers_of_two::{exponent, times_power_of_two};
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
fn assert_contained(
    modes: &QuadraticModes,
    reference: &[c64],
    slack: impl Fn(&QuadraticEigenvalue, c64) -> f64,
    context: &str,
) {
    let finite: Vec<&QuadraticEigenvalue> = modes.eigenvalues.iter().filter(|e| e.s.is_some()).collect();
    assert_eq!(
        finite.len(),
        reference.len(),
        "{context}: {modes:#?}\nreference {reference:?}"
    );
    let near = |e: &QuadraticEigenvalue, z: c64| e.s.is_some_and(|s| (s - z).norm() <= e.error_bound + slack(e, z));
    for e in &finite {
        assert!(
            reference.iter().any(|&z| near(e, z)),
            "{context}: {e:?} contains none of {reference:?}"
        );
    }
    for &z in reference {
        assert!(
            finite.iter().any(|e| near(e, z)),
            "{context}: {z} is in no bound of {finite:#?}"
        );
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
            } else if j == 0 {
                // c = 2√(mk) rounded: the roots are within about √u·ω of a double root, which
                // no bound from a backward error near u can separate.
                Some(QuadraticModeKind::Critical)
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
    let sum_bound: f64 = mode
        .eigenvalues
        .iter()
        .map(|&i| result.eigenvalues[i].error_bound)
        .sum();
    let allowance = sum_bound / (2.0 * omega_n) + zeta * (relative / 2.0 + 8.0 * UNIT_ROUNDOFF);
    assert!(
        (ratio - zeta).abs() <= allowance,
        "{context}: ζ {ratio:e} vs {zeta:e}, allowance {allowance:e}"
    );
}

/// Proportional damping C = αA + βB on graded spring trees (masses over 8 decades,
/// stiffnesses over 12, root fixed): each ω² of (A, B) gives s² + (α + βω²)s + ω² = 0, i.e.
/// s = −ζω ± iω√(1 − ζ²) with ζ = (α/ω + βω)/2, two real roots when ζ > 1. The ω² are the
/// double-double bisection spectrum of the stored A, B. α and β are powers of two; with only
/// one of them C is exactly proportional, with both its rounding (|δC| ≤ u|C|) moves s by at
/// most u κ |s| more, which the check allows.
#[test]
fn proportional_damping_on_graded_trees_matches_the_closed_form() {
    let mut rng = SplitMix::new(0x9a0d_ed01);
    let (mut underdamped, mut overdamped) = (0, 0);
    for seed in 0..36_u64 {
        let n = 2 + rng.below(18);
        let shape = if rng.below(2) == 0 { Shape::Chain } else { Shape::Tree };
        let system = spring_tree(&GradedFamily::new(n, shape, true), seed);
        let spectrum = tree_pencil_spectrum(&system);
        let middle = (spectrum[0] * spectrum[n - 1]).sqrt().sqrt();
        let power = |x: f64| 2f64.powi(x.log2().round() as i32);
        let variant = seed % 3;
        let alpha = if variant == 1 {
            0.0
        } else {
            power(middle * 10f64.powf(rng.uniform(-3.0, 1.0)))
        };
        let beta = if variant == 0 {
            0.0
        } else {
            power(10f64.powf(rng.uniform(-3.0, 1.0)) / middle)
        };
        let c = Mat::from_fn(n, n, |i, j| alpha * system.a[(i, j)] + beta * system.b[(i, j)]);
        let result = solve_dense(&system.a, &c, &system.b, false);
        let mut reference = Vec::new();
        for &omega_sq in &spectrum {
            let damping = Dd::of(alpha).plus(Dd::of(beta).times(Dd::of(omega_sq)));
            reference.extend(quadratic_roots(Dd::of(1.0), damping, Dd::of(omega_sq)));
        }
        let rounded_c = variant == 2;
        let slack = |e: &QuadraticEigenvalue, z: c64| {
            let c_rounding = if rounded_c {
                UNIT_ROUNDOFF * e.condition.unwrap_or(f64::INFINITY) * z.norm()
            } else {
                0.0
            };
            4.0 * UNIT_ROUNDOFF * z.norm() + c_rounding
        };
        let context = format!("seed {seed}, n {n}, α {alpha:e}, β {beta:e}");
        assert_contained(&result, &reference, slack, &context);
        for mode in &result.modes {
            match mode.kind {
                QuadraticModeKind::Underdamped => underdamped += 1,
                QuadraticModeKind::Overdamped => overdamped += 1,
                _ => {}
            }
        }
        assert!(
            result.max_backward_error <= 64.0 * n as f64 * UNIT_ROUNDOFF,
            "{context}: {result:#?}"
        );
    }
    assert!(
        underdamped > 50 && overdamped > 50,
        "{underdamped} underdamped, {overdamped} overdamped modes"
    );
}

/// A spinning rotor (Jeffcott/gyroscope): m s² I + s G + k I with G = [[0, −g], [g, 0]] has
/// s = ±i(√(h² + k/m) ± h), h = g/(2m), all on the imaginary axis; with k < 0 and g² > 4m|k| the
/// rotor is gyroscopically stabilized. m, g, k over many decades; the closed form in
/// double-double from the stored values.
#[test]
fn gyroscopes_have_their_closed_form_eigenvalues_on_the_imaginary_axis() {
    let mut rng = SplitMix::new(0x6e05_c09e);
    for case in 0..200 {
        let m = 10f64.powf(rng.uniform(-100.0, 100.0));
        let omega0 = 10f64.powf(rng.uniform(-60.0, 60.0));
        let stabilized = case % 2 == 1;
        let (k, g) = if stabilized {
            (
                -m * omega0 * omega0,
                2.0 * m * omega0 * (1.0 + 10f64.powf(rng.uniform(-2.0, 3.0))),
            )
        } else {
            (m * omega0 * omega0, m * omega0 * 10f64.powf(rng.uniform(-4.0, 4.0)))
        };
        let a = Mat::from_fn(2, 2, |i, j| if i == j { m } else { 0.0 });
        let gyro = Mat::from_fn(2, 2, |i, j| match (i, j) {
            (0, 1) => -g,
            (1, 0) => g,
            _ => 0.0,
        });
        let b = Mat::from_fn(2, 2, |i, j| if i == j { k } else { 0.0 });
        let result = solve_dense(&a, &gyro, &b, false);
        let h = Dd::of(g).over(Dd::of(2.0 * m));
        let stiffness = Dd::of(k).over(Dd::of(m));
        let w = dd_sqrt(h.times(h).plus(stiffness));
        let fast = w.plus(h);
        let slow = stiffness.over(fast);
        let reference: Vec<c64> = [fast.to_f64(), slow.to_f64()]
            .iter()
            .flat_map(|&v| [c64::new(0.0, v), c64::new(0.0, -v)])
            .collect();
        let context = format!("m {m:e}, g {g:e}, k {k:e}");
        assert_contained(&result, &reference, |_, z| 4.0 * UNIT_ROUNDOFF * z.norm(), &context);
        assert_eq!(result.modes.len(), 2, "{context}");
        for mode in &result.modes {
            assert_eq!(mode.kind, QuadraticModeKind::Neutral, "{context}: {result:#?}");
        }
    }
}

/// Graded spring trees with one massless coordinate and no damping: two infinite eigenvalues
/// (a 2 × 2 Jordan block at s = ∞), and s = ±iω for every ω² of the pencil with that
/// coordinate condensed out, taken from the symmetric modal solver with its own bounds.
#[test]
fn a_massless_coordinate_gives_infinite_eigenvalues_and_the_condensed_modes() {
    let mut rng = SplitMix::new(0x3a55_1e55);
    for seed in 0..30_u64 {
        let n = 3 + rng.below(12);
        let mut system = spring_tree(&GradedFamily::new(n, Shape::Tree, true), seed);
        let massless = rng.below(n);
        system.a[(massless, massless)] = 0.0;
        let problem = crate::PencilProblem::new(system.a.as_ref(), system.b.as_ref()).expect("pencil");
        let modal = crate::solve(&problem, &crate::SolveOptions::default()).expect("modal solve");
        let result = solve_dense(&system.a, &Mat::zeros(n, n), &system.b, false);
        let context = format!("seed {seed}, n {n}, massless {massless}");
        let infinite = result
            .modes
            .iter()
            .filter(|m| m.kind == QuadraticModeKind::Infinite)
            .count();
        assert_eq!(infinite, 2, "{context}: {result:#?}");
        let mut reference = Vec::new();
        let mut omega_bound = Vec::new();
        for mode in modal.modes.iter().filter(|m| m.kind != crate::ModeKind::Infinite) {
            let omega = mode.omega_sq.sqrt();
            reference.extend([c64::new(0.0, omega), c64::new(0.0, -omega)]);
            omega_bound.extend([mode.error_bound / omega; 2]);
        }
        let slack = |_: &QuadraticEigenvalue, z: c64| {
            let k = reference.iter().position(|&r| r == z).unwrap_or(0);
            omega_bound[k] + 4.0 * UNIT_ROUNDOFF * z.norm()
        };
        assert_contained(&result, &reference, slack, &context);
        for mode in result.modes.iter().filter(|m| m.kind != QuadraticModeKind::Infinite) {
            assert_eq!(mode.kind, QuadraticModeKind::Neutral, "{context}: {result:#?}");
        }
    }
}

/// A random n × n matrix with entries uniform in [−1, 1) times `scale`.
fn random_matrix(rng: &mut SplitMix, n: usize, scale: f64) -> Mat<f64> {
    Mat::from_fn(n, n, |_, _| scale * rng.uniform(-1.0, 1.0))
}

/// The relative residuals ‖P̃(a, b)x‖/(H‖x‖) and ‖y*P̃(a, b)‖/(H‖y‖) of every eigenpair the
/// linearization returns, on random problems with non-symmetric A, C, B: the left vectors are
/// read in faer's convention for conjugate pairs.
#[test]
fn left_and_right_vectors_of_the_linearization_annihilate_the_polynomial() {
    let mut rng = SplitMix::new(0x1ef7);
    for case in 0..40 {
        let n = 1 + rng.below(12);
        let a = random_matrix(&mut rng, n, 1.0);
        let (c_scale, b_scale) = (10f64.powf(rng.uniform(-2.0, 2.0)), 10f64.powf(rng.uniform(-3.0, 3.0)));
        let c = random_matrix(&mut rng, n, c_scale);
        let b = random_matrix(&mut rng, n, b_scale);
        let p = scaling::ScaledProblem::new(a.as_ref(), c.as_ref(), b.as_ref()).expect("scaled");
        for pair in linearize::solve_companion(&p).expect("QZ") {
            let (s, t) = (pair.a, pair.b);
            let poly = Mat::from_fn(n, n, |i, j| {
                s * s * p.a[(i, j)] + s * t * p.c[(i, j)] + p.b[(i, j)] * (t * t)
            });
            let h = s.norm_sqr() * p.norm_a + s.norm() * t * p.norm_c + t * t * p.norm_b;
            let right: f64 = (0..n)
                .map(|i| (0..n).map(|j| poly[(i, j)] * pair.x[j]).sum::<c64>().norm_sqr())
                .sum::<f64>()
                .sqrt();
            let left: f64 = (0..n)
                .map(|j| (0..n).map(|i| pair.y[i].conj() * poly[(i, j)]).sum::<c64>().norm_sqr())
                .sum::<f64>()
                .sqrt();
            let (xn, yn) = (
                pair.x.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt(),
                pair.y.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt(),
            );
            let tolerance = 64.0 * n as f64 * UNIT_ROUNDOFF;
            assert!(
                right <= tolerance * h * xn,
                "case {case}: right residual {:e}",
                right / (h * xn)
            );
            assert!(
                left <= tolerance * h * yn,
                "case {case}: left residual {:e}",
                left / (h * yn)
            );
        }
    }
}

/// ‖(s²A + sC + B)x‖ of a reported pair in double-double from the stored matrices.
fn residual_dd(a: &Mat<f64>, c: &Mat<f64>, b: &Mat<f64>, s: c64, x: &[c64]) -> f64 {
    let (re, im): (Vec<f64>, Vec<f64>) = x.iter().map(|z| (z.re, z.im)).unzip();
    let product = |m: &Mat<f64>| (crate::dd::mat_vec(m.as_ref(), &re), crate::dd::mat_vec(m.as_ref(), &im));
    let ((ar, ai), (cr, ci), (br, bi)) = (product(a), product(c), product(b));
    let (sr, si) = (Dd::of(s.re), Dd::of(s.im));
    let (qr, qi) = (sr.times(sr).minus(si.times(si)), Dd::of(2.0).times(sr).times(si));
    (0..x.len())
        .map(|i| {
            let real = qr
                .times(ar[i])
                .minus(qi.times(ai[i]))
                .plus(sr.times(cr[i]))
                .minus(si.times(ci[i]))
                .plus(br[i]);
            let imag = qr
                .times(ai[i])
                .plus(qi.times(ar[i]))
                .plus(sr.times(ci[i]))
                .plus(si.times(cr[i]))
                .plus(bi[i]);
            real.to_f64().powi(2) + imag.to_f64().powi(2)
        })
        .sum::<f64>()
        .sqrt()
}

/// Random A, B (SPD and indefinite) of random scales and random non-symmetric C with
/// τ = ‖C‖/√(‖A‖‖B‖) from 1e-3 to 1e8: the backward error of every returned pair, recomputed
/// in double-double from the stored matrices, is at most the reported η. For τ ≤ 10, where
/// the scaled linearization is backward stable for the quadratic problem (Higham, Li & Tisseur
/// 2007), η ≤ 64 n u; beyond, the small eigenvalues may lose accuracy (their η and bounds say
/// so), and only the first claim is checked.
#[test]
fn backward_errors_bound_the_true_residuals_on_random_nonsymmetric_damping() {
    let mut rng = SplitMix::new(0xbacc_e77a);
    let (mut worst_balanced, mut worst_heavy): (f64, f64) = (0.0, 0.0);
    for case in 0..80 {
        let n = 1 + rng.below(16);
        let (scale_a, scale_b) = (
            10f64.powf(rng.uniform(-40.0, 40.0)),
            10f64.powf(rng.uniform(-40.0, 40.0)),
        );
        let tau = 10f64.powf(if case % 2 == 0 {
            rng.uniform(-3.0, 1.0)
        } else {
            rng.uniform(1.0, 8.0)
        });
        let root = random_matrix(&mut rng, n, 1.0);
        let a = Mat::from_fn(n, n, |i, j| {
            scale_a * (0..n).map(|k| root[(k, i)] * root[(k, j)]).sum::<f64>()
        });
        let b = random_matrix(&mut rng, n, scale_b);
        let b = Mat::from_fn(n, n, |i, j| b[(i, j)] + b[(j, i)]);
        let c = random_matrix(&mut rng, n, 1.0);
        let c_scale = tau * (a.norm_l2() * b.norm_l2()).sqrt() / c.norm_l2();
        let c = Mat::from_fn(n, n, |i, j| c[(i, j)] * c_scale);
        let result = solve_dense(&a, &c, &b, true);
        let x = result.vectors.as_ref().expect("vectors");
        assert_eq!(result.eigenvalues.len(), 2 * n);
        let norms = [a.norm_l2(), c.norm_l2(), b.norm_l2()];
        for (k, e) in result.eigenvalues.iter().enumerate() {
            let Some(s) = e.s else { continue };
            let column: Vec<c64> = (0..n).map(|r| x[(r, k)]).collect();
            let denominator = s.norm_sqr() * norms[0] + s.norm() * norms[1] + norms[2];
            let eta = residual_dd(&a, &c, &b, s, &column) / denominator;
            assert!(
                eta <= e.backward_error,
                "case {case}: true η {eta:e} > reported {:e}",
                e.backward_error
            );
            let relative = e.backward_error / (n as f64 * UNIT_ROUNDOFF);
            if tau <= 10.0 {
                worst_balanced = worst_balanced.max(relative);
                assert!(relative <= 64.0, "case {case}, τ {tau:e}: {e:?}");
            } else {
                worst_heavy = worst_heavy.max(relative);
            }
        }
    }
    println!("largest η/(n u): {worst_balanced:.1} for τ ≤ 10, {worst_heavy:.3e} for τ > 10");
}

#[test]
fn bad_inputs_are_typed_errors() {
    let (a, c, b) = (
        Mat::<f64>::identity(2, 2),
        Mat::<f64>::zeros(2, 2),
        Mat::<f64>::identity(2, 2),
    );
    let options = QuadraticOptions::default();
    let mut nan = b.clone();
    nan[(1, 0)] = f64::NAN;
    assert!(matches!(
        quadratic_modes(a.as_ref(), c.as_ref(), nan.as_ref(), &options),
        Err(ModalError::NonFinite {
            what: "B",
            row: 1,
            col: 0,
            ..
        })
    ));
    let wide = Mat::<f64>::zeros(2, 3);
    assert!(matches!(
        quadratic_modes(a.as_ref(), wide.as_ref(), b.as_ref(), &options),
        Err(ModalError::BadShape { what: "C", .. })
    ));
    let zero = Mat::<f64>::zeros(2, 2);
    assert!(matches!(
        quadratic_modes(zero.as_ref(), zero.as_ref(), zero.as_ref(), &options),
        Err(ModalError::SingularQuadratic { order: 2 })
    ));
    // A, C, B share the null vector e₂: det ≡ 0.
    let shared = Mat::from_fn(2, 2, |i, j| if i == 0 && j == 0 { 1.0 } else { 0.0 });
    assert!(matches!(
        quadratic_modes(shared.as_ref(), shared.as_ref(), shared.as_ref(), &options),
        Err(ModalError::SingularQuadratic { .. })
    ));
    let spread = Mat::from_fn(2, 2, |i, j| if i == j { [1e300, 1e-300][i] } else { 0.0 });
    assert!(matches!(
        quadratic_modes(spread.as_ref(), c.as_ref(), b.as_ref(), &options),
        Err(ModalError::OutOfRange { .. })
    ));
    let empty = Mat::<f64>::zeros(0, 0);
    let none = quadratic_modes(empty.as_ref(), empty.as_ref(), empty.as_ref(), &options).expect("order 0");
    assert!(none.eigenvalues.is_empty() && none.modes.is_empty());
}

/// A mass m on a spring k₁ to the ground, joined by a spring k₂ to a massless node that a
/// damper c ties to the ground: det = (ms² + k₁ + k₂)(cs + k₂) − k₂², a cubic, so one
/// eigenvalue is infinite (simple: the damper gives the massless node a first-order law). The
/// real root lies in (−k₂/c, 0) and is found by bisection in double-double; the other two are
/// the roots of the quotient quadratic.
#[test]
fn a_damped_massless_node_gives_one_infinite_eigenvalue_and_the_cubic_roots() {
    let mut rng = SplitMix::new(0xc0b1c);
    for case in 0..100 {
        let [m, c, k1, k2] = [0; 4].map(|_| 10f64.powf(rng.uniform(-3.0, 3.0)));
        let a = Mat::from_fn(2, 2, |i, j| if (i, j) == (0, 0) { m } else { 0.0 });
        let damping = Mat::from_fn(2, 2, |i, j| if (i, j) == (1, 1) { c } else { 0.0 });
        let b = Mat::from_fn(2, 2, |i, j| if i == j { [k1 + k2, k2][i] } else { -k2 });
        let result = solve_dense(&a, &damping, &b, false);
        let (m_, c_, k11, k2_) = (Dd::of(m), Dd::of(c), Dd::of(b[(0, 0)]), Dd::of(k2));
        // (m s² + k11)(c s + k2) − k2² = mc s³ + m k2 s² + c k11 s + (k11 k2 − k2²).
        let coefficients = [
            m_.times(c_),
            m_.times(k2_),
            c_.times(k11),
            k11.times(k2_).minus(k2_.times(k2_)),
        ];
        let cubic = |s: Dd| {
            coefficients[1..]
                .iter()
                .fold(coefficients[0], |acc, &next| acc.times(s).plus(next))
        };
        let (mut low, mut high) = (Dd::of(-k2 / c * 1.0000001), Dd::of(0.0));
        for _ in 0..200 {
            let middle = low.plus(high).times(Dd::of(0.5));
            if cubic(middle).hi < 0.0 {
                low = middle
            } else {
                high = middle
            }
        }
        let real = low;
        // Synthetic division by (s − real).
        let p = coefficients[0];
        let q = coefficients[1].plus(p.times(real));
        let t = coefficients[2].plus(q.times(real));
        let mut reference = vec![c64::new(real.to_f64(), 0.0)];
        reference.extend(quadratic_roots(p, q, t));
        let context = format!("case {case}: m {m:e}, c {c:e}, k₁ {k1:e}, k₂ {k2:e}");
        assert_contained(&result, &reference, |_, z| 8.0 * UNIT_ROUNDOFF * z.norm(), &context);
        let infinite = result
            .modes
            .iter()
            .filter(|m| m.kind == QuadraticModeKind::Infinite)
            .count();
        assert_eq!(infinite, 1, "{context}: {result:#?}");
    }
}
