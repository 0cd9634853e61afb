//! Scene files: a TOML description of a mechanism and of the analyses requested on it.
//!
//! ```toml
//! title = "double pendulum"
//! gravity = [0.0, 0.0, -9.81]          # m/s², world frame; optional (default: none)
//!
//! [[body]]
//! name = "upper"
//! # exactly one of: mass_properties, primitive, mesh
//! primitive = { shape = "rod", length = 1.0, mass = 1.0 }
//! offset = [0.0, 0.0, -0.5]            # shape centre in the body (= joint) frame, m
//!
//! [[body]]
//! name = "lower"
//! mass_properties = { mass = 1.0, com = [0.0, 0.0, -0.5], inertia = [0.1, 0.1, 0.0, 0.0, 0.0, 0.0] }
//!
//! [[joint]]
//! name = "shoulder"
//! type = "revolute"                    # revolute | prismatic | spherical | free | planar | fixed
//! parent = "ground"                    # "ground" or a body name
//! child = "upper"
//! axis = [0.0, 1.0, 0.0]               # revolute / prismatic / planar normal, parent frame
//! origin = [0.0, 0.0, 0.0]             # joint frame origin in the parent frame, m
//! rpy = [0.0, 0.0, 0.0]                # joint frame orientation (URDF roll-pitch-yaw), rad
//! q0 = [0.1]                           # initial coordinates (length = joint's q size)
//! qd0 = [0.0]                          # initial velocities; optional (default 0)
//! limits = [-1.5, 1.5]                 # 1-coordinate joints: limits for equilibrium searches
//!
//! rotating_frame = { axis = [0.0, 0.0, 1.0], rate = 3.0 }   # optional (§8e), put before tables
//!
//! [[joint_spring]]                     # U = ½ k (q − rest)², on one coordinate of a joint
//! joint = "shoulder"
//! stiffness = 20.0                     # N·m/rad or N/m
//! rest = 0.0                           # optional (default 0)
//! coordinate = 0                       # optional: index within the joint (default 0)
//!
//! [[spring]]                           # U = ½ k (|x_a − x_b| − rest_length)²
//! a = "lower"                          # body name or "ground"
//! a_point = [0.0, 0.0, -1.0]           # body coordinates (world for the ground)
//! b = "ground"
//! b_point = [0.5, 0.0, -2.0]
//! stiffness = 50.0                     # N/m
//! rest_length = 0.0                    # optional (default 0)
//!
//! [[force]]                            # a constant world force at a body point: U = −F·x
//! body = "lower"
//! point = [0.0, 0.0, -1.0]
//! force = [1.0, 0.0, 0.0]
//!
//! [[joint_damper]]                     # Rayleigh damper D = ½ c q̇², on one coordinate of a joint
//! joint = "elbow"
//! damping = 0.2                        # c ≥ 0: N·m·s/rad or N·s/m
//! coordinate = 0                       # optional: index within the joint (default 0)
//!
//! [[damper]]                           # linear damper between two points, c ≥ 0 in N·s/m
//! a = "lower"                          # body name or "ground"
//! a_point = [0.0, 0.0, -1.0]
//! b = "ground"
//! b_point = [0.5, 0.0, -2.0]
//! damping = 1.5
//! axial = false                        # optional: true resists only the rate along the line a–b
//!
//! [analyses]                           # only what is listed is computed
//! mass_properties = true
//! equilibrium = { seek = "minimum" }   # or "stationary"; optional starts = [[...], ...]
//! modes = { lowest = 4 }               # optional lowest = k; at the equilibrium if one is asked
//! response = { duration = 5.0, samples = 200, dq0 = [0.1, 0.0] }   # free response (8.91);
//!                                      # needs every mode; samples × (dof + 1) ≤ 10⁷ unless
//!                                      # raised by --max-response-values
//! impact = { body = "lower", point = [0.0, 0.0, -1.0], normal = [0.0, 0.0, 1.0],
//!            friction = 0.3, restitution = 0.5, law = "stronge",
//!            compare_laws = true }           # at q0 with qd0; compare_laws adds the other two laws
//! dynamics = { q_dot = [0.5, 0.0], tau = [1.0, 0.0], q_ddot = [0.0, 0.0], frame = "body" }
//!                                      # at q0: forward dynamics q̈ for τ (default 0), then the
//!                                      # inverse dynamics τ = A q̈ + c + g − Σ Q with its split and
//!                                      # the joint reactions at q_ddot (default: that q̈); q_dot
//!                                      # defaults to the joints' qd0; frame of the reactions:
//!                                      # "world" (default), "body" or "joint"; then the
//!                                      # damped modes det(s²A + s(C + G) + B) = 0 about q0
//!                                      # (kind, ω_n, ω_d, ζ, s with its bound per mode)
//!                                      # With [[constraint]] tables (see `scene/constraints.rs`):
//!                                      # q0 and q_dot are projected onto the constraints, the
//!                                      # forward dynamics carries the multipliers and reactions,
//!                                      # `equilibrium = true` adds the constrained equilibrium,
//!                                      # and the damped modes are not computed
//! ```
//!
//! Unilateral contacts (`[[contact]]`, see `scene/contacts.rs`) are kept by `simulate`: each
//! impact is located, resolved with its restitution law and reported with its energy loss.
//!
//! Constraints (`[[constraint]]`, kinds "points", "plane", "distance", "coordinate") are used by
//! the dynamics analysis and kept by `simulate`: a scene with constraints that asks for the
//! unconstrained equilibrium, modes, free response or impact is refused rather than answered
//! without them.
//!
//! `inertia` lists the six independent entries (Ixx, Iyy, Izz, Ixy, Ixz, Iyz) about the centre
//! of mass, in the body frame. Unknown fields are errors, and so are coordinate counts that do
//! not match the joints (q0, qd0, limits, joint springs and dampers, starts, dq0, v0, the
//! dynamics' q_dot, tau, q_ddot), and negative or non-finite damping. Every error names
//! the file, the line and column, and the field.

