//! Work-precision report of the modal solvers: error against run time for every applicable
//! method on each problem family, with LAPACK `dsygvd` (OpenBLAS, its default threads) and
//! nalgebra as peers in the same run.
//!
//! Run: `cargo bench -p mechanica-benches --bench modal_report [-- FAMILY...]` with FAMILY among
//! `fixed free ring rotated lumped graded graded-random grid stages` (default: all; `stages-small` = the stages at
//! n = 1000 and 2000 only; `rotated-plain` = mechanica all pairs with `Refinement::Off` against
//! dsygvd on the rotated chain, only when named). Writes
//! `target/reports/modal-<family>.csv`, `modal-<family>.svg` (max relative error of the lowest
//! 10 ω² against run time: one panel per problem family, one series per method joined in order
//! of size, mechanica's reported bound dashed beside its error) and `modal-<family>-backward.svg`
//! (max backward error against run time), and prints the tables
//! ([`mechanica_benches::work_precision`]).
//!
//! - **OpenBLAS kernels.** Some OpenBLAS builds (Debian's 0.3.21 among them) do not recognise
//!   recent Xeons and fall back to their `Prescott` (SSE3) kernels, several times slower; the
//!   report prints the kernel family, and `OPENBLAS_CORETYPE=Haswell` selects the AVX2 kernels
//!   that SciPy's own OpenBLAS uses on such CPUs. Measure the peer with the right kernels.
//! - **Timing.** Not criterion: each point is the median of at least 3 runs, repeated until 0.3 s
//!   have elapsed, and exactly 3 runs for n ≥ 2000 (a 4000 solve takes seconds)
//!   ([`mechanica_benches::median_seconds`]). Input copies are inside the timed region for every
//!   method alike (LAPACK overwrites its inputs).
//! - **Errors.** Eigenvalue errors only against closed forms ([`testing`]) or the committed
//!   60-digit mpmath references (tools/modal_reference.txt): relative for nonzero ω², normwise
//!   (|ŵ|/ω²_max) for a rigid-body mode. Backward errors η = ‖Bx − ω²Ax‖/((‖B‖_F + |ω²|‖A‖_F)‖x‖)
//!   are recomputed here for every method from its vectors. `bound` is the largest relative
//!   error bound mechanica reports for the lowest 10 modes (empty for the peers, which report none).
//! - **Methods.** mechanica `solve`: all pairs (default, auto refinement), values only, lowest 10,
//!   `Refinement::Always` on the lowest 10 (the stiff/low-mode method), `Refinement::Off`
//!   (graded family: all pairs by the plain reduction; rotated family: values only, which with
//!   the default auto refinement falls back to a solve with vectors when its a-priori bounds
//!   promise fewer than 8 digits); `solve_sparse` (shift-invert block Lanczos, 10
//!   lowest; n ≤ 400 falls back to dense); LAPACK `dsygvd` all pairs and values only; nalgebra
//!   (Cholesky, two triangular solves, SymmetricEigen; n ≤ 1000 only, it is slow); SciPy
//!   `eigh(B, A)` all pairs, timed in a Python process by tools/scipy_eigh_point.py (skipped
//!   without python3 and SciPy; [`mechanica_benches::scipy`]).
//! - **Random graded family** (`graded-random`): fixed spring chains and trees of 250, 500 and
//!   1000 masses graded at random over 8 decades of mass and 12 of stiffness
//!   ([`graded::spring_tree`]), against the lowest ω² of the stored pencil by double-double
//!   bisection ([`graded::tree_pencil_lowest`]).
//! - **Stages** (`stages`): the rotated chain at n = 1000, 2000, 4000 split into Cholesky,
//!   reduction, eigensolver, back-transformation and (mechanica only) the accuracy report's
//!   products and the Sturm count, against dpotrf, dsygst, dsyevd, dtrsm — where the time goes.

use mechanica::modal::faer::sparse::Triplet;
use mechanica::modal::faer::{Mat, MatRef, Side, get_global_parallelism};
use mechanica::modal::linalg::reduce::{back_transform, cholesky_lower, reduce};
use mechanica::modal::{
    ModalSolution, PencilProblem, Refinement, Residuals, Selection, SolveOptions, SparsePencil, SparseSolveOptions,
    count_below, solve, solve_sparse,
};
use mechanica_benches::modal::{
    from_col_major, from_nalgebra, from_triplets, lumped_fixed_chain, max_backward_error, max_eigenvalue_error,
    nalgebra_all_pairs, rotated_fixed_chain, to_col_major, to_nalgebra, to_triplets,
};
use mechanica_benches::work_precision::{Panel, Series, WorkPoint, write_work_precision};
use mechanica_benches::{lapack, median_seconds, write_csv};
use mechanica_modal::testing;
use mechanica_modal::testing::graded;
use std::time::Duration;

