//! The dense solver against closed-form spectra, invariants and bad input.

use mechanica_modal::faer::Mat;
use mechanica_modal::{
    BoundKind, Method, ModalError, ModeKind, PencilProblem, Refinement, Residuals, Selection, SolveOptions,
    count_below, solve, testing,
};
use proptest::prelude::*;

const U: f64 = f64::EPSILON;

fn pencil(a: &Mat<f64>, b: &Mat<f64>) -> PencilProblem {
    PencilProblem::new(a.as_ref(), b.as_ref()).expect("valid pencil")
}

fn all_pairs() -> SolveOptions {
    SolveOptions::default()
}

/// Every computed ω² lies within its stated bound of the closed form, the backward errors meet
/// 10·n·u, XᵀAX = I to a few n·u, and the Sturm check agrees.
fn check_against(p: &PencilProblem, exact: &[f64]) {
    let n = p.dim();
    let sol = solve(p, &all_pairs()).expect("solve");
    assert_eq!(sol.modes.len(), exact.len());
    for (m, &w) in sol.modes.iter().zip(exact) {
        assert!(
            (m.omega_sq - w).abs() <= m.error_bound,
            "ω² {} vs exact {w}: error {:e} > bound {:e}",
            m.omega_sq,
            (m.omega_sq - w).abs(),
            m.error_bound
        );
    }
    let eta = sol.accuracy.max_backward_error.expect("vectors were computed");
    assert!(eta <= 10.0 * n as f64 * U, "η = {eta:e}");
    assert!(sol.accuracy.meets_backward_error_target(n));
    let orth = sol.accuracy.orthogonality_error.expect("vectors");
    assert!(orth <= 10.0 * n as f64 * U, "‖XᵀAX − I‖ = {orth:e}");
    let check = sol.accuracy.inertia_check.expect("sturm check");
    assert!(check.consistent, "{check:?}");
}

#[test]
fn fixed_chain_matches_closed_form() {
    for n in [1, 2, 7, 60, 130] {
        let (a, b) = testing::fixed_chain(n);
        check_against(&pencil(&a, &b), &testing::fixed_chain_omega_sq(n));
    }
}

#[test]
fn rotated_chain_keeps_its_spectrum() {
    let n = 90;
    let (a0, b0) = testing::fixed_chain(n);
    // Mass matrix diag(1..2) makes A non-trivial; rotate by a random orthogonal Q.
    let (a1, b1) = (
        Mat::from_fn(n, n, |i, j| if i == j { 1.0 + i as f64 / n as f64 } else { 0.0 }),
        b0.clone(),
    );
    let reference = solve(&pencil(&a1, &b1), &all_pairs()).expect("diagonal problem");
    let q = testing::random_orthogonal(n, 7);
    let (a, b) = testing::rotate(&a1, &b1, &q);
    let sol = solve(&pencil(&a, &b), &all_pairs()).expect("rotated problem");
    for (m, r) in sol.modes.iter().zip(&reference.modes) {
        assert!((m.omega_sq - r.omega_sq).abs() <= m.error_bound + r.error_bound);
    }
    assert!(sol.accuracy.meets_backward_error_target(n));
    let _ = a0;
    let (ar, br) = testing::rotate(&Mat::identity(n, n), &testing::fixed_chain(n).1, &q);
    check_against(&pencil(&ar, &br), &testing::fixed_chain_omega_sq(n));
}

/// The certified shift, the error bounds, the backward errors and the orthogonality error.
type ReportedNumbers = (f64, Vec<f64>, Vec<Option<f64>>, Option<f64>);

/// Large enough (n ≥ 640) for the report's inputs and the bottom certificate to be formed on
/// idle time: the lowest 20 ω² lie within their bounds of the closed form; whichever
/// path decides it (the idle thread at half of T's lowest eigenvalue, or the report at half the
/// lowest computed ω²), the certified shift lies below the closed-form lowest ω², at half the
/// computed one to 8 digits, with no mode below it; values only takes the same path. The three
/// solves of each kind report the same numbers to the bit, whichever work the idle threads
/// finished first (the certified shift is half of T's lowest eigenvalue on both paths, and the
/// sketch's rows are formed alike).
#[test]
fn large_solves_certify_the_bottom_below_the_closed_form() {
    let n = 700;
    let q = testing::random_orthogonal(n, 3);
    let (a, b) = testing::rotate(&Mat::identity(n, n), &testing::fixed_chain(n).1, &q);
    let p = pencil(&a, &b);
    let lowest = testing::fixed_chain_omega_sq(n)[0];
    for vectors in [true, false] {
        let mut first_report: Option<ReportedNumbers> = None;
        for _ in 0..3 {
            let options = SolveOptions {
                vectors,
                residuals: Residuals::Sketched,
                ..SolveOptions::default()
            };
            let sol = solve(&p, &options).expect("solve");
            // The report's inputs formed on idle time (norms, sketch rows) serve as well.
            if vectors {
                assert!(sol.accuracy.meets_backward_error_target(n));
            }
            for (m, w) in sol.modes.iter().zip(testing::fixed_chain_omega_sq(n)).take(20) {
                assert!(
                    (m.omega_sq - w).abs() <= m.error_bound + 4.0 * U * w,
                    "{} vs {w}",
                    m.omega_sq
                );
            }
            let check = sol.accuracy.inertia_check.expect("sturm check");
            assert!(
                check.consistent && check.count.below == 0 && check.computed_below == 0,
                "{check:?}"
            );
            let shift = check.count.shift;
            assert!(shift < lowest, "shift {shift:e} not below ω²₁ = {lowest:e}");
            let half = 0.5 * sol.modes[0].omega_sq;
            assert!((shift - half).abs() <= 1e-8 * half, "shift {shift:e} vs {half:e}");
            let report = (
                shift,
                sol.modes.iter().map(|m| m.error_bound).collect::<Vec<f64>>(),
                sol.modes.iter().map(|m| m.backward_error).collect::<Vec<Option<f64>>>(),
                sol.accuracy.orthogonality_error,
            );
            match &first_report {
                Some(first) => assert!(*first == report, "the report changed between two solves"),
                None => first_report = Some(report),
            }
        }
    }
}

