//! `mechanica modes --mass A.mtx --stiffness B.mtx [--lowest k]`: the small-oscillation modes
//! of a pencil read from Matrix Market files, det(λA + B) = 0 (8.89), with the accuracy report
//! and the wall time of each stage (read, factor, solve, accuracy, refine, Sturm check).
//!
//! Which solver: `--lowest k` on a pencil larger than [`Tuning::dense_limit`] uses the sparse
//! shift-invert Lanczos solver (memory O(nnz + n·k)); everything else is solved densely
//! (all modes, or the k lowest). `--dense` forces the dense solver.

pub(crate) mod records;

use crate::mechanism_run::records::SturmStatus;
use crate::mode_record::ModeRecord;
use crate::pencil_shape_plot::{MAX_MODES, PencilShape};
use crate::report::{Command, Record, Report, Step, timed_step};
use crate::scene_run::records::PlotsRecord;
use mechanica::modal::faer::Mat;
use mechanica::modal::{
    PencilProblem, Refinement, Residuals, Selection, SolveOptions, SparsePencil, SparseSolveOptions, Tuning,
    read_matrix_market, solve, solve_sparse,
};
use records::{
    PencilAccuracyRecord, PencilFactorRecord, PencilModesRecord, PencilReadRecord, PencilRefineRecord, ResidualsName,
    SolverName, SturmRecord,
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
    /// Write the first six mode shapes, each as its displacement against the coordinate index,
    /// to DIR/mode_shapes.svg.
    #[arg(long, value_name = "DIR", conflicts_with = "values_only")]
    pub plot: Option<PathBuf>,
}

/// The default of `--max-dense-order`.
pub const DEFAULT_MAX_DENSE_ORDER: usize = 10_000;

fn stage(analysis: &str, time: Duration, record: impl Into<Record>) -> Step {
    Step::new(analysis, time.as_secs_f64(), record)
}

/// The mode records of a solution, with the shapes when `x` is given (column k: mode k).
fn mode_records(
    modes: &[mechanica::modal::Mode],
    groups: &[mechanica::modal::ModeGroup],
    x: Option<&Mat<f64>>,
) -> Vec<ModeRecord> {
    modes
        .iter()
        .enumerate()
        .map(|(k, mode)| {
            let shape = x
                .filter(|x| k < x.ncols())
                .map(|x| (0..x.nrows()).map(|i| x[(i, k)]).collect());
            ModeRecord::new(mode, groups, shape)
        })
        .collect()
}

/// The first modes with their shapes, for `--plot` (none without vectors).
fn plotted_shapes(modes: &[mechanica::modal::Mode], x: Option<&Mat<f64>>) -> Vec<PencilShape> {
    let Some(x) = x else { return Vec::new() };
    modes
        .iter()
        .take(MAX_MODES.min(x.ncols()))
        .enumerate()
        .map(|(k, mode)| PencilShape {
            number: k + 1,
            omega_sq: Some(mode.omega_sq).filter(|w| w.is_finite()),
            bound: mode.error_bound,
            shape: (0..x.nrows()).map(|i| x[(i, k)]).collect(),
        })
        .collect()
}

fn max_bound(modes: &[mechanica::modal::Mode]) -> f64 {
    modes.iter().map(|m| m.error_bound).fold(0.0, f64::max)
}

/// The outcome of a Sturm check.
fn sturm_status(consistent: Option<bool>) -> SturmStatus {
    match consistent {
        Some(true) => SturmStatus::Consistent,
        Some(false) => SturmStatus::Inconsistent,
        None => SturmStatus::NotRun,
    }
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
    let mut shapes = Vec::new();
    let sparse =
        matches!(args.lowest, Some(k) if n > Tuning::DEFAULT.dense_limit && k < n) && !args.dense && !args.values_only;
    if sparse {
        steps.extend(sparse_steps(args, &a, &b, &mut shapes)?);
    } else if n > args.max_dense_order {
        return Err(format!(
            "order {n} is above the dense limit --max-dense-order {} (about seven n×n matrices of doubles, {:.1} GB): ask for --lowest K (sparse Lanczos), or raise the limit",
            args.max_dense_order,
            7.0 * 8.0 * (n as f64) * (n as f64) / 1e9
        ));
    } else {
        steps.extend(dense_steps(args, refinement, &a, &b, &mut shapes)?);
    }
    if let Some(dir) = &args.plot {
        steps.push(plot_step(dir, &shapes)?);
    }
    Ok(Report::new(
        Command::Modes,
        format!("modes of ({}, {})", args.mass.display(), args.stiffness.display()),
        steps,
    ))
}