/// Modes whose eigenvalue error is reported.
const LOWEST: usize = 10;
/// nalgebra is run up to this order.
const NALGEBRA_MAX: usize = 1000;
/// Dense methods on the sparse grid up to this order.
const GRID_DENSE_MAX: usize = 2500;

type Triplets = Vec<Triplet<usize, usize, f64>>;

/// One problem instance with its exact spectrum (at least the lowest [`LOWEST`] ω², ascending).
struct Case {
    label: String,
    /// The problem family (one panel of the diagrams): its sizes are joined in a series.
    family: String,
    n: usize,
    /// Dense (A, B), when the dense methods apply.
    dense: Option<(Mat<f64>, Mat<f64>)>,
    /// Sparse (A, B) triplets, when the sparse solver applies.
    sparse: Option<(Triplets, Triplets)>,
    exact: Vec<f64>,
    /// Largest exact ω² (scale of the rigid-body mode's error).
    scale: f64,
}

/// One measured point.
struct Row {
    method: &'static str,
    case: String,
    family: String,
    n: usize,
    seconds: f64,
    eig_error: f64,
    backward: Option<f64>,
    bound: Option<f64>,
}

#[derive(Clone, Copy, PartialEq)]
enum Method {
    MechAll,
    MechValues,
    MechValuesPlain,
    MechLowest,
    MechRefined,
    MechPlain,
    MechSketched,
    Sparse,
    LapackAll,
    LapackValues,
    Nalgebra,
    Scipy,
}

impl Method {
    fn label(self) -> &'static str {
        match self {
            Self::MechAll => "mechanica all pairs",
            Self::MechValues => "mechanica values only",
            Self::MechValuesPlain => "mechanica values only, no refinement",
            Self::MechLowest => "mechanica lowest 10",
            Self::MechRefined => "mechanica lowest 10 refined (Always)",
            Self::MechPlain => "mechanica all pairs, no refinement",
            Self::MechSketched => "mechanica all pairs, sketched report",
            Self::Sparse => "mechanica sparse Lanczos 10",
            Self::LapackAll => "LAPACK dsygvd all pairs",
            Self::LapackValues => "LAPACK dsygvd values only",
            Self::Nalgebra => "nalgebra all pairs",
            Self::Scipy => "SciPy eigh all pairs",
        }
    }
}

fn budget(n: usize) -> (usize, Duration) {
    if n >= 2000 {
        (3, Duration::ZERO)
    } else {
        (3, Duration::from_millis(300))
    }
}

/// Largest relative bound mechanica reports over the lowest modes.
fn reported_bound(modes: &[mechanica::modal::Mode], case: &Case) -> f64 {
    modes
        .iter()
        .zip(&case.exact)
        .take(LOWEST)
        .map(|(m, &e)| {
            if e == 0.0 {
                m.error_bound / case.scale
            } else {
                m.error_bound / e.abs()
            }
        })
        .fold(0.0, f64::max)
}

fn mech_options(method: Method) -> SolveOptions {
    let base = SolveOptions::default();
    match method {
        Method::MechValues => SolveOptions { vectors: false, ..base },
        Method::MechValuesPlain => SolveOptions {
            vectors: false,
            refinement: Refinement::Off,
            ..base
        },
        Method::MechLowest => SolveOptions {
            selection: Selection::Lowest(LOWEST),
            ..base
        },
        Method::MechRefined => SolveOptions {
            selection: Selection::Lowest(LOWEST),
            refinement: Refinement::Always,
            ..base
        },
        Method::MechPlain => SolveOptions {
            refinement: Refinement::Off,
            ..base
        },
        Method::MechSketched => SolveOptions {
            residuals: Residuals::Sketched,
            ..base
        },
        _ => base,
    }
}