#[path = "scene/constraints.rs"]
mod constraints;
#[path = "scene/contacts.rs"]
mod contacts;
#[path = "scene/simulate.rs"]
mod simulate;

pub use constraints::ConstraintSpec;
pub use contacts::ContactSpec;
use serde::Deserialize;
pub use simulate::SimulateSpec;
use std::collections::HashMap;
use std::fmt;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// A scene as written in the file, after syntax and schema checks.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// The scene's title, shown in the report.
    pub title: String,
    /// Gravitational acceleration in the world frame, m/s².
    pub gravity: Option<[f64; 3]>,
    /// The bodies.
    #[serde(default, rename = "body")]
    pub bodies: Vec<BodySpec>,
    /// The joints connecting them.
    #[serde(default, rename = "joint")]
    pub joints: Vec<JointSpec>,
    /// A steadily rotating base frame (§8e); everything is then relative to that frame.
    pub rotating_frame: Option<RotatingFrameSpec>,
    /// Springs on joint coordinates.
    #[serde(default, rename = "joint_spring")]
    pub joint_springs: Vec<JointSpringSpec>,
    /// Springs between body points or a body point and the ground.
    #[serde(default, rename = "spring")]
    pub springs: Vec<SpringSpec>,
    /// Constant forces at body points.
    #[serde(default, rename = "force")]
    pub forces: Vec<ForceSpec>,
    /// Rayleigh dampers on joint coordinates (used by the dynamics).
    #[serde(default, rename = "joint_damper")]
    pub joint_dampers: Vec<JointDamperSpec>,
    /// Linear dampers between body points or a body point and the ground (used by the dynamics).
    #[serde(default, rename = "damper")]
    pub dampers: Vec<DamperSpec>,
    /// Holonomic constraints closing loops or holding points (used by the dynamics).
    #[serde(default, rename = "constraint")]
    pub constraints: Vec<ConstraintSpec>,
    /// Unilateral contacts kept by `simulate` (impacts during the motion).
    #[serde(default, rename = "contact")]
    pub contacts: Vec<ContactSpec>,
    /// The analyses requested; nothing else is computed.
    #[serde(default)]
    pub analyses: Analyses,
}

/// The base frame turning at a constant rate about a fixed axis through its origin.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotatingFrameSpec {
    /// Unit axis (world = base frame).
    pub axis: Spanned<[f64; 3]>,
    /// Rate, rad/s.
    pub rate: f64,
}

/// A spring on one coordinate of a joint.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointSpringSpec {
    /// The joint's name.
    pub joint: Spanned<String>,
    /// Stiffness, N·m/rad or N/m.
    pub stiffness: f64,
    /// Rest value of the coordinate.
    #[serde(default)]
    pub rest: f64,
    /// Index of the coordinate within the joint.
    #[serde(default = "unlocated_zero")]
    pub coordinate: Spanned<usize>,
}

/// A spring between two points.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpringSpec {
    /// First end: a body name or "ground".
    pub a: Spanned<String>,
    /// First end's point, body coordinates (world for the ground), m.
    #[serde(default)]
    pub a_point: [f64; 3],
    /// Second end: a body name or "ground".
    pub b: Spanned<String>,
    /// Second end's point, m.
    #[serde(default)]
    pub b_point: [f64; 3],
    /// Stiffness, N/m.
    pub stiffness: f64,
    /// Rest length, m.
    #[serde(default)]
    pub rest_length: f64,
}

/// A Rayleigh damper on one coordinate of a joint: D = ½ c q̇².
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointDamperSpec {
    /// The joint's name.
    pub joint: Spanned<String>,
    /// c ≥ 0, N·m·s/rad or N·s/m.
    pub damping: Spanned<f64>,
    /// Index of the coordinate within the joint.
    #[serde(default = "unlocated_zero")]
    pub coordinate: Spanned<usize>,
}

/// A linear damper between two points: D = ½ c |v|², or ½ c (e·v)² along the line when axial.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DamperSpec {
    /// First end: a body name or "ground".
    pub a: Spanned<String>,
    /// First end's point, body coordinates (world for the ground), m.
    #[serde(default)]
    pub a_point: [f64; 3],
    /// Second end: a body name or "ground".
    pub b: Spanned<String>,
    /// Second end's point, m.
    #[serde(default)]
    pub b_point: [f64; 3],
    /// c ≥ 0, N·s/m.
    pub damping: Spanned<f64>,
    /// Resist only the relative velocity along the line between the points (a dashpot).
    #[serde(default)]
    pub axial: bool,
}

/// A constant world force at a body point.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ForceSpec {
    /// The body's name.
    pub body: Spanned<String>,
    /// Point of application, body coordinates, m.
    #[serde(default)]
    pub point: [f64; 3],
    /// The force, world components, N.
    pub force: [f64; 3],
}

/// One body and the source of its mass properties.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Unique name, referenced by joints.
    pub name: Spanned<String>,
    /// Explicit mass properties.
    pub mass_properties: Option<ExplicitMass>,
    /// A primitive shape.
    pub primitive: Option<Primitive>,
    /// A triangle mesh file with a density.
    pub mesh: Option<MeshSpec>,
    /// Where the shape's own frame (its centre, for primitives) sits in the body frame, m.
    /// The body frame is the joint frame, so a pendulum rod hanging from its hinge has
    /// `offset = [0, 0, -L/2]`.
    #[serde(default)]
    pub offset: [f64; 3],
}

/// Mass, centre of mass and central inertia given explicitly, in the body frame.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExplicitMass {
    /// Mass, kg.
    pub mass: f64,
    /// Centre of mass, m.
    pub com: [f64; 3],
    /// (Ixx, Iyy, Izz, Ixy, Ixz, Iyz) about the centre of mass, kg·m².
    pub inertia: [f64; 6],
}