/// Lumped masses graded over twelve decades with a dense stiffness, all stored exactly: with H
/// the Sylvester–Hadamard matrix of order 128 and d_i = 4^k_i (k_i from −10 to 10), A = D and
/// B = D^½ (HᵀTH/128) D^½ are exact in binary (integers times powers of two), and
/// D^−½ B D^−½ = (H/√128)ᵀ T (H/√128) is an orthogonal similarity of the fixed chain's T, so ω²
/// are the chain's closed form. A stays diagonal, so the solve takes the diagonal-scaling
/// reduction. Every ω² lies within its bound of the closed form (plus the closed form's own
/// 4u rounding), the lowest ten are certified to 1e-8 relative, η and XᵀAX − I meet 10·n·u and
/// the Sturm check agrees.
#[test]
fn lumped_masses_over_twelve_decades_keep_the_chain_spectrum() {
    let n = 128;
    let hadamard = Mat::from_fn(n, n, |i: usize, j: usize| {
        if (i & j).count_ones().is_multiple_of(2) {
            1.0
        } else {
            -1.0
        }
    });
    let (_, t) = testing::fixed_chain(n);
    let similar = hadamard.transpose() * &t * &hadamard;
    let power = |i: usize| -10 + (20 * i / (n - 1)) as i32;
    let a = Mat::from_fn(n, n, |i, j| if i == j { 4f64.powi(power(i)) } else { 0.0 });
    let b = Mat::from_fn(n, n, |i, j| 2f64.powi(power(i) + power(j)) * similar[(i, j)] / n as f64);
    assert!((0..n).all(|j| (0..n).any(|i| i != j && b[(i, j)] != 0.0)), "B is dense");
    let exact = testing::fixed_chain_omega_sq(n);
    let p = pencil(&a, &b);
    let sol = solve(&p, &all_pairs()).expect("solve");
    assert_eq!(sol.modes.len(), n);
    for (k, (m, &w)) in sol.modes.iter().zip(&exact).enumerate() {
        let error = (m.omega_sq - w).abs();
        assert!(
            error <= m.error_bound + 4.0 * U * w,
            "mode {k}: error {error:e}, bound {:e}",
            m.error_bound
        );
        if k < 10 {
            assert!(
                m.error_bound <= 1e-8 * w,
                "mode {k}: bound {:e} for ω² = {w:e}",
                m.error_bound
            );
        }
    }
    assert!(sol.accuracy.max_backward_error.expect("vectors") <= 10.0 * n as f64 * U);
    assert!(sol.accuracy.orthogonality_error.expect("vectors") <= 10.0 * n as f64 * U);
    assert!(sol.accuracy.inertia_check.expect("sturm check").consistent);
}

/// Glued Wilkinson W21+ stiffness (eigenvalue pairs equal to 1e-14, blocks glued by 1e-10 into
/// clusters of six), rotated by a random orthogonal matrix: the divide and conquer's deflation
/// by rotation and its close secular roots, through the public solver. Backward errors and
/// A-orthogonality meet 10·n·u, and every bound interval holds an eigenvalue by the
/// independent LBLᵀ inertia count.
#[test]
fn glued_wilkinson_clusters_keep_orthogonal_modes() {
    let blocks = 6;
    let n = 21 * blocks;
    let mut t = Mat::<f64>::zeros(n, n);
    for i in 0..n {
        t[(i, i)] = (10.0 - (i % 21) as f64).abs() + 11.0;
        if i + 1 < n {
            let coupling = if i % 21 == 20 { 1e-10 } else { 1.0 };
            t[(i, i + 1)] = coupling;
            t[(i + 1, i)] = coupling;
        }
    }
    let q = testing::random_orthogonal(n, 5);
    let (a, b) = testing::rotate(&Mat::identity(n, n), &t, &q);
    let p = pencil(&a, &b);
    let sol = solve(&p, &all_pairs()).expect("solve");
    let eta = sol.accuracy.max_backward_error.expect("vectors");
    assert!(eta <= 10.0 * n as f64 * U, "η = {eta:e}");
    let orth = sol.accuracy.orthogonality_error.expect("vectors");
    assert!(orth <= 10.0 * n as f64 * U, "‖XᵀAX − I‖ = {orth:e}");
    let below = |s: f64| count_below(&p, s).expect("count").below;
    for m in &sol.modes {
        let slack = m.error_bound + 1e-12 * m.omega_sq;
        assert!(
            below(m.omega_sq + slack) > below(m.omega_sq - slack),
            "no eigenvalue within {slack:e} of {}",
            m.omega_sq
        );
    }
    let (lowest, highest) = (&sol.modes[0], &sol.modes[n - 1]);
    assert_eq!(below(lowest.omega_sq - 2.0 * lowest.error_bound - 1e-9), 0);
    assert_eq!(below(highest.omega_sq + 2.0 * highest.error_bound + 1e-9), n);
}

/// Values only with automatic refinement: the modes whose a-priori bound guarantees fewer than
/// 8 digits get their vectors formed internally (inverse iteration on the tridiagonal form), so
/// their bounds are measured (first order) or refined (residual) instead of assumed. Every ω²
/// is within its bound of the closed form and every bound certifies 8 digits, on a rotated
/// chain (order 700: the two-thread tridiagonalization) and on a ring, whose double
/// eigenvalues and rigid-body mode exercise the clustered inverse iteration.
#[test]
fn values_only_solves_measure_their_weakly_bounded_modes() {
    let values_only = SolveOptions {
        vectors: false,
        ..all_pairs()
    };
    let n = 700;
    let q = testing::random_orthogonal(n, 11);
    let (a, b) = testing::rotate(&Mat::identity(n, n), &testing::fixed_chain(n).1, &q);
    let p = pencil(&a, &b);
    let exact = testing::fixed_chain_omega_sq(n);
    let sol = solve(&p, &values_only).expect("solve");
    assert!(sol.vectors.is_none());
    for (i, (m, &w)) in sol.modes.iter().zip(&exact).enumerate() {
        assert!((m.omega_sq - w).abs() <= m.error_bound, "mode {i}");
        assert!(m.error_bound <= 1e-8 * w, "mode {i}: {:e}", m.error_bound / w);
    }
    assert_ne!(sol.accuracy.bound_kinds[0], BoundKind::APriori);
    assert!(sol.accuracy.bound_kinds.contains(&BoundKind::APriori));
    assert!(sol.accuracy.inertia_check.expect("check").consistent);
    let off = solve(
        &p,
        &SolveOptions {
            refinement: Refinement::Off,
            ..values_only
        },
    )
    .expect("solve");
    assert!(
        off.modes[0].error_bound > 1e-8 * exact[0],
        "the a-priori bound alone is weak here"
    );

    let n = 40;
    let (a, b) = testing::ring(n);
    let exact = testing::ring_omega_sq(n);
    let sol = solve(&pencil(&a, &b), &values_only).expect("solve");
    for (i, (m, &w)) in sol.modes.iter().zip(&exact).enumerate() {
        assert!((m.omega_sq - w).abs() <= m.error_bound, "mode {i}");
    }
    assert_eq!(sol.modes[0].kind, ModeKind::Zero);
    assert_ne!(sol.accuracy.bound_kinds[0], BoundKind::APriori);
    let mult: Vec<usize> = sol.groups.iter().map(|g| g.multiplicity).collect();
    assert_eq!(mult.len(), n / 2 + 1, "{mult:?}");
    assert!(mult[1..mult.len() - 1].iter().all(|&m| m == 2), "{mult:?}");
}

