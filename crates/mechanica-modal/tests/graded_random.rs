//! Random graded spring systems: chains and random trees, fixed and free, masses over 8 decades
//! and stiffnesses over 12 drawn independently (not monotone), coordinates numbered at random.
//! The reference spectra come from bisection on double-double inertia counts of the stored
//! matrices (`testing::graded::tree_pencil_spectrum`), independent of the solvers.
//!
//! Every case asserts, for every mode returned: the exact ω² lies within the reported bound;
//! the classification is right (a fixed system has no zero and no unstable mode, a free one
//! exactly one zero mode); and, with `Refinement::Auto`, the five lowest non-rigid modes are
//! right to 1e-8 relative.

mod common;

use common::triplets;
use faer::Mat;
use faer::sparse::Triplet;
use mechanica_modal::testing::graded::{GradedFamily, Shape, SpringTree, spring_tree, tree_pencil_spectrum};
use mechanica_modal::testing::times_power_of_two;
use mechanica_modal::{
    Mode, ModeKind, PencilProblem, Selection, SolveOptions, SparsePencil, SparseSolveOptions, solve, solve_sparse,
};
use proptest::prelude::*;

/// The ways a user asks for modes.
#[derive(Debug, Clone, Copy)]
enum Use {
    AllPairs,
    ValuesOnly,
    Lowest(usize),
    Sparse(usize),
}

fn modes_of(system: &SpringTree, usage: Use) -> Vec<Mode> {
    let n = system.a.nrows();
    if let Use::Sparse(count) = usage {
        let pencil =
            SparsePencil::from_triplets(n, &triplets(&system.a), &triplets(&system.b)).expect("valid sparse pencil");
        let options = SparseSolveOptions {
            count,
            ..SparseSolveOptions::default()
        };
        return solve_sparse(&pencil, &options).expect("sparse solve").modes;
    }
    let problem = PencilProblem::new(system.a.as_ref(), system.b.as_ref()).expect("valid pencil");
    let mut options = SolveOptions::default();
    match usage {
        Use::ValuesOnly => options.vectors = false,
        Use::Lowest(k) => options.selection = Selection::Lowest(k),
        _ => {}
    }
    solve(&problem, &options).expect("dense solve").modes
}

/// Checks every assertion of the module documentation on one system; returns a description of
/// the first failure.
fn check(system: &SpringTree, usage: Use) -> Result<(), String> {
    let reference = tree_pencil_spectrum(system);
    let modes = modes_of(system, usage);
    let rigid = system.rigid_modes;
    for (k, (mode, exact)) in modes.iter().zip(&reference).enumerate() {
        let error = (mode.omega_sq - exact).abs();
        // The reference's own accuracy: 1e-24 relative, 1e-300 absolute.
        let allowed = mode.error_bound + 1e-24 * exact.abs() + 1e-300;
        if error.is_nan() || error > allowed {
            return Err(format!(
                "mode {k}: ω² {} exact {exact} error {error:e} > bound {:e}",
                mode.omega_sq, mode.error_bound
            ));
        }
        let kind_ok = match mode.kind {
            ModeKind::Zero => k < rigid,
            ModeKind::Oscillatory { .. } => k >= rigid,
            _ => false,
        };
        if !kind_ok {
            return Err(format!(
                "mode {k} (ω² {}, exact {exact}) classified {:?}",
                mode.omega_sq, mode.kind
            ));
        }
        if (rigid..rigid + 5).contains(&k) && error > 1e-8 * exact.abs() {
            return Err(format!("low mode {k}: relative error {:e}", error / exact.abs()));
        }
    }
    Ok(())
}

fn family(n: usize, tree: bool, fixed: bool, mass_decades: f64, stiffness_decades: f64) -> GradedFamily {
    let shape = if tree { Shape::Tree } else { Shape::Chain };
    GradedFamily {
        mass_decades: (-mass_decades, 0.0),
        stiffness_decades: (0.0, stiffness_decades),
        ..GradedFamily::new(n, shape, fixed)
    }
}

