//! The free response (8.91) against direct numerical integration of A δ̈ + B δ = 0, and its
//! invariants (energy, time reversal, initial state) and bad input.
//!
//! Reference: classical Runge–Kutta (order 4) on y = (δ, δ̇), ẏ = (δ̇, −A⁻¹Bδ), run with steps h
//! and h/2 and Richardson-extrapolated; |y_{h/2} − y_h|/15 estimates the error of y_{h/2} and
//! bounds (generously) that of the extrapolation. A⁻¹B comes from a Cholesky solve in the test,
//! independent of the modal decomposition. Massless coordinates are eliminated in the test by an
//! explicit Schur complement on their indices.

use mechanica_modal::faer::prelude::Solve;
use mechanica_modal::faer::{Mat, Side};
use mechanica_modal::{
    CoordinateLaw, FreeResponse, ModalError, PencilProblem, Selection, SolveOptions, solve, testing,
};
use proptest::prelude::*;

const U: f64 = f64::EPSILON;

fn pencil(a: &Mat<f64>, b: &Mat<f64>) -> PencilProblem {
    PencilProblem::new(a.as_ref(), b.as_ref()).expect("valid pencil")
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

fn diff_norm(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt()
}

/// Deterministic pseudo-random vector in [−1, 1]ⁿ.
fn pseudo_random(n: usize, seed: u64) -> Vec<f64> {
    let mut s = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15).wrapping_add(1);
    (0..n)
        .map(|_| {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            2.0 * ((s >> 11) as f64 / (1u64 << 53) as f64) - 1.0
        })
        .collect()
}

/// M = A⁻¹B by a Cholesky solve (A positive definite).
fn stiffness_over_mass(a: &Mat<f64>, b: &Mat<f64>) -> Mat<f64> {
    let llt = a.llt(Side::Lower).expect("A positive definite");
    llt.solve(b)
}

/// RK4 for δ̈ = −Mδ with step h; returns δ at t = k·stride·h for k = 0..=samples.
fn rk4(m: &Mat<f64>, d0: &[f64], v0: &[f64], h: f64, stride: usize, samples: usize) -> Vec<Vec<f64>> {
    let n = d0.len();
    let accel = |d: &[f64]| -> Vec<f64> { (0..n).map(|i| -(0..n).map(|j| m[(i, j)] * d[j]).sum::<f64>()).collect() };
    let axpy = |x: &[f64], a: f64, y: &[f64]| -> Vec<f64> { x.iter().zip(y).map(|(p, q)| p + a * q).collect() };
    let (mut d, mut v) = (d0.to_vec(), v0.to_vec());
    let mut out = vec![d.clone()];
    for _ in 0..samples {
        for _ in 0..stride {
            let (k1d, k1v) = (v.clone(), accel(&d));
            let (d2, v2) = (axpy(&d, 0.5 * h, &k1d), axpy(&v, 0.5 * h, &k1v));
            let (k2d, k2v) = (v2.clone(), accel(&d2));
            let (d3, v3) = (axpy(&d, 0.5 * h, &k2d), axpy(&v, 0.5 * h, &k2v));
            let (k3d, k3v) = (v3.clone(), accel(&d3));
            let (d4, v4) = (axpy(&d, h, &k3d), axpy(&v, h, &k3v));
            let (k4d, k4v) = (v4, accel(&d4));
            for i in 0..n {
                d[i] += h / 6.0 * (k1d[i] + 2.0 * k2d[i] + 2.0 * k3d[i] + k4d[i]);
                v[i] += h / 6.0 * (k1v[i] + 2.0 * k2v[i] + 2.0 * k3v[i] + k4v[i]);
            }
        }
        out.push(d.clone());
    }
    out
}

/// Richardson-extrapolated RK4 samples at t_k = k·dt and their error estimates.
fn reference(
    m: &Mat<f64>,
    d0: &[f64],
    v0: &[f64],
    dt: f64,
    steps_per_sample: usize,
    samples: usize,
) -> Vec<(Vec<f64>, f64)> {
    let h = dt / steps_per_sample as f64;
    let coarse = rk4(m, d0, v0, h, steps_per_sample, samples);
    let fine = rk4(m, d0, v0, 0.5 * h, 2 * steps_per_sample, samples);
    coarse
        .iter()
        .zip(&fine)
        .map(|(c, f)| {
            let extrapolated: Vec<f64> = f.iter().zip(c).map(|(f, c)| f + (f - c) / 15.0).collect();
            (extrapolated, diff_norm(f, c) / 15.0)
        })
        .collect()
}

