//! Graded stiff chains (stiffness or stiffness/mass ratios up to 1e12) against 60-digit mpmath
//! references (tools/modal_reference.py → tools/modal_reference.txt, committed).

use mechanica_modal::{BoundKind, PencilProblem, Refinement, Residuals, SolveOptions, solve, testing};

const U: f64 = f64::EPSILON;

struct Case {
    name: String,
    stiffness: Vec<i32>,
    mass: Vec<i32>,
    omega_sq: Vec<f64>,
}

fn cases() -> Vec<Case> {
    let text = include_str!("../../../tools/modal_reference.txt");
    let mut out: Vec<Case> = Vec::new();
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let (key, rest) = line.split_once(' ').expect("key value line");
        let ints = || {
            rest.split_whitespace()
                .map(|t| t.parse::<i32>().expect("exponent"))
                .collect()
        };
        match key {
            "case" => out.push(Case {
                name: rest.to_string(),
                stiffness: Vec::new(),
                mass: Vec::new(),
                omega_sq: Vec::new(),
            }),
            "stiffness" => out.last_mut().expect("case").stiffness = ints(),
            "mass" => out.last_mut().expect("case").mass = ints(),
            "omega_sq" => {
                out.last_mut().expect("case").omega_sq = rest
                    .split_whitespace()
                    .map(|t| t.parse::<f64>().expect("number"))
                    .collect()
            }
            other => panic!("unknown key {other}"),
        }
    }
    assert_eq!(out.len(), 4);
    out
}

fn problem(c: &Case) -> PencilProblem {
    let (a, b) = testing::spring_chain(&c.stiffness, &c.mass);
    PencilProblem::new(a.as_ref(), b.as_ref()).expect("valid chain")
}

#[test]
fn reference_chains_are_the_ones_the_crate_builds() {
    let c = cases();
    assert_eq!(c[0].stiffness, testing::graded_exponents(24, 12));
    assert_eq!(c[1].stiffness, testing::graded_exponents(30, 6));
    assert_eq!(c[3].stiffness, testing::graded_exponents(96, 12));
}

/// The option sets of an automatically refined solve: all pairs, and values only (where the
/// poorly bounded modes get their vectors by inverse iteration), with exact or sketched
/// residuals.
fn auto_options() -> Vec<SolveOptions> {
    let values_only = |residuals| SolveOptions {
        vectors: false,
        residuals,
        ..SolveOptions::default()
    };
    vec![
        SolveOptions::default(),
        values_only(Residuals::Exact),
        values_only(Residuals::Sketched),
    ]
}

/// With automatic refinement every mode is within its stated bound of the 60-digit reference;
/// every bound certifies at least 8 digits (the Auto policy), and the refined modes' residual
/// bounds certify full relative accuracy, ≤ 8·n·u·|ω²| (the gap-weighted residual term is at
/// the u² level; the rest is the rounding of ω² to double). Values only, the lowest mode is
/// refined too, its value is as accurate, and its bound still certifies 8 digits.
#[test]
fn refined_modes_are_correct_to_their_bounds() {
    for c in cases() {
        let p = problem(&c);
        let n = p.dim() as f64;
        for options in auto_options() {
            let sol = solve(&p, &options).expect("solve");
            assert_eq!(sol.modes.len(), c.omega_sq.len());
            assert_eq!(sol.vectors.is_some(), options.vectors);
            assert_eq!(
                sol.accuracy.bound_kinds[0],
                BoundKind::Residual,
                "{} {options:?}",
                c.name
            );
            for (i, (m, &w)) in sol.modes.iter().zip(&c.omega_sq).enumerate() {
                let err = (m.omega_sq - w).abs();
                assert!(
                    err <= m.error_bound,
                    "{} {options:?} mode {i}: error {err:e} > bound {:e}",
                    c.name,
                    m.error_bound
                );
                assert!(m.error_bound <= mechanica_modal::dense::AUTO_REFINE_RELATIVE_BOUND * w);
                let refined = sol.accuracy.bound_kinds[i] == BoundKind::Residual;
                // Values only, the bound is weaker (crate::values_only): the refined value is
                // as accurate as with all vectors, but the residual's components along modes
                // without a computed vector are divided by the smallest gap.
                let certified = if options.vectors { m.error_bound } else { err };
                assert!(
                    !refined || certified <= 8.0 * n * U * w,
                    "{} mode {i}: bound {:e} is not relative-accurate ({:e} relative, kind {:?})",
                    c.name,
                    m.error_bound,
                    m.error_bound / w,
                    sol.accuracy.bound_kinds[i]
                );
            }
            assert!(sol.accuracy.inertia_check.expect("check").consistent);
        }
    }
}