/// Runs one method on one case; None when it does not apply or fails (printed).
fn run(method: Method, case: &Case) -> Option<Row> {
    let (runs, time) = budget(case.n);
    let row = |seconds, omega: &[f64], backward, bound| Row {
        method: method.label(),
        case: case.label.clone(),
        family: case.family.clone(),
        n: case.n,
        seconds,
        eig_error: max_eigenvalue_error(omega, &case.exact, LOWEST, case.scale),
        backward,
        bound,
    };
    let fail = |e: &dyn std::fmt::Display| {
        println!("  {} on {}: {e}", method.label(), case.label);
        None
    };
    match method {
        Method::Sparse => {
            let (ta, tb) = case.sparse.as_ref()?;
            let pencil = match SparsePencil::from_triplets(case.n, ta, tb) {
                Ok(p) => p,
                Err(e) => return fail(&e),
            };
            let options = SparseSolveOptions {
                count: LOWEST.min(case.n.saturating_sub(1)),
                ..SparseSolveOptions::default()
            };
            let (t, out) = median_seconds(runs, time, || solve_sparse(&pencil, &options));
            let sol = match out {
                Ok(s) => s,
                Err(e) => return fail(&e),
            };
            let omega: Vec<f64> = sol.modes.iter().map(|m| m.omega_sq).collect();
            let backward = sparse_backward_error(case.n, ta, tb, sol.vectors.as_ref(), &omega);
            let bound = reported_bound(&sol.modes, case);
            Some(row(t, &omega, Some(backward), Some(bound)))
        }
        Method::LapackAll | Method::LapackValues => {
            let (a, b) = case.dense.as_ref()?;
            if !lapack::available() {
                return None;
            }
            let vectors = method == Method::LapackAll;
            let (ka, kb) = (to_col_major(b.as_ref()), to_col_major(a.as_ref()));
            let (t, out) = median_seconds(runs, time, || lapack::dsygvd(&ka, &kb, case.n, vectors));
            // OpenBLAS threads spin for a while after a call; let them sleep before faer runs.
            std::thread::sleep(Duration::from_millis(200));
            let eig = match out {
                Ok(e) => e,
                Err(e) => return fail(&e),
            };
            let backward = eig.vectors.as_ref().map(|z| {
                let x = from_col_major(z, case.n, case.n);
                max_backward_error(a.as_ref(), b.as_ref(), x.as_ref(), &eig.values)
            });
            Some(row(t, &eig.values, backward, None))
        }
        Method::Scipy => {
            let (a, b) = case.dense.as_ref()?;
            match mechanica_benches::scipy::eigh(a.as_ref(), b.as_ref(), runs) {
                Ok(point) => Some(row(point.seconds, &point.values, Some(point.backward), None)),
                Err(e) => fail(&e),
            }
        }
        Method::Nalgebra => {
            let (a, b) = case.dense.as_ref()?;
            if case.n > NALGEBRA_MAX {
                return None;
            }
            let (na, nb) = (to_nalgebra(a.as_ref()), to_nalgebra(b.as_ref()));
            let (t, out) = median_seconds(runs, time, || nalgebra_all_pairs(&na, &nb));
            let Some((values, x)) = out else {
                return fail(&"Cholesky of A failed");
            };
            let x = from_nalgebra(&x);
            let backward = max_backward_error(a.as_ref(), b.as_ref(), x.as_ref(), &values);
            Some(row(t, &values, Some(backward), None))
        }
        _ => {
            let (a, b) = case.dense.as_ref()?;
            let problem = match PencilProblem::new(a.as_ref(), b.as_ref()) {
                Ok(p) => p,
                Err(e) => return fail(&e),
            };
            let options = mech_options(method);
            let (t, out) = median_seconds(runs, time, || solve(&problem, &options));
            let sol: ModalSolution = match out {
                Ok(s) => s,
                Err(e) => return fail(&e),
            };
            let omega: Vec<f64> = sol.modes.iter().map(|m| m.omega_sq).collect();
            let backward = sol
                .vectors
                .as_ref()
                .map(|x| max_backward_error(a.as_ref(), b.as_ref(), x.as_ref(), &omega));
            let bound = reported_bound(&sol.modes, case);
            Some(row(t, &omega, backward, Some(bound)))
        }
    }
}

/// Backward error of sparse pairs, with A x and B x from the triplets.
fn sparse_backward_error(n: usize, ta: &Triplets, tb: &Triplets, x: MatRef<'_, f64>, omega: &[f64]) -> f64 {
    let frob = |t: &Triplets| t.iter().map(|e| e.val * e.val).sum::<f64>().sqrt();
    let (na, nb) = (frob(ta), frob(tb));
    let apply = |t: &Triplets, j: usize| {
        let mut y = vec![0.0; n];
        for e in t {
            y[e.row] += e.val * x[(e.col, j)];
        }
        y
    };
    (0..x.ncols().min(omega.len()))
        .map(|j| {
            let (ax, bx) = (apply(ta, j), apply(tb, j));
            let r = (0..n).map(|i| (bx[i] - omega[j] * ax[i]).powi(2)).sum::<f64>().sqrt();
            r / ((nb + omega[j].abs() * na) * x.col(j).norm_l2())
        })
        .fold(0.0, f64::max)
}

