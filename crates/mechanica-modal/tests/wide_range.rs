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
    BoundKind, ModalError, Mode, ModeKind, PencilProblem, Refinement, Selection, SolveOptions, SparsePencil,
    SparseSolveOptions, solve, solve_sparse,
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

/// Pencils with entries up to f64::MAX, whose ‖B‖_F may exceed the largest double: the dense
/// solve reports the norms finite (saturated at f64::MAX, as documented) with finite modes and
/// bounds that hold; the sparse solve refuses a norm it cannot represent with `OutOfRange`.
/// Exact ω²: B/top is the tridiagonal (−½, 1, −½) of order n, A diagonal, so ω² = top·μ with μ
/// the eigenvalues of the small pencil, found by bisection on its Sturm sequence.
#[test]
fn pencils_at_the_top_of_the_range_report_finite_norms_and_true_modes() {
    for n in [2usize, 3, 5, 9, 14] {
        for (k, top) in [1e300, 1e307, f64::MAX / 2.0, f64::MAX].into_iter().enumerate() {
            let b = Mat::from_fn(n, n, |i, j| match i.abs_diff(j) {
                0 => top,
                1 => -top / 2.0,
                _ => 0.0,
            });
            let masses: Vec<f64> = (0..n).map(|i| 1.0 + ((i * 7 + k) % 5) as f64).collect();
            let a = Mat::from_fn(n, n, |i, j| if i == j { masses[i] } else { 0.0 });
            // ‖B‖_F = top·√(n + (n − 1)/2).
            let norm_fits = top * (1.5 * n as f64 - 0.5).sqrt() <= f64::MAX;
            let problem = PencilProblem::new(a.as_ref(), b.as_ref()).expect("symmetric");
            match solve(&problem, &SolveOptions::default()) {
                Ok(s) => {
                    assert!(s.accuracy.norm_a.is_finite() && s.accuracy.norm_b.is_finite());
                    let relative = (1.5 * n as f64 - 0.5).sqrt();
                    if norm_fits {
                        let ratio = s.accuracy.norm_b / top;
                        assert!(
                            (ratio - relative).abs() <= 1e-14 * relative,
                            "n {n}, top {top:e}: ‖B‖_F/top {ratio}"
                        );
                    } else {
                        assert_eq!(s.accuracy.norm_b, f64::MAX, "n {n}, top {top:e}");
                    }
                    for (i, mode) in s.modes.iter().enumerate() {
                        let exact = top * tridiagonal_eigenvalue(&masses, i);
                        assert!(mode.omega_sq.is_finite() && mode.error_bound.is_finite());
                        assert!(
                            (mode.omega_sq - exact).abs() <= mode.error_bound + 1e-13 * exact,
                            "n {n}, top {top:e}, mode {i}: {} vs {exact:e} ± {:e}",
                            mode.omega_sq,
                            mode.error_bound
                        );
                    }
                }
                // ω² up to 2·top/min m may exceed the largest double.
                Err(e @ ModalError::OutOfRange { .. }) => assert!(top > f64::MAX / 4.0, "n {n}, top {top:e}: {e}"),
                Err(e) => panic!("n {n}, top {top:e}: {e}"),
            }
            let pencil = SparsePencil::from_triplets(n, &triplets(&a), &triplets(&b)).expect("valid");
            let options = SparseSolveOptions {
                count: 1,
                ..SparseSolveOptions::default()
            };
            match solve_sparse(&pencil, &options) {
                Ok(s) => assert!(
                    s.modes
                        .iter()
                        .all(|m| m.omega_sq.is_finite() && m.error_bound.is_finite())
                ),
                Err(e @ ModalError::OutOfRange { .. }) => assert!(!norm_fits, "sparse, n {n}, top {top:e}: {e}"),
                Err(e) => panic!("sparse, n {n}, top {top:e}: {e}"),
            }
        }
    }
}