/// Values only with more weakly bounded modes than `Tuning::flagged_vectors_up_to` (masses graded
/// over six decades make ‖A⁻¹‖ large): all vectors are computed instead, and every mode agrees with
/// the all-pairs solve within the two bounds, with measured (not assumed) bounds.
#[test]
fn values_only_with_many_weak_modes_computes_all_vectors() {
    let n = 300;
    let masses: Vec<f64> = (0..n).map(|i| 10f64.powf(-6.0 * i as f64 / (n - 1) as f64)).collect();
    let a = Mat::from_fn(n, n, |i, j| if i == j { masses[i] } else { 0.0 });
    let b = testing::fixed_chain(n).1;
    let q = testing::random_orthogonal(n, 3);
    let (a, b) = testing::rotate(&a, &b, &q);
    let p = pencil(&a, &b);
    let values_only = SolveOptions {
        vectors: false,
        ..all_pairs()
    };
    let assumed = solve(
        &p,
        &SolveOptions {
            refinement: Refinement::Off,
            ..values_only
        },
    )
    .expect("solve");
    let weak = assumed
        .modes
        .iter()
        .filter(|m| m.error_bound > mechanica_modal::dense::AUTO_REFINE_RELATIVE_BOUND * m.omega_sq.abs())
        .count();
    assert!(
        weak > mechanica_modal::Tuning::DEFAULT.flagged_vectors_up_to.max(n / 4),
        "{weak} weak modes"
    );
    let measured = solve(&p, &values_only).expect("solve");
    let reference = solve(&p, &all_pairs()).expect("solve");
    assert!(measured.vectors.is_none());
    for (i, (m, r)) in measured.modes.iter().zip(&reference.modes).enumerate() {
        assert!(
            (m.omega_sq - r.omega_sq).abs() <= m.error_bound + r.error_bound,
            "mode {i}"
        );
        assert_ne!(measured.accuracy.bound_kinds[i], BoundKind::APriori, "mode {i}");
    }
}

#[test]
fn free_chain_has_one_rigid_body_mode() {
    let n = 40;
    let (a, b) = testing::free_chain(n);
    let p = pencil(&a, &b);
    check_against(&p, &testing::free_chain_omega_sq(n));
    let sol = solve(&p, &all_pairs()).expect("solve");
    assert_eq!(sol.modes[0].kind, ModeKind::Zero);
    for m in &sol.modes[1..] {
        assert!(
            matches!(m.kind, ModeKind::Oscillatory { omega } if (omega * omega - m.omega_sq).abs() <= 4.0 * U * m.omega_sq)
        );
    }
    // The rigid-body mode is a uniform translation: x ∝ (1, …, 1).
    let x = sol.vectors.expect("vectors");
    let x0 = x[(0, 0)];
    for i in 0..n {
        assert!((x[(i, 0)] - x0).abs() <= 100.0 * n as f64 * U * x0.abs());
    }
}

#[test]
fn ring_eigenvalues_come_in_groups_with_orthonormal_bases() {
    let n = 12;
    let (a, b) = testing::ring(n);
    let p = pencil(&a, &b);
    check_against(&p, &testing::ring_omega_sq(n));
    let sol = solve(&p, &all_pairs()).expect("solve");
    // k = 0 and k = n/2 are simple; every other frequency is double.
    let mult: Vec<usize> = sol.groups.iter().map(|g| g.multiplicity).collect();
    assert_eq!(mult.len(), n / 2 + 1);
    assert_eq!(mult[0], 1);
    assert_eq!(*mult.last().expect("groups"), 1);
    assert!(mult[1..mult.len() - 1].iter().all(|&m| m == 2), "{mult:?}");
    let x = sol.vectors.expect("vectors");
    for g in &sol.groups {
        let cols = x.as_ref().subcols(g.first, g.multiplicity);
        // Basis of the eigenspace: (B − ω²A)X_g = 0 and X_gᵀ A X_g = I.
        let r = &b * cols - (&a * cols) * g.omega_sq;
        assert!(r.norm_max() <= 100.0 * n as f64 * U, "group at {}", g.omega_sq);
        let gram = cols.transpose() * &a * cols;
        let e = &gram - Mat::<f64>::identity(g.multiplicity, g.multiplicity);
        assert!(e.norm_max() <= 10.0 * n as f64 * U);
    }
}

#[test]
fn unstable_modes_report_their_growth_rate() {
    // A = I, B = diag(−4, 1, 9): one unstable mode with growth rate 2 (λ = 4 > 0).
    let a = Mat::<f64>::identity(3, 3);
    let b = Mat::from_fn(3, 3, |i, j| if i == j { [-4.0, 1.0, 9.0][i] } else { 0.0 });
    let q = testing::random_orthogonal(3, 1);
    let (a, b) = testing::rotate(&a, &b, &q);
    let sol = solve(&pencil(&a, &b), &all_pairs()).expect("solve");
    match sol.modes[0].kind {
        ModeKind::Unstable { growth_rate } => assert!((growth_rate - 2.0).abs() <= 10.0 * U * 2.0),
        other => panic!("expected unstable, got {other:?}"),
    }
    assert!((sol.modes[0].lambda - 4.0).abs() <= sol.modes[0].error_bound);
    assert!(matches!(sol.modes[2].kind, ModeKind::Oscillatory { omega } if (omega - 3.0).abs() < 1e-14));
    assert_eq!(count_below(&pencil(&a, &b), 0.0).expect("shift").below, 1);
}

