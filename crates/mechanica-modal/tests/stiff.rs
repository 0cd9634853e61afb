//! Graded stiff chains (stiffness or stiffness/mass ratios up to 1e12) against 60-digit mpmath
//! references (tools/modal_reference.py → tools/modal_reference.txt, committed).

use mechanica_modal::{BoundKind, PencilProblem, Refinement, Residuals, SolveOptions, families, solve};

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
    assert_eq!(out.len(), 3);
    out
}

fn problem(c: &Case) -> PencilProblem {
    let (a, b) = families::spring_chain(&c.stiffness, &c.mass);
    PencilProblem::new(a.as_ref(), b.as_ref()).expect("valid chain")
}

#[test]
fn reference_chains_are_the_ones_the_crate_builds() {
    let c = cases();
    assert_eq!(c[0].stiffness, families::graded_exponents(24, 12));
    assert_eq!(c[1].stiffness, families::graded_exponents(30, 6));
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
                assert!(m.error_bound <= mechanica_modal::solve::AUTO_REFINE_RELATIVE_BOUND * w);
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

/// Without refinement the reduction loses digits of the lowest mode on the 1e12 chain, and its
/// first-order bound says so honestly: the bound still contains the error.
#[test]
fn unrefined_bounds_are_honest_but_weak() {
    let c = &cases()[0];
    let p = problem(c);
    let sol = solve(
        &p,
        &SolveOptions {
            refinement: Refinement::Off,
            ..SolveOptions::default()
        },
    )
    .expect("solve");
    let low = &sol.modes[0];
    assert_eq!(sol.accuracy.bound_kinds[0], BoundKind::FirstOrder);
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
            assert!(m.error_bound <= mechanica_modal::solve::AUTO_REFINE_RELATIVE_BOUND * w);
        }
        assert_eq!(sol.accuracy.bound_kinds[0], BoundKind::Residual, "{}", c.name);
    }
}
