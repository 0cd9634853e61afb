//! Dense graded pencils with exactly known spectra, outside the spring chains and trees: every
//! coordinate coupled to every other (a complete graph), masses graded at random over up to
//! 2^±40 (not monotone). With A = D² and B = D C D, D a diagonal of powers of two and
//! C = a·I − b·11ᵀ with small integers a, b, every entry is stored exactly and the pencil's
//! ω² are those of C: a − n·b once and a with multiplicity n − 1. Choosing a > n·b, a = n·b or
//! a < n·b gives a positive definite B, a free structure with one rigid-body mode, or one
//! unstable mode.
//!
//! Every case asserts, for every mode and every way of asking for modes: the exact ω² of the
//! mode's rank lies within its bound; a mode is never called zero unless its exact ω² is zero;
//! no mode has the wrong sign; and with B positive definite every mode is oscillatory
//! (Sylvester's law, proven by the scaled Cholesky test however B is graded).

use faer::Mat;
use mechanica_modal::testing::graded::SplitMix;
use mechanica_modal::testing::times_power_of_two;
use mechanica_modal::{Mode, ModeKind, PencilProblem, Refinement, Selection, SolveOptions, solve};
use proptest::prelude::*;

/// The three kinds of stiffness the family draws.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Stiffness {
    Definite,
    Free,
    Indefinite,
}

/// A graded complete-graph pencil and its exact ω², ascending.
fn complete_graph(seed: u64, n: usize, kind: Stiffness) -> (Mat<f64>, Mat<f64>, Vec<f64>) {
    let mut rng = SplitMix::new(seed);
    let spread = 1 + rng.below(40) as i32;
    let exponents: Vec<i32> = (0..n)
        .map(|_| rng.below(2 * spread as usize + 1) as i32 - spread)
        .collect();
    let b_coupling = 1.0 + rng.below(4) as f64;
    let nb = n as f64 * b_coupling;
    let a_diagonal = match kind {
        Stiffness::Definite => nb + 1.0 + rng.below(2 * n) as f64,
        Stiffness::Free => nb,
        Stiffness::Indefinite => nb - 1.0 - rng.below(n) as f64,
    };
    let d = |i: usize| times_power_of_two(1.0, exponents[i]);
    let a = Mat::from_fn(n, n, |i, j| if i == j { d(i) * d(i) } else { 0.0 });
    let c = |i: usize, j: usize| if i == j { a_diagonal - b_coupling } else { -b_coupling };
    let b = Mat::from_fn(n, n, |i, j| d(i) * c(i, j) * d(j));
    let mut exact = vec![a_diagonal; n];
    exact[0] = a_diagonal - nb;
    exact.sort_by(f64::total_cmp);
    (a, b, exact)
}

/// The ways a user asks for modes.
#[derive(Debug, Clone, Copy)]
enum Use {
    Default,
    Always,
    Off,
    ValuesOnly,
    Lowest(usize),
}

fn modes_of(a: &Mat<f64>, b: &Mat<f64>, usage: Use) -> Vec<Mode> {
    let problem = PencilProblem::new(a.as_ref(), b.as_ref()).expect("valid pencil");
    let mut options = SolveOptions::default();
    match usage {
        Use::Always => options.refinement = Refinement::Always,
        Use::Off => options.refinement = Refinement::Off,
        Use::ValuesOnly => options.vectors = false,
        Use::Lowest(k) => options.selection = Selection::Lowest(k.min(a.nrows())),
        Use::Default => {}
    }
    solve(&problem, &options).expect("dense solve").modes
}

/// Whether `kind` is a classification the exact value `exact` allows: zero only for an exact
/// zero, a sign only where it is the exact one, undecided always (it claims nothing).
fn allowed(kind: ModeKind, exact: f64) -> bool {
    match kind {
        ModeKind::Zero => exact == 0.0,
        ModeKind::Oscillatory { .. } => exact > 0.0,
        ModeKind::Unstable { .. } => exact < 0.0,
        ModeKind::Undecided => true,
        ModeKind::Infinite => false,
    }
}

fn check(seed: u64, n: usize, kind: Stiffness, usage: Use) -> Result<(), String> {
    let (a, b, exact) = complete_graph(seed, n, kind);
    let modes = modes_of(&a, &b, usage);
    let expected = match usage {
        Use::Lowest(k) => k.min(n),
        _ => n,
    };
    if modes.len() != expected {
        return Err(format!("{} modes, expected {expected}", modes.len()));
    }
    for (rank, (mode, &exact)) in modes.iter().zip(&exact).enumerate() {
        let error = (mode.omega_sq - exact).abs();
        if error > mode.error_bound {
            return Err(format!(
                "mode {rank}: ω² = {} ± {}, exact {exact}",
                mode.omega_sq, mode.error_bound
            ));
        }
        if !allowed(mode.kind, exact) {
            return Err(format!(
                "mode {rank}: exact ω² = {exact} called {:?} ({mode:?})",
                mode.kind
            ));
        }
        if kind == Stiffness::Definite && !matches!(mode.kind, ModeKind::Oscillatory { .. }) {
            return Err(format!("mode {rank} of a definite B called {:?}", mode.kind));
        }
    }
    Ok(())
}

