//! `mechanica modes --mass A.mtx --stiffness B.mtx [--lowest k]`: the small-oscillation modes
//! of a pencil read from Matrix Market files, det(λA + B) = 0 (8.89), with the accuracy report
//! and the wall time of each stage (read, factor, solve, accuracy, refine, Sturm check).
//!
//! Which solver: `--lowest k` on a pencil larger than [`Tuning::dense_limit`] uses the sparse
//! shift-invert Lanczos solver (memory O(nnz + n·k)); everything else is solved densely
//! (all modes, or the k lowest). `--dense` forces the dense solver.

use crate::report::{Quantity, Report, Step, timed_step};
use mechanica::modal::faer::Mat;
use mechanica::modal::{
    ModeKind, PencilProblem, Refinement, Residuals, Selection, SolveOptions, SparsePencil, SparseSolveOptions, Tuning,
    read_matrix_market, solve, solve_sparse,
};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Arguments of `mechanica modes`.
#[derive(Debug, clap::Args)]
pub struct ModesArgs {
    /// Mass matrix A (symmetric positive semidefinite), Matrix Market file, coordinate or array (as `scipy.io.mmwrite` writes dense arrays).
    #[arg(long, value_name = "A.mtx")]
    pub mass: PathBuf,
    /// Stiffness matrix B (symmetric), Matrix Market file, coordinate or array (as `scipy.io.mmwrite` writes dense arrays).
    #[arg(long, value_name = "B.mtx")]
    pub stiffness: PathBuf,
    /// Only the k lowest modes (sparse Lanczos above the dense limit).
    #[arg(long, value_name = "K")]
    pub lowest: Option<usize>,
    /// Solve densely even when --lowest would pick the sparse solver.
    #[arg(long)]
    pub dense: bool,
    /// Include the mode shapes (column by column, n values per mode).
    #[arg(long)]
    pub shapes: bool,
    /// Eigenvalues only (dense solver; no shapes). Bounds are a-priori, except for modes whose
    /// a-priori bound is weak, which --refinement auto measures and refines.
    #[arg(long, conflicts_with = "shapes")]
    pub values_only: bool,
    /// Refinement of poorly bounded low modes: auto, off or always (dense solver).
    #[arg(long, value_name = "POLICY", default_value = "auto")]
    pub refinement: String,
    /// Sketched accuracy report (probabilistic upper bounds at O(n²) cost; dense solver).
    #[arg(long)]
    pub sketched: bool,
    /// Largest order solved densely: a dense solve keeps about seven n×n matrices (n = 10 000:
    /// about 5.6 GB); above it the dense solver is refused with an error (use --lowest K).
    #[arg(long, value_name = "N", default_value_t = DEFAULT_MAX_DENSE_ORDER)]
    pub max_dense_order: usize,
}

/// The default of `--max-dense-order`.
pub const DEFAULT_MAX_DENSE_ORDER: usize = 10_000;

fn quantity(name: &str, values: Vec<f64>, unit: &str, accuracy: Option<String>) -> Quantity {
    Quantity {
        name: name.into(),
        values,
        unit: unit.into(),
        accuracy,
    }
}

fn stage(analysis: &str, time: Duration, quantities: Vec<Quantity>) -> Step {
    Step {
        analysis: analysis.into(),
        seconds: time.as_secs_f64(),
        quantities,
        notes: Vec::new(),
    }
}

/// The classification code written to the report (0 oscillatory, 1 zero, 2 unstable, 3 infinite,
/// 4 undecided: the interval ω² ± bound contains zero).
fn kind_code(kind: ModeKind) -> f64 {
    match kind {
        ModeKind::Oscillatory { .. } => 0.0,
        ModeKind::Zero => 1.0,
        ModeKind::Unstable { .. } => 2.0,
        ModeKind::Infinite => 3.0,
        ModeKind::Undecided => 4.0,
    }
}

const KIND_UNIT: &str =
    "kind (0 oscillatory, 1 zero/rigid-body, 2 unstable, 3 infinite, 4 undecided: ω² ± bound contains 0)";

