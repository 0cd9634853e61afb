//! `mechanica mass FILE`: the inertia calculator for triangle-mesh files.

use crate::report::Report;

/// Arguments of `mechanica mass`.
#[derive(Debug, clap::Args)]
pub struct MassArgs {
    /// The mesh file (STL binary or ASCII, or OBJ).
    pub file: std::path::PathBuf,
}

/// Runs the inertia calculator on one mesh file.
pub fn run(args: &MassArgs) -> Result<Report, String> {
    Err(format!("{}: the mass command is not implemented yet", args.file.display()))
}