/// Writes `mode_shapes.svg` into `dir` (created if needed) and reports the file.
fn plot_step(dir: &Path, shapes: &[PencilShape]) -> Result<Step, String> {
    let start = std::time::Instant::now();
    std::fs::create_dir_all(dir).map_err(|e| format!("plot directory {}: {e}", dir.display()))?;
    let path = dir.join("mode_shapes.svg");
    crate::pencil_shape_plot::write(shapes, &path)?;
    let files = vec![path.display().to_string()];
    Ok(stage("plots", start.elapsed(), PlotsRecord { files }))
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
    let read_step = timed_step("read Matrix Market files", || -> Result<PencilReadRecord, String> {
        let (a, b) = (read(&args.mass)?, read(&args.stiffness)?);
        if a.nrows != a.ncols || b.nrows != b.ncols || a.nrows != b.nrows {
            return Err(format!(
                "A is {}×{} and B is {}×{}: both must be square and of the same order",
                a.nrows, a.ncols, b.nrows, b.ncols
            ));
        }
        mechanica::modal::check_every_coordinate_used(a.nrows, &a.entries, &b.entries).map_err(|e| e.to_string())?;
        let record = PencilReadRecord {
            order: a.nrows,
            mass_entries: a.entries.len(),
            stiffness_entries: b.entries.len(),
        };
        files = Some((a, b));
        Ok(record)
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
    shapes: &mut Vec<PencilShape>,
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
    *shapes = plotted_shapes(&sol.modes, Some(&sol.vectors));
    let r = &sol.report;
    let t = r.timings;
    let factor = PencilFactorRecord {
        shift: Some(r.shift),
        factor_entries: Some(r.factor_nnz),
    };
    let modes = PencilModesRecord {
        solver: SolverName::SparseLanczos,
        modes: mode_records(&sol.modes, &sol.groups, Some(&sol.vectors).filter(|_| args.shapes)),
        max_bound: max_bound(&sol.modes),
        max_backward_error: Some(r.max_backward_error),
        orthogonality_error: Some(r.orthogonality_error),
    };
    let sturm = SturmRecord {
        status: sturm_status(Some(r.consistent)),
        shift: r.inertia.map(|c| c.count.shift),
        count_below: r.inertia.map(|c| c.count.below),
        computed_below: Some(r.computed_below),
    };
    let no_count = PencilRefineRecord { refined_modes: None };
    Ok(vec![
        stage("factor B − σA (sparse Cholesky)", t.factor, factor),
        stage("solve (shift-invert block Lanczos)", t.lanczos, modes),
        stage("refine (Rayleigh–Ritz, double-double residuals)", t.refine, no_count),
        stage("Sturm check (inertia of B − τA)", t.inertia, sturm),
    ])
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
    shapes: &mut Vec<PencilShape>,
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
    *shapes = plotted_shapes(&sol.modes, sol.vectors.as_ref());
    let t = sol.timings;
    let factor = PencilFactorRecord {
        shift: None,
        factor_entries: None,
    };
    let modes = PencilModesRecord {
        solver: SolverName::Dense,
        modes: mode_records(&sol.modes, &sol.groups, sol.vectors.as_ref().filter(|_| args.shapes)),
        max_bound: max_bound(&sol.modes),
        max_backward_error: None,
        orthogonality_error: None,
    };
    let mut steps = vec![
        stage("factor (Cholesky of A, reduction C = L⁻¹BL⁻ᵀ)", t.factor, factor),
        stage("solve (eigen-decomposition, back-transformation)", t.eigen, modes),
    ];
    steps.extend(dense_accuracy_steps(&sol.accuracy, &t));
    Ok(steps)
}

/// The accuracy report, refinement and Sturm check steps of a dense solution.
fn dense_accuracy_steps(acc: &mechanica::modal::AccuracyReport, t: &mechanica::modal::SolveTimings) -> [Step; 3] {
    let accuracy = PencilAccuracyRecord {
        residuals: match acc.residuals {
            Residuals::Sketched => ResidualsName::Sketched,
            _ => ResidualsName::Exact,
        },
        max_backward_error: acc.max_backward_error,
        orthogonality_error: acc.orthogonality_error,
    };
    let refined = acc.refinement_steps.iter().filter(|&&s| s > 0).count();
    let check = acc.inertia_check;
    let sturm = SturmRecord {
        status: sturm_status(check.map(|c| c.consistent)),
        shift: check.map(|c| c.count.shift),
        count_below: check.map(|c| c.count.below),
        computed_below: check.map(|c| c.computed_below),
    };
    [
        stage("accuracy report", t.accuracy, accuracy),
        stage(
            "refine (Newton, double-double residuals)",
            t.refine,
            PencilRefineRecord {
                refined_modes: Some(refined),
            },
        ),
        stage("Sturm check (inertia of B − sA)", t.inertia, sturm),
    ]
}