#[test]
fn massless_coordinate_is_condensed_and_reported_infinite() {
    // ground –1– m=1 –1– (massless) –1– m=1 –1– ground: condensing the middle node leaves the
    // pencil (I, [[1.5, −0.5], [−0.5, 1.5]]) with ω² = 1 and 2, plus one infinite mode.
    let a = Mat::from_fn(3, 3, |i, j| if i == j && i != 1 { 1.0 } else { 0.0 });
    let (_, b) = testing::fixed_chain(3);
    let sol = solve(&pencil(&a, &b), &all_pairs()).expect("solve");
    assert_eq!(sol.method, Method::CondensedReduction { massless: 1 });
    assert_eq!(sol.modes.len(), 3);
    assert!((sol.modes[0].omega_sq - 1.0).abs() <= sol.modes[0].error_bound);
    assert!((sol.modes[1].omega_sq - 2.0).abs() <= sol.modes[1].error_bound);
    assert_eq!(sol.modes[2].kind, ModeKind::Infinite);
    assert_eq!(sol.modes[2].lambda, f64::NEG_INFINITY);
    let x = sol.vectors.expect("vectors");
    // Lifted shapes satisfy the full pencil: the middle node sits at the mean of its neighbours.
    for k in 0..2 {
        assert!((x[(1, k)] - 0.5 * (x[(0, k)] + x[(2, k)])).abs() <= 10.0 * U);
    }
    assert!(sol.accuracy.max_backward_error.expect("vectors") <= 30.0 * U);
    // The infinite mode is the massless direction e₂.
    assert!((x[(1, 2)].abs() - 1.0).abs() <= 10.0 * U);
    assert!(sol.accuracy.inertia_check.expect("certified").consistent);
}

/// Unit springs between two walls through 2m + 1 nodes, of which the even ones (including both
/// ends) are massless and the odd ones carry unit masses; the coordinates are shuffled so that
/// the massless ones are scattered. Condensing each massless node puts two unit springs in series
/// (½), so the m finite modes are those of a fixed–fixed chain of unit masses and springs ½:
/// ω² = 2 sin²(kπ/(2(m + 1))); the m + 1 infinite modes are the massless unit vectors; a
/// massless node of a finite mode sits at the mean of its neighbours. A is diagonal, so the
/// massless directions come from sorting its diagonal, not from an eigen-decomposition.
#[test]
fn scattered_massless_nodes_of_a_lumped_chain_are_condensed() {
    let m = 150;
    let n = 2 * m + 1;
    // Node i of the chain is coordinate place[i] (a fixed pseudo-random permutation).
    let mut place: Vec<usize> = (0..n).collect();
    let mut s = 7_u64;
    for i in (1..n).rev() {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        place.swap(i, (s >> 33) as usize % (i + 1));
    }
    let (_, t) = testing::fixed_chain(n);
    let a = Mat::from_fn(n, n, |i, j| {
        if i == j && place.iter().position(|&p| p == i).unwrap_or(0) % 2 == 1 {
            1.0
        } else {
            0.0
        }
    });
    let node = |c: usize| place.iter().position(|&p| p == c).unwrap_or(0);
    let b = Mat::from_fn(n, n, |i, j| t[(node(i), node(j))]);
    let sol = solve(&pencil(&a, &b), &all_pairs()).expect("solve");
    assert_eq!(sol.method, Method::CondensedReduction { massless: m + 1 });
    assert_eq!(sol.modes.len(), n);
    let x = sol.vectors.expect("vectors");
    for k in 0..m {
        let s = ((k + 1) as f64 * std::f64::consts::PI / (2.0 * (m + 1) as f64)).sin();
        let exact = 2.0 * s * s;
        let mode = &sol.modes[k];
        assert!(
            (mode.omega_sq - exact).abs() <= mode.error_bound + 4.0 * U * exact,
            "mode {k}"
        );
        assert!(matches!(mode.kind, ModeKind::Oscillatory { .. }));
        // Every massless interior node at the mean of its two massed neighbours; the end nodes
        // at half their one neighbour (the wall is fixed).
        for i in (0..n).step_by(2) {
            let left = if i == 0 { 0.0 } else { x[(place[i - 1], k)] };
            let right = if i == n - 1 { 0.0 } else { x[(place[i + 1], k)] };
            assert!(
                (x[(place[i], k)] - 0.5 * (left + right)).abs() <= 100.0 * U,
                "mode {k} node {i}"
            );
        }
    }
    for k in m..n {
        assert_eq!(sol.modes[k].kind, ModeKind::Infinite);
        // A massless unit vector.
        let column: Vec<f64> = (0..n).map(|i| x[(i, k)].abs()).collect();
        let top = column.iter().copied().fold(0.0, f64::max);
        let at = column.iter().position(|&v| v == top).unwrap_or(0);
        assert_eq!(node(at) % 2, 0, "infinite mode {k} is not massless");
        assert!((top - 1.0).abs() <= 10.0 * U && column.iter().filter(|&&v| v != 0.0).count() == 1);
    }
    assert!(sol.accuracy.max_backward_error.expect("vectors") <= 10.0 * n as f64 * U);
    let check = sol
        .accuracy
        .inertia_check
        .expect("the condensed solve is certified too");
    assert!(check.consistent, "{check:?}");
    assert_eq!(check.count.below + check.count.zero + check.count.above, n);
}