fn chain_case(label: &str, n: usize, pencil: fn(usize) -> (Mat<f64>, Mat<f64>), exact: fn(usize) -> Vec<f64>) -> Case {
    let (a, b) = pencil(n);
    let exact = exact(n);
    let scale = exact.iter().copied().fold(0.0, f64::max);
    let sparse = Some((to_triplets(a.as_ref()), to_triplets(b.as_ref())));
    Case {
        label: format!("{label} n={n}"),
        family: label.to_string(),
        n,
        dense: Some((a, b)),
        sparse,
        exact,
        scale,
    }
}

/// Random graded spring chains and trees (`testing::graded`: masses 10^U(−8,0), stiffnesses
/// 10^U(0,12), not monotone, randomly numbered, fixed to the ground) of order `n`, with the
/// lowest ω² of their stored pencils by double-double bisection on inertia counts.
fn graded_random_case(n: usize, shape: graded::Shape) -> Case {
    let family = graded::GradedFamily::new(n, shape, true);
    let system = graded::spring_tree(&family, 0x5eed + n as u64);
    let exact = graded::tree_pencil_lowest(&system, LOWEST);
    let scale = exact.last().copied().unwrap_or(1.0);
    let name = if shape == graded::Shape::Chain {
        "random graded chain"
    } else {
        "random graded tree"
    };
    Case {
        label: format!("{name} n={n}"),
        family: name.to_string(),
        n,
        sparse: Some((to_triplets(system.a.as_ref()), to_triplets(system.b.as_ref()))),
        dense: Some((system.a, system.b)),
        exact,
        scale,
    }
}

/// The graded stiff chains of tools/modal_reference.txt with their 60-digit ω².
fn graded_cases() -> Vec<Case> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../tools/modal_reference.txt");
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) => {
            println!("  cannot read {path}: {e}");
            return Vec::new();
        }
    };
    let ints = |s: &str| -> Vec<i32> { s.split_whitespace().filter_map(|w| w.parse().ok()).collect() };
    let mut cases = Vec::new();
    let (mut name, mut k, mut m) = (String::new(), Vec::new(), Vec::new());
    for line in text.lines() {
        if let Some(rest) = line.strip_prefix("case ") {
            name = rest.trim().to_string();
        } else if let Some(rest) = line.strip_prefix("stiffness ") {
            k = ints(rest);
        } else if let Some(rest) = line.strip_prefix("mass ") {
            m = ints(rest);
        } else if let Some(rest) = line.strip_prefix("omega_sq ") {
            let exact: Vec<f64> = rest.split_whitespace().filter_map(|w| w.parse().ok()).collect();
            let (a, b) = testing::spring_chain(&k, &m);
            let scale = exact.iter().copied().fold(0.0, f64::max);
            // The same chain twice, interleaved (a symmetric structure): every ω² is double.
            let (a2, b2) = (interleaved_copies(&a), interleaved_copies(&b));
            let doubled: Vec<f64> = exact.iter().flat_map(|&w| [w, w]).collect();
            for (label, a, b, exact) in [
                (name.clone(), a, b, exact),
                (format!("{name} doubled"), a2, b2, doubled),
            ] {
                cases.push(Case {
                    label,
                    family: name.clone(),
                    n: a.nrows(),
                    sparse: Some((to_triplets(a.as_ref()), to_triplets(b.as_ref()))),
                    dense: Some((a, b)),
                    exact,
                    scale,
                });
            }
        }
    }
    cases
}

/// Two uncoupled copies of `m`, interleaved: copy c's coordinate i is 2i + c.
fn interleaved_copies(m: &Mat<f64>) -> Mat<f64> {
    let n = m.nrows();
    Mat::from_fn(
        2 * n,
        2 * n,
        |i, j| if i % 2 == j % 2 { m[(i / 2, j / 2)] } else { 0.0 },
    )
}

fn grid_case(side: usize) -> Case {
    let n = side * side;
    let (ta, tb) = testing::grid_laplacian(side, side);
    let exact = testing::grid_omega_sq(side, side, LOWEST);
    let dense = (n <= GRID_DENSE_MAX).then(|| (from_triplets(n, &ta), from_triplets(n, &tb)));
    // The largest ω² of the grid is below 8; only the scale of a zero mode uses it (none here).
    Case {
        label: format!("grid {side}x{side} n={n}"),
        family: "grid".into(),
        n,
        dense,
        sparse: Some((ta, tb)),
        exact,
        scale: 8.0,
    }
}

fn lumped_case(n: usize) -> Case {
    dense_fixed_chain_case("lumped", lumped_fixed_chain(n))
}

fn rotated_case(n: usize) -> Case {
    dense_fixed_chain_case("rotated", rotated_fixed_chain(n))
}