/// All pairs without refinement: the reduction's own accuracy.
fn unrefined(p: &PencilProblem) -> mechanica_modal::ModalSolution {
    let options = SolveOptions {
        refinement: Refinement::Off,
        ..SolveOptions::default()
    };
    solve(p, &options).expect("solve")
}

/// Without refinement the reduction loses digits of the lowest mode on the 1e12 chain, and its
/// bound says so honestly: a weak first-order bound is raised to the a-priori (Weyl) bound when
/// that is larger, and the bound still contains the error.
#[test]
fn unrefined_bounds_are_honest_but_weak() {
    let c = &cases()[0];
    let p = problem(c);
    let sol = unrefined(&p);
    let low = &sol.modes[0];
    assert!(matches!(
        sol.accuracy.bound_kinds[0],
        BoundKind::FirstOrder | BoundKind::APriori
    ));
    assert!((low.omega_sq - c.omega_sq[0]).abs() <= low.error_bound);
    assert!(
        low.error_bound > 1e-8 * c.omega_sq[0],
        "the plain reduction is not relative-accurate here"
    );
    let refined = solve(&p, &SolveOptions::default()).expect("solve");
    assert_eq!(refined.accuracy.bound_kinds[0], BoundKind::Residual);
    assert!(refined.accuracy.refinement_steps[0] >= 1);
    // The lowest mode is among the refined ones in every case.
    for c in cases() {
        let sol = solve(&problem(&c), &SolveOptions::default()).expect("solve");
        assert_eq!(sol.accuracy.bound_kinds[0], BoundKind::Residual, "{}", c.name);
    }
}

/// Values only on a subset (the lowest 3): the refined lowest mode's residual bound allows for
/// the never-measured error of the unselected neighbours, and every value is within its bound
/// of the 60-digit reference.
#[test]
fn values_only_subsets_are_correct_to_their_bounds() {
    for c in cases() {
        let p = problem(&c);
        let options = SolveOptions {
            selection: mechanica_modal::Selection::Lowest(3),
            vectors: false,
            ..SolveOptions::default()
        };
        let sol = solve(&p, &options).expect("solve");
        assert_eq!(sol.modes.len(), 3);
        for (i, (m, &w)) in sol.modes.iter().zip(&c.omega_sq).enumerate() {
            let err = (m.omega_sq - w).abs();
            assert!(
                err <= m.error_bound,
                "{} mode {i}: error {err:e} > bound {:e}",
                c.name,
                m.error_bound
            );
            assert!(m.error_bound <= mechanica_modal::dense::AUTO_REFINE_RELATIVE_BOUND * w);
        }
        assert_eq!(sol.accuracy.bound_kinds[0], BoundKind::Residual, "{}", c.name);
    }
}

/// Two uncoupled copies of a chain, interleaved (copy c's coordinate i is 2i + c; a
/// permutation, so the pencil is stored exactly), the second copy's masses scaled by `scale`:
/// its ω² are those of the chain divided by `scale`.
fn doubled(c: &Case, scale: f64) -> PencilProblem {
    let (a, b) = testing::spring_chain(&c.stiffness, &c.mass);
    let n = a.nrows();
    let copy = |m: &mechanica_modal::faer::Mat<f64>, s: f64| {
        mechanica_modal::faer::Mat::from_fn(2 * n, 2 * n, |i, j| {
            if i % 2 != j % 2 {
                0.0
            } else if i % 2 == 0 {
                m[(i / 2, j / 2)]
            } else {
                s * m[(i / 2, j / 2)]
            }
        })
    };
    PencilProblem::new(copy(&a, scale).as_ref(), copy(&b, 1.0).as_ref()).expect("valid doubled chain")
}