/// The i-th smallest μ (0-based) of det(T − μ M) = 0, T = tridiag(−½, 1, −½), M = diag(m), by
/// bisection on the count of negative pivots of T − μM (Sylvester), to full precision.
fn tridiagonal_eigenvalue(masses: &[f64], i: usize) -> f64 {
    let below = |mu: f64| {
        let mut count = 0;
        let mut pivot = 1.0;
        for (k, m) in masses.iter().enumerate() {
            pivot = 1.0 - mu * m - if k == 0 { 0.0 } else { 0.25 / pivot };
            if pivot == 0.0 {
                pivot = -f64::EPSILON;
            }
            if pivot < 0.0 {
                count += 1;
            }
        }
        count
    };
    let (mut lo, mut hi) = (0.0, 2.0 / masses.iter().cloned().fold(f64::INFINITY, f64::min));
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if below(mid) > i { hi = mid } else { lo = mid }
    }
    0.5 * (lo + hi)
}

/// Every refinement policy, values only, the lowest three and the sparse solver on `case`: each
/// mode holds its exact ω² within its bound, or the pencil is refused as out of range.
fn every_use_holds(case: &Case, label: &str) {
    for usage in [
        Use::All(Refinement::Auto),
        Use::All(Refinement::Always),
        Use::All(Refinement::Off),
        Use::ValuesOnly,
        Use::Lowest(3),
        Use::Sparse(3),
    ] {
        match modes_of(case, usage) {
            Ok(modes) => {
                let failed = failures(case, &modes);
                assert!(failed.is_empty(), "{label} {usage:?}: {failed:?}");
            }
            Err(ModalError::OutOfRange { .. }) => {}
            Err(other) => panic!("{label} {usage:?}: {other}"),
        }
    }
}

/// A pencil (A = I) whose B spans 345 decades: a coupling of 1e308 and a block of entries near
/// 2e-37. The exact scaling that brings it into range puts its soft modes (ω² ≈ 4e-37) next to
/// the bottom of the normal numbers, where their residuals are subnormal: squaring them gave
/// zero, and bounds of 2e-52 on values 1e-39 off. Exact ω² by mpmath at 400 digits on the
/// stored doubles; the permuted copy (found by the fuzz target `abi_modal`) must hold them too.
#[test]
fn soft_modes_of_a_pencil_spanning_the_whole_range_keep_true_bounds() {
    let tiny = 2.08310546875e-37;
    let mut b = Mat::<f64>::zeros(7, 7);
    for (i, j, v) in [
        (0, 0, -9.765625000000001e-32),
        (0, 1, -9.765625e-12),
        (0, 2, -3.12333984375e-22),
        (0, 3, 1e308),
        (2, 4, tiny),
        (2, 5, tiny),
        (2, 6, tiny),
        (3, 3, tiny),
        (3, 4, tiny),
        (3, 5, tiny),
        (3, 6, tiny),
        (4, 4, tiny),
    ] {
        b[(i, j)] = v;
        b[(j, i)] = v;
    }
    let exact = vec![
        (-1e308, -4.882802084472657e-32),
        (-3.3705354505882815e-37, -1.9259089240799186e-53),
        (0.0, 0.0),
        (0.0, 0.0),
        (1.2874299818382818e-37, -1.6218850567960923e-54),
        (4.1662109375e-37, 7.670458539527698e-94),
        (1e308, -4.882802084472657e-32),
    ];
    let case = Case {
        a: Mat::identity(7, 7),
        b,
        exact,
    };
    each_ordering_holds(&case, &[[0, 1, 2, 3, 4, 5, 6], [1, 2, 3, 4, 5, 6, 0]]);
}