/// A massless middle node held by a negative spring to the ground (−3) between unit springs:
/// B = [[2, −1, 0], [−1, −1, −1], [0, −1, 2]], A = diag(1, 0, 1). B₀₀ = −1 is nonsingular, so
/// condensing gives S = [[3, 1], [1, 3]], ω² = 2 and 4, plus one infinite mode. The Sturm count
/// of the full B − sA includes B₀₀'s negative eigenvalue (Haynsworth inertia additivity); the
/// check subtracts it and agrees with the condensed spectrum at every shift it may pick, and an
/// independent count at s = 3 (between the modes) on B − sA itself has two negative pivots.
/// `copies` decoupled fixed chains of `masses` unit masses, each pair of neighbours (and each
/// end and its wall) joined by a stiff spring k₁ and a soft spring k₂ = 1 in series through a
/// massless node: A = diag(0, 1, 0, 1, …, 0) per chain. The condensed chain has springs
/// k = k₁k₂/(k₁ + k₂), so ω²_j = 4k sin²(jπ/(2(masses + 1))), each `copies` times.
fn series_spring_chains(masses: usize, k1: f64, copies: usize) -> (Mat<f64>, Mat<f64>) {
    let k2 = 1.0;
    let size = 2 * masses + 1;
    let n = copies * size;
    let mut a = Mat::<f64>::zeros(n, n);
    let mut b = Mat::<f64>::zeros(n, n);
    for c in 0..copies {
        let o = c * size;
        for segment in 0..=masses {
            let node = o + 2 * segment;
            b[(node, node)] += k1 + k2;
            if segment > 0 {
                b[(node - 1, node - 1)] += k1;
                b[(node - 1, node)] -= k1;
                b[(node, node - 1)] -= k1;
            }
            if segment < masses {
                b[(node + 1, node + 1)] += k2;
                b[(node + 1, node)] -= k2;
                b[(node, node + 1)] -= k2;
                a[(node + 1, node + 1)] = 1.0;
            }
        }
    }
    (a, b)
}

#[test]
fn stiff_springs_to_massless_nodes_keep_every_digit_of_the_low_modes() {
    // k₁ = 1e12: the condensed stiffness k₁ − k₁²/(k₁ + 1) cancels 12 digits, so the condensed
    // pencil alone carries errors of u·k₁ ≈ 1e-4 in its entries (a power of two would round
    // exactly and hide this). Refinement measures residuals on the stored A and B in
    // double-double and must recover every digit.
    let (masses, k1) = (60, 1e12);
    let spring = k1 / (k1 + 1.0);
    let omega_exact = |j: usize| {
        let s = (j as f64 * std::f64::consts::PI / (2.0 * (masses + 1) as f64)).sin();
        4.0 * spring * s * s
    };
    for copies in [1, 2] {
        let (a, b) = series_spring_chains(masses, k1, copies);
        let p = pencil(&a, &b);
        let unrefined = solve(
            &p,
            &SolveOptions {
                refinement: Refinement::Off,
                ..SolveOptions::default()
            },
        )
        .expect("solve");
        let sol = solve(&p, &all_pairs()).expect("solve");
        assert_eq!(
            sol.method,
            Method::CondensedReduction {
                massless: copies * (masses + 1)
            }
        );
        for k in 0..10 * copies {
            // The closed form in f64 carries a few roundings of its own (k and 4k sin²).
            let exact = omega_exact(1 + k / copies);
            let (raw, mode) = (&unrefined.modes[k], &sol.modes[k]);
            // The case is hard: the unrefined lowest modes are wrong well beyond 1e-9, and say so.
            if k < copies {
                assert!((raw.omega_sq - exact).abs() > 1e-9 * exact, "mode {k} is not hard");
            }
            assert!(
                (raw.omega_sq - exact).abs() <= raw.error_bound + 8.0 * U * exact,
                "mode {k}"
            );
            assert!(
                (mode.omega_sq - exact).abs() <= mode.error_bound + 8.0 * U * exact,
                "mode {k}: {:e} vs bound {:e}",
                (mode.omega_sq - exact).abs(),
                mode.error_bound
            );
            // Every digit, for the repeated pair too: its block was formed from the unrefined
            // bounds (relative 1e0, spanning the lowest ten modes) and is narrowed to the pair
            // by the refined residuals, so its Rayleigh–Ritz defect is taken at the pair's ω².
            assert!(
                mode.error_bound <= 1e-13 * exact,
                "copies {copies} mode {k}: bound {:e}",
                mode.error_bound / exact
            );
            assert_eq!(sol.accuracy.bound_kinds[k], BoundKind::Residual, "mode {k}");
            assert!(sol.accuracy.refinement_steps[k] > 0, "mode {k}");
        }
        if copies == 2 {
            let lowest = &sol.groups[0];
            assert_eq!((lowest.first, lowest.multiplicity), (0, 2), "{:?}", sol.groups);
        }
        let check = sol.accuracy.inertia_check.expect("certified");
        assert!(check.consistent, "{check:?}");
    }
}

#[test]
fn condensed_sturm_check_allows_for_negative_stiffness_of_massless_coordinates() {
    let a = Mat::from_fn(3, 3, |i, j| if i == j && i != 1 { 1.0 } else { 0.0 });
    let b = Mat::from_fn(3, 3, |i, j| {
        [[2.0, -1.0, 0.0], [-1.0, -1.0, -1.0], [0.0, -1.0, 2.0]][i][j]
    });
    let p = pencil(&a, &b);
    let sol = solve(&p, &all_pairs()).expect("solve");
    assert_eq!(sol.method, Method::CondensedReduction { massless: 1 });
    assert!((sol.modes[0].omega_sq - 2.0).abs() <= sol.modes[0].error_bound);
    assert!((sol.modes[1].omega_sq - 4.0).abs() <= sol.modes[1].error_bound);
    assert_eq!(sol.modes[2].kind, ModeKind::Infinite);
    let check = sol.accuracy.inertia_check.expect("certified");
    assert!(check.consistent, "{check:?}");
    assert_eq!(check.count.below, check.computed_below);
    assert_eq!(check.count.below + check.count.zero + check.count.above, 3);
    // The raw count at s = 3: one mode below plus B₀₀'s negative eigenvalue.
    assert_eq!(count_below(&p, 3.0).expect("count").below, 2);
}

#[test]
fn indefinite_mass_names_the_pivot() {
    let a = Mat::from_fn(3, 3, |i, j| if i == j { [1.0, -2.0, 1.0][i] } else { 0.0 });
    let b = Mat::<f64>::identity(3, 3);
    match solve(&pencil(&a, &b), &all_pairs()) {
        Err(ModalError::IndefiniteMass {
            pivot: 1,
            min_eigenvalue,
            ..
        }) => assert_eq!(min_eigenvalue, -2.0),
        other => panic!("expected IndefiniteMass at pivot 1, got {other:?}"),
    }
}

