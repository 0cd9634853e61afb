//! Runs the analyses a scene asks for, and only those, timing each step.

pub(crate) mod records;

use crate::report::{Command, Report, Step, timed_step};
use crate::scene::{BodySpec, JointKind, JointSpec, Scene};
use mechanica::kinematics::nalgebra::{Isometry3, Matrix3, UnitQuaternion, Vector3};
use mechanica::kinematics::tree::{Joint, KinematicTree, TreeBuilder};
use mechanica::mass::MassProperties;
use mechanica::mass::mesh::MeshOptions;
use mechanica::mass::primitives::{self, Amount};
use mechanica::mass::validity::{ValidityTolerance, check_allowing_zero_mass};
use records::{BodyRecord, BuildRecord, MassRecord, PlotsRecord};
use std::path::Path;

/// A scene turned into library objects: the tree, each body's mass properties in its own
/// frame, and the initial coordinates.
pub(crate) struct Model {
    pub tree: KinematicTree,
    pub bodies: Vec<MassProperties>,
    pub q0: Vec<f64>,
    pub qd0: Vec<f64>,
    /// Per scene joint (by name): its body index.
    pub joint_body: Vec<(String, usize)>,
    /// Per coordinate: limits from the scene.
    pub limits: Vec<Option<[f64; 2]>>,
}

/// Runs `scene` (loaded from `file`) and returns its report; with `plot_dir`, also writes the
/// SVG plots of what was computed there.
pub fn run(scene: &Scene, file: &Path, plot_dir: Option<&Path>) -> Result<Report, String> {
    run_at(scene, file, plot_dir, None, false)
}

/// [`run`], evaluated at the coordinates `state` instead of the scene's q0 when given: the
/// equilibrium search is left out, so the modes are those of the linearisation at `state`.
/// With `matrices`, a step reports A(q), U*(q), its gradient and Hessian at the start state
/// ([`crate::state_matrices`]).
pub fn run_at(
    scene: &Scene,
    file: &Path,
    plot_dir: Option<&Path>,
    state: Option<&[f64]>,
    matrices: bool,
) -> Result<Report, String> {
    let mut at_state;
    let scene = match state {
        Some(_) => {
            at_state = scene.clone();
            at_state.analyses.equilibrium = None;
            &at_state
        }
        None => scene,
    };
    let mut steps: Vec<Step> = Vec::new();
    let mut model = None;
    steps.push(timed_step("build: bodies and kinematic tree", || {
        let mut built = build_model(scene, file)?;
        if let Some(q) = state {
            built.q0 = checked_state(q, &coordinate_names(&built))?;
        }
        let record = BuildRecord {
            bodies: scene
                .bodies
                .iter()
                .zip(&built.bodies)
                .map(|(spec, props)| BodyRecord {
                    name: spec.name.get_ref().clone(),
                    mass: props.mass,
                })
                .collect(),
            dof: built.tree.dof(),
            coordinates: coordinate_names(&built),
            q0: built.q0.clone(),
        };
        model = Some(built);
        Ok::<_, String>(record)
    })?);
    let model = model.ok_or("internal: model not built")?;
    if scene.analyses.mass_properties {
        let gravity = scene.gravity.map(Vector3::from);
        steps.push(timed_step("mass properties at q0", || mass_report(&model, gravity))?);
    }
    if matrices {
        steps.push(crate::state_matrices::step(scene, &model)?);
    }
    let mut plots = crate::plots::PlotData::default();
    crate::mechanism_run::run(scene, &model, &mut steps, &mut plots)?;
    crate::dynamics_run::run(scene, &model, &mut steps)?;
    crate::simulate_run::run(scene, file, &model, &mut steps, &mut plots)?;
    for step in &steps {
        crate::report::check_finite(step).map_err(|e| e.to_string())?;
    }
    if let Some(dir) = plot_dir {
        let start = std::time::Instant::now();
        let written = plots.write_all(dir)?;
        let files = written.iter().map(|p| p.display().to_string()).collect();
        steps.push(Step::new("plots", start.elapsed().as_secs_f64(), PlotsRecord { files }));
    }
    Ok(Report::new(Command::Run, scene.title.clone(), steps))
}

