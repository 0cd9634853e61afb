//! The report: a titled, versioned list of typed steps, each one analysis with its results,
//! accuracy and wall-clock time. The same structures give the JSON report (serde, laid out in
//! docs/json-report.md and docs/report.schema.json) and the text report ([`text`]).

mod finite;
pub mod text;

pub use finite::{NonFiniteResult, check_finite};
use serde::Serialize;

/// The version of the JSON layout: additions keep it, renames and removals raise it. Version 1
/// was the untyped `steps[].quantities[]` layout.
pub const SCHEMA_VERSION: u32 = 2;

/// Which command produced a report.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Command {
    /// `mechanica run`: a scene file, a URDF robot or the default scene.
    Run,
    /// `mechanica mass`: the inertia calculator.
    Mass,
    /// `mechanica modes`: the modes of a pencil from Matrix Market files.
    Modes,
    /// `mechanica version`.
    Version,
}

/// A whole report.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// The layout version, [`SCHEMA_VERSION`].
    pub schema_version: u32,
    /// The mechanica version that produced the report.
    pub mechanica_version: String,
    /// The command.
    pub command: Command,
    /// The scene's title, or what the command computed.
    pub title: String,
    /// The steps, in the order they ran.
    pub steps: Vec<Step>,
}

impl Report {
    /// A report of `command` with this build's versions.
    pub fn new(command: Command, title: String, steps: Vec<Step>) -> Report {
        Report {
            schema_version: SCHEMA_VERSION,
            mechanica_version: mechanica::version().into(),
            command,
            title,
            steps,
        }
    }
}

/// One step: a typed record of one analysis, with its title, time, warnings and remarks.
#[derive(Debug, Clone, Serialize)]
pub struct Step {
    /// What was computed: the `analysis` tag and the analysis's own fields.
    #[serde(flatten)]
    pub record: Record,
    /// The analysis in words, with the equations it solves.
    pub title: String,
    /// The scene the step belongs to, when a report merges several (the default scene).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scene: Option<String>,
    /// Wall-clock time of the step, in seconds.
    pub seconds: f64,
    /// Things the user should look at (e.g. a link made massless, a point that is not an
    /// equilibrium), each a sentence starting with "warning:".
    pub warnings: Vec<String>,
    /// Remarks in words (files written, a chart re-centred).
    pub notes: Vec<String>,
}

impl Step {
    /// A step titled `title` with `record`, no warnings or notes.
    pub fn new(title: &str, seconds: f64, record: impl Into<Record>) -> Step {
        Step {
            record: record.into(),
            title: title.into(),
            scene: None,
            seconds,
            warnings: Vec::new(),
            notes: Vec::new(),
        }
    }
}

