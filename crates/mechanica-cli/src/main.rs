//! The `mechanica` command line: runs a scene file, a URDF robot or the built-in default scene,
//! computes the mass properties of a mesh file, or the modes of a pencil from Matrix Market
//! files, and prints a readable report, or JSON with `--json`.

mod constraint_run;
mod damped_run;
mod default_scene;
mod dynamics_run;
mod impact_plot;
mod mass_command;
mod mechanism_run;
mod mode_record;
mod mode_shape;
mod mode_shape_plot;
mod modes_command;
mod pencil_shape_plot;
mod plots;
mod progress;
mod report;
mod scene;
mod scene_run;
mod simulate_run;
mod simulation_plots;
mod spectrum_plot;
mod state_matrices;
mod trajectory_file;
mod urdf;

use clap::{Parser, Subcommand};
use std::io::Write as _;
use std::process::ExitCode;

/// Analytical mechanics for simulators.
#[derive(Debug, Parser)]
#[command(name = "mechanica", version, about, long_about = None)]
struct Cli {
    /// Print the machine-readable JSON report (docs/json-report.md) instead of the text report.
    #[arg(long, global = true)]
    json: bool,
    #[command(subcommand)]
    command: Option<Command>,
}

/// Arguments of `mechanica run`.
#[derive(Debug, clap::Args)]
struct RunArgs {
    /// The scene file (TOML) or URDF robot; the built-in default scene when omitted.
    scene: Option<std::path::PathBuf>,
    /// URDF input: replace invalid link inertias by the nearest physical tensors (and say so)
    /// instead of refusing the file.
    #[arg(long)]
    repair_inertia: bool,
    /// URDF input: make a link without <inertial> whose mesh cannot be used (missing file,
    /// unsupported format) massless, with a warning in the report, instead of refusing the file.
    #[arg(long)]
    allow_missing_mesh: bool,
    /// Scene input: the most values a free response may store, samples × (dof + 1); a scene
    /// asking for more is refused.
    #[arg(long, value_name = "N", default_value_t = scene::SceneLimits::DEFAULT.max_response_values)]
    max_response_values: usize,
    /// Write SVG plots (spectrum, mode shapes, free response, impact energy) into this directory.
    #[arg(long, value_name = "DIR")]
    plot: Option<std::path::PathBuf>,
    /// Evaluate at these coordinates instead of q0 (comma-separated, one per coordinate, in the
    /// order the report prints q0): every analysis starts there, and the modes are those of the
    /// linearisation at q, without an equilibrium search.
    /// An empty value is the configuration of a robot without coordinates.
    #[arg(long, value_name = "Q1,Q2,...", value_parser = parse_coordinates, allow_hyphen_values = true)]
    q: Option<Coordinates>,
    /// Also report, at the start state (--q, or the scene's q0), the mass matrix A(q), the
    /// potential U*(q), its gradient and its Hessian ∂²U*/∂q∂q, in full, over the named
    /// coordinates.
    #[arg(long)]
    matrices: bool,
}

impl Default for RunArgs {
    /// The default scene with the default options (a bare `mechanica`).
    fn default() -> RunArgs {
        RunArgs {
            scene: None,
            repair_inertia: false,
            allow_missing_mesh: false,
            max_response_values: scene::SceneLimits::DEFAULT.max_response_values,
            plot: None,
            q: None,
            matrices: false,
        }
    }
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run a scene file (TOML; see the format in the README) or a URDF robot, or the built-in default scene
    /// when no file is given (also what a bare `mechanica` does).
    Run(RunArgs),
    /// The inertia calculator: mass, centre of mass, inertia, principal moments and axes of a
    /// triangle mesh file (STL or OBJ), with the mesh's diagnostics.
    Mass(mass_command::MassArgs),
    /// Small-oscillation modes of a pencil (A, B) from Matrix Market files: det(λA + B) = 0
    /// with the accuracy report and each stage's wall time (sparse Lanczos for --lowest k on
    /// large pencils).
    Modes(modes_command::ModesArgs),
    /// Print the library version, the C ABI version and the compiled-in features.
    Version,
}

/// Runs a scene file, a URDF robot (by its extension) or the default scene.
fn run(args: &RunArgs) -> Result<report::Report, String> {
    let plot = args.plot.as_deref();
    let state = args.q.as_ref().map(|q| q.0.as_slice());
    match &args.scene {
        None if state.is_some() => Err("--q needs a scene or URDF file: the default scene holds two mechanisms".into()),
        None if args.matrices => {
            Err("--matrices needs a scene or URDF file: the default scene holds two mechanisms".into())
        }
        None => default_scene::run(plot),
        Some(path) if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("urdf")) => {
            let options = urdf::UrdfOptions {
                repair_inertia: args.repair_inertia,
                allow_missing_mesh: args.allow_missing_mesh,
            };
            let (scene, notes) = urdf::load(path, options)?;
            let mut report = scene_run::run_at(&scene, path, plot, state, args.matrices)?;
            if let Some(first) = report.steps.first_mut() {
                let (warnings, remarks): (Vec<String>, Vec<String>) =
                    notes.into_iter().partition(|n| n.starts_with("warning:"));
                first.warnings.extend(warnings);
                first.notes.extend(remarks);
            }
            Ok(report)
        }
        Some(path) => {
            let limits = scene::SceneLimits {
                max_response_values: args.max_response_values,
            };
            let scene = scene::Scene::load_with(path, &limits).map_err(|e| e.to_string())?;
            scene_run::run_at(&scene, path, plot, state, args.matrices)
        }
    }
}

/// The report of the command, checked finite.
fn report_of(command: Command) -> Result<report::Report, String> {
    let report = match command {
        Command::Run(args) => run(&args),
        Command::Mass(args) => mass_command::run(&args),
        Command::Modes(args) => modes_command::run(&args),
        Command::Version => report::version_report(),
    }?;
    for step in &report.steps {
        report::check_finite(step).map_err(|e| e.to_string())?;
    }
    Ok(report)
}

/// The values of `--q`.
#[derive(Debug, Clone)]
struct Coordinates(Vec<f64>);

/// `--q`: comma-separated numbers; an empty (or blank) value is no coordinate at all.
fn parse_coordinates(text: &str) -> Result<Coordinates, String> {
    if text.trim().is_empty() {
        return Ok(Coordinates(Vec::new()));
    }
    text.split(',')
        .map(|item| {
            item.trim()
                .parse::<f64>()
                .map_err(|e| format!("\"{}\" is not a number: {e}", item.trim()))
        })
        .collect::<Result<Vec<_>, _>>()
        .map(Coordinates)
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let report = match report_of(cli.command.unwrap_or(Command::Run(RunArgs::default()))) {
        Ok(report) => report,
        Err(error) => {
            eprintln!("mechanica: {error}");
            return ExitCode::FAILURE;
        }
    };
    if cli.json {
        // Streamed: a long mechanism's report (every body's displacement in every mode) runs
        // to hundreds of megabytes, which need not be held in memory as one string.
        let mut out = std::io::BufWriter::new(std::io::stdout().lock());
        let written = serde_json::to_writer_pretty(&mut out, &report)
            .map_err(|e| e.to_string())
            .and_then(|()| writeln!(out).and_then(|()| out.flush()).map_err(|e| e.to_string()));
        match written {
            Ok(()) => {}
            Err(error) => {
                eprintln!("mechanica: could not write the report as JSON: {error}");
                return ExitCode::FAILURE;
            }
        }
    } else {
        print!("{}", report.to_text());
    }
    ExitCode::SUCCESS
}