/// The coordinates given with `--q`, checked against the model's (named) coordinates.
fn checked_state(q: &[f64], names: &[String]) -> Result<Vec<f64>, String> {
    if q.len() != names.len() {
        return Err(format!(
            "--q has {} values; the model has {} coordinates ({})",
            q.len(),
            names.len(),
            names.join(", ")
        ));
    }
    if let Some(k) = q.iter().position(|v| !v.is_finite()) {
        return Err(format!("--q: the value of {} is not finite: {}", names[k], q[k]));
    }
    Ok(q.to_vec())
}

/// The mass properties of one body in its own frame, from the scene's description.
fn body_mass(body: &BodySpec, index: usize, file: &Path) -> Result<MassProperties, String> {
    let name = body.name.get_ref();
    let located = |e: &dyn std::fmt::Display| format!("{}: body[{index}] \"{name}\": {e}", file.display());
    if let Some(m) = &body.mass_properties {
        let [ixx, iyy, izz, ixy, ixz, iyz] = m.inertia;
        let inertia = Matrix3::new(ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz);
        if m.mass == 0.0 {
            // A massless link (a frame), common in URDF files, or a zero mass with a tensor
            // (a rotor whose mass is negligible), accepted when a body could have that tensor.
            let props = MassProperties {
                mass: 0.0,
                p_oc: Vector3::from(m.com),
                inertia_c: inertia,
            };
            return check_allowing_zero_mass(&props, &ValidityTolerance::default())
                .map(|()| props)
                .map_err(|e| located(&e));
        }
        return MassProperties::new(m.mass, Vector3::from(m.com), inertia).map_err(|e| located(&e));
    }
    if let Some(p) = &body.primitive {
        let amount = match (p.mass, p.density) {
            (Some(m), None) => Amount::Mass(m),
            (None, Some(rho)) => Amount::Density(rho),
            _ => return Err(located(&"give exactly one of primitive.mass, primitive.density")),
        };
        let need =
            |value: Option<f64>, field: &str| value.ok_or_else(|| located(&format!("primitive.{field} is required")));
        let shape = p.shape.get_ref().as_str();
        let result = match shape {
            "point" => primitives::point(amount),
            "rod" => primitives::rod(need(p.length, "length")?, amount),
            "sphere" => primitives::sphere(need(p.radius, "radius")?, amount),
            "disc" => primitives::disc_lamina(need(p.radius, "radius")?, amount),
            "cylinder" => primitives::cylinder(need(p.radius, "radius")?, need(p.length, "length")?, amount),
            "box" => {
                let [x, y, z] = p.size.ok_or_else(|| located(&"primitive.size is required"))?;
                primitives::solid_box(x, y, z, amount)
            }
            other => {
                return Err(located(&format!(
                    "unknown primitive shape \"{other}\" (point, rod, sphere, disc, cylinder, box)"
                )));
            }
        };
        return result.map_err(|e| located(&e));
    }
    if let Some(mesh) = &body.mesh {
        let path = file.parent().unwrap_or(Path::new(".")).join(mesh.file.get_ref());
        let triangles =
            mechanica::mass::io::load_mesh(&path).map_err(|e| located(&format!("{}: {e}", path.display())))?;
        let result = triangles
            .mass_properties(Amount::Density(mesh.density), &MeshOptions::default())
            .map_err(|e| located(&e))?;
        return Ok(result.properties);
    }
    Err(located(&"no mass source"))
}