/// Compares the free response with the integrated reference at every sample. The tolerance is
/// the reference's own error estimate (×10), the response's stated error bound, and 10·n·u of
/// the larger of the two trajectories' norms times the condition √κ(A) of the A-orthonormal
/// shapes (the rounding of the projection and of the superposition).
fn compare(problem: &PencilProblem, m: &Mat<f64>, d0: &[f64], v0: &[f64], dt: f64, samples: usize) -> FreeResponse {
    let n = problem.dim();
    let response = FreeResponse::from_problem(problem, d0, v0).expect("free response");
    let fit = response.fit();
    assert!(fit.relative_displacement_residual <= 10.0 * n as f64 * U, "{fit:?}");
    assert!(fit.relative_velocity_residual <= 10.0 * n as f64 * U, "{fit:?}");
    let reference = reference(m, d0, v0, dt, 400, samples);
    let shape_condition = shape_condition(problem);
    for (k, (expected, estimate)) in reference.iter().enumerate() {
        let t = k as f64 * dt;
        let got = response.displacement(t).expect("finite response");
        let scale = norm(expected).max(norm(&got)).max(norm(d0));
        let tolerance =
            10.0 * estimate + response.error_bound(t).expect("bound") + 10.0 * n as f64 * U * shape_condition * scale;
        let error = diff_norm(&got, expected);
        assert!(
            error <= tolerance,
            "t = {t}: error {error:e} > tolerance {tolerance:e} (RK estimate {estimate:e})"
        );
    }
    response
}

/// √(λ_max(A)/λ_min(A)): the condition of A-orthonormal shapes as a basis.
fn shape_condition(problem: &PencilProblem) -> f64 {
    let s = problem.a().self_adjoint_eigenvalues(Side::Lower).expect("eigenvalues");
    (s[s.len() - 1] / s[0]).sqrt()
}

#[test]
fn rotated_graded_mass_chain_matches_integration() {
    let n = 8;
    let (_, b0) = testing::fixed_chain(n);
    let a0 = Mat::from_fn(n, n, |i, j| if i == j { 1.0 + 0.5 * i as f64 } else { 0.0 });
    let q = testing::random_orthogonal(n, 3);
    let (a, b) = testing::rotate(&a0, &b0, &q);
    let p = pencil(&a, &b);
    let response = compare(
        &p,
        &stiffness_over_mass(&a, &b),
        &pseudo_random(n, 1),
        &pseudo_random(n, 2),
        0.5,
        20,
    );
    assert!(
        response
            .coordinates()
            .iter()
            .all(|c| matches!(c.law, CoordinateLaw::Oscillatory { .. }))
    );
}

#[test]
fn free_chain_drifts_with_its_rigid_body_mode() {
    let n = 7;
    let (a, b) = testing::free_chain(n);
    let p = pencil(&a, &b);
    // A net velocity makes the rigid-body coordinate grow linearly.
    let v0: Vec<f64> = pseudo_random(n, 5).iter().map(|v| v + 0.3).collect();
    let d0 = pseudo_random(n, 6);
    let response = compare(&p, &stiffness_over_mass(&a, &b), &d0, &v0, 0.5, 20);
    let rigid = response.coordinates()[0];
    assert_eq!(rigid.law, CoordinateLaw::Linear);
    // The centre of mass moves at the mean velocity: q₀ = Σδ/√n, q̇₀ = Σv/√n.
    let mean_v = v0.iter().sum::<f64>() / n as f64;
    let centre = |t: f64| response.displacement(t).expect("finite").iter().sum::<f64>() / n as f64;
    let expected_drift = mean_v * 10.0;
    let drift = centre(10.0) - centre(0.0);
    assert!((drift - expected_drift).abs() <= 1e2 * n as f64 * U * (1.0 + expected_drift.abs()));
}