/// A dense pencil with the fixed chain's closed-form spectrum (rotated or lumped), labelled
/// "`kind` fixed chain n=…".
fn dense_fixed_chain_case(kind: &str, (a, b): (Mat<f64>, Mat<f64>)) -> Case {
    let n = a.nrows();
    let exact = testing::fixed_chain_omega_sq(n);
    let scale = exact.iter().copied().fold(0.0, f64::max);
    Case {
        label: format!("{kind} fixed chain n={n}"),
        family: format!("{kind} fixed chain"),
        n,
        dense: Some((a, b)),
        sparse: None,
        exact,
        scale,
    }
}

fn format_opt(v: Option<f64>) -> String {
    v.map(|x| format!("{x:.2e}")).unwrap_or_default()
}

/// Runs `methods` on `cases`, writes the CSV and both plots, prints the table.
fn report(name: &str, title: &str, cases: &[Case], methods: &[Method]) -> Vec<Row> {
    println!("\n## {name}: {title}");
    println!("| method | case | n | seconds | max rel err lowest 10 | max backward err | reported bound |");
    println!("|---|---|---|---|---|---|---|");
    let mut rows = Vec::new();
    for case in cases {
        for &method in methods {
            if let Some(r) = run(method, case) {
                println!(
                    "| {} | {} | {} | {:.4e} | {:.2e} | {} | {} |",
                    r.method,
                    r.case,
                    r.n,
                    r.seconds,
                    r.eig_error,
                    format_opt(r.backward),
                    format_opt(r.bound)
                );
                rows.push(r);
            }
        }
    }
    let header = [
        "method",
        "case",
        "n",
        "seconds",
        "max_rel_eig_error_lowest10",
        "max_backward_error",
        "reported_bound",
    ];
    let csv: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            vec![
                r.method.to_string(),
                r.case.clone(),
                r.n.to_string(),
                format!("{:.6e}", r.seconds),
                format!("{:.3e}", r.eig_error),
                format_opt(r.backward),
                format_opt(r.bound),
            ]
        })
        .collect();
    if let Err(e) = write_csv(&format!("modal-{name}"), &header, &csv) {
        println!("  cannot write csv: {e}");
    }
    let eig = panels(&rows, methods, |r| Some(r.eig_error), |r| r.bound);
    let backward = panels(&rows, methods, |r| r.backward, |_| None);
    let plots = [
        (
            format!("modal-{name}"),
            format!("{title}: max relative error of the lowest 10 ω² against run time"),
            "max relative error, lowest 10 ω²",
            eig,
        ),
        (
            format!("modal-{name}-backward"),
            format!("{title}: max backward error against run time"),
            "max backward error",
            backward,
        ),
    ];
    for (file, caption, y_label, panels) in plots {
        if let Err(e) = write_work_precision(&file, &caption, y_label, &panels) {
            println!("  cannot plot {file}: {e}");
        }
    }
    rows
}

/// One panel per problem family (in the order the rows were measured), one series per method
/// with its points ordered by size: the error `pick`s, and the bound `bound` reports.
fn panels(
    rows: &[Row],
    methods: &[Method],
    pick: impl Fn(&Row) -> Option<f64>,
    bound: impl Fn(&Row) -> Option<f64>,
) -> Vec<Panel> {
    let mut families: Vec<&str> = Vec::new();
    for r in rows {
        if !families.contains(&r.family.as_str()) {
            families.push(&r.family);
        }
    }
    let point = |r: &Row, error: f64| WorkPoint {
        order: r.n as f64,
        seconds: r.seconds,
        error,
    };
    families
        .into_iter()
        .map(|family| {
            let series = methods
                .iter()
                .map(|m| {
                    let mine = || rows.iter().filter(|r| r.family == family && r.method == m.label());
                    Series {
                        label: m.label().into(),
                        points: mine().filter_map(|r| pick(r).map(|e| point(r, e))).collect(),
                        bound: mine().filter_map(|r| bound(r).map(|b| point(r, b))).collect(),
                    }
                })
                .filter(|s| !s.points.is_empty())
                .collect();
            Panel {
                title: family.to_string(),
                series,
            }
        })
        .collect()
}