/// The library joint for a scene joint.
fn joint_of(spec: &JointSpec) -> Joint {
    let axis = spec.axis.as_ref().map_or(Vector3::z(), |a| Vector3::from(*a.get_ref()));
    match spec.kind.get_ref() {
        JointKind::Revolute => Joint::Revolute { axis },
        JointKind::Prismatic => Joint::Prismatic { axis },
        JointKind::Spherical => Joint::Spherical,
        JointKind::Free => Joint::Free,
        JointKind::Planar => Joint::Planar,
        JointKind::Fixed => Joint::Fixed,
    }
}

pub(crate) fn build_model(scene: &Scene, file: &Path) -> Result<Model, String> {
    let bodies = scene
        .bodies
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let offset = Isometry3::translation(b.offset[0], b.offset[1], b.offset[2]);
            body_mass(b, i, file).map(|m| m.transformed(&offset))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let body_index: std::collections::HashMap<&str, usize> = scene
        .bodies
        .iter()
        .enumerate()
        .map(|(i, b)| (b.name.get_ref().as_str(), i))
        .collect();
    let joint_of_child: std::collections::HashMap<&str, &JointSpec> =
        scene.joints.iter().map(|j| (j.child.get_ref().as_str(), j)).collect();
    // The scene guarantees one joint per body; add bodies in scene order so indices agree.
    let mut builder = TreeBuilder::new();
    let mut q0 = Vec::new();
    let mut qd0 = Vec::new();
    let mut joint_body = Vec::new();
    let mut limits = Vec::new();
    for (i, body) in scene.bodies.iter().enumerate() {
        let joint = *joint_of_child
            .get(body.name.get_ref().as_str())
            .ok_or_else(|| format!("{}: body[{i}] has no joint", file.display()))?;
        let parent = body_index.get(joint.parent.get_ref().as_str()).copied();
        let lib_joint = joint_of(joint);
        let index = builder.add_body(
            parent,
            lib_joint,
            Isometry3::from_parts(
                Vector3::from(joint.origin).into(),
                UnitQuaternion::from_euler_angles(joint.rpy[0], joint.rpy[1], joint.rpy[2]),
            ),
        );
        debug_assert_eq!(index, i);
        let joint_values = |values: &Option<toml::Spanned<Vec<f64>>>, what: &str, out: &mut Vec<f64>| match values {
            Some(values) if values.get_ref().len() != lib_joint.dof() => Err(format!(
                "{}: joint \"{}\": {what} has {} values, the joint has {}",
                file.display(),
                joint.name,
                values.get_ref().len(),
                lib_joint.dof()
            )),
            Some(values) => {
                out.extend_from_slice(values.get_ref());
                Ok(())
            }
            None => {
                out.extend(std::iter::repeat_n(0.0, lib_joint.dof()));
                Ok(())
            }
        };
        joint_values(&joint.q0, "q0", &mut q0)?;
        joint_values(&joint.qd0, "qd0", &mut qd0)?;
        if joint.limits.is_some() && lib_joint.dof() != 1 {
            return Err(format!(
                "{}: joint \"{}\": limits apply to one-coordinate joints only",
                file.display(),
                joint.name
            ));
        }
        limits.extend(std::iter::repeat_n(
            joint.limits.as_ref().map(|l| *l.get_ref()),
            lib_joint.dof(),
        ));
        joint_body.push((joint.name.clone(), i));
    }
    // A tree with several bodies on the ground would have several roots; the tree needs one.
    let tree = builder.build().map_err(|e| format!("{}: {e}", file.display()))?;
    Ok(Model {
        tree,
        bodies,
        q0,
        qd0,
        joint_body,
        limits,
    })
}