#[test]
fn inverted_chain_grows_at_its_rates() {
    // Springs minus a destabilising −1·I (an array of inverted pendulums): the two lowest modes
    // of tridiag(−1, 2, −1) − I have ω² = 4 sin²(kπ/14) − 1 < 0 (k = 1, 2).
    let n = 6;
    let (a, b0) = testing::fixed_chain(n);
    let b = Mat::from_fn(n, n, |i, j| b0[(i, j)] - if i == j { 1.0 } else { 0.0 });
    let p = pencil(&a, &b);
    let response = compare(
        &p,
        &stiffness_over_mass(&a, &b),
        &pseudo_random(n, 7),
        &pseudo_random(n, 8),
        0.25,
        20,
    );
    let unstable: Vec<f64> = response
        .coordinates()
        .iter()
        .filter_map(|c| match c.law {
            CoordinateLaw::Exponential { growth_rate } => Some(growth_rate),
            _ => None,
        })
        .collect();
    let exact: Vec<f64> = testing::fixed_chain_omega_sq(n)
        .iter()
        .filter(|w| **w < 1.0)
        .map(|w| (1.0 - w).sqrt())
        .collect();
    assert_eq!(unstable.len(), 2);
    for (g, e) in unstable.iter().zip(&exact) {
        assert!((g - e).abs() <= 1e2 * n as f64 * U, "γ = {g} vs {e}");
    }
}

#[test]
fn ring_with_double_frequencies_matches_integration() {
    let n = 8;
    let (a, b) = testing::ring(n);
    let p = pencil(&a, &b);
    let sol = solve(&p, &SolveOptions::default()).expect("solve");
    assert!(sol.groups.iter().any(|g| g.multiplicity == 2));
    compare(
        &p,
        &stiffness_over_mass(&a, &b),
        &pseudo_random(n, 9),
        &pseudo_random(n, 10),
        0.5,
        20,
    );
}

/// Chain of 6 nodes between two walls with unit springs; nodes 1 and 3 are massless.
fn chain_with_massless_nodes() -> (Mat<f64>, Mat<f64>, Vec<usize>, Vec<usize>) {
    let n = 6;
    let masses = [1.0, 0.0, 2.0, 0.0, 1.0, 1.5];
    let (_, b) = testing::fixed_chain(n);
    let a = Mat::from_fn(n, n, |i, j| if i == j { masses[i] } else { 0.0 });
    (a, b, vec![0, 2, 4, 5], vec![1, 3])
}

#[test]
fn massless_coordinates_follow_statically() {
    let (a, b, massive, massless) = chain_with_massless_nodes();
    let n = a.nrows();
    let p = pencil(&a, &b);
    let (nz, nw) = (massive.len(), massless.len());
    let sub = |m: &Mat<f64>, r: &[usize], c: &[usize]| Mat::from_fn(r.len(), c.len(), |i, j| m[(r[i], c[j])]);
    let (azz, bzz, bzw, bww) = (
        sub(&a, &massive, &massive),
        sub(&b, &massive, &massive),
        sub(&b, &massive, &massless),
        sub(&b, &massless, &massless),
    );
    // w = G z with G = −B_ww⁻¹ B_wz; the reduced stiffness is B_zz + B_zw G.
    let g = -bww.llt(Side::Lower).expect("B_ww > 0").solve(bzw.transpose());
    let reduced = &bzz + &bzw * &g;
    let m = stiffness_over_mass(&azz, &reduced);
    let d0 = pseudo_random(n, 11);
    let v0 = pseudo_random(n, 12);
    let response = FreeResponse::from_problem(&p, &d0, &v0).expect("response");
    assert_eq!(response.fit().massless, nw);
    assert_eq!(response.coordinates().len(), nz);
    // The inconsistency of the initial state is exactly the static correction of w.
    let pick = |v: &[f64], idx: &[usize]| idx.iter().map(|&i| v[i]).collect::<Vec<f64>>();
    let (z0, zd0) = (pick(&d0, &massive), pick(&v0, &massive));
    let w_static = |z: &[f64]| {
        (0..nw)
            .map(|i| (0..nz).map(|j| g[(i, j)] * z[j]).sum())
            .collect::<Vec<f64>>()
    };
    let expected_residual = diff_norm(&pick(&d0, &massless), &w_static(&z0));
    let expected_velocity_residual = diff_norm(&pick(&v0, &massless), &w_static(&zd0));
    let fit = response.fit();
    let tol = 10.0 * n as f64 * U * shape_condition_of(&azz) * (norm(&d0) + norm(&v0));
    assert!(
        (fit.displacement_residual - expected_residual).abs() <= tol,
        "{fit:?} vs {expected_residual}"
    );
    assert!((fit.velocity_residual - expected_velocity_residual).abs() <= tol);
    let dt = 0.5;
    let reference = reference(&m, &z0, &zd0, dt, 400, 20);
    for (k, (z, estimate)) in reference.iter().enumerate() {
        let t = k as f64 * dt;
        let got = response.displacement(t).expect("finite");
        let mut expected = vec![0.0; n];
        for (i, &c) in massive.iter().enumerate() {
            expected[c] = z[i];
        }
        for (i, &c) in massless.iter().enumerate() {
            expected[c] = w_static(z)[i];
        }
        let tolerance = 10.0 * estimate
            + response.error_bound(t).expect("bound")
            + 10.0 * n as f64 * U * shape_condition_of(&azz) * norm(&expected).max(norm(&d0));
        let error = diff_norm(&got, &expected);
        assert!(error <= tolerance, "t = {t}: {error:e} > {tolerance:e}");
    }
}