/// A primitive body, by mass or by density (exactly one of the two).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Primitive {
    /// rod | sphere | box | cylinder | disc | point.
    pub shape: Spanned<String>,
    /// Total mass, kg.
    pub mass: Option<f64>,
    /// Density (per length, area or volume, by the shape's dimension).
    pub density: Option<f64>,
    /// Length of a rod or cylinder, m.
    pub length: Option<f64>,
    /// Radius of a sphere, cylinder or disc, m.
    pub radius: Option<f64>,
    /// Edge lengths of a box, m.
    pub size: Option<[f64; 3]>,
}

/// A mesh body: a file (STL or OBJ, relative to the scene file) and its density, kg/m³.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSpec {
    /// Path of the mesh file.
    pub file: Spanned<String>,
    /// Volume density, kg/m³.
    pub density: f64,
}

/// One joint between a parent ("ground" or a body) and a child body.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointSpec {
    /// Name, for reports.
    pub name: String,
    /// Joint type.
    #[serde(rename = "type")]
    pub kind: Spanned<JointKind>,
    /// Parent body name, or "ground".
    pub parent: Spanned<String>,
    /// Child body name.
    pub child: Spanned<String>,
    /// Axis (revolute, prismatic) or plane normal (planar), in the parent frame.
    pub axis: Option<Spanned<[f64; 3]>>,
    /// Joint-frame origin in the parent frame, m.
    #[serde(default)]
    pub origin: [f64; 3],
    /// Joint-frame orientation in the parent frame: roll, pitch, yaw about the parent's x, y,
    /// z axes (R = R_z(yaw) R_y(pitch) R_x(roll), as in URDF), rad.
    #[serde(default)]
    pub rpy: [f64; 3],
    /// Initial generalized coordinates.
    pub q0: Option<Spanned<Vec<f64>>>,
    /// Initial generalized velocities.
    pub qd0: Option<Spanned<Vec<f64>>>,
    /// Limits [lower, upper] of a one-coordinate joint, for equilibrium searches.
    pub limits: Option<Spanned<[f64; 2]>>,
}

/// The joint types of a kinematic tree.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum JointKind {
    /// One rotation about an axis.
    Revolute,
    /// One translation along an axis.
    Prismatic,
    /// Three rotations about a point.
    Spherical,
    /// Six degrees of freedom.
    Free,
    /// Two translations in a plane and one rotation about its normal.
    Planar,
    /// No motion.
    Fixed,
}

impl JointKind {
    /// The number of coordinates of a joint of this kind.
    pub fn dof(self) -> usize {
        match self {
            JointKind::Revolute | JointKind::Prismatic => 1,
            JointKind::Spherical | JointKind::Planar => 3,
            JointKind::Free => 6,
            JointKind::Fixed => 0,
        }
    }
}

/// The analyses a scene asks for.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Analyses {
    /// Mass properties of every body and of the whole mechanism.
    #[serde(default)]
    pub mass_properties: bool,
    /// An equilibrium search from q0 (and optional further starts), with its stability.
    pub equilibrium: Option<EquilibriumSpec>,
    /// Small-oscillation modes, at the equilibrium when one is searched, else at q0.
    pub modes: Option<ModesSpec>,
    /// The free response from a disturbed equilibrium (8.91); needs `modes`.
    pub response: Option<Spanned<ResponseSpec>>,
    /// One impact of a body point against the ground, at (q0, qd0).
    pub impact: Option<ImpactSpec>,
    /// Forward and inverse dynamics, with the joint reactions, at q0.
    pub dynamics: Option<DynamicsSpec>,
    /// The motion from (q0, qd0) integrated in time (see `scene/simulate.rs`).
    pub simulate: Option<SimulateSpec>,
}

/// The frames in which the dynamics step can report joint reactions.
pub const DYNAMICS_FRAMES: [&str; 3] = ["world", "body", "joint"];

/// The state and frame of the dynamics step.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DynamicsSpec {
    /// q̇ (default: the joints' qd0).
    pub q_dot: Option<Spanned<Vec<f64>>>,
    /// The applied generalized forces τ of the forward dynamics (default 0).
    pub tau: Option<Spanned<Vec<f64>>>,
    /// The accelerations of the inverse dynamics and reactions (default: the forward q̈).
    pub q_ddot: Option<Spanned<Vec<f64>>>,
    /// "world" (default), "body" or "joint": the frame of the joint reactions.
    pub frame: Option<Spanned<String>>,
    /// With constraints: also seek the constrained equilibrium near q0 (FM 4.83–4.86).
    #[serde(default)]
    pub equilibrium: bool,
}

/// Equilibrium search options.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EquilibriumSpec {
    /// "minimum" (default: a stable equilibrium) or "stationary" (any).
    pub seek: Option<Spanned<String>>,
    /// Further starting points (each of length dof).
    #[serde(default)]
    pub starts: Vec<Spanned<Vec<f64>>>,
    /// Iteration limit.
    pub max_iterations: Option<usize>,
}

/// Mode options.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModesSpec {
    /// Only the k lowest modes.
    pub lowest: Option<Spanned<usize>>,
}

/// Free-response options.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ResponseSpec {
    /// Time span, s.
    pub duration: Spanned<f64>,
    /// Number of samples (at least 2; see [`SceneLimits::max_response_values`]).
    #[serde(default = "default_samples")]
    pub samples: Spanned<usize>,
    /// Initial displacement from the equilibrium, per coordinate.
    pub dq0: Option<Spanned<Vec<f64>>>,
    /// Initial velocity, per coordinate.
    pub v0: Option<Spanned<Vec<f64>>>,
}

fn default_samples() -> Spanned<usize> {
    Spanned::new(0..0, 200)
}

fn unlocated_zero() -> Spanned<usize> {
    Spanned::new(0..0, 0)
}

/// Limits on what a scene may ask for, so that a typing slip cannot exhaust memory or time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SceneLimits {
    /// The largest number of values a free response may store: samples × (dof + 1) (the times
    /// and every coordinate), 8 bytes each.
    pub max_response_values: usize,
}