/// The per-mode quantities shared by the dense and the sparse report.
fn mode_quantities(modes: &[mechanica::modal::Mode], groups: &[mechanica::modal::ModeGroup]) -> Vec<Quantity> {
    let bound = modes.iter().map(|m| m.error_bound).fold(0.0, f64::max);
    let omega: Vec<f64> = modes
        .iter()
        .map(|m| match m.kind {
            ModeKind::Oscillatory { omega } => omega,
            ModeKind::Infinite => f64::INFINITY,
            _ => 0.0,
        })
        .collect();
    let mut quantities = vec![
        quantity(
            "λ (8.89: det(λA + B) = 0)",
            modes.iter().map(|m| m.lambda).collect(),
            "1/s²",
            None,
        ),
        quantity(
            "ω² = −λ",
            modes.iter().map(|m| m.omega_sq).collect(),
            "rad²/s²",
            Some(format!("max error bound {bound:.2e}")),
        ),
        quantity(
            "error bound of ω²",
            modes.iter().map(|m| m.error_bound).collect(),
            "rad²/s²",
            None,
        ),
        quantity(
            "backward error η",
            modes.iter().map(|m| m.backward_error.unwrap_or(f64::NAN)).collect(),
            "",
            None,
        ),
        quantity("ω (oscillatory modes)", omega.clone(), "rad/s", None),
        quantity(
            "frequency f = ω/2π",
            omega.iter().map(|w| w / std::f64::consts::TAU).collect(),
            "Hz",
            None,
        ),
        quantity(
            "growth rate (unstable modes)",
            modes
                .iter()
                .map(|m| match m.kind {
                    ModeKind::Unstable { growth_rate } => growth_rate,
                    _ => 0.0,
                })
                .collect(),
            "1/s",
            None,
        ),
        quantity(
            "classification",
            modes.iter().map(|m| kind_code(m.kind)).collect(),
            KIND_UNIT,
            None,
        ),
        quantity(
            "group multiplicity",
            modes.iter().map(|m| groups[m.group].multiplicity as f64).collect(),
            "",
            None,
        ),
    ];
    // Values only: no backward error was measured; the row is left out rather than printed as NaN.
    quantities.retain(|q| !(q.name == "backward error η" && q.values.iter().all(|v| v.is_nan())));
    quantities
}

fn shapes(x: &Mat<f64>) -> Quantity {
    let values = (0..x.ncols())
        .flat_map(|j| (0..x.nrows()).map(move |i| x[(i, j)]))
        .collect();
    quantity("mode shapes (column-major, n per mode)", values, "", None)
}

fn read(path: &Path) -> Result<mechanica::modal::MatrixMarket, String> {
    read_matrix_market(path).map_err(|e| format!("{}: {e}", path.display()))
}

/// Runs the command.
pub fn run(args: &ModesArgs) -> Result<Report, String> {
    let refinement = parse_refinement(&args.refinement)?;
    let (read_step, a, b) = read_pencil(args)?;
    let n = a.nrows;
    let mut steps = vec![read_step];
    let sparse =
        matches!(args.lowest, Some(k) if n > Tuning::DEFAULT.dense_limit && k < n) && !args.dense && !args.values_only;
    if sparse {
        steps.extend(sparse_steps(args, &a, &b)?);
    } else if n > args.max_dense_order {
        return Err(format!(
            "order {n} is above the dense limit --max-dense-order {} (about seven n×n matrices of doubles, {:.1} GB): ask for --lowest K (sparse Lanczos), or raise the limit",
            args.max_dense_order,
            7.0 * 8.0 * (n as f64) * (n as f64) / 1e9
        ));
    } else {
        steps.extend(dense_steps(args, refinement, &a, &b)?);
    }
    Ok(Report {
        title: format!("modes of ({}, {})", args.mass.display(), args.stiffness.display()),
        version: env!("CARGO_PKG_VERSION").into(),
        steps,
    })
}

/// The refinement policy named by `--refinement` (auto, off or always).
fn parse_refinement(name: &str) -> Result<Refinement, String> {
    match name {
        "auto" => Ok(Refinement::Auto),
        "off" => Ok(Refinement::Off),
        "always" => Ok(Refinement::Always),
        other => Err(format!("--refinement must be auto, off or always, got {other}")),
    }
}

/// Reads A and B, checks that they are square and of one order, and reports the timed step.
fn read_pencil(
    args: &ModesArgs,
) -> Result<(Step, mechanica::modal::MatrixMarket, mechanica::modal::MatrixMarket), String> {
    let mut files = None;
    let read_step = timed_step("read Matrix Market files", || -> Result<Vec<Quantity>, String> {
        let (a, b) = (read(&args.mass)?, read(&args.stiffness)?);
        if a.nrows != a.ncols || b.nrows != b.ncols || a.nrows != b.nrows {
            return Err(format!(
                "A is {}×{} and B is {}×{}: both must be square and of the same order",
                a.nrows, a.ncols, b.nrows, b.ncols
            ));
        }
        mechanica::modal::check_every_coordinate_used(a.nrows, &a.entries, &b.entries).map_err(|e| e.to_string())?;
        let out = vec![
            quantity("order n", vec![a.nrows as f64], "", None),
            quantity(
                "stored entries of A, B",
                vec![a.entries.len() as f64, b.entries.len() as f64],
                "",
                None,
            ),
        ];
        files = Some((a, b));
        Ok(out)
    })?;
    let Some((a, b)) = files else {
        return Err("the Matrix Market files were not read".into());
    };
    Ok((read_step, a, b))
}