fn shape_condition_of(a: &Mat<f64>) -> f64 {
    let s = a.self_adjoint_eigenvalues(Side::Lower).expect("eigenvalues");
    (s[s.len() - 1] / s[0]).sqrt()
}

#[test]
fn incomplete_solutions_are_refused() {
    let (a, b) = testing::fixed_chain(4);
    let p = pencil(&a, &b);
    let d = [0.1; 4];
    for options in [
        SolveOptions {
            vectors: false,
            ..SolveOptions::default()
        },
        SolveOptions {
            selection: Selection::Lowest(2),
            ..SolveOptions::default()
        },
    ] {
        let sol = solve(&p, &options).expect("solve");
        assert!(matches!(
            FreeResponse::new(&p, &sol, &d, &d),
            Err(ModalError::IncompleteSolution { dim: 4, .. })
        ));
    }
    // A solution of a different pencil.
    let (a5, b5) = testing::fixed_chain(5);
    let other = solve(&pencil(&a5, &b5), &SolveOptions::default()).expect("solve");
    assert!(matches!(
        FreeResponse::new(&p, &other, &d, &d),
        Err(ModalError::IncompleteSolution { .. })
    ));
}

#[test]
fn bad_vectors_and_times_are_located() {
    let (a, b) = testing::fixed_chain(4);
    let p = pencil(&a, &b);
    assert!(matches!(
        FreeResponse::from_problem(&p, &[0.0; 3], &[0.0; 4]),
        Err(ModalError::BadLength {
            what: "delta0",
            len: 3,
            expected: 4
        })
    ));
    assert!(matches!(
        FreeResponse::from_problem(&p, &[0.0; 4], &[0.0, f64::NAN, 0.0, 0.0]),
        Err(ModalError::NonFiniteValue {
            what: "delta_dot0",
            index: 1,
            ..
        })
    ));
    let r = FreeResponse::from_problem(&p, &[0.1; 4], &[0.0; 4]).expect("response");
    let mut out = [7.0; 4];
    assert!(matches!(
        r.at(f64::INFINITY, &mut out),
        Err(ModalError::NonFiniteValue { what: "t", .. })
    ));
    assert!(matches!(
        r.at(1.0, &mut [0.0; 5]),
        Err(ModalError::BadLength { what: "out", .. })
    ));
    assert_eq!(out, [7.0; 4]);
    assert!(r.error_bound(f64::NAN).is_err());
}

#[test]
fn unstable_growth_beyond_f64_is_an_error() {
    let (a, b0) = testing::fixed_chain(3);
    let b = Mat::from_fn(3, 3, |i, j| b0[(i, j)] - if i == j { 4.0 } else { 0.0 });
    let p = pencil(&a, &b);
    let r = FreeResponse::from_problem(&p, &[0.1, 0.2, 0.3], &[0.0; 3]).expect("response");
    let mut out = [0.0; 3];
    assert!(r.at(1.0, &mut out).is_ok());
    assert!(matches!(r.at(1e4, &mut out), Err(ModalError::ResponseOverflow { .. })));
    assert!(matches!(
        r.velocity_at(-1e4, &mut out),
        Err(ModalError::ResponseOverflow { .. })
    ));
}