/// Diagonal A and a B with a coupling of 3e236 between two coordinates beside entries from
/// 1e-39 to 3e24 (found by the fuzz target `abi_modal`): one ordering reported ω² = 151.97 with
/// a bound of 3e-14 where the exact value is 6.8e-9. Exact ω² by mpmath at 600 digits.
#[test]
fn modes_beside_a_coupling_of_1e236_keep_true_bounds_in_every_ordering() {
    let a = [
        0.5843137254901961,
        0.1897764553292134,
        0.40737010757610437,
        0.6213931486991684,
        0.35625238422217137,
        0.00729381246662089,
    ];
    let small = 2.7858398437500002e-9;
    let mut b = Mat::<f64>::from_fn(6, 6, |_, _| small);
    for (i, j, v) in [
        (0, 0, -2.2679687500000003e-16),
        (0, 1, 3.204898491568124e236),
        (0, 2, 2.77666015625e-9),
        (2, 3, 1829785156250000.0),
        (2, 4, 1.0513671874999999e-39),
        (2, 5, 0.0),
        (3, 4, -2.88916015625e24),
        (3, 5, 0.5),
        (4, 4, 0.5),
        (5, 5, 278583984375.0),
    ] {
        b[(i, j)] = v;
        b[(j, i)] = v;
    }
    let exact = vec![
        (-9.624320331581576e236, -1.3129867357547846e220),
        (-6.140581458690555e24, 85048399.36682881),
        (6.838596627834567e-9, 3.1174581542345484e-25),
        (38194563631831.85, -0.0006637444398503094),
        (6.140581458690555e24, -85048397.96332943),
        (9.624320331581576e236, 1.3129867357547846e220),
    ];
    let case = Case {
        a: Mat::from_fn(6, 6, |i, j| if i == j { a[i] } else { 0.0 }),
        b,
        exact,
    };
    each_ordering_holds(
        &case,
        &[
            [0, 1, 2, 3, 4, 5],
            [1, 5, 4, 0, 3, 2],
            [5, 4, 3, 2, 1, 0],
            [2, 0, 4, 1, 5, 3],
        ],
    );
}

/// The coordinates of `case` reordered by each of `orderings`: each must hold every exact ω².
fn each_ordering_holds<const N: usize>(case: &Case, orderings: &[[usize; N]]) {
    for order in orderings {
        let permuted = Case {
            a: Mat::from_fn(N, N, |i, j| case.a[(order[i], order[j])]),
            b: Mat::from_fn(N, N, |i, j| case.b[(order[i], order[j])]),
            exact: case.exact.clone(),
        };
        every_use_holds(&permuted, &format!("order {order:?}"));
    }
}

/// Every `stride`-th ordering of the coordinates of `case` in lexicographic order, the first
/// included: each must hold every exact ω².
fn every_ordering_holds(case: &Case, stride: usize) {
    let n = case.a.nrows();
    let mut order: Vec<usize> = (0..n).collect();
    let mut orderings = 0;
    loop {
        if orderings % stride == 0 {
            let permuted = Case {
                a: Mat::from_fn(n, n, |i, j| case.a[(order[i], order[j])]),
                b: Mat::from_fn(n, n, |i, j| case.b[(order[i], order[j])]),
                exact: case.exact.clone(),
            };
            every_use_holds(&permuted, &format!("order {order:?}"));
        }
        orderings += 1;
        if !next_permutation(&mut order) {
            break;
        }
    }
    assert_eq!(orderings, (1..=n).product::<usize>());
}

/// The next permutation in lexicographic order; false after the last.
fn next_permutation(p: &mut [usize]) -> bool {
    let Some(i) = (1..p.len()).rev().find(|&i| p[i - 1] < p[i]) else {
        return false;
    };
    let j = (i..p.len())
        .rev()
        .find(|&j| p[j] > p[i - 1])
        .expect("a larger entry after i − 1");
    p.swap(i - 1, j);
    p[i..].reverse();
    true
}

fn symmetric(n: usize, entries: &[(usize, usize, f64)]) -> Mat<f64> {
    let mut m = Mat::<f64>::zeros(n, n);
    for &(i, j, v) in entries {
        m[(i, j)] = v;
        m[(j, i)] = v;
    }
    m
}