/// The `--lowest k` modes by sparse shift-invert Lanczos: the factor, solve, refine and Sturm
/// check steps.
fn sparse_steps(
    args: &ModesArgs,
    a: &mechanica::modal::MatrixMarket,
    b: &mechanica::modal::MatrixMarket,
) -> Result<Vec<Step>, String> {
    let count = args.lowest.unwrap_or(0);
    let pencil = SparsePencil::from_triplets(a.nrows, &a.entries, &b.entries).map_err(|e| e.to_string())?;
    let sol = solve_sparse(
        &pencil,
        &SparseSolveOptions {
            count,
            ..SparseSolveOptions::default()
        },
    )
    .map_err(|e| e.to_string())?;
    let r = &sol.report;
    let t = r.timings;
    let mut steps = Vec::new();
    steps.push(stage(
        "factor B − σA (sparse Cholesky)",
        t.factor,
        vec![
            quantity("shift σ", vec![r.shift], "rad²/s²", None),
            quantity("stored entries of the factor", vec![r.factor_nnz as f64], "", None),
        ],
    ));
    let mut quantities = mode_quantities(&sol.modes, &sol.groups);
    quantities.push(quantity(
        "max backward error, A-orthogonality error",
        vec![r.max_backward_error, r.orthogonality_error],
        "",
        None,
    ));
    quantities.push(quantity(
        "Sturm check: shift, count below, computed below",
        vec![
            r.inertia.map_or(f64::NAN, |c| c.count.shift),
            r.inertia.map_or(f64::NAN, |c| c.count.below as f64),
            r.computed_below as f64,
        ],
        "",
        Some(if r.consistent { "consistent" } else { "INCONSISTENT" }.into()),
    ));
    if args.shapes {
        quantities.push(shapes(&sol.vectors));
    }
    steps.push(stage("solve (shift-invert block Lanczos)", t.lanczos, quantities));
    steps.push(stage(
        "refine (Rayleigh–Ritz, double-double residuals)",
        t.refine,
        Vec::new(),
    ));
    steps.push(stage("Sturm check (inertia of B − τA)", t.inertia, Vec::new()));
    Ok(steps)
}

/// The dense n × n matrix summing the triplets `t` (duplicates add up).
fn dense_matrix(n: usize, t: &[mechanica::modal::faer::sparse::Triplet<usize, usize, f64>]) -> Mat<f64> {
    let mut m = Mat::<f64>::zeros(n, n);
    for e in t {
        m[(e.row, e.col)] += e.val;
    }
    m
}

/// All modes (or the k lowest) by the dense solver: the factor, solve, accuracy, refine and
/// Sturm check steps.
fn dense_steps(
    args: &ModesArgs,
    refinement: Refinement,
    a: &mechanica::modal::MatrixMarket,
    b: &mechanica::modal::MatrixMarket,
) -> Result<Vec<Step>, String> {
    let n = a.nrows;
    let problem = PencilProblem::new(
        dense_matrix(n, &a.entries).as_ref(),
        dense_matrix(n, &b.entries).as_ref(),
    )
    .map_err(|e| e.to_string())?;
    let options = SolveOptions {
        selection: args.lowest.map_or(Selection::All, Selection::Lowest),
        vectors: !args.values_only,
        refinement,
        residuals: if args.sketched {
            Residuals::Sketched
        } else {
            Residuals::Exact
        },
    };
    let sol = solve(&problem, &options).map_err(|e| e.to_string())?;
    let t = sol.timings;
    let mut steps = Vec::new();
    steps.push(stage(
        "factor (Cholesky of A, reduction C = L⁻¹BL⁻ᵀ)",
        t.factor,
        Vec::new(),
    ));
    let mut quantities = mode_quantities(&sol.modes, &sol.groups);
    if let Some(x) = sol.vectors.as_ref().filter(|_| args.shapes) {
        quantities.push(shapes(x));
    }
    steps.push(stage(
        "solve (eigen-decomposition, back-transformation)",
        t.eigen,
        quantities,
    ));
    steps.extend(dense_accuracy_steps(&sol.accuracy, &t));
    Ok(steps)
}

/// The accuracy report, refinement and Sturm check steps of a dense solution.
fn dense_accuracy_steps(acc: &mechanica::modal::AccuracyReport, t: &mechanica::modal::SolveTimings) -> [Step; 3] {
    // Values only: no pair was formed, so there is no backward error to print (not a NaN).
    let measured = match (acc.max_backward_error, acc.orthogonality_error) {
        (Some(eta), Some(orthogonality)) => vec![quantity(
            "max backward error, A-orthogonality error",
            vec![eta, orthogonality],
            "",
            Some(format!("{:?} residuals", acc.residuals)),
        )],
        _ => Vec::new(),
    };
    let accuracy = stage("accuracy report", t.accuracy, measured);
    let refined = acc.refinement_steps.iter().filter(|&&s| s > 0).count();
    let refine = stage(
        "refine (Newton, double-double residuals)",
        t.refine,
        vec![quantity("refined modes", vec![refined as f64], "", None)],
    );
    let check = acc.inertia_check;
    let sturm = stage(
        "Sturm check (inertia of B − sA)",
        t.inertia,
        vec![quantity(
            "shift, count below, computed below",
            check.map_or(vec![], |c| {
                vec![c.count.shift, c.count.below as f64, c.computed_below as f64]
            }),
            "",
            Some(match check {
                Some(c) if c.consistent => "consistent".into(),
                Some(_) => "INCONSISTENT".into(),
                None => "not run (no finite mode)".into(),
            }),
        )],
    );
    [accuracy, refine, sturm]
}