#[test]
fn singular_pencil_is_rejected() {
    let a = Mat::from_fn(2, 2, |i, j| if i == j && i == 0 { 1.0 } else { 0.0 });
    let b = a.clone();
    assert!(matches!(
        solve(&pencil(&a, &b), &all_pairs()),
        Err(ModalError::SingularPencil { nullity: 1, .. })
    ));
}

#[test]
fn subsets_agree_with_the_full_spectrum() {
    let n = 70;
    let (a, b) = testing::fixed_chain(n);
    let p = pencil(&a, &b);
    let exact = testing::fixed_chain_omega_sq(n);
    let lowest = solve(
        &p,
        &SolveOptions {
            selection: Selection::Lowest(5),
            ..all_pairs()
        },
    )
    .expect("lowest");
    assert_eq!(lowest.modes.len(), 5);
    assert_eq!(lowest.vectors.as_ref().map(|x| x.ncols()), Some(5));
    for (m, w) in lowest.modes.iter().zip(&exact) {
        assert!((m.omega_sq - w).abs() <= m.error_bound);
    }
    assert!(lowest.accuracy.inertia_check.expect("check").consistent);
    let interval = solve(
        &p,
        &SolveOptions {
            selection: Selection::Interval { lower: 1.0, upper: 2.0 },
            vectors: false,
            refinement: Refinement::Auto,
            residuals: Residuals::Exact,
        },
    )
    .expect("interval");
    let expected: Vec<f64> = exact.iter().copied().filter(|w| (1.0..=2.0).contains(w)).collect();
    assert_eq!(interval.modes.len(), expected.len());
    assert!(interval.vectors.is_none());
    for (m, w) in interval.modes.iter().zip(&expected) {
        assert_eq!(interval.accuracy.bound_kinds[0], BoundKind::APriori);
        assert!((m.omega_sq - w).abs() <= m.error_bound);
    }
    assert!(matches!(
        solve(
            &p,
            &SolveOptions {
                selection: Selection::Lowest(n + 1),
                ..all_pairs()
            }
        ),
        Err(ModalError::TooManyModes {
            requested: 71,
            available: 70
        })
    ));
    for (lower, upper) in [(2.0, 1.0), (f64::NAN, 1.0), (0.0, f64::INFINITY)] {
        assert!(matches!(
            solve(
                &p,
                &SolveOptions {
                    selection: Selection::Interval { lower, upper },
                    ..all_pairs()
                }
            ),
            Err(ModalError::BadInterval { .. })
        ));
    }
}

/// An interval above (or below) the whole spectrum selects nothing, in every mode of solve.
#[test]
fn empty_intervals_select_nothing() {
    let (a, b) = testing::fixed_chain(6);
    let p = pencil(&a, &b);
    for (lower, upper) in [(5.0, 6.0), (-2.0, -1.0)] {
        for vectors in [false, true] {
            for refinement in [Refinement::Auto, Refinement::Off] {
                let sol = solve(
                    &p,
                    &SolveOptions {
                        selection: Selection::Interval { lower, upper },
                        vectors,
                        refinement,
                        residuals: Residuals::Exact,
                    },
                )
                .expect("an empty selection is not an error");
                assert!(sol.modes.is_empty());
                assert!(sol.accuracy.inertia_check.is_none_or(|c| c.consistent));
            }
        }
    }
}

#[test]
fn bad_input_is_located() {
    let mut a = Mat::<f64>::identity(4, 4);
    a[(2, 3)] = f64::NAN;
    let b = Mat::<f64>::identity(4, 4);
    assert!(matches!(
        PencilProblem::new(a.as_ref(), b.as_ref()),
        Err(ModalError::NonFinite {
            what: "A",
            row: 2,
            col: 3,
            ..
        })
    ));
    let rect = Mat::<f64>::zeros(3, 4);
    assert!(matches!(
        PencilProblem::new(rect.as_ref(), rect.as_ref()),
        Err(ModalError::BadShape { what: "A", .. })
    ));
}

fn spd_and_symmetric(n: usize, entries: &[f64]) -> (Mat<f64>, Mat<f64>) {
    let g = Mat::from_fn(n, n, |i, j| entries[(i * n + j) % entries.len()]);
    let h = Mat::from_fn(n, n, |i, j| entries[(i * 7 + j * 3 + 1) % entries.len()]);
    let mut a = &g * g.transpose();
    for i in 0..n {
        a[(i, i)] += 1.0;
    }
    let b = Mat::from_fn(n, n, |i, j| h[(i, j)] + h[(j, i)]);
    (a, b)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    /// Random definite pencils: backward error ≤ 10·n·u, A-orthonormal modes, the Sturm
    /// check, Σ ω² = trace(A⁻¹B) within the summed bounds, and values-only solves that agree.
    #[test]
    fn random_pencils_are_solved_backward_stably(n in 1usize..14, entries in prop::collection::vec(-1.0f64..1.0, 30)) {
        let (a, b) = spd_and_symmetric(n, &entries);
        let p = pencil(&a, &b);
        let sol = solve(&p, &all_pairs()).expect("definite pencil");
        let eta = sol.accuracy.max_backward_error.expect("vectors");
        prop_assert!(eta <= 10.0 * n as f64 * U, "η = {:e}", eta);
        let cond_a = {
            let s = a.self_adjoint_eigenvalues(mechanica_modal::faer::Side::Lower).expect("evd");
            s[n - 1] / s[0]
        };
        prop_assert!(sol.accuracy.orthogonality_error.expect("vectors") <= 10.0 * n as f64 * U * cond_a);
        prop_assert!(sol.accuracy.inertia_check.expect("check").consistent);
        let llt = a.llt(mechanica_modal::faer::Side::Lower).expect("spd");
        use mechanica_modal::faer::linalg::solvers::Solve;
        let ainv_b = llt.solve(&b);
        let trace: f64 = (0..n).map(|i| ainv_b[(i, i)]).sum();
        let sum: f64 = sol.modes.iter().map(|m| m.omega_sq).sum();
        let bound: f64 = sol.modes.iter().map(|m| m.error_bound).sum::<f64>()
            + 10.0 * n as f64 * U * ainv_b.norm_l2() * cond_a;
        prop_assert!((trace - sum).abs() <= bound, "trace {} vs Σ {}", trace, sum);
        // Values only (weakly bounded modes measured by inverse iteration): every ω² agrees
        // with the all-pairs one within the two bounds.
        let values = solve(&p, &SolveOptions { vectors: false, ..all_pairs() }).expect("values");
        for (v, m) in values.modes.iter().zip(&sol.modes) {
            prop_assert!((v.omega_sq - m.omega_sq).abs() <= v.error_bound + m.error_bound,
                "values only {} vs {}", v.omega_sq, m.omega_sq);
        }
    }
}