/// A dense A and a B with entries from 1e-137 to 1e22 (found by the fuzz target `abi_modal`):
/// the reduction cannot separate ω² ≈ −4.4e-32 from 3.18 (its bounds are 1.8e7), and in one
/// ordering the polishing of the refined soft mode converged to the eigenpair of 3.18, reported
/// twice. A refined or polished value must stay within the bound it started from. Exact ω² by
/// `tools/modal_found_pencils_reference.py`; all 24 orderings.
#[test]
fn a_refined_mode_never_takes_the_eigenpair_of_its_neighbour() {
    let a = [
        [
            1.5371442801070985,
            -0.3408479252830148,
            -0.6911467285826802,
            0.7035937365144491,
        ],
        [
            -0.3408479252830148,
            1.2798205931422886,
            0.5351544953882694,
            -0.34600993152707815,
        ],
        [
            -0.6911467285826802,
            0.5351544953882694,
            2.2062756345359262,
            -0.7405649181455374,
        ],
        [
            0.7035937365144491,
            -0.34600993152707815,
            -0.7405649181455374,
            2.0814717394051727,
        ],
    ];
    let b = symmetric(
        4,
        &[
            (0, 0, -9.765625e21),
            (0, 1, 188916015625.0),
            (0, 2, -1.40556640625e-32),
            (0, 3, 2.9072265625000003e-28),
            (1, 1, 7.926859425671704e-137),
            (1, 2, -9.765625000000001e-32),
            (1, 3, -9.765625000000001e-32),
            (2, 2, -9.765625000000001e-32),
            (2, 3, 1.22275390625e-12),
            (3, 3, -3.759765625e20),
        ],
    );
    every_ordering_holds(
        &Case {
            a: Mat::from_fn(4, 4, |i, j| a[i][j]),
            b,
            exact: vec![
                (-8.265690672732003e21, 367881.1268458769),
                (-2.0735819330377584e20, -3201.079013832632),
                (-4.426294179717817e-32, 1.5981230094689223e-48),
                (3.177858761323168, 1.4077939887984742e-16),
            ],
        },
        1,
    );
}

/// A B whose only entries are a subnormal coupling 1.09e-321 (found by the fuzz target
/// `abi_modal`): the sparse pencil halved the entry and its mirror before adding them, which
/// rounds among subnormals (1.09e-321 is an odd multiple of the smallest double), and solved a
/// pencil 0.45 % away with a bound of two units of the last place. Exact ω² by
/// `tools/modal_found_pencils_reference.py` (the five middle ones are below the smallest double).
#[test]
fn a_subnormal_coupling_is_the_same_pencil_to_the_sparse_solver() {
    let diagonal = [
        0.0010610388815402985,
        0.004910071216523647,
        0.0010000065192580223,
        0.0010000065192580223,
        0.0010000065192580223,
        0.0010000065192580223,
        0.0025258844941854477,
    ];
    let off = [
        (0, 1, 2.1494925022125244e-6),
        (0, 2, 2.421438694000244e-7),
        (0, 3, 2.421438694000244e-7),
        (0, 4, 2.421438694000244e-7),
        (0, 5, 2.421438694000244e-7),
        (0, 6, -9.527429938316345e-7),
        (1, 2, 1.9138678908348083e-6),
        (1, 3, 1.9138678908348083e-6),
        (1, 4, 1.9138678908348083e-6),
        (1, 5, 1.9138678908348083e-6),
        (1, 6, -3.0957162380218506e-6),
        (2, 3, 6.51925802230835e-9),
        (2, 4, 6.51925802230835e-9),
        (2, 5, 6.51925802230835e-9),
        (2, 6, -1.1883676052093506e-6),
        (3, 4, 6.51925802230835e-9),
        (3, 5, 6.51925802230835e-9),
        (3, 6, -1.1883676052093506e-6),
        (4, 5, 6.51925802230835e-9),
        (4, 6, -1.1883676052093506e-6),
        (5, 6, -1.1883676052093506e-6),
    ];
    let mut a = symmetric(7, &off);
    for (i, d) in diagonal.iter().enumerate() {
        a[(i, i)] = *d;
    }
    let case = Case {
        a,
        b: symmetric(7, &[(0, 4, 1.09e-321)]),
        exact: vec![
            (-1.06026e-318, 0.0),
            (-0.0, -0.0),
            (-0.0, -0.0),
            (0.0, 0.0),
            (0.0, 0.0),
            (0.0, 0.0),
            (1.05976e-318, 0.0),
        ],
    };
    every_use_holds(&case, "");
    let pencil = SparsePencil::from_triplets(7, &triplets(&case.a), &triplets(&case.b)).expect("a valid pencil");
    assert_eq!(
        pencil.b().val(),
        &[1.09e-321, 1.09e-321],
        "the stored coupling, to the last bit"
    );
}

