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
//! [analyses]                           # only what is listed is computed
//! mass_properties = true
//! equilibrium = { seek = "minimum" }   # or "stationary"; optional starts = [[...], ...]
//! modes = { lowest = 4 }               # optional lowest = k; at the equilibrium if one is asked
//! response = { duration = 5.0, samples = 200, dq0 = [0.1, 0.0] }   # free response (8.91)
//! impact = { body = "lower", point = [0.0, 0.0, -1.0], normal = [0.0, 0.0, 1.0],
//!            friction = 0.3, restitution = 0.5, law = "stronge",
//!            compare_laws = true }           # at q0 with qd0; compare_laws adds the other two laws
//! ```
//!
//! `inertia` lists the six independent entries (Ixx, Iyy, Izz, Ixy, Ixz, Iyz) about the centre
//! of mass, in the body frame. Unknown fields are errors. Every error names the file, the line
//! and column, and the field.

use serde::Deserialize;
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
    #[serde(default)]
    pub coordinate: usize,
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
    pub response: Option<ResponseSpec>,
    /// One impact of a body point against the ground, at (q0, qd0).
    pub impact: Option<ImpactSpec>,
}

/// Equilibrium search options.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EquilibriumSpec {
    /// "minimum" (default: a stable equilibrium) or "stationary" (any).
    pub seek: Option<Spanned<String>>,
    /// Further starting points (each of length dof).
    #[serde(default)]
    pub starts: Vec<Vec<f64>>,
    /// Iteration limit.
    pub max_iterations: Option<usize>,
}

/// Mode options.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModesSpec {
    /// Only the k lowest modes.
    pub lowest: Option<usize>,
}

/// Free-response options.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ResponseSpec {
    /// Time span, s.
    pub duration: f64,
    /// Number of samples.
    #[serde(default = "default_samples")]
    pub samples: usize,
    /// Initial displacement from the equilibrium, per coordinate.
    pub dq0: Option<Vec<f64>>,
    /// Initial velocity, per coordinate.
    pub v0: Option<Vec<f64>>,
}

fn default_samples() -> usize {
    200
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
    /// Reads and validates the scene file at `path`.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let text = std::fs::read_to_string(path).map_err(|e| SceneError {
            file: path.to_path_buf(),
            position: None,
            field: String::new(),
            message: format!("cannot read the scene file: {e}"),
        })?;
        Scene::parse(&text, path)
    }

    /// Parses and validates scene text; `file` is used in error messages.
    pub fn parse(text: &str, file: &Path) -> Result<Scene, SceneError> {
        let scene: Scene = toml::from_str(text).map_err(|e| SceneError {
            file: file.to_path_buf(),
            position: e.span().map(|s| line_column(text, s.start)),
            field: String::new(),
            message: e.message().trim().to_string(),
        })?;
        scene.validate(text, file)?;
        Ok(scene)
    }

    /// Validates a scene built in memory (e.g. from a URDF); errors name the file and field.
    pub fn check(&self, file: &Path) -> Result<(), String> {
        self.validate("", file).map_err(|e| e.to_string())
    }

    /// Checks what the schema cannot: unique names, resolvable references, one parent per body,
    /// no cycles, one mass source per body, finite numbers and unit axes.
    fn validate(&self, text: &str, file: &Path) -> Result<(), SceneError> {
        let validator = Validator {
            scene: self,
            text,
            file,
        };
        let index_of = validator.body_indices()?;
        let parent_of = validator.parent_indices(&index_of)?;
        validator.check_acyclic(&parent_of)?;
        validator.check_references(&index_of)?;
        if let Some(frame) = &self.rotating_frame {
            validator.check_unit_axis(&frame.axis, "rotating_frame.axis".into())?;
        }
        validator.check_option_names()?;
        validator.check_response_needs_modes()
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
                .filter(|_| !self.text.is_empty())
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
        if let Some(impact) = &self.scene.analyses.impact {
            self.check_body(&impact.body, "analyses.impact.body".into(), index_of)?;
        }
        for (i, spring) in self.scene.joint_springs.iter().enumerate() {
            let name = spring.joint.get_ref();
            if !self.scene.joints.iter().any(|j| &j.name == name) {
                return Err(self.error(
                    Some(spring.joint.span()),
                    format!("joint_spring[{i}].joint"),
                    format!("no joint named \"{name}\""),
                ));
            }
        }
        Ok(())
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

    /// Ok unless a free response is asked for without `modes`.
    fn check_response_needs_modes(&self) -> Result<(), SceneError> {
        if self.scene.analyses.response.is_some() && self.scene.analyses.modes.is_none() {
            return Err(self.error(
                None,
                "analyses.response".into(),
                "the free response needs `modes`".into(),
            ));
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

    #[test]
    fn a_missing_file_is_reported_with_its_path() {
        let e = Scene::load(Path::new("/nonexistent/scene.toml")).expect_err("missing");
        assert!(e.to_string().contains("/nonexistent/scene.toml"), "{e}");
    }
}