#[test]
fn zero_mass_matrix_gives_only_infinite_modes() {
    // A = 0, B = I: every direction is massless; det(λ·0 + I) = 1 has no finite root.
    let n = 4;
    let a = Mat::<f64>::zeros(n, n);
    let b = Mat::<f64>::identity(n, n);
    let sol = solve(&pencil(&a, &b), &all_pairs()).expect("solve");
    assert_eq!(sol.method, Method::CondensedReduction { massless: n });
    assert_eq!(sol.modes.len(), n);
    assert!(sol.modes.iter().all(|m| m.kind == ModeKind::Infinite));
    assert_eq!(sol.groups.len(), 1);
    assert_eq!(sol.groups[0].multiplicity, n);
}

#[test]
fn tiny_orders_do_not_reach_faer_size_limits() {
    for n in 1..=3 {
        let (a, b) = testing::free_chain(n);
        let p = pencil(&a, &b);
        for selection in [Selection::All, Selection::Lowest(0), Selection::Lowest(n)] {
            for vectors in [false, true] {
                for refinement in [Refinement::Auto, Refinement::Off, Refinement::Always] {
                    for residuals in [Residuals::Exact, Residuals::Sketched] {
                        let sol = solve(
                            &p,
                            &SolveOptions {
                                selection,
                                vectors,
                                refinement,
                                residuals,
                            },
                        )
                        .expect("solve");
                        assert!(
                            sol.modes
                                .iter()
                                .all(|m| m.omega_sq.is_finite() && m.error_bound.is_finite())
                        );
                    }
                }
            }
        }
    }
}

/// The fixed chain with masses 1 + i/n (ω² of the unit chain), turned by a random rotation.
fn rotated_graded_mass_chain(n: usize) -> (Mat<f64>, Mat<f64>) {
    let d = Mat::from_fn(n, n, |i, j| if i == j { 1.0 + i as f64 / n as f64 } else { 0.0 });
    let (_, t) = testing::fixed_chain(n);
    let b = Mat::from_fn(n, n, |i, j| (d[(i, i)] * d[(j, j)]).sqrt() * t[(i, j)]);
    testing::rotate(&d, &b, &testing::random_orthogonal(n, 9))
}

/// The sketched report bounds the exact one from above, within the factor its lower tail
/// allows, on a rotated chain, a free chain (rigid-body mode) and a graded 1e12 chain; every
/// ω² still lies within its (sketched) bound of the closed form. (Orders past the crossover
/// below which the exact products are formed instead.)
#[test]
fn sketched_residuals_bound_the_exact_ones() {
    let n = 300;
    let (ra, rb) = rotated_graded_mass_chain(n);
    let (fa, fb) = testing::free_chain(n);
    let graded = testing::spring_chain(&testing::graded_exponents(n, 12), &vec![0; n]);
    let cases = [
        (pencil(&ra, &rb), testing::fixed_chain_omega_sq(n)),
        (pencil(&fa, &fb), testing::free_chain_omega_sq(n)),
        (pencil(&graded.0, &graded.1), Vec::new()),
    ];
    for (p, exact) in &cases {
        let exact_report = solve(p, &all_pairs()).expect("exact");
        let sketched = solve(
            p,
            &SolveOptions {
                residuals: Residuals::Sketched,
                ..SolveOptions::default()
            },
        )
        .expect("sketched");
        assert_eq!(sketched.accuracy.residuals, Residuals::Sketched);
        assert_eq!(exact_report.accuracy.residuals, Residuals::Exact);
        for (i, (e, s)) in exact_report.modes.iter().zip(&sketched.modes).enumerate() {
            let (e_eta, s_eta) = (e.backward_error.expect("vectors"), s.backward_error.expect("vectors"));
            // Both are computed residuals: each carries rounding of order n·u (exactly 0 for the
            // rigid-body mode of the free chain, where B·1 = 0 without rounding).
            if e.omega_sq == s.omega_sq {
                let floor = p.dim() as f64 * U;
                assert!(
                    s_eta + floor >= e_eta && s_eta <= 8.0 * e_eta + floor,
                    "mode {i}: {s_eta:e} vs {e_eta:e}"
                );
            }
            if let Some(w) = exact.get(i) {
                assert!((s.omega_sq - w).abs() <= s.error_bound, "mode {i}");
            }
        }
        let (e_orth, s_orth) = (
            exact_report.accuracy.orthogonality_error.expect("vectors"),
            sketched.accuracy.orthogonality_error.expect("vectors"),
        );
        assert!(s_orth >= e_orth, "{s_orth:e} < {e_orth:e}");
        assert!(sketched.accuracy.meets_backward_error_target(p.dim()));
        assert!(sketched.accuracy.inertia_check.expect("check").consistent);
    }
}

/// A sketch requested where the exact products cost less (all pairs of a small pencil, or a
/// few pairs of a larger one) gives the exact report: the same backward errors and
/// orthogonality error as asking for it, and `residuals` says so.
#[test]
fn sketches_are_not_formed_where_exact_products_cost_less() {
    let n = 240;
    let (ra, rb) = rotated_graded_mass_chain(n);
    let (small_a, small_b) = testing::rotate(
        &Mat::<f64>::identity(30, 30),
        &testing::fixed_chain(30).1,
        &testing::random_orthogonal(30, 3),
    );
    for (p, selection) in [
        (pencil(&small_a, &small_b), Selection::All),
        (pencil(&ra, &rb), Selection::Lowest(5)),
    ] {
        let options = |residuals| SolveOptions {
            selection,
            residuals,
            ..SolveOptions::default()
        };
        let exact = solve(&p, &options(Residuals::Exact)).expect("exact");
        let asked_sketch = solve(&p, &options(Residuals::Sketched)).expect("sketched");
        assert_eq!(asked_sketch.accuracy.residuals, Residuals::Exact);
        let etas = |s: &mechanica_modal::ModalSolution| -> Vec<Option<f64>> {
            s.modes.iter().map(|m| m.backward_error).collect()
        };
        assert_eq!(etas(&asked_sketch), etas(&exact));
        assert_eq!(
            asked_sketch.accuracy.orthogonality_error,
            exact.accuracy.orthogonality_error
        );
    }
}