/// Two massless coordinates coupled by 1e308, and a coupling of 2.3e-25 between two massed ones
/// (found by the fuzz target `abi_modal`): the exact scaling puts the condensed pencil at
/// 1e-293, where the residual norms of the soft pair were formed from squares that underflowed
/// to zero, and ω² = −1.9e-30 and 4.4e-24 were reported with bounds of 4e-46 and 1e-39 where
/// the exact values are ∓1.06e-24. Exact ω² by mpmath at 1000 digits (the condensed pencil
/// formed exactly); several orderings.
#[test]
fn residual_norms_of_a_pencil_scaled_to_the_bottom_of_the_range_do_not_underflow() {
    let mut a = Mat::<f64>::zeros(6, 6);
    for (i, v) in [(0, 0.05215533684290837), (2, 0.8889906157015335), (4, 1.0), (5, 1.0)] {
        a[(i, i)] = v;
    }
    let tiny = -9.765625000000001e-32;
    let b = symmetric(
        6,
        &[
            (0, 0, tiny),
            (0, 1, 2.62490234375e18),
            (0, 2, 2.29052734375e-25),
            (0, 3, -2.4232421875e38),
            (0, 4, 7.8125e-22),
            (0, 5, -4.8710937499999995e-40),
            (1, 1, -0.00010618164062500001),
            (1, 2, 4.1943359375e16),
            (1, 3, 1e308),
            (1, 4, -1.38310546875e-12),
            (1, 5, -9.960937500000001e-30),
            (2, 2, tiny),
            (2, 3, tiny),
            (2, 4, tiny),
            (2, 5, tiny),
            (3, 3, tiny),
            (3, 4, 1.22705078125e-13),
            (3, 5, 2.2298828125000002e-8),
            (4, 4, 734863281.25),
            (4, 5, 1.32607421875e-24),
            (5, 5, 336230468750000.0),
        ],
    );
    let exact = vec![
        (-1.0637459502754536e-24, 5.023079953983739e-41),
        (1.0637439680132916e-24, -2.0654286781838652e-41),
        (734863281.25, 1.5924828298099973e-50),
        (336230468750000.0, 5.229974200395649e-63),
        (f64::INFINITY, 0.0),
        (f64::INFINITY, 0.0),
    ];
    each_ordering_holds(
        &Case { a, b, exact },
        &[
            [0, 1, 2, 3, 4, 5],
            [1, 5, 4, 2, 0, 3],
            [5, 4, 3, 2, 1, 0],
            [3, 0, 5, 1, 2, 4],
        ],
    );
}