impl SceneLimits {
    /// 10⁷ values (80 MB): e.g. 10⁶ samples of a 9-coordinate mechanism. The `mechanica run`
    /// option `--max-response-values` raises it.
    pub const DEFAULT: SceneLimits = SceneLimits {
        max_response_values: 10_000_000,
    };
}

impl Default for SceneLimits {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// An impact of a body point against the ground.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImpactSpec {
    /// The striking body's name.
    pub body: Spanned<String>,
    /// The contact point, body coordinates, m.
    pub point: [f64; 3],
    /// The ground's unit normal (pointing towards the body).
    pub normal: [f64; 3],
    /// Coulomb friction coefficient.
    #[serde(default)]
    pub friction: f64,
    /// Restitution coefficient in [0, 1].
    #[serde(default)]
    pub restitution: f64,
    /// "stronge" (default), "poisson" or "newton".
    pub law: Option<Spanned<String>>,
    /// Also resolve the impact under the two other laws, for comparison (and the energy plot).
    #[serde(default)]
    pub compare_laws: bool,
}

/// A scene error, located in its file.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneError {
    /// The scene file.
    pub file: PathBuf,
    /// 1-based line and column, when known.
    pub position: Option<(usize, usize)>,
    /// The field concerned, e.g. `joint[2].parent`.
    pub field: String,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some((line, column)) = self.position {
            write!(f, ":{line}:{column}")?;
        }
        if !self.field.is_empty() {
            write!(f, ": field {}", self.field)?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for SceneError {}

/// The 1-based (line, column) of a byte offset in `text`.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.rfind('\n').map_or(before.len(), |nl| before.len() - nl - 1) + 1;
    (line, column)
}

impl Scene {
    /// Reads and validates the scene file at `path` under `limits`.
    pub fn load_with(path: &Path, limits: &SceneLimits) -> Result<Scene, SceneError> {
        let text = std::fs::read_to_string(path).map_err(|e| SceneError {
            file: path.to_path_buf(),
            position: None,
            field: String::new(),
            message: format!("cannot read the scene file: {e}"),
        })?;
        Scene::parse_with(&text, path, limits)
    }

    /// Parses and validates scene text under the default [`SceneLimits`]; `file` is used in
    /// error messages.
    pub fn parse(text: &str, file: &Path) -> Result<Scene, SceneError> {
        Scene::parse_with(text, file, &SceneLimits::DEFAULT)
    }

    /// Parses and validates scene text under `limits`; `file` is used in error messages.
    pub fn parse_with(text: &str, file: &Path, limits: &SceneLimits) -> Result<Scene, SceneError> {
        let scene: Scene = toml::from_str(text).map_err(|e| SceneError {
            file: file.to_path_buf(),
            position: e.span().map(|s| line_column(text, s.start)),
            field: String::new(),
            message: e.message().trim().to_string(),
        })?;
        scene.validate(text, file, limits)?;
        Ok(scene)
    }

    /// Validates a scene built in memory (e.g. from a URDF); errors name the file and field.
    pub fn check(&self, file: &Path) -> Result<(), String> {
        self.validate("", file, &SceneLimits::DEFAULT)
            .map_err(|e| e.to_string())
    }

    /// Checks what the schema cannot: unique names, resolvable references, one parent per body,
    /// no cycles, one mass source per body, unit axes, coordinate counts (q0, qd0, limits,
    /// joint springs, starts, dq0, v0) and the analyses' options within `limits`.
    fn validate(&self, text: &str, file: &Path, limits: &SceneLimits) -> Result<(), SceneError> {
        let validator = Validator {
            scene: self,
            text,
            file,
            limits,
        };
        let index_of = validator.body_indices()?;
        let parent_of = validator.parent_indices(&index_of)?;
        validator.check_acyclic(&parent_of)?;
        validator.check_references(&index_of)?;
        if let Some(frame) = &self.rotating_frame {
            validator.check_unit_axis(&frame.axis, "rotating_frame.axis".into())?;
        }
        validator.check_option_names()?;
        validator.check_joint_values()?;
        validator.check_joint_springs()?;
        validator.check_dampers()?;
        validator.check_constraints(&index_of)?;
        validator.check_contacts(&index_of)?;
        validator.check_analyses()
    }
}

/// The checks of [`Scene::validate`], with what every error needs to be located.
struct Validator<'a> {
    /// The scene being checked.
    scene: &'a Scene,
    /// The scene's source text; empty for a scene built in memory.
    text: &'a str,
    /// The scene file, named in every error.
    file: &'a Path,
    /// What the analyses may ask for.
    limits: &'a SceneLimits,
}

/// Index of each body, by name.
type BodyIndex<'a> = HashMap<&'a str, usize>;

impl<'a> Validator<'a> {
    /// A located error: the span becomes a line and column when there is source text.
    fn error(&self, span: Option<std::ops::Range<usize>>, field: String, message: String) -> SceneError {
        SceneError {
            file: self.file.to_path_buf(),
            // A scene built in memory (no source text) has no positions to report.
            position: span
                .filter(|s| !self.text.is_empty() && s.end > s.start)
                .map(|s| line_column(self.text, s.start)),
            field,
            message,
        }
    }

    /// Ok when `axis` is finite and has unit length within 1e-9; else an error on `field`.
    fn check_unit_axis(&self, axis: &Spanned<[f64; 3]>, field: String) -> Result<(), SceneError> {
        let norm = axis.get_ref().iter().map(|a| a * a).sum::<f64>().sqrt();
        if norm.is_finite() && (norm - 1.0).abs() <= 1e-9 {
            Ok(())
        } else {
            Err(self.error(
                Some(axis.span()),
                field,
                format!("axis must be a unit vector, |axis| = {norm}"),
            ))
        }
    }