/// Six uncoupled free chains (each with one rigid-body mode), turned by a random rotation: the
/// rotated stiffness is singular only up to rounding, so the six zero eigenvalues of the stored
/// pencil are of order u·‖B‖, of either sign, and refinement bounds them far more tightly than
/// that. They are still rigid-body modes to the precision of the data: classified zero (not
/// unstable with a growth rate of 1e-8), and one group of multiplicity six, in every mode of
/// solve. The ring (one rigid-body mode, every other frequency double) likewise.
#[test]
fn rigid_body_modes_of_a_rounded_stiffness_are_zero() {
    let copies = 6;
    let (a1, b1) = testing::free_chain(10);
    let n1 = a1.nrows();
    let n = copies * n1;
    let copied = |m: &Mat<f64>| {
        Mat::from_fn(n, n, |i, j| {
            if i % copies == j % copies {
                m[(i / copies, j / copies)]
            } else {
                0.0
            }
        })
    };
    let (a, b) = testing::rotate(&copied(&a1), &copied(&b1), &testing::random_orthogonal(n, 5));
    let (ar, br) = testing::ring(12);
    let (ar, br) = testing::rotate(&ar, &br, &testing::random_orthogonal(12, 3));
    for (p, zeros) in [(pencil(&a, &b), copies), (pencil(&ar, &br), 1)] {
        for vectors in [true, false] {
            let options = SolveOptions { vectors, ..all_pairs() };
            let sol = solve(&p, &options).expect("solve");
            let kinds: Vec<ModeKind> = sol.modes.iter().map(|m| m.kind).collect();
            assert!(kinds[..zeros].iter().all(|k| *k == ModeKind::Zero), "{kinds:?}");
            assert!(
                kinds[zeros..].iter().all(|k| matches!(k, ModeKind::Oscillatory { .. })),
                "{kinds:?}"
            );
            assert_eq!(sol.groups[0].multiplicity, zeros, "vectors {vectors}");
            for m in &sol.modes[..zeros] {
                assert!(m.omega_sq.abs() <= 1e-13, "{:e}", m.omega_sq);
            }
        }
    }
}

/// Diagonal pencils: ω² = b_i/a_i exactly. The zero classification follows the data
/// componentwise: a small negative stiffness on a decoupled coordinate beside stiff ones is an
/// instability (growth rate 1e-3), not a rigid-body mode; a soft but exactly stored spring is
/// oscillatory; an exact zero is zero. Values only and with vectors agree.
#[test]
fn resolved_small_modes_are_not_called_zero() {
    let diagonal = |d: &[f64]| Mat::from_fn(d.len(), d.len(), |i, j| if i == j { d[i] } else { 0.0 });
    let cases: [(&[f64], &[f64]); 3] = [
        (&[1.0, 1.0, 1.0], &[-1e-6, 1e10, 2e10]),
        (&[1e6, 1.0], &[1e-3, 1e8]),
        (&[1.0, 1.0, 1e-3, 1.0], &[0.0, 1e-15, 1e-16, 1.0]),
    ];
    for (masses, stiffnesses) in cases {
        let p = pencil(&diagonal(masses), &diagonal(stiffnesses));
        let mut exact: Vec<f64> = masses.iter().zip(stiffnesses).map(|(m, k)| k / m).collect();
        exact.sort_by(f64::total_cmp);
        for vectors in [true, false] {
            let options = SolveOptions { vectors, ..all_pairs() };
            let sol = solve(&p, &options).expect("solve");
            for (m, &w) in sol.modes.iter().zip(&exact) {
                assert!(
                    (m.omega_sq - w).abs() <= m.error_bound + U * w.abs(),
                    "{w:e}: {:e}",
                    m.omega_sq
                );
                let expected = if w == 0.0 {
                    ModeKind::Zero
                } else if w < 0.0 {
                    ModeKind::Unstable {
                        growth_rate: (-m.omega_sq).sqrt(),
                    }
                } else {
                    ModeKind::Oscillatory {
                        omega: m.omega_sq.sqrt(),
                    }
                };
                assert_eq!(m.kind, expected, "ω² = {w:e}, vectors {vectors}");
            }
        }
    }
}

/// Two free chains (two rigid-body modes) beside a chain of six soft springs of 1e-10, stored
/// exactly: the soft modes (ω² from 6e-12) are oscillatory, and the zero group has multiplicity
/// two, the nullity of B.
#[test]
fn soft_springs_do_not_join_the_rigid_body_group() {
    let (af, bf) = testing::free_chain(10);
    let (asoft, bsoft) = testing::spring_chain(&[-10; 6], &[0; 6]);
    let blocks = [(&af, &bf), (&af, &bf), (&asoft, &bsoft)];
    let n: usize = blocks.iter().map(|(a, _)| a.nrows()).sum();
    let mut a = Mat::<f64>::zeros(n, n);
    let mut b = Mat::<f64>::zeros(n, n);
    let mut offset = 0;
    for (ak, bk) in blocks {
        let m = ak.nrows();
        for j in 0..m {
            for i in 0..m {
                a[(offset + i, offset + j)] = ak[(i, j)];
                b[(offset + i, offset + j)] = bk[(i, j)];
            }
        }
        offset += m;
    }
    for vectors in [true, false] {
        let options = SolveOptions { vectors, ..all_pairs() };
        let sol = solve(&pencil(&a, &b), &options).expect("solve");
        assert_eq!(sol.groups[0].multiplicity, 2, "vectors {vectors}");
        assert!(sol.modes[..2].iter().all(|m| m.kind == ModeKind::Zero));
        assert!(
            sol.modes[2..8]
                .iter()
                .all(|m| matches!(m.kind, ModeKind::Oscillatory { .. })),
            "vectors {vectors}: {:?}",
            &sol.modes[2..8]
        );
    }
}