/// A dense A and a B whose entries run from 1e-4 down to 2.5e-41, with five eigenvalues within
/// 3e-32 of zero (found by the fuzz target `abi_modal`): the reduction bounds them to 4e-19, and
/// in one ordering the second mode was refined to ω² = −1.2e-33 with a bound of 2.8e-32, the
/// residual bound of an eigenvalue that is not the second (−1.26e-31). A residual bound is the
/// mode's own only where its interval is apart from every other mode's, or chains only with
/// refined, A-orthogonal modes; otherwise the mode keeps the interval it was refined from.
/// Exact ω² by `tools/modal_found_pencils_reference.py`.
#[test]
fn a_residual_bound_is_a_modes_own_only_apart_from_unrefined_intervals() {
    let a = [
        [
            1.0010721039250492,
            1.3971701264381409e-05,
            7.692724466323853e-07,
            0.0,
            -0.00038496311753988266,
            3.9674341678619385e-07,
            0.00746630784124136,
            3.018416464328766e-05,
        ],
        [
            1.3971701264381409e-05,
            1.2004464201852678,
            4.973262548446655e-07,
            0.0,
            -0.01638881955295801,
            1.3688579201698303e-05,
            0.29780180659145117,
            4.347600042819977e-05,
        ],
        [
            7.692724466323853e-07,
            4.973262548446655e-07,
            2.5540481562018393,
            0.0,
            2.425163984298706e-06,
            -0.0017273258417844772,
            0.21676191687583923,
            0.5931299384683371,
        ],
        [0.0, 0.0, 0.0, 1.001, 0.0, 0.0, 0.0, 0.0],
        [
            -0.00038496311753988266,
            -0.01638881955295801,
            2.425163984298706e-06,
            0.0,
            1.0998843189552425,
            -7.91158527135849e-06,
            -0.17283406667411327,
            -7.91158527135849e-06,
        ],
        [
            3.9674341678619385e-07,
            1.3688579201698303e-05,
            -0.0017273258417844772,
            0.0,
            -7.91158527135849e-06,
            1.001003139488399,
            8.362717926502228e-05,
            -0.00011507514864206314,
        ],
        [
            0.00746630784124136,
            0.29780180659145117,
            0.21676191687583923,
            0.0,
            -0.17283406667411327,
            8.362717926502228e-05,
            2.7515441876128315,
            0.3897318113595247,
        ],
        [
            3.018416464328766e-05,
            4.347600042819977e-05,
            0.5931299384683371,
            0.0,
            -7.91158527135849e-06,
            -0.00011507514864206314,
            0.3897318113595247,
            1.5830786030963062,
        ],
    ];
    let b = symmetric(
        8,
        &[
            (0, 0, 2.4902343749999996e-41),
            (3, 6, -8.105468750000001e-30),
            (3, 7, -2.1510742187499998e-29),
            (4, 4, 0.0001056640625),
            (4, 5, -9.765625000000001e-32),
            (4, 6, -9.765625000000001e-32),
            (4, 7, -9.765625000000001e-32),
            (5, 5, -9.765625000000001e-32),
            (5, 6, -9.765625000000001e-32),
            (5, 7, -2.6100585937499997e-39),
        ],
    );
    let exact = vec![
        (-1.79843026355666e-29, 9.559913337237697e-46),
        (-1.2643503025664794e-31, -8.510477925611152e-48),
        (0.0, 0.0),
        (0.0, 0.0),
        (2.487567444583889e-41, 8.565382347875238e-58),
        (2.888544612505745e-32, 4.280637809726671e-49),
        (1.798430579045534e-29, 1.1095147290617016e-47),
        (9.706246953735587e-05, 1.3047167606195596e-21),
    ];
    each_ordering_holds(
        &Case {
            a: Mat::from_fn(8, 8, |i, j| a[i][j]),
            b,
            exact,
        },
        &[
            [0, 1, 2, 3, 4, 5, 6, 7],
            [1, 2, 3, 4, 5, 6, 7, 0],
            [7, 6, 5, 4, 3, 2, 1, 0],
            [4, 0, 6, 2, 7, 3, 5, 1],
        ],
    );
}

/// Five massless coordinates whose stiffness block B₀₀ is nearly singular (condition 1.6e10,
/// found by the fuzz target `abi_modal`): in about a third of the orderings the third mode was
/// reported as 2.17688e-6 with a first-order bound of 5e-11 where the exact value is
/// 2.17760e-6; its refinement found the exact value and was refused for leaving that (false)
/// bound. Exact ω² by `tools/modal_found_pencils_reference.py` (condensed at 400 digits); every
/// 37th of the 40 320 orderings.
#[test]
fn a_refinement_that_leaves_a_false_first_order_bound_is_kept() {
    let (a, b) = nearly_singular_massless_block(8);
    let infinite = (f64::INFINITY, 0.0);
    let mut exact = vec![(0.0, 0.0), (0.0, 0.0), (2.1776049630479103e-06, -2.676658650854568e-23)];
    exact.extend([infinite; 5]);
    let case = Case { a, b, exact };
    every_ordering_holds(&case, 37);
}