    /// The index of each body by name, checking that names are unique and not "ground" and that
    /// each body has exactly one mass source.
    fn body_indices(&self) -> Result<BodyIndex<'a>, SceneError> {
        let mut index_of: BodyIndex<'a> = HashMap::new();
        for (i, body) in self.scene.bodies.iter().enumerate() {
            let name = body.name.get_ref().as_str();
            if name == "ground" {
                return Err(self.error(
                    Some(body.name.span()),
                    format!("body[{i}].name"),
                    "\"ground\" is reserved".into(),
                ));
            }
            if index_of.insert(name, i).is_some() {
                return Err(self.error(
                    Some(body.name.span()),
                    format!("body[{i}].name"),
                    format!("duplicate body name \"{name}\""),
                ));
            }
            let sources = [
                body.mass_properties.is_some(),
                body.primitive.is_some(),
                body.mesh.is_some(),
            ];
            if sources.iter().filter(|&&s| s).count() != 1 {
                return Err(self.error(
                    Some(body.name.span()),
                    format!("body[{i}]"),
                    "give exactly one of mass_properties, primitive, mesh".into(),
                ));
            }
        }
        Ok(index_of)
    }

    /// The parent of each body (`None`: the ground), checking that every joint names existing
    /// bodies, has the axis its type needs, and that every body has exactly one parent joint.
    fn parent_indices(&self, index_of: &BodyIndex<'a>) -> Result<Vec<Option<usize>>, SceneError> {
        let bodies = &self.scene.bodies;
        let mut parent_of: Vec<Option<usize>> = vec![None; bodies.len()];
        let mut has_parent = vec![false; bodies.len()];
        for (j, joint) in self.scene.joints.iter().enumerate() {
            let (child, parent) = self.joint_ends(j, joint, index_of)?;
            if has_parent[child] {
                return Err(self.error(
                    Some(joint.child.span()),
                    format!("joint[{j}].child"),
                    format!(
                        "body \"{}\" already has a parent joint (a tree gives each body one)",
                        joint.child.get_ref()
                    ),
                ));
            }
            has_parent[child] = true;
            parent_of[child] = parent;
            self.check_joint_axis(j, joint)?;
        }
        if let Some((i, _)) = has_parent.iter().enumerate().find(|(_, has)| !**has) {
            return Err(self.error(
                Some(bodies[i].name.span()),
                format!("body[{i}]"),
                format!(
                    "body \"{}\" is connected by no joint (give it a parent, e.g. \"ground\")",
                    bodies[i].name.get_ref()
                ),
            ));
        }
        Ok(parent_of)
    }

    /// The (child, parent) body indices of joint `j` (parent `None`: the ground), child first.
    fn joint_ends(
        &self,
        j: usize,
        joint: &JointSpec,
        index_of: &BodyIndex<'a>,
    ) -> Result<(usize, Option<usize>), SceneError> {
        let child_name = joint.child.get_ref().as_str();
        let child = *index_of.get(child_name).ok_or_else(|| {
            self.error(
                Some(joint.child.span()),
                format!("joint[{j}].child"),
                format!("no body named \"{child_name}\""),
            )
        })?;
        let parent_name = joint.parent.get_ref().as_str();
        let parent = if parent_name == "ground" {
            None
        } else {
            Some(*index_of.get(parent_name).ok_or_else(|| {
                self.error(
                    Some(joint.parent.span()),
                    format!("joint[{j}].parent"),
                    format!("no body named \"{parent_name}\""),
                )
            })?)
        };
        Ok((child, parent))
    }

    /// Ok when joint `j` has an axis if its type needs one, and any axis given is a unit vector.
    fn check_joint_axis(&self, j: usize, joint: &JointSpec) -> Result<(), SceneError> {
        let needs_axis = matches!(
            joint.kind.get_ref(),
            JointKind::Revolute | JointKind::Prismatic | JointKind::Planar
        );
        match (&joint.axis, needs_axis) {
            (None, true) => Err(self.error(
                Some(joint.kind.span()),
                format!("joint[{j}].axis"),
                "this joint type needs an axis".into(),
            )),
            (Some(axis), _) => self.check_unit_axis(axis, format!("joint[{j}].axis")),
            (None, false) => Ok(()),
        }
    }

    /// Ok when following parents from every body reaches the ground within `bodies.len()` steps.
    fn check_acyclic(&self, parent_of: &[Option<usize>]) -> Result<(), SceneError> {
        let bodies = &self.scene.bodies;
        for start in 0..bodies.len() {
            let mut steps = 0;
            let mut at = Some(start);
            while let Some(b) = at {
                steps += 1;
                if steps > bodies.len() {
                    return Err(self.error(
                        Some(bodies[start].name.span()),
                        format!("body[{start}]"),
                        format!(
                            "the joints form a cycle through body \"{}\"",
                            bodies[start].name.get_ref()
                        ),
                    ));
                }
                at = parent_of[b];
            }
        }
        Ok(())
    }

    /// Ok when every spring, force, impact and joint spring names a body (or joint) that exists.
    fn check_references(&self, index_of: &BodyIndex<'a>) -> Result<(), SceneError> {
        for (i, spring) in self.scene.springs.iter().enumerate() {
            self.check_body_or_ground(&spring.a, format!("spring[{i}].a"), index_of)?;
            self.check_body_or_ground(&spring.b, format!("spring[{i}].b"), index_of)?;
        }
        for (i, force) in self.scene.forces.iter().enumerate() {
            self.check_body(&force.body, format!("force[{i}].body"), index_of)?;
        }
        for (i, damper) in self.scene.dampers.iter().enumerate() {
            self.check_body_or_ground(&damper.a, format!("damper[{i}].a"), index_of)?;
            self.check_body_or_ground(&damper.b, format!("damper[{i}].b"), index_of)?;
        }
        for (i, damper) in self.scene.joint_dampers.iter().enumerate() {
            self.check_joint_name(&damper.joint, format!("joint_damper[{i}].joint"))?;
        }
        if let Some(impact) = &self.scene.analyses.impact {
            self.check_body(&impact.body, "analyses.impact.body".into(), index_of)?;
        }
        for (i, spring) in self.scene.joint_springs.iter().enumerate() {
            self.check_joint_name(&spring.joint, format!("joint_spring[{i}].joint"))?;
        }
        Ok(())
    }

    /// Ok when `name` is a joint's name; else an error on `field`.
    fn check_joint_name(&self, name: &Spanned<String>, field: String) -> Result<(), SceneError> {
        if self.scene.joints.iter().any(|j| &j.name == name.get_ref()) {
            return Ok(());
        }
        let message = format!("no joint named \"{}\"", name.get_ref());
        Err(self.error(Some(name.span()), field, message))
    }

    /// Ok when `name` is "ground" or a body's name; else an error on `field`.
    fn check_body_or_ground(
        &self,
        name: &Spanned<String>,
        field: String,
        index_of: &BodyIndex<'a>,
    ) -> Result<(), SceneError> {
        if name.get_ref() == "ground" {
            Ok(())
        } else {
            self.check_body(name, field, index_of)
        }
    }

    /// Ok when `name` is a body's name; else an error on `field`.
    fn check_body(&self, name: &Spanned<String>, field: String, index_of: &BodyIndex<'a>) -> Result<(), SceneError> {
        let n = name.get_ref().as_str();
        if index_of.contains_key(n) {
            Ok(())
        } else {
            Err(self.error(Some(name.span()), field, format!("no body named \"{n}\"")))
        }
    }

    /// Ok when the equilibrium's `seek` and the impact's `law`, if given, are known names.
    fn check_option_names(&self) -> Result<(), SceneError> {
        let analyses = &self.scene.analyses;
        for (label, name) in [
            (
                "analyses.equilibrium.seek",
                analyses.equilibrium.as_ref().and_then(|e| e.seek.as_ref()),
            ),
            (
                "analyses.impact.law",
                analyses.impact.as_ref().and_then(|i| i.law.as_ref()),
            ),
        ] {
            let allowed: &[&str] = if label.ends_with("seek") {
                &["minimum", "stationary"]
            } else {
                &["stronge", "poisson", "newton"]
            };
            if let Some(name) = name
                && !allowed.contains(&name.get_ref().as_str())
            {
                return Err(self.error(
                    Some(name.span()),
                    label.into(),
                    format!("\"{}\" is not one of {allowed:?}", name.get_ref()),
                ));
            }
        }
        Ok(())
    }

    /// The number of coordinates of the whole scene (each body has one joint once
    /// [`Validator::parent_indices`] has passed).
    fn dof(&self) -> usize {
        self.scene.joints.iter().map(|j| j.kind.get_ref().dof()).sum()
    }

    /// An error on `field` at `values` unless it holds `expected` numbers.
    fn check_length(
        &self,
        values: &Spanned<Vec<f64>>,
        expected: usize,
        field: String,
        whose: &str,
    ) -> Result<(), SceneError> {
        let got = values.get_ref().len();
        if got == expected {
            return Ok(());
        }
        Err(self.error(
            Some(values.span()),
            field,
            format!("{got} values given, {whose} {expected} coordinate(s)"),
        ))
    }

    /// Ok when every joint's q0 and qd0 have one value per coordinate of the joint and limits
    /// are given on one-coordinate joints only.
    fn check_joint_values(&self) -> Result<(), SceneError> {
        for (j, joint) in self.scene.joints.iter().enumerate() {
            let dof = joint.kind.get_ref().dof();
            let kind = format!("{:?}", joint.kind.get_ref()).to_lowercase();
            let whose = format!("the {kind} joint \"{}\" has", joint.name);
            for (values, what) in [(&joint.q0, "q0"), (&joint.qd0, "qd0")] {
                if let Some(values) = values {
                    self.check_length(values, dof, format!("joint[{j}].{what}"), &whose)?;
                }
            }
            if let Some(limits) = &joint.limits
                && dof != 1
            {
                return Err(self.error(
                    Some(limits.span()),
                    format!("joint[{j}].limits"),
                    format!("limits apply to one-coordinate joints only; {whose} {dof}"),
                ));
            }
        }
        Ok(())
    }

    /// Ok when every joint spring's coordinate index lies within its joint.
    fn check_joint_springs(&self) -> Result<(), SceneError> {
        for (i, spring) in self.scene.joint_springs.iter().enumerate() {
            self.check_coordinate(
                &spring.joint,
                &spring.coordinate,
                format!("joint_spring[{i}].coordinate"),
            )?;
        }
        Ok(())
    }

    /// Ok when `coordinate` indexes a coordinate of the joint named `joint` (an unknown joint is
    /// reported by [`Validator::check_references`]); else an error on `field`.
    fn check_coordinate(
        &self,
        joint: &Spanned<String>,
        coordinate: &Spanned<usize>,
        field: String,
    ) -> Result<(), SceneError> {
        let Some(spec) = self.scene.joints.iter().find(|j| &j.name == joint.get_ref()) else {
            return Ok(());
        };
        let dof = spec.kind.get_ref().dof();
        let index = *coordinate.get_ref();
        if index < dof {
            return Ok(());
        }
        let span = Some(coordinate.span()).filter(|s| s.end > s.start);
        let message = format!("coordinate {index} of joint \"{}\", which has {dof}", spec.name);
        Err(self.error(span.or(Some(joint.span())), field, message))
    }

    /// Ok when every damper's coefficient is finite and ≥ 0 and every joint damper's coordinate
    /// lies within its joint.
    fn check_dampers(&self) -> Result<(), SceneError> {
        let joint = self.scene.joint_dampers.iter().enumerate();
        let joint = joint.map(|(i, d)| (&d.damping, format!("joint_damper[{i}].damping")));
        let point = self.scene.dampers.iter().enumerate();
        let point = point.map(|(i, d)| (&d.damping, format!("damper[{i}].damping")));
        for (damping, field) in joint.chain(point) {
            let c = *damping.get_ref();
            if !(c.is_finite() && c >= 0.0) {
                let message = format!("the damping coefficient must be finite and ≥ 0, got {c}");
                return Err(self.error(Some(damping.span()), field, message));
            }
        }
        for (i, damper) in self.scene.joint_dampers.iter().enumerate() {
            self.check_coordinate(
                &damper.joint,
                &damper.coordinate,
                format!("joint_damper[{i}].coordinate"),
            )?;
        }
        Ok(())
    }

    /// Ok when the equilibrium starts, the modes and the free response ask for something
    /// well defined (lengths equal to the dof, a free response with every mode, at least two
    /// samples over a positive finite span, within the limits).
    fn check_analyses(&self) -> Result<(), SceneError> {
        let analyses = &self.scene.analyses;
        let dof = self.dof();
        let whose = "the scene has";
        self.check_constrained_analyses()?;
        if let Some(equilibrium) = &analyses.equilibrium {
            for (i, start) in equilibrium.starts.iter().enumerate() {
                self.check_length(start, dof, format!("analyses.equilibrium.starts[{i}]"), whose)?;
            }
        }
        if let Some(lowest) = analyses.modes.as_ref().and_then(|m| m.lowest.as_ref())
            && !(1..=dof.max(1)).contains(lowest.get_ref())
        {
            return Err(self.error(
                Some(lowest.span()),
                "analyses.modes.lowest".into(),
                format!("{} modes asked for; the scene has {dof} coordinates", lowest.get_ref()),
            ));
        }
        if let Some(dynamics) = &analyses.dynamics {
            self.check_dynamics(dynamics, dof)?;
        }
        if let Some(simulate) = &analyses.simulate {
            self.check_simulate(simulate, dof)?;
        }
        match &analyses.response {
            Some(response) => self.check_response(response, dof),
            None => Ok(()),
        }
    }

    /// Ok when the dynamics' state vectors have one finite value per coordinate and its frame
    /// is a known name.
    fn check_dynamics(&self, spec: &DynamicsSpec, dof: usize) -> Result<(), SceneError> {
        for (values, what) in [(&spec.q_dot, "q_dot"), (&spec.tau, "tau"), (&spec.q_ddot, "q_ddot")] {
            let Some(values) = values else { continue };
            let field = format!("analyses.dynamics.{what}");
            self.check_length(values, dof, field.clone(), "the scene has")?;
            if let Some(bad) = values.get_ref().iter().find(|v| !v.is_finite()) {
                return Err(self.error(Some(values.span()), field, format!("{bad} is not a finite number")));
            }
        }
        if let Some(frame) = &spec.frame
            && !DYNAMICS_FRAMES.contains(&frame.get_ref().as_str())
        {
            let message = format!("\"{}\" is not one of {DYNAMICS_FRAMES:?}", frame.get_ref());
            return Err(self.error(Some(frame.span()), "analyses.dynamics.frame".into(), message));
        }
        Ok(())
    }

    /// Ok when the free response is well defined (see [`Validator::check_analyses`]).
    fn check_response(&self, response: &Spanned<ResponseSpec>, dof: usize) -> Result<(), SceneError> {
        let analyses = &self.scene.analyses;
        let spec = response.get_ref();
        let at = |field: &str| format!("analyses.response.{field}");
        let Some(modes) = &analyses.modes else {
            return Err(self.error(
                Some(response.span()),
                "analyses.response".into(),
                "the free response needs `modes`".into(),
            ));
        };
        if let Some(lowest) = &modes.lowest {
            return Err(self.error(
                Some(lowest.span()),
                "analyses.modes.lowest".into(),
                "the free response needs every mode: remove `lowest`".into(),
            ));
        }
        let duration = *spec.duration.get_ref();
        if !(duration.is_finite() && duration > 0.0) {
            let message = format!("the duration must be finite and > 0 s, got {duration}");
            return Err(self.error(Some(spec.duration.span()), at("duration"), message));
        }
        let samples = *spec.samples.get_ref();
        let stored = samples as u128 * (dof as u128 + 1);
        if samples < 2 || stored > self.limits.max_response_values as u128 {
            let message = if samples < 2 {
                format!("at least 2 samples are needed, got {samples}")
            } else {
                format!(
                    "{samples} samples of {dof} coordinates store {stored} values, above the limit of {} \
                     (raise it with --max-response-values)",
                    self.limits.max_response_values
                )
            };
            let span = Some(spec.samples.span())
                .filter(|s| s.end > s.start)
                .unwrap_or(response.span());
            return Err(self.error(Some(span), at("samples"), message));
        }
        for (values, what) in [(&spec.dq0, "dq0"), (&spec.v0, "v0")] {
            if let Some(values) = values {
                self.check_length(values, dof, at(what), "the scene has")?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PENDULUM: &str = r#"
title = "double pendulum"
gravity = [0.0, 0.0, -9.81]

[[body]]
name = "upper"
primitive = { shape = "rod", length = 1.0, mass = 1.0 }

[[body]]
name = "lower"
mass_properties = { mass = 1.0, com = [0.0, 0.0, -0.5], inertia = [0.1, 0.1, 0.0, 0.0, 0.0, 0.0] }

[[joint]]
name = "shoulder"
type = "revolute"
parent = "ground"
child = "upper"
axis = [0.0, 1.0, 0.0]

[[joint]]
name = "elbow"
type = "revolute"
parent = "upper"
child = "lower"
axis = [0.0, 1.0, 0.0]
origin = [0.0, 0.0, -1.0]

[analyses]
mass_properties = true
"#;

    fn parse(text: &str) -> Result<Scene, SceneError> {
        Scene::parse(text, Path::new("scene.toml"))
    }

    #[test]
    fn a_valid_scene_parses() {
        let scene = parse(PENDULUM).expect("valid scene");
        assert_eq!(scene.bodies.len(), 2);
        assert_eq!(*scene.joints[1].kind.get_ref(), JointKind::Revolute);
        assert!(scene.analyses.mass_properties);
    }

    #[test]
    fn an_unknown_field_is_located() {
        let text = PENDULUM.replace("origin = [0.0, 0.0, -1.0]", "orgin = [0.0, 0.0, -1.0]");
        let e = parse(&text).expect_err("unknown field");
        let line = text.lines().position(|l| l.starts_with("orgin")).map(|i| i + 1);
        assert_eq!(e.position.map(|p| p.0), line, "{e}");
        assert!(e.message.contains("orgin"), "{e}");
    }

    #[test]
    fn a_missing_body_is_located() {
        let text = PENDULUM.replace("parent = \"upper\"", "parent = \"uper\"");
        let e = parse(&text).expect_err("missing body");
        assert_eq!(e.field, "joint[1].parent");
        let line = text.lines().position(|l| l.contains("\"uper\"")).map(|i| i + 1);
        assert_eq!(e.position.map(|p| p.0), line);
        assert!(e.to_string().starts_with("scene.toml:"), "{e}");
    }

    #[test]
    fn cyclic_joints_are_rejected() {
        let text = PENDULUM.replace("parent = \"ground\"", "parent = \"lower\"");
        let e = parse(&text).expect_err("cycle");
        assert!(e.message.contains("cycle"), "{e}");
    }

    #[test]
    fn non_unit_axes_and_double_parents_are_rejected() {
        let text = PENDULUM.replacen("axis = [0.0, 1.0, 0.0]", "axis = [0.0, 2.0, 0.0]", 1);
        assert_eq!(parse(&text).expect_err("axis").field, "joint[0].axis");
        let text = PENDULUM.replace("child = \"lower\"", "child = \"upper\"");
        assert_eq!(parse(&text).expect_err("two parents").field, "joint[1].child");
    }

    /// The 1-based line of the first line of `text` containing `needle`.
    fn line_of(text: &str, needle: &str) -> Option<usize> {
        text.lines().position(|l| l.contains(needle)).map(|i| i + 1)
    }

    /// Each semantic error names its field and the line of the offending value.
    #[test]
    fn semantic_errors_name_the_field_and_the_line() {
        let analyses = "[analyses]\nequilibrium = {}\nmodes = {}\n";
        let with_analyses = PENDULUM.replace("[analyses]\nmass_properties = true\n", analyses);
        let response = |block: &str| format!("{with_analyses}response = {block}\n");
        let cases: Vec<(String, &str, &str)> = vec![
            (
                PENDULUM.replace(
                    "origin = [0.0, 0.0, -1.0]",
                    "origin = [0.0, 0.0, -1.0]\nq0 = [0.1, 0.2]",
                ),
                "joint[1].q0",
                "q0 = [0.1, 0.2]",
            ),
            (
                PENDULUM.replace("axis = [0.0, 1.0, 0.0]\n\n", "axis = [0.0, 1.0, 0.0]\nqd0 = []\n\n"),
                "joint[0].qd0",
                "qd0 = []",
            ),
            (
                PENDULUM
                    .replacen("type = \"revolute\"", "type = \"spherical\"", 1)
                    .replace("axis = [0.0, 1.0, 0.0]\n\n", "limits = [-1.0, 1.0]\n\n"),
                "joint[0].limits",
                "limits = [-1.0, 1.0]",
            ),
            (
                format!("{PENDULUM}\n[[joint_spring]]\njoint = \"elbow\"\nstiffness = 1.0\ncoordinate = 1\n"),
                "joint_spring[0].coordinate",
                "coordinate = 1",
            ),
            (
                with_analyses.replace("equilibrium = {}", "equilibrium = { starts = [[0.1, 0.2], [0.3]] }"),
                "analyses.equilibrium.starts[1]",
                "starts =",
            ),
            (
                with_analyses.replace("modes = {}", "modes = { lowest = 0 }"),
                "analyses.modes.lowest",
                "lowest = 0",
            ),
            (
                response("{ duration = 0.0 }"),
                "analyses.response.duration",
                "response =",
            ),
            (
                response("{ duration = 1.0, samples = 1 }"),
                "analyses.response.samples",
                "response =",
            ),
            (
                response("{ duration = 1.0, samples = 10000000000 }"),
                "analyses.response.samples",
                "response =",
            ),
            (
                response("{ duration = 1.0, dq0 = [0.1, 0.0, 0.0] }"),
                "analyses.response.dq0",
                "response =",
            ),
            (
                response("{ duration = 1.0, v0 = [0.1] }"),
                "analyses.response.v0",
                "response =",
            ),
            (
                PENDULUM.replace(
                    "mass_properties = true",
                    "mass_properties = true\nresponse = { duration = 1.0 }",
                ),
                "analyses.response",
                "response =",
            ),
            (
                response("{ duration = 1.0 }").replace("modes = {}", "modes = { lowest = 1 }"),
                "analyses.modes.lowest",
                "lowest = 1",
            ),
        ];
        for (text, field, needle) in cases {
            let e = parse(&text).expect_err(field);
            assert_eq!(e.field, field, "{e}");
            assert_eq!(e.position.map(|p| p.0), line_of(&text, needle), "{field}: {e}");
        }
    }

    /// The response limit counts samples × (dof + 1) values and can be raised.
    #[test]
    fn the_response_limit_is_on_stored_values_and_can_be_raised() {
        let text = PENDULUM.replace(
            "mass_properties = true",
            "modes = {}\nresponse = { duration = 1.0, samples = 1000 }",
        );
        // Two coordinates: 1000 samples store 3000 values.
        let tight = SceneLimits {
            max_response_values: 2999,
        };
        let e = Scene::parse_with(&text, Path::new("scene.toml"), &tight).expect_err("over the limit");
        assert!(
            e.message.contains("3000 values") && e.message.contains("--max-response-values"),
            "{e}"
        );
        let enough = SceneLimits {
            max_response_values: 3000,
        };
        Scene::parse_with(&text, Path::new("scene.toml"), &enough).expect("at the limit");
    }

    #[test]
    fn a_missing_file_is_reported_with_its_path() {
        let e = Scene::load_with(Path::new("/nonexistent/scene.toml"), &SceneLimits::DEFAULT).expect_err("missing");
        assert!(e.to_string().contains("/nonexistent/scene.toml"), "{e}");
    }
}