/// Declares the [`Record`] enum, one variant per analysis, with `From` for each record type
/// and the text dispatch.
macro_rules! records {
    ($($(#[$doc:meta])* $variant:ident($ty:ty),)*) => {
        /// The typed result of one analysis; serialized with an `analysis` tag (snake_case of
        /// the variant) beside the record's fields.
        #[derive(Debug, Clone, Serialize)]
        #[serde(tag = "analysis", rename_all = "snake_case")]
        pub enum Record {
            $($(#[$doc])* $variant($ty),)*
        }
        $(impl From<$ty> for Record {
            fn from(record: $ty) -> Record {
                Record::$variant(record)
            }
        })*
        impl Record {
            /// Writes the record's lines of the text report.
            pub fn write_text(&self, out: &mut text::Text) {
                match self {
                    $(Record::$variant(r) => r.write_text(out),)*
                }
            }
        }
    };
}

use crate::constraint_run::records as constrained;
use crate::dynamics_run::records as dynamics;
use crate::mass_command::records as mesh;
use crate::mechanism_run::records as mechanism;
use crate::modes_command::records as pencil;
use crate::scene_run::records as scene;

records! {
    /// The bodies, coordinates and q0 of a scene.
    Build(scene::BuildRecord),
    /// Total mass properties of a scene at q0.
    MassProperties(scene::MassRecord),
    /// A(q), U*(q), its gradient and Hessian at the start state (`run --matrices`).
    StateMatrices(crate::state_matrices::StateMatricesRecord),
    /// The mechanism built from a scene (potentials, rotating frame).
    Mechanism(mechanism::MechanismRecord),
    /// An equilibrium search.
    Equilibrium(mechanism::EquilibriumRecord),
    /// The modes and stability of a mechanism.
    Modes(mechanism::ModesRecord),
    /// The free response by modal superposition.
    Response(mechanism::ResponseRecord),
    /// An impact of a body point on the ground.
    Impact(mechanism::ImpactRecord),
    /// Kane's double pendulum on a rough floor under every restitution law.
    ImpactShowcase(mechanism::ShowcaseRecord),
    /// Forward dynamics at q0.
    ForwardDynamics(dynamics::ForwardRecord),
    /// Inverse dynamics and joint reactions at q0.
    InverseDynamics(dynamics::InverseRecord),
    /// The damped modes about q0.
    DampedModes(dynamics::DampedModesRecord),
    /// q0 and q̇ projected onto the constraints.
    ConstraintProjection(constrained::ProjectionRecord),
    /// Forward dynamics with Lagrange multipliers.
    ConstrainedDynamics(constrained::ConstrainedForwardRecord),
    /// The constrained equilibrium.
    ConstrainedEquilibrium(constrained::ConstrainedEquilibriumRecord),
    /// A simulation in time.
    Simulate(crate::simulate_run::SimulateRecord),
    /// The SVG plots written.
    Plots(scene::PlotsRecord),
    /// A mesh file read (and welded).
    MeshLoad(mesh::MeshLoadRecord),
    /// The mass properties of a mesh.
    MeshMassProperties(mesh::MeshMassRecord),
    /// What the mesh checks found.
    MeshDiagnostics(mesh::MeshDiagnosticsRecord),
    /// Two Matrix Market files read.
    PencilRead(pencil::PencilReadRecord),
    /// The factorization of a pencil.
    PencilFactor(pencil::PencilFactorRecord),
    /// The modes of a pencil.
    PencilModes(pencil::PencilModesRecord),
    /// The accuracy report of a dense pencil solve.
    PencilAccuracy(pencil::PencilAccuracyRecord),
    /// Refinement of poorly bounded modes.
    PencilRefine(pencil::PencilRefineRecord),
    /// The Sturm (inertia) check of a pencil's spectrum.
    SturmCheck(pencil::SturmRecord),
    /// The library's versions and features.
    Library(LibraryRecord),
}

/// Times `body` and wraps its record into a step titled `title`.
pub fn timed_step<R: Into<Record>, E>(title: &str, body: impl FnOnce() -> Result<R, E>) -> Result<Step, E> {
    let start = std::time::Instant::now();
    let record = body()?;
    Ok(Step::new(title, start.elapsed().as_secs_f64(), record))
}

/// The `version` command's record.
#[derive(Debug, Clone, Serialize)]
pub struct LibraryRecord {
    /// `mech_abi_version()` of the C ABI.
    pub abi_version: u32,
    /// `mech_features()`: one bit per compiled-in feature (include/mechanica.h).
    pub feature_bits: u32,
    /// The compiled-in features by name (the facade's cargo features).
    pub features: Vec<String>,
}

/// The facade's features and their `MECH_FEATURE_BIT_*` bits.
fn feature_names(bits: u32) -> Vec<String> {
    use mechanica::ffi::*;
    [
        ("kinematics", MECH_FEATURE_BIT_KINEMATICS),
        ("mass", MECH_FEATURE_BIT_MASS),
        ("impulse", MECH_FEATURE_BIT_IMPULSE),
        ("modal", MECH_FEATURE_BIT_MODAL),
        ("mechanism", MECH_FEATURE_BIT_MECHANISM),
        ("dynamics", MECH_FEATURE_BIT_DYNAMICS),
        ("motion", MECH_FEATURE_BIT_MOTION),
        ("urdf", MECH_FEATURE_BIT_URDF),
    ]
    .into_iter()
    .filter(|(_, bit)| bits & bit != 0)
    .map(|(name, _)| name.to_string())
    .collect()
}

impl LibraryRecord {
    fn write_text(&self, out: &mut text::Text) {
        out.count("C ABI version", self.abi_version as usize);
        out.line(
            "features",
            &format!("{} ({:#x})", self.features.join(", "), self.feature_bits),
        );
    }
}

/// The `version` command's report.
pub fn version_report() -> Result<Report, String> {
    use mechanica::ffi::{mech_abi_version, mech_features};
    let bits = mech_features();
    let record = LibraryRecord {
        abi_version: mech_abi_version(),
        feature_bits: bits,
        features: feature_names(bits),
    };
    Ok(Report::new(
        Command::Version,
        "version".into(),
        vec![Step::new("library", 0.0, record)],
    ))
}