/// A symmetric stiff structure: every eigenvalue of the graded chains doubled. The copies of a
/// repeated eigenvalue are refined together as one block, so the lowest pairs reach full
/// relative accuracy with a bound that says so, as a simple mode does; each group has
/// multiplicity 2 and an A-orthonormal basis. Every bound holds; the modes within the Auto
/// budget ([`Tuning::auto_refined_at_least`], from the lowest up) are bounded to 1e-8
/// relative. Without refinement the same pair keeps only the reduction's accuracy (its bound
/// honest but weak).
#[test]
fn repeated_stiff_modes_are_refined_as_one_block() {
    let tuning = mechanica_modal::Tuning::DEFAULT;
    for c in cases() {
        let p = doubled(&c, 1.0);
        let budget = tuning.auto_refined_at_least.max(p.dim() / tuning.auto_refined_fraction);
        let n = p.dim() as f64;
        for options in auto_options() {
            let sol = solve(&p, &options).expect("solve");
            assert_eq!(sol.groups.len(), c.omega_sq.len(), "{} {options:?}", c.name);
            assert!(sol.groups.iter().all(|g| g.multiplicity == 2), "{} {options:?}", c.name);
            for (i, m) in sol.modes.iter().enumerate() {
                let w = c.omega_sq[i / 2];
                let err = (m.omega_sq - w).abs();
                assert!(
                    err <= m.error_bound,
                    "{} {options:?} mode {i}: error {err:e} > bound {:e}",
                    c.name,
                    m.error_bound
                );
                assert!(
                    i >= budget || m.error_bound <= mechanica_modal::dense::AUTO_REFINE_RELATIVE_BOUND * w,
                    "{} {options:?} mode {i}: bound {:e} relative",
                    c.name,
                    m.error_bound / w
                );
            }
            for i in 0..2 {
                assert_eq!(
                    sol.accuracy.bound_kinds[i],
                    BoundKind::Residual,
                    "{} {options:?}",
                    c.name
                );
                let certified = if options.vectors {
                    sol.modes[i].error_bound
                } else {
                    (sol.modes[i].omega_sq - c.omega_sq[0]).abs()
                };
                assert!(
                    certified <= 8.0 * n * U * c.omega_sq[0],
                    "{} {options:?}: {certified:e}",
                    c.name
                );
            }
            if let Some(x) = &sol.vectors {
                // The refined pair's basis is A-orthonormal.
                let xg = x.as_ref().subcols(0, 2);
                let gram = xg.transpose() * p.a() * xg;
                for (i, j) in [(0, 0), (0, 1), (1, 1)] {
                    let target = if i == j { 1.0 } else { 0.0 };
                    assert!(
                        (gram[(i, j)] - target).abs() <= 10.0 * n * U,
                        "{}: gram {:e}",
                        c.name,
                        gram[(i, j)]
                    );
                }
            }
            assert!(sol.accuracy.inertia_check.expect("check").consistent);
        }
        let plain = unrefined(&p);
        let low = &plain.modes[0];
        assert!((low.omega_sq - c.omega_sq[0]).abs() <= low.error_bound, "{}", c.name);
        if c.name.starts_with("graded_stiffness_n24") {
            assert!(
                low.error_bound > 1e-8 * c.omega_sq[0],
                "the plain reduction is not relative-accurate here"
            );
        }
    }
}