fn usage_of(index: usize) -> Use {
    [Use::Default, Use::Always, Use::Off, Use::ValuesOnly, Use::Lowest(3)][index % 5]
}

fn stiffness_of(index: usize) -> Stiffness {
    [Stiffness::Definite, Stiffness::Free, Stiffness::Indefinite][index % 3]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]
    #[test]
    fn graded_complete_graphs_keep_their_bounds_and_classes(
        seed in any::<u64>(),
        n in 2usize..40,
        kind in 0usize..3,
        usage in 0usize..5,
    ) {
        let (kind, usage) = (stiffness_of(kind), usage_of(usage));
        prop_assert_eq!(check(seed, n, kind, usage), Ok(()), "{:?}, {:?}", kind, usage);
    }
}

/// Four masses graded by 2^±30 on a complete graph (C = 5I − 11ᵀ: ω² = 1 and 5, 5, 5): values
/// only, every mode was once called zero with bounds of 36–40, since the norm-wise resolution of
/// the graded data exceeded the values.
#[test]
fn four_graded_masses_on_a_complete_graph_are_oscillatory() {
    let exponents = [14, 27, 23, 1];
    let d = |i: usize| times_power_of_two(1.0, exponents[i]);
    let a = Mat::from_fn(4, 4, |i, j| if i == j { d(i) * d(i) } else { 0.0 });
    let b = Mat::from_fn(4, 4, |i, j| d(i) * if i == j { 4.0 } else { -1.0 } * d(j));
    for usage in [Use::Default, Use::Always, Use::Off, Use::ValuesOnly, Use::Lowest(2)] {
        for (mode, exact) in modes_of(&a, &b, usage).iter().zip([1.0, 5.0, 5.0, 5.0]) {
            assert!(matches!(mode.kind, ModeKind::Oscillatory { .. }), "{usage:?}: {mode:?}");
            assert!((mode.omega_sq - exact).abs() <= mode.error_bound, "{usage:?}: {mode:?}");
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]
    /// A complete graph of 17 to 64 masses graded over up to 2^±40 has one eigenvalue
    /// repeated n − 1 times, and the reduction's bounds (u‖B‖‖A⁻¹‖, up to 1e12 here) make the
    /// whole spectrum one cluster. Refined as one block, with the default options, every mode is
    /// decided: the rigid-body mode of the free graph zero, all others oscillatory, the values
    /// to 1e-8 relative.
    #[test]
    fn large_repeated_clusters_of_graded_pencils_are_refined_and_decided(
        seed in any::<u64>(),
        n in 17usize..65,
        free in any::<bool>(),
    ) {
        let kind = if free { Stiffness::Free } else { Stiffness::Definite };
        prop_assert_eq!(check(seed, n, kind, Use::Default), Ok(()));
        let (a, b, exact) = complete_graph(seed, n, kind);
        for (mode, &exact) in modes_of(&a, &b, Use::Default).iter().zip(&exact) {
            if exact == 0.0 {
                prop_assert_eq!(mode.kind, ModeKind::Zero, "{:?}", mode);
            } else {
                prop_assert!(matches!(mode.kind, ModeKind::Oscillatory { .. }), "{:?}", mode);
                prop_assert!(mode.error_bound <= 1e-8 * exact, "{:?}, exact {}", mode, exact);
            }
        }
    }

    /// The lowest few modes of the same pencils: the selection's edge cuts the repeated
    /// eigenvalue, and the solve widens it so that the cluster is refined whole. Every selected
    /// mode is decided, its value to 1e-8 relative, and the Sturm check is consistent.
    #[test]
    fn a_lowest_selection_that_cuts_a_repeated_cluster_is_decided(
        seed in any::<u64>(),
        n in 17usize..65,
        k in 2usize..7,
        free in any::<bool>(),
    ) {
        let kind = if free { Stiffness::Free } else { Stiffness::Definite };
        prop_assert_eq!(check(seed, n, kind, Use::Lowest(k)), Ok(()));
        let (a, b, exact) = complete_graph(seed, n, kind);
        let problem = PencilProblem::new(a.as_ref(), b.as_ref()).expect("valid pencil");
        let options = SolveOptions {
            selection: Selection::Lowest(k),
            ..SolveOptions::default()
        };
        let solution = solve(&problem, &options).expect("dense solve");
        prop_assert_eq!(solution.modes.len(), k);
        prop_assert_eq!(solution.vectors.as_ref().map(|x| x.ncols()), Some(k));
        prop_assert!(solution.accuracy.inertia_check.is_some_and(|c| c.consistent));
        for (mode, &exact) in solution.modes.iter().zip(&exact) {
            if exact == 0.0 {
                prop_assert_eq!(mode.kind, ModeKind::Zero, "{:?}", mode);
            } else {
                prop_assert!(matches!(mode.kind, ModeKind::Oscillatory { .. }), "{:?}", mode);
                prop_assert!(mode.error_bound <= 1e-8 * exact, "{:?}, exact {}", mode, exact);
            }
        }
    }
}