/// The pencil of [`a_refinement_that_leaves_a_false_first_order_bound_is_kept`] (A diagonal with
/// five massless coordinates, B₀₀ of condition 1.6e10), with `n − 8` uncoupled unit oscillators
/// appended.
fn nearly_singular_massless_block(n: usize) -> (Mat<f64>, Mat<f64>) {
    let masses = [0.0, 1.0, 0.0, 1.0, 0.00375371938658732, 0.0, 0.0, 0.0];
    let mut b = symmetric(
        n,
        &[
            (0, 0, -8.43780517578125),
            (0, 1, -0.00030517578125),
            (0, 2, -0.00030517578125),
            (0, 3, 2.65594482421875),
            (0, 4, 8.90594482421875),
            (0, 5, 8.86260986328125),
            (0, 6, 8.86260986328125),
            (0, 7, 8.86260986328125),
            (3, 6, 0.00213623046875),
            (5, 7, 3.515625),
            (6, 6, -2.09564208984375),
            (6, 7, 3.52935791015625),
            (7, 7, -3.52935791015625),
        ],
    );
    for i in 8..n {
        b[(i, i)] = 1.0;
    }
    let a = Mat::from_fn(n, n, |i, j| match (i == j, masses.get(i)) {
        (false, _) => 0.0,
        (true, Some(&m)) => m,
        (true, None) => 1.0,
    });
    (a, b)
}

/// On a condensation whose massless block B₀₀ is nearly singular (u·κ(B₀₀) above the 8 digits
/// Auto asks for) first-order bounds are not trusted: `Refinement::Auto` refines every mode,
/// even the uncoupled unit oscillators whose first-order bounds are at the rounding level, and
/// every finite mode ends with a residual bound that holds (ω² = 1 exactly for those).
#[test]
fn a_nearly_singular_massless_block_has_every_mode_refined() {
    let (a, b) = nearly_singular_massless_block(11);
    let problem = PencilProblem::new(a.as_ref(), b.as_ref()).expect("a valid pencil");
    let solution = solve(&problem, &SolveOptions::default()).expect("a solvable pencil");
    let finite = solution.modes.iter().filter(|m| m.kind != ModeKind::Infinite).count();
    assert_eq!(finite, 6);
    let kinds = &solution.accuracy.bound_kinds[..finite];
    assert!(kinds.iter().all(|&k| k == BoundKind::Residual), "{kinds:?}");
    for mode in &solution.modes[3..finite] {
        assert!((mode.omega_sq - 1.0).abs() <= mode.error_bound, "{mode:?}");
    }
    let third = &solution.modes[2];
    let error = ((third.omega_sq - 2.1776049630479103e-06) + 2.676658650854568e-23).abs();
    assert!(error <= third.error_bound, "{third:?}");
}