/// Two copies whose masses differ by 2⁻⁴⁰ (exactly representable): every eigenvalue splits by
/// 9.1e-13 relative, far inside the reduction's bounds, so each pair starts as one cluster.
/// The block refinement resolves it: both values match their references (the chain's ω² and
/// ω²/(1 + 2⁻⁴⁰)) within their bounds, and with all vectors the bounds are tight enough that
/// the two come back as separate groups (values only, the bounds are weaker, see
/// `refined_modes_are_correct_to_their_bounds`, and may keep them in one group).
#[test]
fn a_cluster_of_two_close_stiff_modes_is_resolved() {
    let c = &cases()[0];
    let scale = 1.0 + 2f64.powi(-40);
    let p = doubled(c, scale);
    for options in auto_options() {
        let sol = solve(&p, &options).expect("solve");
        let lower = c.omega_sq[0] / scale;
        let upper = c.omega_sq[0];
        for (m, w) in sol.modes.iter().zip([lower, upper]) {
            // The reference ω²/(1 + 2⁻⁴⁰) is itself rounded: allow u·w for it.
            let err = (m.omega_sq - w).abs();
            assert!(
                err <= m.error_bound + U * w,
                "{options:?}: error {err:e} > bound {:e}",
                m.error_bound
            );
            assert!(
                !options.vectors || m.error_bound <= 1e-3 * (upper - lower),
                "{options:?}: bound {:e}",
                m.error_bound
            );
        }
        assert!(
            !options.vectors || sol.modes[0].group != sol.modes[1].group,
            "{options:?}"
        );
    }
}

/// A selection that cuts a repeated stiff eigenvalue (the lowest 1 of a doubled pair) cannot
/// refine it as a block from its own modes (the other copy is not selected), which would leave
/// the reduction's weak bound; the solve is repeated with a wider selection, and the pair is
/// refined whole. The lowest 1, 2 and 3 all get residual bounds to 1e-8, and the Sturm check
/// agrees in every case.
#[test]
fn a_selection_that_cuts_a_cluster_is_refined_whole() {
    let c = &cases()[0];
    let p = doubled(c, 1.0);
    let w = c.omega_sq[0];
    for (count, refined) in [(1, true), (2, true), (3, true)] {
        let options = SolveOptions {
            selection: mechanica_modal::Selection::Lowest(count),
            ..SolveOptions::default()
        };
        let sol = solve(&p, &options).expect("solve");
        assert_eq!(sol.modes.len(), count);
        let low = &sol.modes[0];
        assert!((low.omega_sq - w).abs() <= low.error_bound, "lowest {count}");
        let kind = sol.accuracy.bound_kinds[0];
        assert_eq!(kind == BoundKind::Residual, refined, "lowest {count}: {kind:?}");
        assert_eq!(
            low.error_bound <= 1e-8 * w,
            refined,
            "lowest {count}: {:e}",
            low.error_bound / w
        );
        // The Sturm shift is placed in a real gap, not between the two copies the cut split.
        let check = sol.accuracy.inertia_check.expect("check");
        assert!(check.consistent, "lowest {count}: {check:?}");
    }
}

