//! Dense pencils whose entries span up to 80 decades, with random signs and zero patterns
//! (B indefinite), against exact ω² from 250-digit arithmetic on the stored doubles
//! (`tools/modal_wide_range_reference.py`, numbers in `tests/data/wide_range_pencils.txt`).
//!
//! For every pencil and every way of asking (all pairs at each refinement policy, values only,
//! the lowest k, sparse), every returned mode must hold its exact ω² within its bound, and its
//! classification must agree with the exact sign: an oscillatory mode has ω² > 0, an unstable one
//! ω² < 0. A typed error is allowed (the pencil may be beyond what double precision resolves),
//! a wrong number is not.

mod common;

use common::triplets;
use faer::Mat;
use mechanica_modal::{
    ModalError, Mode, ModeKind, PencilProblem, Refinement, Selection, SolveOptions, SparsePencil, SparseSolveOptions,
    solve, solve_sparse,
};

/// One stored pencil with its exact spectrum as (hi, lo) pairs, ascending.
struct Case {
    a: Mat<f64>,
    b: Mat<f64>,
    exact: Vec<(f64, f64)>,
}

fn numbers(line: &str) -> Vec<f64> {
    line.split_whitespace()
        .map(|t| t.parse::<f64>().expect("a number"))
        .collect()
}

fn cases() -> Vec<Case> {
    let text = include_str!("data/wide_range_pencils.txt");
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let mut out = Vec::new();
    while let Some(first) = lines.next() {
        let n: usize = first.trim().parse().expect("an order");
        let a = numbers(lines.next().expect("A"));
        let b = numbers(lines.next().expect("B"));
        let exact = (0..n)
            .map(|_| {
                let v = numbers(lines.next().expect("ω²"));
                (v[0], v[1])
            })
            .collect();
        out.push(Case {
            a: Mat::from_fn(n, n, |i, j| a[i * n + j]),
            b: Mat::from_fn(n, n, |i, j| b[i * n + j]),
            exact,
        });
    }
    out
}

#[derive(Debug, Clone, Copy)]
enum Use {
    All(Refinement),
    ValuesOnly,
    Lowest(usize),
    Sparse(usize),
}

/// The modes, or the typed refusal.
fn modes_of(case: &Case, usage: Use) -> Result<Vec<Mode>, mechanica_modal::ModalError> {
    let n = case.a.nrows();
    if let Use::Sparse(count) = usage {
        let pencil = SparsePencil::from_triplets(n, &triplets(&case.a), &triplets(&case.b))?;
        let options = SparseSolveOptions {
            count,
            ..SparseSolveOptions::default()
        };
        return solve_sparse(&pencil, &options).map(|s| s.modes);
    }
    let problem = PencilProblem::new(case.a.as_ref(), case.b.as_ref())?;
    let mut options = SolveOptions::default();
    match usage {
        Use::All(refinement) => options.refinement = refinement,
        Use::ValuesOnly => options.vectors = false,
        Use::Lowest(k) => options.selection = Selection::Lowest(k),
        Use::Sparse(_) => {}
    }
    solve(&problem, &options).map(|s| s.modes)
}

/// Every mode against the exact ω² of the same rank; a description of each failure.
fn failures(case: &Case, modes: &[Mode]) -> Vec<String> {
    let mut out = Vec::new();
    if modes.len() > case.exact.len() {
        out.push(format!("{} modes for order {}", modes.len(), case.exact.len()));
    }
    for (k, (mode, &(hi, lo))) in modes.iter().zip(&case.exact).enumerate() {
        if hi.is_infinite() || mode.kind == ModeKind::Infinite {
            if !(hi.is_infinite() && mode.kind == ModeKind::Infinite && mode.omega_sq == f64::INFINITY) {
                out.push(format!(
                    "mode {k}: {:?} ω² {:e}, exact {hi:e}",
                    mode.kind, mode.omega_sq
                ));
            }
            continue;
        }
        let error = ((mode.omega_sq - hi) - lo).abs();
        if error.is_nan() || error > mode.error_bound * (1.0 + 4.0 * f64::EPSILON) {
            out.push(format!(
                "mode {k}: ω² {:e} exact {hi:e}, error {error:e} above bound {:e}",
                mode.omega_sq, mode.error_bound
            ));
        }
        let wrong_sign = match mode.kind {
            ModeKind::Oscillatory { .. } => hi <= 0.0,
            ModeKind::Unstable { .. } => hi >= 0.0,
            _ => false,
        };
        let rate_ok = match mode.kind {
            ModeKind::Oscillatory { omega } => omega.is_finite() && omega >= 0.0,
            ModeKind::Unstable { growth_rate } => growth_rate.is_finite() && growth_rate >= 0.0,
            _ => true,
        };
        if wrong_sign || !rate_ok {
            out.push(format!("mode {k}: {:?} but exact ω² {hi:e}", mode.kind));
        }
    }
    out
}

#[test]
fn every_bound_holds_on_pencils_spanning_eighty_decades() {
    let cases = cases();
    assert!(cases.len() >= 100, "the reference file holds {} pencils", cases.len());
    let (mut solved, mut refused, mut problems) = (0, 0, Vec::new());
    for (c, case) in cases.iter().enumerate() {
        let n = case.a.nrows();
        let massless = (0..n).any(|i| case.a[(i, i)] == 0.0);
        let finite = case.exact.iter().filter(|(hi, _)| hi.is_finite()).count();
        let uses = [
            Use::All(Refinement::Auto),
            Use::All(Refinement::Always),
            Use::All(Refinement::Off),
            Use::ValuesOnly,
            Use::Lowest(1 + c % finite),
            Use::Sparse(1 + c % finite.saturating_sub(1).max(1)),
        ];
        for usage in uses {
            match modes_of(case, usage) {
                Ok(modes) => {
                    solved += 1;
                    problems.extend(
                        failures(case, &modes)
                            .into_iter()
                            .map(|f| format!("case {c} {usage:?}: {f}")),
                    );
                }
                // B restricted to the massless directions may be singular within rounding of ‖B‖
                // (entries 40 decades below it): a typed refusal is then a right answer.
                Err(ModalError::SingularPencil { .. }) if massless => refused += 1,
                // The sparse solver may find fewer modes than asked in a tiny pencil.
                Err(_) if matches!(usage, Use::Sparse(_)) => refused += 1,
                Err(e) => problems.push(format!("case {c} {usage:?}: refused: {e}")),
            }
        }
    }
    assert!(
        problems.is_empty(),
        "{} wrong results:\n{}",
        problems.len(),
        problems.join("\n")
    );
    assert!(refused * 5 <= solved, "{refused} refusals against {solved} answers");
}