/// E = ½δ̇ᵀAδ̇ + ½δᵀBδ.
fn energy(p: &PencilProblem, d: &[f64], v: &[f64]) -> f64 {
    let n = d.len();
    let quad = |m: mechanica_modal::faer::MatRef<'_, f64>, x: &[f64]| {
        (0..n)
            .map(|i| (0..n).map(|j| x[i] * m[(i, j)] * x[j]).sum::<f64>())
            .sum::<f64>()
    };
    0.5 * quad(p.a(), v) + 0.5 * quad(p.b(), d)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// Energy is conserved, δ(0) and δ̇(0) are reproduced, and reversing time equals reversing
    /// the initial velocity, for random initial states of a rotated chain.
    #[test]
    fn invariants_of_the_free_response(seed in 0u64..1000, t in -20.0f64..20.0) {
        let n = 6;
        let (_, b0) = testing::fixed_chain(n);
        let a0 = Mat::from_fn(n, n, |i, j| if i == j { 1.0 + i as f64 } else { 0.0 });
        let (a, b) = testing::rotate(&a0, &b0, &testing::random_orthogonal(n, seed));
        let p = pencil(&a, &b);
        let (d0, v0) = (pseudo_random(n, seed + 1), pseudo_random(n, seed + 2));
        let r = FreeResponse::from_problem(&p, &d0, &v0).expect("response");
        let kappa = shape_condition(&p);
        let e0 = energy(&p, &d0, &v0);
        let (d, v) = (r.displacement(t).expect("d"), r.velocity(t).expect("v"));
        let norms = p.a().norm_l2() * norm(&v).powi(2).max(norm(&v0).powi(2))
            + p.b().norm_l2() * norm(&d).powi(2).max(norm(&d0).powi(2));
        // Each pair has backward error ≤ 10·n·u and XᵀAX = I to 10·n·u; the energy of the
        // superposition then differs from the conserved modal energy by that much of the norms,
        // amplified by the condition of the shapes.
        prop_assert!((energy(&p, &d, &v) - e0).abs() <= 10.0 * n as f64 * U * kappa * kappa * norms);
        let back = FreeResponse::from_problem(&p, &d0, &v0.iter().map(|x| -x).collect::<Vec<_>>()).expect("r");
        let d_back = back.displacement(-t).expect("d");
        prop_assert!(diff_norm(&d, &d_back) <= 10.0 * n as f64 * U * kappa * norm(&d).max(norm(&d0)) * (1.0 + t.abs()));
    }
}

/// ‖v‖₂ of tiny or huge vectors: the entries scaled by a power of two first.
fn scaled_norm(v: &[f64]) -> f64 {
    let largest = v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    if largest == 0.0 {
        return 0.0;
    }
    // 2^e in two factors: 2^e alone overflows for subnormal entries.
    let e = -(largest.log2().floor() as i32);
    let (s1, s2) = (2f64.powi(e / 2), 2f64.powi(e - e / 2));
    norm(&v.iter().map(|x| x * s1 * s2).collect::<Vec<_>>()) / s1 / s2
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// The reported fit of the initial state is true at every scale of δ(0) and δ̇(0), down to
    /// subnormal entries: ‖δ(0) − δ₀‖ is the reported displacement residual (to rounding), and
    /// the relative residual is that over ‖δ₀‖. The squares of entries below 1e-162 underflow,
    /// and a relative residual of 0 was reported for a δ₀ of 1e-304 rebuilt as 0.
    #[test]
    fn the_initial_fit_is_true_at_every_scale(seed in 0u64..1000, exponent in -1070i32..300) {
        let n = 5;
        let (_, b0) = testing::fixed_chain(n);
        let a0 = Mat::from_fn(n, n, |i, j| if i == j { 1.0 + i as f64 } else { 0.0 });
        let (a, b) = testing::rotate(&a0, &b0, &testing::random_orthogonal(n, seed));
        let p = pencil(&a, &b);
        let scale = 2f64.powi(exponent);
        let d0: Vec<f64> = pseudo_random(n, seed + 1).iter().map(|x| x * scale).collect();
        let v0: Vec<f64> = pseudo_random(n, seed + 2).iter().map(|x| x * scale).collect();
        let r = FreeResponse::from_problem(&p, &d0, &v0).expect("response");
        let fit = r.fit();
        for (rebuilt, start, absolute, relative) in [
            (r.displacement(0.0).expect("δ(0)"), &d0, fit.displacement_residual, fit.relative_displacement_residual),
            (r.velocity(0.0).expect("δ̇(0)"), &v0, fit.velocity_residual, fit.relative_velocity_residual),
        ] {
            let difference: Vec<f64> = rebuilt.iter().zip(start).map(|(x, y)| x - y).collect();
            let (actual, size) = (scaled_norm(&difference), scaled_norm(start));
            prop_assert!((actual - absolute).abs() <= 1e-12 * actual + f64::from_bits(8), "{actual:e} vs {absolute:e}");
            if size > 0.0 {
                prop_assert!((actual / size - relative).abs() <= 1e-12 * relative + 1e-300, "{} vs {relative:e}", actual / size);
            }
        }
    }
}