/// A dense A and a B of entries from 2e-11 down to a subnormal 4.7e-321, with six eigenvalues
/// within 1e-41 of zero (found by the fuzz target `abi_modal` through the sparse solver's dense
/// path): the lowest four, selected and refined as one block, were given the quadratic bound of
/// a gap to the unselected modes measured with the selection's refined bounds, which the
/// unselected values (never refined, 1e-12 off after scaling) do not have; ω² = −6.98e-44 was
/// reported within 1.4e-55 of the exact −8.17e-44. Every count k of `Lowest(k)` and of the
/// sparse solver. Exact ω² by `tools/modal_found_pencils_reference.py`.
#[test]
fn unselected_modes_keep_the_uncertainty_of_the_reduction() {
    let a = [
        [
            1.0120237649658914,
            -0.2289765551686287,
            0.7622260749340057,
            -0.43085211236029863,
            -0.2668326608836651,
            -1.2547426763921976,
            -0.48041342198848724,
        ],
        [
            -0.2289765551686287,
            3.3095041181201332,
            0.2040815893560648,
            0.22612688224762678,
            0.22860143147408962,
            0.6102276127785444,
            -0.5678917402401567,
        ],
        [
            0.7622260749340057,
            0.2040815893560648,
            1.7911876601407524,
            -0.9422234827652574,
            -0.9110971540212631,
            -0.48230474069714546,
            -0.027302628383040428,
        ],
        [
            -0.43085211236029863,
            0.22612688224762678,
            -0.9422234827652574,
            1.3890334761942025,
            0.39497001096606255,
            0.5796955274417996,
            0.8108259486034513,
        ],
        [
            -0.2668326608836651,
            0.22860143147408962,
            -0.9110971540212631,
            0.39497001096606255,
            1.6969582786092754,
            0.40319159999489784,
            -1.1125753866508603,
        ],
        [
            -1.2547426763921976,
            0.6102276127785444,
            -0.48230474069714546,
            0.5796955274417996,
            0.40319159999489784,
            3.168565905956387,
            0.2802895065397024,
        ],
        [
            -0.48041342198848724,
            -0.5678917402401567,
            -0.027302628383040428,
            0.8108259486034513,
            -1.1125753866508603,
            0.2802895065397024,
            2.3286369464600676,
        ],
    ];
    let b = symmetric(
        7,
        &[
            (0, 0, 2.21611328125e-11),
            (0, 1, 4.654e-321),
            (0, 3, -9.765625000000001e-32),
            (0, 4, -9.765625000000001e-32),
            (0, 5, -2.27509765625e-27),
            (0, 6, -9.765625000000001e-32),
            (1, 1, 2.0996093749999998e-41),
        ],
    );
    let case = Case {
        a: Mat::from_fn(7, 7, |i, j| a[i][j]),
        b,
        exact: vec![
            (-8.165108150448452e-44, -4.633846622460756e-60),
            (0.0, 0.0),
            (0.0, 0.0),
            (0.0, 0.0),
            (0.0, 0.0),
            (8.372565739339997e-42, -3.3465951769891056e-58),
            (2.0210066019847653e-10, -7.132424548130415e-27),
        ],
    };
    every_use_holds(&case, "");
    for k in 1..=7 {
        for usage in [Use::Lowest(k), Use::Sparse(k)] {
            let modes = modes_of(&case, usage).expect("a pencil within range");
            let failed = failures(&case, &modes);
            assert!(failed.is_empty(), "{usage:?}: {failed:?}");
        }
    }
}

/// A = 0.96·I and a B with couplings up to 1e100 (found by the fuzz target `abi_modal` at
/// ±1e100): four refined modes near zero whose intervals chain through one wide interval each
/// kept their own residual bound, although sorted values and sorted eigenvalues do not pair that
/// way; ω² = 1.2e-68 ± 1.3e21 was reported for the exact 1.63e36. A chain's members now share
/// the chain's block bound. Exact ω² by `tools/modal_found_pencils_reference.py`.
#[test]
fn modes_chained_through_a_wide_interval_share_its_bound() {
    let b = symmetric(
        6,
        &[
            (0, 0, -2.5107421875e-38),
            (2, 3, 1.25009765625e21),
            (2, 4, -3.0295711161086577e-128),
            (2, 5, -2.74814453125e31),
            (3, 3, 1.56630859375e36),
            (3, 4, -0.215107421875),
            (3, 5, 1.9481445312499998e-35),
            (4, 4, 4.717996333842129e-105),
            (4, 5, -1e100),
            (5, 5, 1.6709960937500002e-28),
        ],
    );
    let case = Case {
        a: Mat::from_fn(6, 6, |i, j| if i == j { 0.9607843137254902 } else { 0.0 }),
        b,
        exact: vec![
            (-1.0408163265306122e100, -3.277694902867525e83),
            (-1038447.7440581296, -1.7938535475334055e-11),
            (-2.613221460459184e-38, 4.501149289144137e-55),
            (0.0, 0.0),
            (1.630239556760204e36, 3.0286008740628226e19),
            (1.0408163265306122e100, 3.277694902867525e83),
        ],
    };
    each_ordering_holds(&case, &[[0, 1, 2, 3, 4, 5], [1, 2, 0, 3, 4, 5]]);
}
