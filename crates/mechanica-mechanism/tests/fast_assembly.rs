//! The tree assemblies (mass matrix A, Hessian B of the field potential, gyroscopic matrix G,
//! the body displacements and effective masses of the modes) against their definitions summed
//! over point masses, on random trees of every joint kind, shape and scale.
//!
//! Each body is replaced by six point masses m/6 at c ± √(3σ_j/m) e_j along the principal axes
//! e_j of its spread S_c = ½ tr(I_c) 1 − I_c (eigenvalues σ_j): the same mass, centre and second
//! moment, so every integral of a quadratic in x over the body is the same sum over the
//! points. The definitions are then the sums over points of
//! A_kl = m J_k·J_l, B_kl = m [J_k·K J_l + (K x − g)·∂²x/∂q_k∂q_l], G_kl = 2 m J_k·(Ω × J_l),
//! with J_k = ∂x/∂q_k from the kinematics crate's point Jacobian and
//! ∂²x/∂q_k∂q_l = w_e × J_l for e the earlier of k, l on the point's root path (symmetrised
//! inside one rotation vector, see `mechanica_mechanism::configuration`).

mod common;

use common::{random_scaled_tree, random_vector};
use mechanica_kinematics::tree::{KinematicTree, Workspace};
use mechanica_mass::MassProperties;
use mechanica_mechanism::{Mechanism, RotatingFrame, mechanism_modes};
use mechanica_modal::SolveOptions;
use nalgebra::{Matrix3, Unit, Vector3};

/// The definitions of A, B and G at one configuration (column-major n × n each).
struct Definitions {
    a: Vec<f64>,
    b: Vec<f64>,
    g: Vec<f64>,
}

/// Six point masses with the body's (world) mass, centre and second moment (module docs).
fn equimomental_points(world: &MassProperties) -> Vec<(f64, Vector3<f64>)> {
    if world.mass == 0.0 {
        return Vec::new();
    }
    let spread = Matrix3::identity() * (0.5 * world.inertia_c.trace()) - world.inertia_c;
    let eigen = spread.symmetric_eigen();
    let mut points = Vec::with_capacity(6);
    for j in 0..3 {
        let offset = eigen.eigenvectors.column(j) * (3.0 * eigen.eigenvalues[j].max(0.0) / world.mass).sqrt();
        points.push((world.mass / 6.0, world.p_oc + offset));
        points.push((world.mass / 6.0, world.p_oc - offset));
    }
    points
}

/// The body's mass properties in world components at the workspace's positions.
fn world_body(ws: &Workspace, i: usize, body: &MassProperties) -> MassProperties {
    let r = ws.rotation(i).expect("rotation");
    MassProperties {
        mass: body.mass,
        p_oc: ws.point_position(i, &body.p_oc).expect("centre"),
        inertia_c: r.matrix() * body.inertia_c * r.matrix().transpose(),
    }
}

/// (depth of the owning body, index): the carrying order of coordinates on one root path.
fn rank(tree: &KinematicTree, k: usize) -> (usize, usize) {
    (tree.depth(tree.dof_body(k).expect("body")).expect("depth"), k)
}

fn in_rotation_vector(tree: &KinematicTree, k: usize) -> bool {
    let body = tree.dof_body(k).expect("body");
    tree.joint(body).is_some_and(|j| j.has_rotation_vector()) && k + 3 >= tree.dof_range(body).end
}

/// ∂²x/∂q_k∂q_l at the point x of `body` from the columns J (3 × n, column-major).
fn second_derivative(
    tree: &KinematicTree,
    ws: &Workspace,
    body: usize,
    jac: &[f64],
    k: usize,
    l: usize,
) -> Vector3<f64> {
    let column = |c: usize| Vector3::new(jac[3 * c], jac[3 * c + 1], jac[3 * c + 2]);
    let spin = |c: usize| ws.motion_column(c).expect("column").0;
    let on_path = |c: usize| tree.is_ancestor_or_self(tree.dof_body(c).expect("body"), body);
    if !(on_path(k) && on_path(l)) {
        return Vector3::zeros();
    }
    let same_block = in_rotation_vector(tree, k) && in_rotation_vector(tree, l) && tree.dof_body(k) == tree.dof_body(l);
    if same_block {
        return (spin(k).cross(&column(l)) + spin(l).cross(&column(k))) * 0.5;
    }
    let (early, late) = if rank(tree, k) <= rank(tree, l) { (k, l) } else { (l, k) };
    spin(early).cross(&column(late))
}