/// A cluster that chains three exact zero modes (three free chains) to six soft ones (a fixed
/// chain with springs of 1e-6), beside a 1e12-graded chain, permuted (i → 7i mod 44, exact):
/// the block refinement's bounds hold at ω² = 0 too, where a bound scaled by each member's own
/// |ω²| would vanish (and fall far below the computed ω² of a zero mode).
#[test]
fn a_zero_cluster_chained_to_soft_modes_keeps_valid_bounds() {
    let (af, bf) = testing::free_chain(10);
    let (asoft, bsoft) = testing::fixed_chain(6);
    let c = testing::power_of_ten(-6);
    let bsoft = mechanica_modal::faer::Mat::from_fn(6, 6, |i, j| c * bsoft[(i, j)]);
    let (ag, bg) = testing::spring_chain(&testing::graded_exponents(8, 12), &[0; 8]);
    let blocks = [(&af, &bf), (&af, &bf), (&af, &bf), (&asoft, &bsoft), (&ag, &bg)];
    let n = 44;
    let place = |i: usize| (7 * i) % n;
    let mut a = mechanica_modal::faer::Mat::<f64>::zeros(n, n);
    let mut b = mechanica_modal::faer::Mat::<f64>::zeros(n, n);
    let mut offset = 0;
    for (ak, bk) in blocks {
        let m = ak.nrows();
        for j in 0..m {
            for i in 0..m {
                a[(place(offset + i), place(offset + j))] = ak[(i, j)];
                b[(place(offset + i), place(offset + j))] = bk[(i, j)];
            }
        }
        offset += m;
    }
    assert_eq!(offset, n);
    let p = PencilProblem::new(a.as_ref(), b.as_ref()).expect("valid pencil");
    let soft: Vec<f64> = testing::fixed_chain_omega_sq(6).iter().map(|w| c * w).collect();
    let exact: Vec<f64> = [0.0, 0.0, 0.0].iter().chain(&soft).copied().collect();
    for options in auto_options() {
        let sol = solve(&p, &options).expect("solve");
        for (i, (m, &w)) in sol.modes.iter().zip(&exact).enumerate() {
            let err = (m.omega_sq - w).abs();
            assert!(
                err <= m.error_bound + 4.0 * U * w,
                "{options:?} mode {i}: error {err:e} > bound {:e}",
                m.error_bound
            );
        }
        assert_eq!(sol.groups[0].multiplicity, 3, "{options:?}");
    }
}

/// A chain turned by Q = diag(H, H, …) with H the 4×4 Hadamard matrix over 2 (exactly
/// orthogonal in binary): QᵀBQ has entries (integer sums)/4 of a chain whose springs are integer
/// powers of ten below 2⁵³, so it is formed exactly and has the reference's eigenvalues. Its
/// stiffness is block tridiagonal with 4×4 blocks (about 12n nonzeros), dense to the solver at
/// n = 96, so the dense refinement paths are taken.
fn hadamard_turned(c: &Case) -> PencilProblem {
    let (a, b) = testing::spring_chain(&c.stiffness, &c.mass);
    let n = a.nrows();
    assert_eq!(n % 4, 0);
    let sign = |i: usize, j: usize| {
        if (i & j).count_ones().is_multiple_of(2) {
            0.5
        } else {
            -0.5
        }
    };
    let q = mechanica_modal::faer::Mat::from_fn(n, n, |i, j| if i / 4 == j / 4 { sign(i % 4, j % 4) } else { 0.0 });
    let turn = |m: &mechanica_modal::faer::Mat<f64>| q.transpose() * m * &q;
    PencilProblem::new(turn(&a).as_ref(), turn(&b).as_ref()).expect("valid turned chain")
}

/// The 96-mass chain turned densely ([`hadamard_turned`]): with Auto refinement, all pairs and
/// the lowest 3 with and without vectors, the lowest modes are within their bounds of the
/// 60-digit references and certified to the 8 digits Auto promises: the steps must iterate in
/// double-double where a double iterate would stop the lowest bound near 1e-6 relative, and a
/// cluster of the lowest two whose block step fails must not keep first-order bounds.
#[test]
fn a_densely_turned_long_chain_is_certified_to_its_references() {
    let c = cases()
        .into_iter()
        .find(|c| c.name == "graded_stiffness_n96")
        .expect("case");
    let p = hadamard_turned(&c);
    for selection in [mechanica_modal::Selection::All, mechanica_modal::Selection::Lowest(3)] {
        for vectors in [true, false] {
            let options = SolveOptions {
                selection,
                vectors,
                ..SolveOptions::default()
            };
            let sol = solve(&p, &options).expect("solve");
            for (i, (m, &w)) in sol.modes.iter().zip(&c.omega_sq).take(3).enumerate() {
                let err = (m.omega_sq - w).abs();
                assert!(
                    err <= m.error_bound,
                    "{options:?} mode {i}: error {err:e} > bound {:e}",
                    m.error_bound
                );
                assert!(
                    m.error_bound <= mechanica_modal::dense::AUTO_REFINE_RELATIVE_BOUND * w,
                    "{options:?} mode {i}: bound {:e} relative",
                    m.error_bound / w
                );
            }
        }
    }
}
