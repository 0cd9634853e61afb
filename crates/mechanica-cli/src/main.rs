//! The `mechanica` command line: runs a scene file, a URDF robot or the built-in default scene,
//! computes the mass properties of a mesh file, or the modes of a pencil from Matrix Market
//! files, and prints a readable report, or JSON with `--json`.

mod constraint_run;
mod damped_run;
mod default_scene;
mod dynamics_run;
mod mass_command;
mod mechanism_run;
mod modes_command;
mod plots;
mod progress;
mod report;
mod scene;
mod scene_run;
mod simulate_run;
mod simulation_plots;
mod trajectory_file;
mod urdf;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Analytical mechanics for simulators.
#[derive(Debug, Parser)]
#[command(name = "mechanica", version, about, long_about = None)]
struct Cli {
    /// Print the machine-readable JSON report instead of the text report.
    #[arg(long, global = true)]
    json: bool,
    /// URDF input: replace invalid link inertias by the nearest physical tensors (and say so)
    /// instead of refusing the file.
    #[arg(long, global = true)]
    repair_inertia: bool,
    /// URDF input: make a link without <inertial> whose mesh cannot be used (missing file,
    /// unsupported format) massless, with a warning in the report, instead of refusing the file.
    #[arg(long, global = true)]
    allow_missing_mesh: bool,
    /// Scene input: the most values a free response may store, samples × (dof + 1); a scene
    /// asking for more is refused.
    #[arg(long, global = true, value_name = "N", default_value_t = scene::SceneLimits::DEFAULT.max_response_values)]
    max_response_values: usize,
    /// Write SVG plots (spectrum, mode shapes, free response, impact energy) into this directory.
    #[arg(long, global = true, value_name = "DIR")]
    plot: Option<std::path::PathBuf>,
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run a scene file (TOML; see the format in the README) or a URDF robot, or the built-in default scene
    /// when no file is given (also what a bare `mechanica` does).
    Run {
        /// The scene file.
        scene: Option<std::path::PathBuf>,
    },
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

fn main() -> ExitCode {
    let cli = Cli::parse();
    let report = match cli.command.unwrap_or(Command::Run { scene: None }) {
        Command::Run { scene: None } => default_scene::run(cli.plot.as_deref()),
        Command::Run { scene: Some(path) } if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("urdf")) => {
            let options = urdf::UrdfOptions {
                repair_inertia: cli.repair_inertia,
                allow_missing_mesh: cli.allow_missing_mesh,
            };
            urdf::load(&path, options).and_then(|(scene, notes)| {
                let mut report = scene_run::run(&scene, &path, cli.plot.as_deref())?;
                if let Some(first) = report.steps.first_mut() {
                    first.notes.extend(notes);
                }
                Ok(report)
            })
        }
        Command::Run { scene: Some(path) } => {
            let limits = scene::SceneLimits {
                max_response_values: cli.max_response_values,
            };
            scene::Scene::load_with(&path, &limits)
                .map_err(|e| e.to_string())
                .and_then(|scene| scene_run::run(&scene, &path, cli.plot.as_deref()))
        }
        Command::Mass(args) => mass_command::run(&args),
        Command::Modes(args) => modes_command::run(&args),
        Command::Version => report::version_report(),
    };
    match report {
        Ok(report) => {
            if cli.json {
                match serde_json::to_string_pretty(&report) {
                    Ok(text) => println!("{text}"),
                    Err(error) => {
                        eprintln!("mechanica: could not encode the report as JSON: {error}");
                        return ExitCode::FAILURE;
                    }
                }
            } else {
                print!("{}", report.to_text());
            }
            ExitCode::SUCCESS
        }
        Err(error) => {
            eprintln!("mechanica: {error}");
            ExitCode::FAILURE
        }
    }
}