/// Total mass properties in the world frame at q0, and the gravitational potential
/// U = −m g·x₀ when the scene has gravity.
fn mass_report(model: &Model, gravity: Option<Vector3<f64>>) -> Result<MassRecord, String> {
    let mut ws = model.tree.workspace();
    model
        .tree
        .update_positions(&mut ws, &model.q0)
        .map_err(|e| e.to_string())?;
    let mut world = Vec::with_capacity(model.bodies.len());
    for (b, props) in model.bodies.iter().enumerate() {
        let rotation = ws.rotation(b).map_err(|e| e.to_string())?;
        let position = ws.position(b).map_err(|e| e.to_string())?;
        let pose = Isometry3::from_parts(position.into(), rotation.into());
        world.push(props.transformed(&pose));
    }
    let total = MassProperties::sum(world.iter()).map_err(|e| e.to_string())?;
    let axes = total.principal_axes().map_err(|e| e.to_string())?;
    Ok(MassRecord {
        total_mass: total.mass,
        centre_of_mass: total.p_oc.into(),
        principal_moments: axes.moments.into(),
        principal_relative_residual: axes.relative_residual,
        gravitational_potential: gravity.map(|g| -total.mass * g.dot(&total.p_oc)),
    })
}

/// One name per coordinate, in coordinate order: the joint's name, indexed within joints of
/// several coordinates.
pub(crate) fn coordinate_names(model: &Model) -> Vec<String> {
    let mut names = vec![String::new(); model.q0.len()];
    for (joint, body) in &model.joint_body {
        let range = model.tree.dof_range(*body);
        let several = range.len() > 1;
        for (i, k) in range.enumerate() {
            if let Some(name) = names.get_mut(k) {
                *name = if several {
                    format!("{joint}[{i}]")
                } else {
                    joint.clone()
                };
            }
        }
    }
    names
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pendulum_at(q0: [f64; 2]) -> Model {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes/double_pendulum.toml");
        let text = std::fs::read_to_string(&path).expect("scene file");
        let text = text
            .replace(
                "origin = [0.0, 0.0, 0.0]",
                &format!("origin = [0.0, 0.0, 0.0]\nq0 = [{}]", q0[0]),
            )
            .replace(
                "origin = [0.0, 0.0, -1.0]",
                &format!("origin = [0.0, 0.0, -1.0]\nq0 = [{}]", q0[1]),
            );
        let scene = Scene::parse(&text, &path).expect("valid scene");
        build_model(&scene, &path).expect("model")
    }

    #[test]
    fn double_pendulum_centre_of_mass_matches_the_closed_form() {
        let (t1, t2) = (0.3, -0.7);
        let model = pendulum_at([t1, t2]);
        let q = mass_report(&model, Some(Vector3::new(0.0, 0.0, -9.81))).expect("report");
        // Rotation about +y maps (0, 0, -l) to (-l sin θ, 0, -l cos θ).
        let upper = Vector3::new(-0.5 * t1.sin(), 0.0, -0.5 * t1.cos());
        let elbow = Vector3::new(-t1.sin(), 0.0, -t1.cos());
        let lower = elbow + Vector3::new(-0.5 * (t1 + t2).sin(), 0.0, -0.5 * (t1 + t2).cos());
        let expected = (upper + lower) / 2.0;
        assert_eq!(q.total_mass, 2.0);
        let potential = q.gravitational_potential.expect("gravity");
        assert!((potential - 2.0 * 9.81 * expected.z).abs() < 1e-13);
        for k in 0..3 {
            assert!(
                (q.centre_of_mass[k] - expected[k]).abs() < 1e-15,
                "{:?} vs {expected:?}",
                q.centre_of_mass
            );
        }
    }

    #[test]
    fn hanging_double_pendulum_principal_moments() {
        // Both rods on the z axis, centre of mass at z = -1: I = 2·mL²/12 + 2·m·(1/2)² = 2/3 about
        // x and y, and 0 about the rods' common axis.
        let q = mass_report(&pendulum_at([0.0, 0.0]), None).expect("report");
        let moments = &q.principal_moments;
        assert!(
            moments[0].abs() < 1e-15
                && (moments[1] - 2.0 / 3.0).abs() < 1e-15
                && (moments[2] - 2.0 / 3.0).abs() < 1e-15
        );
    }
}