/// Prints the dense comparison (ratios mechanica/LAPACK) from the rotated-chain rows.
fn dense_summary(rows: &[Row]) {
    let find = |m: Method, n: usize| rows.iter().find(|r| r.method == m.label() && r.n == n);
    println!("\n## dense comparison (rotated fixed chain), seconds and mechanica/LAPACK ratios");
    println!(
        "| n | mechanica all | dsygvd all | ratio | mechanica all, sketched report | ratio | mechanica values | dsygvd values | ratio | nalgebra all | η mechanica | η dsygvd | η nalgebra | err mechanica | err dsygvd | err nalgebra |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut sizes: Vec<usize> = rows.iter().map(|r| r.n).collect();
    sizes.dedup();
    for n in sizes {
        let t = |m| find(m, n).map(|r| r.seconds);
        let ratio = |a: Option<f64>, b: Option<f64>| match (a, b) {
            (Some(a), Some(b)) => format!("{:.2}", a / b),
            _ => String::new(),
        };
        let s = |v: Option<f64>| v.map(|x| format!("{x:.3}")).unwrap_or_default();
        let bw = |m| format_opt(find(m, n).and_then(|r| r.backward));
        let er = |m| format_opt(find(m, n).map(|r| r.eig_error));
        println!(
            "| {n} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            s(t(Method::MechAll)),
            s(t(Method::LapackAll)),
            ratio(t(Method::MechAll), t(Method::LapackAll)),
            s(t(Method::MechSketched)),
            ratio(t(Method::MechSketched), t(Method::LapackAll)),
            s(t(Method::MechValues)),
            s(t(Method::LapackValues)),
            ratio(t(Method::MechValues), t(Method::LapackValues)),
            s(t(Method::Nalgebra)),
            bw(Method::MechAll),
            bw(Method::LapackAll),
            bw(Method::Nalgebra),
            er(Method::MechAll),
            er(Method::LapackAll),
            er(Method::Nalgebra),
        );
    }
}

/// Stage timings of mechanica's dense path against LAPACK's on the rotated chain.
fn stages(sizes: &[usize]) {
    println!("\n## stages (rotated fixed chain), median seconds");
    println!("| n | stage | mechanica (faer) | LAPACK (OpenBLAS) | ratio |");
    println!("|---|---|---|---|---|");
    let par = get_global_parallelism();
    let mut rows = Vec::new();
    for &n in sizes {
        let (runs, time) = budget(n);
        let (a, b) = rotated_fixed_chain(n);
        let Some(l) = cholesky_lower(a.as_ref(), par) else {
            println!("  A does not factor at n = {n}");
            continue;
        };
        let c = reduce(l.as_ref(), b.as_ref(), par);
        let mut line = |stage: &str, mech: f64, lap: Option<f64>| {
            let ratio = lap.map(|x| format!("{:.2}", mech / x)).unwrap_or_default();
            let lap_s = lap.map(|x| format!("{x:.3}")).unwrap_or_default();
            println!("| {n} | {stage} | {mech:.3} | {lap_s} | {ratio} |");
            rows.push(vec![
                n.to_string(),
                stage.to_string(),
                format!("{mech:.6e}"),
                lap.map(|x| format!("{x:.6e}")).unwrap_or_default(),
            ]);
        };
        let lapack_time = |f: &mut dyn FnMut() -> Result<(), lapack::LapackError>| -> Option<f64> {
            if !lapack::available() {
                return None;
            }
            let (t, out) = median_seconds(runs, time, &mut *f);
            std::thread::sleep(Duration::from_millis(200));
            out.ok().map(|_| t)
        };
        // Cholesky.
        let (t_chol, _) = median_seconds(runs, time, || cholesky_lower(a.as_ref(), par).map(|l| l[(0, 0)]));
        let a_cm = to_col_major(a.as_ref());
        let l_chol = lapack_time(&mut || {
            let mut m = a_cm.clone();
            lapack::dpotrf(&mut m, n)
        });
        line("Cholesky (cholesky / dpotrf)", t_chol, l_chol);
        // Reduction.
        let (t_red, _) = median_seconds(runs, time, || reduce(l.as_ref(), b.as_ref(), par)[(0, 0)]);
        let (b_cm, l_cm) = (to_col_major(b.as_ref()), to_col_major(l.as_ref()));
        let l_red = lapack_time(&mut || {
            let mut m = b_cm.clone();
            lapack::dsygst(&mut m, &l_cm, n)
        });
        line("reduction C = L⁻¹BL⁻ᵀ (reduce / dsygst)", t_red, l_red);
        // Eigensolver with and without vectors.
        let (t_evd, eig) = median_seconds(runs, time, || c.self_adjoint_eigen(Side::Lower));
        let c_cm = to_col_major(c.as_ref());
        let l_evd = lapack_time(&mut || {
            let mut m = c_cm.clone();
            lapack::dsyevd(&mut m, n, true).map(|_| ())
        });
        line("EVD of C, vectors (self_adjoint_eigen / dsyevd V)", t_evd, l_evd);
        let (t_val, _) = median_seconds(runs, time, || c.self_adjoint_eigenvalues(Side::Lower));
        let l_val = lapack_time(&mut || {
            let mut m = c_cm.clone();
            lapack::dsyevd(&mut m, n, false).map(|_| ())
        });
        line("EVD of C, values (self_adjoint_eigenvalues / dsyevd N)", t_val, l_val);
        // Back-transformation.
        let y = match eig {
            Ok(e) => e.U().to_owned(),
            Err(_) => {
                println!("  faer EVD failed at n = {n}");
                continue;
            }
        };
        let (t_back, _) = median_seconds(runs, time, || {
            let mut x = y.clone();
            back_transform(l.as_ref(), x.as_mut(), par);
            x[(0, 0)]
        });
        let y_cm = to_col_major(y.as_ref());
        let l_back = lapack_time(&mut || {
            let mut m = y_cm.clone();
            lapack::back_transform(&l_cm, &mut m, n)
        });
        line("back-transform X = L⁻ᵀY (back_transform / dtrsm)", t_back, l_back);
        // The products of the accuracy report (as in mechanica's accuracy::a_posteriori).
        let mut x = y.clone();
        back_transform(l.as_ref(), x.as_mut(), par);
        let (t_products, _) = median_seconds(runs, time, || accuracy_products(a.as_ref(), b.as_ref(), x.as_ref()));
        line("accuracy products AX, BX, XᵀAX (mechanica only)", t_products, None);
        // Whole solves and mechanica's extras.
        let Ok(problem) = PencilProblem::new(a.as_ref(), b.as_ref()) else {
            continue;
        };
        let (t_count, _) = median_seconds(runs, time, || count_below(&problem, 2.0).map(|c| c.below));
        line("Sturm count LBLᵀ of B − sA (subsets; mechanica only)", t_count, None);
        // An all-pairs solve certifies the bottom of the spectrum with a Cholesky of B − sA.
        let (t_inertia, _) = median_seconds(runs, time, || {
            let shifted = Mat::from_fn(n, n, |i, j| b[(i, j)] - 1e-7 * a[(i, j)]);
            cholesky_lower(shifted.as_ref(), par).map(|l| l[(0, 0)])
        });
        line(
            "Sturm certificate of all pairs, Cholesky of B − sA (mechanica only)",
            t_inertia,
            None,
        );
        let (t_all, _) = median_seconds(runs, time, || {
            solve(&problem, &SolveOptions::default()).map(|s| s.modes.len())
        });
        let (ka, kb) = (b_cm.clone(), a_cm.clone());
        let l_all = lapack_time(&mut || lapack::dsygvd(&ka, &kb, n, true).map(|_| ()));
        line("whole solve, all pairs (solve / dsygvd)", t_all, l_all);
        let sketched = SolveOptions {
            residuals: Residuals::Sketched,
            ..SolveOptions::default()
        };
        let (t_sketched, _) = median_seconds(runs, time, || solve(&problem, &sketched).map(|s| s.modes.len()));
        let l_all = lapack_time(&mut || lapack::dsygvd(&ka, &kb, n, true).map(|_| ()));
        line(
            "whole solve, all pairs, sketched report (solve / dsygvd)",
            t_sketched,
            l_all,
        );
        let extras = t_all - (t_chol + t_red + t_evd + t_back + t_products + t_inertia);
        line(
            "  whole solve minus the stages above (copies, bounds, classification)",
            extras,
            None,
        );
    }
    let header = ["n", "stage", "mechanica_seconds", "lapack_seconds"];
    if let Err(e) = write_csv("modal-dense-stages", &header, &rows) {
        println!("  cannot write csv: {e}");
    }
}

/// A X, B X (full products) and the lower triangle of XᵀAX: the n³ work of mechanica's
/// a-posteriori accuracy report, replicated here to time it alone.
fn accuracy_products(a: MatRef<'_, f64>, b: MatRef<'_, f64>, x: MatRef<'_, f64>) -> f64 {
    use mechanica::modal::faer::Accum;
    use mechanica::modal::faer::linalg::matmul::matmul;
    use mechanica::modal::faer::linalg::matmul::triangular::{BlockStructure, matmul as tri_matmul};
    let par = get_global_parallelism();
    let (n, m) = (x.nrows(), x.ncols());
    let mut ax = Mat::<f64>::zeros(n, m);
    let mut bx = Mat::<f64>::zeros(n, m);
    matmul(ax.as_mut(), Accum::Replace, a, x, 1.0, par);
    matmul(bx.as_mut(), Accum::Replace, b, x, 1.0, par);
    let mut g = Mat::<f64>::zeros(m, m);
    tri_matmul(
        g.as_mut(),
        BlockStructure::TriangularLower,
        Accum::Replace,
        x.transpose(),
        BlockStructure::Rectangular,
        ax.as_ref(),
        BlockStructure::Rectangular,
        1.0,
        par,
    );
    g[(0, 0)] + bx[(0, 0)]
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).filter(|a| !a.starts_with("--")).collect();
    let wanted = |name: &str| args.is_empty() || args.iter().any(|a| a == name);
    match lapack::threads() {
        Some(t) => println!(
            "LAPACK: OpenBLAS with {t} threads, kernels {}",
            lapack::core_name().unwrap_or_default()
        ),
        None => println!("LAPACK: not available (built without OpenBLAS): the dsygvd series are skipped"),
    }
    println!("faer parallelism: {:?}", get_global_parallelism());
    use Method::*;
    let chain_methods = [
        MechAll,
        MechValues,
        MechLowest,
        MechRefined,
        Sparse,
        LapackAll,
        LapackValues,
        Nalgebra,
    ];
    let chain_sizes = [100, 400, 1000, 2000];
    type Family = (
        &'static str,
        &'static str,
        &'static str,
        fn(usize) -> (Mat<f64>, Mat<f64>),
        fn(usize) -> Vec<f64>,
    );
    let chains: [Family; 3] = [
        (
            "fixed",
            "fixed chain",
            "Fixed-fixed spring chain",
            testing::fixed_chain,
            testing::fixed_chain_omega_sq,
        ),
        (
            "free",
            "free chain",
            "Free-free spring chain (rigid-body mode)",
            testing::free_chain,
            testing::free_chain_omega_sq,
        ),
        (
            "ring",
            "ring",
            "Spring ring (double eigenvalues)",
            testing::ring,
            testing::ring_omega_sq,
        ),
    ];
    for (key, label, title, pencil, exact) in chains {
        if wanted(key) {
            let cases: Vec<Case> = chain_sizes
                .iter()
                .map(|&n| chain_case(label, n, pencil, exact))
                .collect();
            report(key, title, &cases, &chain_methods);
        }
    }
    if wanted("rotated") {
        let cases: Vec<Case> = [200, 1000, 2000, 4000].into_iter().map(rotated_case).collect();
        let methods = [
            MechAll,
            MechSketched,
            MechValues,
            MechValuesPlain,
            MechLowest,
            LapackAll,
            LapackValues,
            Nalgebra,
        ];
        let rows = report("rotated", "Rotated fixed chain (dense)", &cases, &methods);
        dense_summary(&rows);
    }
    if wanted("lumped") {
        // Diagonal masses, dense stiffness: mechanica scales instead of factoring, dsygvd does not.
        let cases: Vec<Case> = [200, 1000, 2000].into_iter().map(lumped_case).collect();
        let methods = [MechAll, MechSketched, MechValues, MechLowest, LapackAll, LapackValues];
        report(
            "lumped",
            "Lumped masses, rotated stiffness (A diagonal, B dense)",
            &cases,
            &methods,
        );
    }
    if args.iter().any(|a| a == "rotated-plain") {
        // Like-for-like with dsygvd: all pairs without the auto refinement of the low modes.
        let cases: Vec<Case> = [1000, 2000, 4000].into_iter().map(rotated_case).collect();
        report(
            "rotated-plain",
            "Rotated fixed chain, no refinement",
            &cases,
            &[MechPlain, MechSketched, LapackAll],
        );
    }
    if wanted("graded") {
        let methods = [
            MechPlain,
            MechAll,
            MechValues,
            MechLowest,
            MechRefined,
            Sparse,
            LapackAll,
            LapackValues,
            Nalgebra,
        ];
        report(
            "graded",
            "Graded stiff chains, single and doubled (mpmath references)",
            &graded_cases(),
            &methods,
        );
    }
    if wanted("graded-random") {
        // The certified low modes (default: Auto) against the plain reduction and the peers.
        let cases: Vec<Case> = [250, 500, 1000]
            .into_iter()
            .flat_map(|n| [graded::Shape::Chain, graded::Shape::Tree].map(|shape| graded_random_case(n, shape)))
            .collect();
        let methods = [MechPlain, MechAll, MechValues, MechLowest, Sparse, LapackAll, Scipy];
        report(
            "graded-random",
            "Random graded spring chains and trees (double-double references)",
            &cases,
            &methods,
        );
    }
    if wanted("grid") {
        let cases: Vec<Case> = [20, 50, 100, 300].into_iter().map(grid_case).collect();
        let methods = [Sparse, MechLowest, LapackValues];
        report("grid", "5-point grid Laplacian (sparse)", &cases, &methods);
    }
    if wanted("stages") {
        stages(&[1000, 2000, 4000]);
    } else if wanted("stages-small") {
        stages(&[1000, 2000]);
    }
}