/// A, B and G by their definitions (module docs) for gravity `g`, field stiffness `field_k`
/// and rotation vector `omega`.
fn definitions(
    tree: &KinematicTree,
    bodies: &[MassProperties],
    q: &[f64],
    g: &Vector3<f64>,
    field_k: &Matrix3<f64>,
    omega: &Vector3<f64>,
) -> Definitions {
    let n = tree.dof();
    let mut ws = tree.workspace();
    tree.update_positions(&mut ws, q).expect("positions");
    let mut out = Definitions {
        a: vec![0.0; n * n],
        b: vec![0.0; n * n],
        g: vec![0.0; n * n],
    };
    let mut jac = vec![0.0; 3 * n];
    for (i, body) in bodies.iter().enumerate() {
        let world = world_body(&ws, i, body);
        for (m, x) in equimomental_points(&world) {
            let local = ws.rotation(i).expect("R").inverse() * (x - ws.position(i).expect("o"));
            tree.point_jacobian(&ws, i, &local, &mut jac).expect("jacobian");
            let column = |c: usize| Vector3::new(jac[3 * c], jac[3 * c + 1], jac[3 * c + 2]);
            let load = field_k * x - g;
            for k in 0..n {
                for l in 0..n {
                    let (jk, jl) = (column(k), column(l));
                    out.a[k + n * l] += m * jk.dot(&jl);
                    out.g[k + n * l] += 2.0 * m * jk.dot(&omega.cross(&jl));
                    let curvature = load.dot(&second_derivative(tree, &ws, i, &jac, k, l));
                    out.b[k + n * l] += m * (jk.dot(&(field_k * jl)) + curvature);
                }
            }
        }
    }
    out
}

/// max |fast − definition| ≤ tolerance · max |definition| over all entries.
fn assert_matches(what: &str, seed: u64, fast: &faer::Mat<f64>, definition: &[f64], tolerance: f64) {
    let n = fast.nrows();
    let scale = definition.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    for l in 0..n {
        for k in 0..n {
            let error = (fast[(k, l)] - definition[k + n * l]).abs();
            assert!(
                error <= tolerance * scale,
                "seed {seed}: {what}[{k},{l}] = {} vs definition {} (scale {scale:e})",
                fast[(k, l)],
                definition[k + n * l]
            );
        }
    }
}

/// q with random entries of size ~1 rad or ~L, rotation vectors zero (Hessians are exact there).
fn random_configuration(tree: &KinematicTree, seed: u64, length: f64) -> Vec<f64> {
    let mut q = random_vector(tree.dof(), seed, 1.0);
    for (k, value) in q.iter_mut().enumerate() {
        let body = tree.dof_body(k).expect("body");
        let translational = match tree.joint(body) {
            Some(j) if j.has_rotation_vector() => k < tree.dof_range(body).end - 3,
            Some(mechanica_kinematics::tree::Joint::Prismatic { .. }) => true,
            Some(mechanica_kinematics::tree::Joint::Planar) => k < tree.dof_range(body).end - 1,
            _ => false,
        };
        if in_rotation_vector(tree, k) {
            *value = 0.0;
        } else if translational {
            *value *= length;
        }
    }
    q
}