fn usage(code: u8, n: usize) -> Use {
    match code % 4 {
        0 => Use::AllPairs,
        1 => Use::ValuesOnly,
        2 => Use::Lowest(5.min(n)),
        _ => Use::Sparse(6.min(n)),
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    /// Random sizes, shapes, supports, grading ranges (up to 8 decades of mass and 12 of
    /// stiffness), seeds and modes of use.
    #[test]
    fn random_graded_systems_have_true_bounds_right_kinds_and_accurate_low_modes(
        n in 6usize..90,
        tree in any::<bool>(),
        fixed in any::<bool>(),
        mass_decades in 0.0f64..8.0,
        stiffness_decades in 0.0f64..12.0,
        code in any::<u8>(),
        seed in any::<u64>(),
    ) {
        let system = spring_tree(&family(n, tree, fixed, mass_decades, stiffness_decades), seed);
        if let Err(failure) = check(&system, usage(code, n)) {
            prop_assert!(false, "{}", failure);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(6))]
    /// The same properties at 320–420 masses, between the random sizes above and the
    /// thousand-mass systems below, over random shapes, supports, full gradings, seeds and
    /// modes of use.
    #[test]
    fn graded_systems_of_three_to_four_hundred_masses(
        n in 320usize..420,
        tree in any::<bool>(),
        fixed in any::<bool>(),
        code in any::<u8>(),
        seed in any::<u64>(),
    ) {
        let system = spring_tree(&family(n, tree, fixed, 8.0, 12.0), seed);
        if let Err(failure) = check(&system, usage(code, n)) {
            prop_assert!(false, "{}", failure);
        }
    }
}

/// The full grading at the larger sizes, one seed per shape, support and use.
#[test]
fn fully_graded_systems_of_a_few_hundred_masses() {
    for (k, (tree, fixed)) in [(false, true), (true, true), (false, false), (true, false)]
        .into_iter()
        .enumerate()
    {
        for code in 0..2u8 {
            let system = spring_tree(&family(240, tree, fixed, 8.0, 12.0), 1000 + k as u64);
            if let Err(e) = check(&system, usage(code + k as u8, 240)) {
                panic!("tree {tree} fixed {fixed} use {:?}: {e}", usage(code + k as u8, 240));
            }
        }
    }
}

/// Seeds on which the reduction alone gave low modes with no correct digit, negative ω² for a
/// fixed chain, rigid-body modes the data do not have, and values outside their bounds.
#[test]
fn regression_seeds_of_each_kind() {
    let cases = [
        (120, false, true, 1, Use::AllPairs),
        (30, true, true, 8, Use::AllPairs),
        (120, false, false, 0, Use::AllPairs),
        (30, true, false, 7, Use::AllPairs),
        (60, false, true, 6, Use::ValuesOnly),
        (60, true, false, 3, Use::Lowest(5)),
        (60, false, false, 0, Use::Sparse(6)),
    ];
    for (n, tree, fixed, seed, use_) in cases {
        let system = spring_tree(&family(n, tree, fixed, 8.0, 12.0), seed);
        if let Err(e) = check(&system, use_) {
            panic!("n {n} tree {tree} fixed {fixed} seed {seed} {use_:?}: {e}");
        }
    }
}

/// The reference itself: on a unit fixed chain it reproduces the closed form
/// ω²_k = 4 sin²(kπ / (2(n + 1))) to a few ulps.
#[test]
fn the_reference_reproduces_the_closed_form_of_a_unit_chain() {
    let n = 40;
    let (a, b) = mechanica_modal::testing::fixed_chain(n);
    let parent = (0..n).map(|i| i.checked_sub(1)).collect();
    let system = SpringTree {
        a,
        b,
        parent,
        rigid_modes: 0,
    };
    let exact = mechanica_modal::testing::fixed_chain_omega_sq(n);
    for (r, e) in tree_pencil_spectrum(&system).iter().zip(&exact) {
        assert!((r - e).abs() <= 4.0 * f64::EPSILON * e, "{r} vs {e}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]
    /// A graded system with A scaled by 2^p and B by 2^q, anywhere in the double range (entries
    /// up to 1e308 and down to subnormal): the modes are the unscaled reference times 2^(q − p)
    /// within their bounds, and a spectrum that leaves the range of doubles is a typed error.
    #[test]
    fn graded_systems_anywhere_in_the_double_range(
        n in 4usize..40,
        tree in any::<bool>(),
        fixed in any::<bool>(),
        p in -1000i32..1000,
        q in -1000i32..1000,
        seed in any::<u64>(),
    ) {
        let system = spring_tree(&family(n, tree, fixed, 4.0, 6.0), seed);
        let reference = tree_pencil_spectrum(&system);
        let (lo_a, hi_a) = (1e-4 * 0.9, 1.0);
        let (lo_b, hi_b) = (1e-300, 4.0 * 1e6);
        // Keep every stored nonzero entry a normal or subnormal double, never zero or infinite.
        prop_assume!(times_power_of_two(lo_a, p) > 0.0 && times_power_of_two(hi_a, p).is_finite());
        prop_assume!(times_power_of_two(hi_b, q).is_finite() && times_power_of_two(lo_b, q) >= 0.0);
        let scaled = |m: &Mat<f64>, e: i32| Mat::from_fn(m.nrows(), m.ncols(), |i, j| times_power_of_two(m[(i, j)], e));
        let (a, b) = (scaled(&system.a, p), scaled(&system.b, q));
        prop_assume!(b.col_iter().flat_map(|c| c.iter().copied().collect::<Vec<_>>()).zip(system.b.col_iter().flat_map(|c| c.iter().copied().collect::<Vec<_>>())).all(|(s, o)| (s == 0.0) == (o == 0.0) && times_power_of_two(s, -q) == o));
        let problem = PencilProblem::new(a.as_ref(), b.as_ref()).expect("finite pencil");
        let exact: Vec<f64> = reference.iter().map(|&w| times_power_of_two(w, q - p)).collect();
        let representable = exact.iter().all(|w| w.is_finite());
        match solve(&problem, &SolveOptions::default()) {
            Ok(solution) => {
                prop_assert!(representable);
                for (k, (mode, w)) in solution.modes.iter().zip(&exact).enumerate() {
                    let error = (mode.omega_sq - w).abs();
                    let allowed = mode.error_bound + 1e-24 * w.abs() + times_power_of_two(1e-300, q - p).max(f64::from_bits(1));
                    prop_assert!(error <= allowed, "mode {}: {} vs {} (bound {:e})", k, mode.omega_sq, w, mode.error_bound);
                }
            }
            Err(mechanica_modal::ModalError::OutOfRange { .. }) => prop_assert!(!representable || exact.iter().any(|w| w.abs() > 1e300)),
            Err(other) => prop_assert!(false, "unexpected error {}", other),
        }
    }
}

/// Lumped masses 1, 2, 3 and 1.8e19 on a chain: a small mass is a mass, never a massless
/// coordinate, however large its neighbour.
#[test]
fn a_small_mass_beside_a_huge_one_is_not_massless() {
    let masses = [1.0, 2.0, 3.0, 1.8e19];
    let n = masses.len();
    let a = Mat::from_fn(n, n, |i, j| if i == j { masses[i] } else { 0.0 });
    let b = mechanica_modal::testing::fixed_chain(n).1;
    let parent = (0..n).map(|i| i.checked_sub(1)).collect();
    let system = SpringTree {
        a,
        b,
        parent,
        rigid_modes: 0,
    };
    let reference = tree_pencil_spectrum(&system);
    let problem = PencilProblem::new(system.a.as_ref(), system.b.as_ref()).expect("pencil");
    let solution = solve(&problem, &SolveOptions::default()).expect("solve");
    for (mode, exact) in solution.modes.iter().zip(&reference) {
        assert!(matches!(mode.kind, ModeKind::Oscillatory { .. }), "{mode:?}");
        assert!(
            (mode.omega_sq - exact).abs() <= mode.error_bound,
            "{} vs {exact}",
            mode.omega_sq
        );
    }
}

/// The sparse solver's own path (Lanczos above the dense limit) on graded chains and trees of a
/// few thousand masses: the six lowest modes within their bounds, right to 1e-8, classified.
#[test]
fn sparse_lanczos_on_large_graded_systems() {
    for (k, (tree, fixed)) in [(false, true), (true, true), (false, false), (true, false)]
        .into_iter()
        .enumerate()
    {
        let n = 800;
        let system = spring_tree(&family(n, tree, fixed, 8.0, 12.0), 77 + k as u64);
        let reference = mechanica_modal::testing::graded::tree_pencil_lowest(&system, 6);
        let modes = modes_of(&system, Use::Sparse(6));
        for (i, (mode, exact)) in modes.iter().zip(&reference).enumerate() {
            let error = (mode.omega_sq - exact).abs();
            let context = format!(
                "tree {tree} fixed {fixed} mode {i}: {} vs {exact}, bound {:e}",
                mode.omega_sq, mode.error_bound
            );
            assert!(error <= mode.error_bound + 1e-24 * exact.abs() + 1e-300, "{context}");
            if i >= system.rigid_modes {
                assert!(error <= 1e-8 * exact.abs(), "{context}");
                assert!(
                    matches!(mode.kind, ModeKind::Oscillatory { .. }),
                    "{context}: {:?}",
                    mode.kind
                );
            } else {
                assert_eq!(mode.kind, ModeKind::Zero, "{context}");
            }
        }
    }
}

/// A declared order far beyond the entries (a file of one entry declaring 10⁹ or 2⁶³
/// coordinates) is a singular pencil, refused before anything of that order is allocated; every
/// coordinate with an entry in A or B passes.
#[test]
fn coordinates_without_entries_are_refused_before_allocation() {
    use mechanica_modal::{ModalError, check_every_coordinate_used};
    let one = [Triplet::new(0, 0, 1.0)];
    for order in [2usize, 12_000, 1_000_000_000, 1 << 63] {
        match check_every_coordinate_used(order, &one, &one) {
            Err(ModalError::EmptyCoordinate { index: 1, order: o }) => assert_eq!(o, order),
            other => panic!("order {order}: {other:?}"),
        }
    }
    let a = [Triplet::new(0, 0, 1.0), Triplet::new(2, 2, 1.0)];
    let b = [Triplet::new(1, 0, -1.0)];
    assert!(check_every_coordinate_used(3, &a, &b).is_ok());
    assert!(matches!(
        check_every_coordinate_used(4, &a, &b),
        Err(ModalError::EmptyCoordinate { index: 3, .. })
    ));
    assert!(SparsePencil::from_triplets(1 << 40, &one, &one).is_err());
}

/// Fixed chains and trees of a thousand masses, where B's smallest eigenvalues fall below the
/// rounding that a double-precision Cholesky factorization of B can resolve: no mode is zero
/// or unstable (B stays positive definite under the rounding of every entry, proven by the
/// forest elimination), and the lowest five values lie within bounds of at most 1e-8
/// relative, in every mode of use. The first seed is the work-precision report's chain, whose
/// lowest mode was called zero before the forest proof, and whose residual bounds on its
/// lowest four modes exceed the values (inertia enclosures give them 2e-11).
#[test]
fn fixed_systems_of_a_thousand_masses_have_no_zero_modes() {
    for (shape, seed, use_) in [
        (Shape::Chain, 0x5eed + 1000, Use::AllPairs),
        (Shape::Chain, 41, Use::ValuesOnly),
        (Shape::Chain, 42, Use::Lowest(5)),
        (Shape::Tree, 43, Use::AllPairs),
        (Shape::Tree, 44, Use::Sparse(6)),
    ] {
        let system = spring_tree(&GradedFamily::new(1000, shape, true), seed);
        let lowest = mechanica_modal::testing::graded::tree_pencil_lowest(&system, 5);
        let modes = modes_of(&system, use_);
        for (k, mode) in modes.iter().enumerate() {
            assert!(
                matches!(mode.kind, ModeKind::Oscillatory { .. }),
                "{shape:?} seed {seed} {use_:?}: mode {k} (ω² {:e} ± {:e}) classified {:?}",
                mode.omega_sq,
                mode.error_bound,
                mode.kind
            );
        }
        assert_bounded_to_eight_digits(&modes, &lowest, 0, &format!("{shape:?} seed {seed} {use_:?}"));
    }
}

/// Free chains and trees of a thousand masses keep exactly one zero mode: the proof of a
/// positive definite stiffness asks for room for the rounding of every entry, which a free
/// structure's assembled stiffness (singular up to that rounding) never has. The next modes are
/// oscillatory: where their intervals chain with the zero mode's wide one (the chain's members
/// share its bound), an inertia count of the forest B − sA orders them above it, and the four
/// above the zero mode lie within bounds of at most 1e-8 relative (inertia enclosures with a
/// margin relative to B + ω²A).
#[test]
fn free_systems_of_a_thousand_masses_keep_one_zero_mode() {
    for (shape, seed, use_) in [
        (Shape::Chain, 51, Use::AllPairs),
        (Shape::Chain, 52, Use::ValuesOnly),
        (Shape::Tree, 53, Use::Lowest(5)),
        (Shape::Tree, 54, Use::ValuesOnly),
    ] {
        let system = spring_tree(&GradedFamily::new(1000, shape, false), seed);
        let modes = modes_of(&system, use_);
        let kinds: Vec<_> = modes.iter().take(3).map(|m| m.kind).collect();
        assert!(
            kinds[0] == ModeKind::Zero && kinds[1..].iter().all(|k| matches!(k, ModeKind::Oscillatory { .. })),
            "{shape:?} seed {seed} {use_:?}: lowest kinds {kinds:?}"
        );
        let lowest = mechanica_modal::testing::graded::tree_pencil_lowest(&system, 5);
        assert_bounded_to_eight_digits(&modes, &lowest, 1, &format!("{shape:?} seed {seed} {use_:?}"));
    }
}

/// Modes `from`.. of `lowest` (the exact lowest ω²) lie within their bounds, and each bound is
/// at most 1e-8 of the value.
fn assert_bounded_to_eight_digits(modes: &[Mode], lowest: &[f64], from: usize, context: &str) {
    for (k, exact) in lowest.iter().enumerate().skip(from) {
        let error = (modes[k].omega_sq - exact).abs();
        assert!(
            error <= modes[k].error_bound + 1e-24 * exact && modes[k].error_bound <= 1e-8 * exact,
            "{context}: mode {k} ω² {:e} exact {exact:e} bound {:e}",
            modes[k].omega_sq,
            modes[k].error_bound
        );
    }
}