/// Every entry agrees with its definition within 1e-12 of the matrix's largest entry: each
/// entry sums O(n) products of rounded kinematic quantities, well inside that for n ≤ 12.
#[test]
fn mass_matrix_hessian_and_gyroscopic_matrix_match_their_definitions_on_random_trees() {
    for seed in 0..60 {
        let n = 1 + (seed as usize * 7) % 12;
        let (tree, bodies, length) = random_scaled_tree(n, seed, seed % 3 != 0, true);
        if tree.dof() == 0 {
            continue;
        }
        let q = random_configuration(&tree, seed + 1000, length);
        let parameters = random_vector(3, seed + 2000, 1.0);
        let axis = Unit::new_normalize(Vector3::new(parameters[0], parameters[1], 1.0));
        // Gravity along the axis (as a rotating frame requires); the centrifugal and gravity
        // terms of comparable size (Ω² L ≈ g) or one of them alone.
        let g_size = 9.81 * 10f64.powf(parameters[2]);
        let (gravity, rate) = match seed % 3 {
            0 => (axis.into_inner() * -g_size, 0.0),
            1 => (Vector3::zeros(), (g_size / length).sqrt()),
            _ => (axis.into_inner() * -g_size, (g_size / length).sqrt()),
        };
        let mut mechanism = Mechanism::new(tree.clone(), bodies.clone()).expect("mechanism");
        mechanism.set_gravity(gravity).expect("gravity");
        if rate > 0.0 {
            mechanism
                .set_rotating_frame(Some(RotatingFrame { axis, rate }))
                .expect("frame");
        }
        let field = mechanism.field();
        let omega = axis.into_inner() * rate;
        let reference = definitions(&tree, &bodies, &q, &gravity, &field.k, &omega);
        let a = mechanism.mass_matrix(&q).expect("A");
        let b = mechanism.potential(&q, true).expect("U").hessian.expect("B");
        let g = mechanism.gyroscopic_matrix(&q).expect("G");
        assert_matches("A", seed, &a, &reference.a, 1e-13);
        assert_matches("B", seed, &b, &reference.b, 1e-13);
        assert_matches("G", seed, &g, &reference.g, 1e-13);
    }
}

/// Body displacements and effective masses of the modes against J x per body, summed
/// directly from the point and angular Jacobians, within 1e-12 of Σ_k |J_k| |x_k|.
#[test]
fn mode_body_displacements_and_effective_masses_match_the_jacobians() {
    for seed in 0..24 {
        let n = 1 + (seed as usize * 5) % 9;
        let (tree, bodies, length) = random_scaled_tree(n, seed + 500, seed % 2 == 0, false);
        if tree.dof() == 0 {
            continue;
        }
        let q = random_configuration(&tree, seed + 3000, length);
        let mut mechanism = Mechanism::new(tree, bodies.clone()).expect("mechanism");
        mechanism.set_gravity(Vector3::new(0.0, 0.0, -9.81)).expect("gravity");
        let modes = mechanism_modes(&mut mechanism, &q, &SolveOptions::default()).expect("modes");
        let tree = mechanism.tree();
        let dof = tree.dof();
        let mut ws = tree.workspace();
        tree.update_positions(&mut ws, &modes.q).expect("positions");
        let x = modes.solution.vectors.as_ref().expect("vectors");
        let (mut jp, mut jw) = (vec![0.0; 3 * dof], vec![0.0; 3 * dof]);
        for mode in 0..x.ncols() {
            let mut participation = Vector3::zeros();
            let mut participation_scale = 0.0;
            for (i, body) in bodies.iter().enumerate() {
                tree.point_jacobian(&ws, i, &body.p_oc, &mut jp).expect("Jp");
                tree.angular_jacobian(&ws, i, &mut jw).expect("Jw");
                let (mut translation, mut rotation) = (Vector3::zeros(), Vector3::zeros());
                let (mut t_scale, mut r_scale) = (0.0, 0.0);
                for k in 0..dof {
                    let (p, w) = (
                        Vector3::new(jp[3 * k], jp[3 * k + 1], jp[3 * k + 2]),
                        Vector3::new(jw[3 * k], jw[3 * k + 1], jw[3 * k + 2]),
                    );
                    translation += p * x[(k, mode)];
                    rotation += w * x[(k, mode)];
                    t_scale += p.norm() * x[(k, mode)].abs();
                    r_scale += w.norm() * x[(k, mode)].abs();
                }
                let fast = modes.body_displacements[mode][i];
                assert!(
                    (fast.translation - translation).norm() <= 1e-12 * t_scale,
                    "seed {seed} mode {mode} body {i}: {:?} vs {translation:?}",
                    fast.translation
                );
                assert!(
                    (fast.rotation - rotation).norm() <= 1e-12 * r_scale,
                    "seed {seed} mode {mode} body {i}: {:?} vs {rotation:?}",
                    fast.rotation
                );
                participation += translation * body.mass;
                participation_scale += t_scale * body.mass;
            }
            for d in 0..3 {
                let expected = participation[d].powi(2);
                let error = (modes.effective_masses[mode][d] - expected).abs();
                assert!(
                    error <= 1e-12 * participation_scale.powi(2),
                    "seed {seed} mode {mode} axis {d}: {} vs {expected}",
                    modes.effective_masses[mode][d]
                );
            }
        }
    }
}
