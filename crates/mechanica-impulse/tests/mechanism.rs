//! Mechanisms in generalized coordinates (7.115–7.117): closed forms (a free body equals the
//! rigid-body contact, a struck pendulum, a struck double pendulum, a box falling flat on four
//! contacts), the energy identity, energy never gained (proptest), grazing, separating and
//! redundant contacts, Kane's double pendulum, and bad input.

use mechanica_impulse::mechanism_contact::DELASSUS_RANK_RELATIVE;
use mechanica_impulse::showcase::{KANE_STATE, kane_double_pendulum, kane_double_pendulum_demo};
use mechanica_impulse::{
    BodyPoint, ContactLaw, ContactMode, ContactSpace, ImpactModel, ImpactOptions, ImpulseError, MechanismContact,
    MechanismImpact, MechanismInertia, MultiContactOptions, PointImpulse, RestitutionLaw, RigidBody,
    apply_point_impulses, resolve_contact, resolve_contacts, resolve_single_contact,
};
use mechanica_kinematics::tree::{Joint, KinematicTree, TreeBuilder, Workspace};
use mechanica_mass::MassProperties;
use mechanica_mass::mechanism::TreeMass;
use nalgebra::{Isometry3, Matrix3, Rotation3, Vector3};
use proptest::prelude::*;

/// A tree with its workspace at q, its factored mass matrix and the body properties.
struct Mechanism {
    tree: KinematicTree,
    ws: Workspace,
    inertia: MechanismInertia,
    bodies: Vec<MassProperties>,
}

impl Mechanism {
    fn new(tree: KinematicTree, bodies: Vec<MassProperties>, q: &[f64]) -> Self {
        let mut ws = tree.workspace();
        tree.update_positions(&mut ws, q).expect("positions");
        let mut mass = TreeMass::new(&tree, bodies.clone()).expect("tree mass");
        let inertia = MechanismInertia::new(&tree, &ws, &mut mass).expect("positive definite A");
        Self {
            tree,
            ws,
            inertia,
            bodies,
        }
    }

    /// World velocity of the centre of mass and angular velocity of `body` at `q_dot`.
    fn body_velocity(&self, body: usize, q_dot: &[f64]) -> (Vector3<f64>, Vector3<f64>) {
        let mut ws = self.ws.clone();
        self.tree.update_velocities(&mut ws, q_dot).expect("velocities");
        (
            ws.point_velocity(body, &self.bodies[body].p_oc).expect("v"),
            ws.angular_velocity(body).expect("w"),
        )
    }

    /// The world-frame mass properties of `body` (centre p_WC, central inertia in W axes).
    fn world_properties(&self, body: usize) -> MassProperties {
        let r = self.ws.rotation(body).expect("rotation");
        let b = self.bodies[body];
        MassProperties {
            mass: b.mass,
            p_oc: self.ws.point_position(body, &b.p_oc).expect("c"),
            inertia_c: r.matrix() * b.inertia_c * r.matrix().transpose(),
        }
    }

    fn energy(&self, q_dot: &[f64]) -> f64 {
        self.inertia.kinetic_energy(q_dot).expect("energy")
    }
}

fn solid(mass: f64, diag: Vector3<f64>, c: Vector3<f64>, tilt: Vector3<f64>) -> MassProperties {
    let r = Rotation3::new(tilt);
    MassProperties {
        mass,
        p_oc: c,
        inertia_c: r.matrix() * Matrix3::from_diagonal(&diag) * r.matrix().transpose(),
    }
}

fn law(e: f64, f: f64, law: RestitutionLaw) -> ContactLaw {
    ContactLaw::new(e, f, law).expect("law")
}

fn ground_contact(body: usize, p_bq: Vector3<f64>, law: ContactLaw) -> MechanismContact {
    MechanismContact {
        point: BodyPoint { body, p_bq },
        other: None,
        normal_w: Vector3::y(),
        law,
    }
}

fn rel_err(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    (a - b).norm() / b.norm().max(1.0)
}

/// A single free body (slender cylinder, tilted) as a one-body mechanism striking the ground
/// must give exactly the two-body contact (`resolve_contact`) against a fixed ground, for a smooth,
/// a sticking, a sliding and a swerving (3-D) impact.
#[test]
fn free_body_mechanism_equals_rigid_body_contact() {
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Free, Isometry3::identity());
    let tree = builder.build().expect("tree");
    // A slender cylinder along its body y axis: axial inertia 1e-3 of the transverse one.
    let props = solid(
        2.0,
        Vector3::new(0.5, 5e-4, 0.5),
        Vector3::new(0.0, 0.4, 0.0),
        Vector3::zeros(),
    );
    let q = [0.1, 0.8, -0.2, 0.3, -0.2, 0.6];
    let q_dot = [0.4, -1.5, 0.3, 0.7, -0.4, 1.1];
    let mech = Mechanism::new(tree, vec![props], &q);
    let tip = Vector3::new(0.0, -0.1, 0.0);
    let p_wr = mech.ws.point_position(0, &tip).expect("tip");
    let (v, w) = mech.body_velocity(0, &q_dot);
    let rigid = RigidBody::from_mass_properties(&mech.world_properties(0), v, w).expect("rigid body");
    let ground = RigidBody::fixed(Vector3::zeros()).expect("ground");
    for (e, f, l) in [
        (0.5, 0.0, RestitutionLaw::Stronge),
        (0.0, f64::INFINITY, RestitutionLaw::Stronge),
        (0.7, 0.05, RestitutionLaw::Poisson),
        (0.6, 0.4, RestitutionLaw::Newton),
        (0.8, 0.3, RestitutionLaw::Stronge),
    ] {
        let contact = ground_contact(0, tip, law(e, f, l));
        let options = ImpactOptions::default();
        let reference = resolve_contact(&ground, &rigid, &p_wr, &Vector3::y(), &contact.law, &options).expect("ref");
        let impact = resolve_single_contact(&mech.tree, &mech.ws, &mech.inertia, &q_dot, &contact, &options)
            .expect("mechanism impact");
        assert_eq!(impact.model, ImpactModel::Process);
        let c = &impact.contacts[0];
        assert_eq!(c.mode, reference.contact.mode, "e {e} f {f}");
        // Both run the same process on W matrices that agree to round-off (the body's via
        // G = diag(1/m, J⁻¹), the mechanism's via A⁻¹ in coordinates); the process error is
        // the larger of the two reported integration errors.
        let scale = reference.contact.impulse_w.norm();
        let tol = 1e-10 * scale + 10.0 * (reference.contact.integration_error + impact.integration_error);
        assert!(
            (c.impulse_w - reference.contact.impulse_w).norm() <= tol,
            "impulse e {e} f {f}"
        );
        let (v_after, w_after) = mech.body_velocity(0, &impact.q_dot_after);
        let v_scale = v.norm() + w.norm();
        let tol_v = 1e-9 * v_scale + 1e3 * tol;
        assert!(
            (v_after - reference.body2.v_wc_after).norm() <= tol_v,
            "v after e {e} f {f}"
        );
        assert!(
            (w_after - reference.body2.w_w_after).norm() <= tol_v,
            "w after e {e} f {f}"
        );
        assert!(
            (impact.energy_change - reference.contact.energy_change).abs() <= 1e-9 * impact.energy_before + 1e3 * tol,
            "energy e {e} f {f}"
        );
    }
}

/// A body on a revolute hinge struck at a point: Δθ̇ = (r × S)·a / I_a with I_a the moment of
/// inertia about the hinge axis (7.87*–7.91* reduced to one coordinate), and the same as the
/// hinged rigid body (`RigidBody::hinged_on_axis`).
#[test]
fn pendulum_struck_at_a_point() {
    let axis = Vector3::new(0.2, 0.3, 0.9).normalize();
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Revolute { axis }, Isometry3::translation(0.3, -0.2, 0.5));
    let tree = builder.build().expect("tree");
    let props = solid(
        1.7,
        Vector3::new(0.1, 0.25, 0.3),
        Vector3::new(0.4, -0.6, 0.1),
        Vector3::new(0.3, 0.1, -0.4),
    );
    let q = [0.7];
    let q_dot = [-1.3];
    let mech = Mechanism::new(tree, vec![props], &q);
    let point = Vector3::new(0.2, -0.9, 0.3);
    let s = Vector3::new(0.5, 1.2, -0.7);
    let r = mech.ws.point_position(0, &point).expect("x") - Vector3::new(0.3, -0.2, 0.5);
    let a_w = mech.ws.rotation(0).expect("R") * axis;
    let world = mech.world_properties(0);
    let d = world.p_oc - Vector3::new(0.3, -0.2, 0.5);
    let i_pivot = world.inertia_c + (Matrix3::identity() * d.norm_squared() - d * d.transpose()) * world.mass;
    let i_axis = a_w.dot(&(i_pivot * a_w));
    let expected = r.cross(&s).dot(&a_w) / i_axis;
    let impulse = PointImpulse {
        point: BodyPoint { body: 0, p_bq: point },
        s_w: s,
    };
    let response = apply_point_impulses(&mech.tree, &mech.ws, &mech.inertia, &q_dot, &[impulse]).expect("impulse");
    assert!((response.delta_q_dot[0] - expected).abs() <= 1e-13 * expected.abs());
    assert!(response.backward_error <= 1e-15);
    // Energy: ΔT = ½ I_a (θ̇⁺² − θ̇⁻²).
    let dt = 0.5 * i_axis * (response.q_dot_after[0].powi(2) - q_dot[0].powi(2));
    assert!((response.energy_change - dt).abs() <= 1e-13 * dt.abs().max(1.0));
    // Body level: the same body hinged on the same axis.
    let (v, w) = mech.body_velocity(0, &q_dot);
    let rigid = RigidBody::from_mass_properties(&world, v, w)
        .expect("body")
        .hinged_on_axis(&Vector3::new(0.3, -0.2, 0.5), &a_w)
        .expect("hinge");
    let x = mech.ws.point_position(0, &point).expect("x");
    let body = rigid
        .apply_impulse_at(&s, &x, &Vector3::zeros())
        .expect("body response");
    let (v_after, w_after) = mech.body_velocity(0, &response.q_dot_after);
    assert!(rel_err(&w_after, &body.w_w_after) <= 1e-12);
    assert!(rel_err(&v_after, &body.v_wc_after) <= 1e-12);
    assert!((body.energy_change - response.energy_change).abs() <= 1e-12 * dt.abs().max(1.0));
}

/// A planar double pendulum of point masses m₁, m₂ on massless links L₁, L₂ struck at its tip:
/// Δq̇ = A⁻¹ Jᵀ S with A and the tip Jacobian J written in closed form.
#[test]
fn double_pendulum_struck_at_the_tip() {
    let (m1, m2, l1, l2) = (1.3, 0.7, 0.9, 0.6);
    let z = Joint::Revolute { axis: Vector3::z() };
    let mut builder = TreeBuilder::new();
    let b0 = builder.add_body(None, z, Isometry3::identity());
    let b1 = builder.add_body(Some(b0), z, Isometry3::translation(0.0, -l1, 0.0));
    let tree = builder.build().expect("tree");
    // Point masses at the link ends, with a tiny inertia so that nothing else matters: their
    // inertia tensors are zero (a point mass has none), A is still definite in θ₁, θ₂.
    let point = |m: f64, l: f64| MassProperties {
        mass: m,
        p_oc: Vector3::new(0.0, -l, 0.0),
        inertia_c: Matrix3::zeros(),
    };
    let (t1, t2) = (0.4, -0.9);
    let q_dot = [0.8, -1.1];
    let mech = Mechanism::new(tree, vec![point(m1, l1), point(m2, l2)], &[t1, t2]);
    let phi = t1 + t2;
    let a11 = m1 * l1 * l1 + m2 * (l1 * l1 + l2 * l2 + 2.0 * l1 * l2 * t2.cos());
    let a12 = m2 * (l2 * l2 + l1 * l2 * t2.cos());
    let a22 = m2 * l2 * l2;
    let a = mech.inertia.mass_matrix();
    for (got, want) in [(a[0], a11), (a[2], a12), (a[1], a12), (a[3], a22)] {
        assert!((got - want).abs() <= 1e-14 * a11);
    }
    let j1 = Vector3::new(l1 * t1.cos() + l2 * phi.cos(), l1 * t1.sin() + l2 * phi.sin(), 0.0);
    let j2 = Vector3::new(l2 * phi.cos(), l2 * phi.sin(), 0.0);
    let s = Vector3::new(-0.6, 2.0, 0.3);
    let (q1, q2) = (j1.dot(&s), j2.dot(&s));
    let det = a11 * a22 - a12 * a12;
    let expected = [(a22 * q1 - a12 * q2) / det, (a11 * q2 - a12 * q1) / det];
    let impulse = PointImpulse {
        point: BodyPoint {
            body: b1,
            p_bq: Vector3::new(0.0, -l2, 0.0),
        },
        s_w: s,
    };
    let r = apply_point_impulses(&mech.tree, &mech.ws, &mech.inertia, &q_dot, &[impulse]).expect("impulse");
    for k in 0..2 {
        assert!((r.generalized_impulse[k] - [q1, q2][k]).abs() <= 1e-14 * s.norm());
        assert!((r.delta_q_dot[k] - expected[k]).abs() <= 1e-12 * expected[k].abs().max(1.0));
    }
    // ΔT from the energies on both sides.
    let dt = mech.energy(&r.q_dot_after) - mech.energy(&q_dot);
    assert!((r.energy_change - dt).abs() <= 1e-12 * mech.energy(&q_dot).max(1.0));
}

/// A free body struck by two impulses at once: Lagrange's equations (7.117) give the same
/// velocities as the body-level (7.61–7.71) response to the resultant impulse and moment.
#[test]
fn lagrange_impulse_agrees_with_body_level() {
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Free, Isometry3::translation(0.1, 0.0, -0.3));
    let tree = builder.build().expect("tree");
    let props = solid(
        3.2,
        Vector3::new(0.2, 0.35, 0.4),
        Vector3::new(0.1, 0.2, -0.1),
        Vector3::new(0.5, -0.3, 0.2),
    );
    let q = [0.5, -0.2, 0.9, -0.4, 0.8, 0.3];
    let q_dot = [0.3, 0.1, -0.7, 1.2, -0.4, 0.6];
    let mech = Mechanism::new(tree, vec![props], &q);
    let impulses = [
        PointImpulse {
            point: BodyPoint {
                body: 0,
                p_bq: Vector3::new(0.5, 0.1, 0.0),
            },
            s_w: Vector3::new(1.0, -2.0, 0.5),
        },
        PointImpulse {
            point: BodyPoint {
                body: 0,
                p_bq: Vector3::new(-0.2, 0.4, 0.3),
            },
            s_w: Vector3::new(-0.3, 0.6, 1.5),
        },
    ];
    let r = apply_point_impulses(&mech.tree, &mech.ws, &mech.inertia, &q_dot, &impulses).expect("response");
    let world = mech.world_properties(0);
    let (v, w) = mech.body_velocity(0, &q_dot);
    let rigid = RigidBody::from_mass_properties(&world, v, w).expect("rigid");
    let mut s_total = Vector3::zeros();
    let mut m_total = Vector3::zeros();
    for i in &impulses {
        let x = mech.ws.point_position(0, &i.point.p_bq).expect("x");
        s_total += i.s_w;
        m_total += (x - world.p_oc).cross(&i.s_w);
    }
    let body = rigid.apply_impulse(&s_total, &m_total).expect("body");
    let (v_after, w_after) = mech.body_velocity(0, &r.q_dot_after);
    assert!(rel_err(&v_after, &body.v_wc_after) <= 1e-12);
    assert!(rel_err(&w_after, &body.w_w_after) <= 1e-12);
    assert!((r.energy_change - body.energy_change).abs() <= 1e-12 * r.energy_before.max(1.0));
}

/// A box falling flat on its four bottom corners (W of rank 6 < 12): frictionless and with
/// friction that sticks, the box leaves with v_y⁺ = −e v_y⁻, no spin, ΔT = −½ m (1 − e²) v².
#[test]
fn box_falling_flat_on_four_redundant_contacts() {
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Free, Isometry3::identity());
    let tree = builder.build().expect("tree");
    let (mass, hx, hy, hz) = (2.5, 0.4, 0.2, 0.3);
    let diag = Vector3::new(hy * hy + hz * hz, hx * hx + hz * hz, hx * hx + hy * hy) * (mass / 3.0);
    let props = solid(mass, diag, Vector3::zeros(), Vector3::zeros());
    let v = 1.5;
    let q_dot = [0.0, -v, 0.0, 0.0, 0.0, 0.0];
    let mech = Mechanism::new(tree, vec![props], &[0.0, hy, 0.0, 0.0, 0.0, 0.0]);
    for (e, f) in [(0.0, 0.0), (0.5, 0.0), (1.0, 0.0), (0.5, 0.8)] {
        let contacts: Vec<_> = [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)]
            .iter()
            .map(|&(sx, sz)| {
                ground_contact(
                    0,
                    Vector3::new(sx * hx, -hy, sz * hz),
                    law(e, f, RestitutionLaw::Stronge),
                )
            })
            .collect();
        let options = MultiContactOptions::default();
        let r = resolve_contacts(&mech.tree, &mech.ws, &mech.inertia, &q_dot, &contacts, &options).expect("impact");
        assert_eq!(r.model, ImpactModel::Simultaneous);
        assert!(r.converged, "e {e} f {f}: residual {}", r.complementarity_residual);
        assert!(r.complementarity_residual <= options.tolerance * v);
        assert!(r.delassus_rank < 12, "rank {}", r.delassus_rank);
        let (v_after, w_after) = mech.body_velocity(0, &r.q_dot_after);
        // PGS converges linearly; the velocity error is bounded by the residual (m/s) times a
        // modest factor (W's coupling, ≤ number of contacts).
        let tol = 8.0 * options.tolerance * v + 1e-14;
        assert!(
            (v_after - Vector3::new(0.0, e * v, 0.0)).norm() <= tol,
            "e {e} f {f}: {v_after}"
        );
        assert!(w_after.norm() * hx <= tol, "e {e} f {f}: {w_after}");
        let total: f64 = r.contacts.iter().map(|c| c.normal_impulse).sum();
        assert!((total - mass * (1.0 + e) * v).abs() <= mass * tol);
        let dt = -0.5 * mass * (1.0 - e * e) * v * v;
        assert!(
            (r.energy_change - dt).abs() <= 2.0 * mass * v * tol,
            "e {e}: {} vs {dt}",
            r.energy_change
        );
    }
}

/// Frictionless simultaneous impacts of a planar double pendulum pinned between two contacts
/// (an LCP with both contacts active): compare with the direct KKT solution W P = −(1 + e) u⁻.
#[test]
fn two_active_frictionless_contacts_match_the_kkt_solution() {
    let z = Joint::Revolute { axis: Vector3::z() };
    let mut builder = TreeBuilder::new();
    let b0 = builder.add_body(None, z, Isometry3::identity());
    let b1 = builder.add_body(Some(b0), z, Isometry3::translation(0.0, -1.0, 0.0));
    let tree = builder.build().expect("tree");
    let rod = solid(
        1.0,
        Vector3::new(1.0, 1e-3, 1.0) / 12.0,
        Vector3::new(0.0, -0.5, 0.0),
        Vector3::zeros(),
    );
    let mech = Mechanism::new(tree, vec![rod, rod], &[0.3, -0.5]);
    let e = 0.6;
    // Contact 0: elbow against a wall with normal +x; contact 1: tip on the floor (+y).
    let contacts = [
        MechanismContact {
            point: BodyPoint {
                body: b0,
                p_bq: Vector3::new(0.0, -1.0, 0.0),
            },
            other: None,
            normal_w: Vector3::x(),
            law: ContactLaw::smooth(e).expect("law"),
        },
        ground_contact(b1, Vector3::new(0.0, -1.0, 0.0), ContactLaw::smooth(e).expect("law")),
    ];
    // The first of a few velocity states at which the KKT solution has both contacts active.
    let mut found = None;
    let grid = (0..81).map(|k| [0.5 * (k % 9) as f64 - 2.0, 0.5 * (k / 9) as f64 - 2.0]);
    for q_dot in grid {
        let space = ContactSpace::new(&mech.tree, &mech.ws, &mech.inertia, &q_dot, &contacts).expect("space");
        let w = space.delassus();
        let u = space.u_before();
        let (un0, un1) = (u[2], u[5]);
        let (w00, w01, w11) = (w[2 + 6 * 2], w[2 + 6 * 5], w[5 + 6 * 5]);
        let det = w00 * w11 - w01 * w01;
        let (r0, r1) = (-(1.0 + e) * un0, -(1.0 + e) * un1);
        let p = [(w11 * r0 - w01 * r1) / det, (w00 * r1 - w01 * r0) / det];
        if p[0] > 0.0 && p[1] > 0.0 && un0 < 0.0 && un1 < 0.0 {
            found = Some((q_dot, p, un0, un1, w00, w01, w11));
            break;
        }
    }
    let (q_dot, p, un0, un1, w00, w01, w11) = found.expect("a state with both contacts active");
    let options = MultiContactOptions::default();
    let r = resolve_contacts(&mech.tree, &mech.ws, &mech.inertia, &q_dot, &contacts, &options).expect("impact");
    for k in 0..2 {
        // The residual bounds the velocity error; divide by the smallest eigenvalue of W_nn.
        let lam_min = 0.5 * (w00 + w11 - ((w00 - w11).powi(2) + 4.0 * w01 * w01).sqrt());
        let tol = 4.0 * r.complementarity_residual / lam_min + 1e-13 * p[k];
        assert!((r.contacts[k].normal_impulse - p[k]).abs() <= tol, "contact {k}");
        assert!((r.contacts[k].u_after_w.dot(&contacts[k].normal_w) + e * [un0, un1][k]).abs() <= 1e-9);
    }
    assert!(r.energy_change <= 0.0);
}

/// The exact energy identity ΔT = P·(u⁻ + ½ W P) = ½ q̇⁺ᵀAq̇⁺ − ½ q̇⁻ᵀAq̇⁻ for single and
/// multiple frictional contacts.
#[test]
fn energy_identity() {
    let m = chain(&[
        Joint::Spherical,
        Joint::Revolute { axis: Vector3::x() },
        Joint::Spherical,
    ]);
    let q_dot = [0.3, -0.8, 0.5, 1.2, -0.4, 0.9, 0.2];
    let c0 = ground_contact(2, Vector3::new(0.1, -0.5, 0.0), law(0.5, 0.4, RestitutionLaw::Stronge));
    let c1 = ground_contact(1, Vector3::new(0.0, -0.5, 0.1), law(0.3, 0.8, RestitutionLaw::Poisson));
    for contacts in [vec![c0], vec![c0, c1]] {
        let r = resolve_contacts(
            &m.tree,
            &m.ws,
            &m.inertia,
            &q_dot,
            &contacts,
            &MultiContactOptions::default(),
        )
        .expect("impact");
        let dt = m.energy(&r.q_dot_after) - m.energy(&q_dot);
        let t = m.energy(&q_dot);
        assert!((r.energy_change - dt).abs() <= 1e-12 * t, "{} vs {dt}", r.energy_change);
        assert!((r.energy_before - t).abs() <= 1e-15 * t);
    }
}

/// A chain of bodies hanging along −y, each 0.5 m below its parent, with the given joints.
fn chain(joints: &[Joint]) -> Mechanism {
    let mut builder = TreeBuilder::new();
    let mut parent = None;
    let mut bodies = Vec::new();
    for (i, joint) in joints.iter().enumerate() {
        let placement = if i == 0 {
            Isometry3::translation(0.0, 1.0, 0.0)
        } else {
            Isometry3::translation(0.0, -0.5, 0.0)
        };
        parent = Some(builder.add_body(parent, *joint, placement));
        bodies.push(solid(
            1.0 + 0.3 * i as f64,
            Vector3::new(0.03, 0.01, 0.025),
            Vector3::new(0.0, -0.25, 0.0),
            Vector3::new(0.1 * i as f64, 0.2, 0.0),
        ));
    }
    let tree = builder.build().expect("tree");
    let q: Vec<f64> = (0..tree.dof()).map(|k| 0.3 * ((k as f64) * 1.7).sin()).collect();
    Mechanism::new(tree, bodies, &q)
}

/// Grazing (u_n = 0) and separating contacts receive no impulse, single or multiple.
#[test]
fn grazing_and_separating_contacts_get_no_impulse() {
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Free, Isometry3::identity());
    let tree = builder.build().expect("tree");
    let props = solid(1.0, Vector3::new(0.1, 0.1, 0.1), Vector3::zeros(), Vector3::zeros());
    let mech = Mechanism::new(tree, vec![props], &[0.0; 6]);
    let bottom = Vector3::new(0.0, -0.2, 0.0);
    let rough = law(0.5, 0.7, RestitutionLaw::Stronge);
    // Grazing: sliding along the floor; separating: moving up.
    for q_dot in [[1.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.3, 0.5, 0.0, 0.0, 0.0, 0.0]] {
        let single = resolve_single_contact(
            &mech.tree,
            &mech.ws,
            &mech.inertia,
            &q_dot,
            &ground_contact(0, bottom, rough),
            &ImpactOptions::default(),
        )
        .expect("single");
        assert_eq!(single.contacts[0].mode, ContactMode::NoImpact);
        assert!(single.delta_q_dot.iter().all(|d| *d == 0.0));
        let contacts = [
            ground_contact(0, bottom, rough),
            ground_contact(0, Vector3::new(0.2, -0.2, 0.0), rough),
        ];
        let multi = resolve_contacts(
            &mech.tree,
            &mech.ws,
            &mech.inertia,
            &q_dot,
            &contacts,
            &MultiContactOptions::default(),
        )
        .expect("multi");
        assert!(multi.delta_q_dot.iter().all(|d| *d == 0.0), "{:?}", multi.delta_q_dot);
        assert!(multi.contacts.iter().all(|c| c.mode == ContactMode::NoImpact));
        assert_eq!(multi.energy_change, 0.0);
    }
}

/// A duplicated frictionless contact (W rank deficient) gives the same Δq̇ and total impulse
/// as the contact alone (the process), with no NaN; the rank is reported.
#[test]
fn duplicated_contact_gives_the_same_total_impulse() {
    let m = chain(&[Joint::Spherical, Joint::Spherical]);
    let q_dot = [0.5, -0.3, 0.8, -1.0, 0.2, 0.6];
    let tip = Vector3::new(0.05, -0.5, 0.02);
    // Orient the floor normal against the tip's velocity so that the contact approaches.
    let probe = ground_contact(1, tip, law(0.0, 0.0, RestitutionLaw::Poisson));
    let space = ContactSpace::new(&m.tree, &m.ws, &m.inertia, &q_dot, &[probe]).expect("space");
    let sign = if space.u_before()[2] < 0.0 { 1.0 } else { -1.0 };
    for (e, f) in [(0.0, 0.0), (0.7, 0.0), (1.0, 0.0)] {
        let mut c = ground_contact(1, tip, law(e, f, RestitutionLaw::Poisson));
        c.normal_w *= sign;
        let options = MultiContactOptions::default();
        let one = resolve_single_contact(&m.tree, &m.ws, &m.inertia, &q_dot, &c, &options.process).expect("one");
        let two = resolve_contacts(&m.tree, &m.ws, &m.inertia, &q_dot, &[c, c], &options).expect("two");
        assert!(
            one.contacts[0].normal_impulse > 0.0,
            "the contact must be active: e {e} f {f} {one:?}"
        );
        assert_eq!(two.delassus_rank, one.delassus_rank);
        let p_one = one.contacts[0].impulse_w;
        let p_two = two.contacts[0].impulse_w + two.contacts[1].impulse_w;
        let tol = 8.0 * (two.complementarity_residual + options.tolerance) * q_dot.len() as f64;
        assert!(
            (p_two - p_one).norm() <= tol * p_one.norm(),
            "e {e} f {f}: {p_two} vs {p_one}"
        );
        for (a, b) in one.delta_q_dot.iter().zip(&two.delta_q_dot) {
            assert!(a.is_finite() && (a - b).abs() <= tol * (1.0 + a.abs()), "e {e} f {f}");
        }
    }
}

/// Kane & Levinson's double pendulum on a rough floor: Newton's law gains energy, Poisson's
/// and Stronge's do not; Newton's law does give u_n⁺ = −e u_n⁻.
#[test]
fn kane_double_pendulum_energy_by_law() {
    let rows = kane_double_pendulum_demo().expect("demo");
    assert_eq!(rows.len(), 3);
    let (newton, poisson, stronge) = (&rows[0], &rows[1], &rows[2]);
    assert_eq!((newton.law, poisson.law, stronge.law), ("Newton", "Poisson", "Stronge"));
    assert!(newton.energy_change > 0.0, "Newton gains: {}", newton.energy_change);
    assert!(poisson.energy_change < 0.0);
    assert!(stronge.energy_change < 0.0);
    // Newton's law ends at u_n⁺ = −e u_n⁻; u_n⁻ from the pendulum's tip velocity.
    let (theta, theta_dot) = KANE_STATE;
    let (t1, phi) = (theta[0], theta[0] + theta[1]);
    let v_tip_y = theta_dot[0] * (t1.sin() + phi.sin()) + theta_dot[1] * phi.sin();
    assert!(v_tip_y < 0.0);
    assert!((newton.normal_velocity_after + 0.5 * v_tip_y).abs() <= 1e-12);
    // Without friction all three laws coincide.
    let smooth = kane_double_pendulum(theta, theta_dot, 0.5, 0.0).expect("smooth");
    for r in &smooth[1..] {
        assert!((r.energy_change - smooth[0].energy_change).abs() <= 1e-14);
    }
}

/// Bad input gives typed errors naming the problem; nothing panics.
#[test]
fn bad_input_is_rejected() {
    let m = chain(&[Joint::Spherical, Joint::Revolute { axis: Vector3::z() }]);
    let q_dot = [0.1, 0.2, -0.3, 0.5];
    let good = ground_contact(1, Vector3::new(0.0, -0.5, 0.0), law(0.5, 0.3, RestitutionLaw::Stronge));
    let options = MultiContactOptions::default();
    let run = |q: &[f64], c: MechanismContact| resolve_contacts(&m.tree, &m.ws, &m.inertia, q, &[c, good], &options);
    let unwrap_contact = |e: ImpulseError| match e {
        ImpulseError::InContact { contact, source } => (contact, *source),
        other => panic!("expected InContact, got {other:?}"),
    };
    assert!(matches!(
        run(&[0.1, f64::NAN, 0.0, 0.0], good),
        Err(ImpulseError::NonFinite { .. })
    ));
    assert!(matches!(
        run(&[0.1, 0.2], good),
        Err(ImpulseError::DimensionMismatch {
            expected: 4,
            got: 2,
            ..
        })
    ));
    let mut c = good;
    c.normal_w = Vector3::new(0.0, 2.0, 0.0);
    let (i, e) = unwrap_contact(run(&q_dot, c).expect_err("non-unit"));
    assert_eq!(i, 0);
    assert!(matches!(e, ImpulseError::NotUnit { .. }));
    c = good;
    c.normal_w = Vector3::new(f64::NAN, 1.0, 0.0);
    assert!(matches!(
        unwrap_contact(run(&q_dot, c).expect_err("nan")).1,
        ImpulseError::NonFinite { .. }
    ));
    c = good;
    c.law.restitution = 1.5;
    assert!(matches!(
        unwrap_contact(run(&q_dot, c).expect_err("e")).1,
        ImpulseError::RestitutionOutOfRange(_)
    ));
    c = good;
    c.law.friction = -0.1;
    assert!(matches!(
        unwrap_contact(run(&q_dot, c).expect_err("f")).1,
        ImpulseError::NegativeFriction(_)
    ));
    c = good;
    c.point.body = 7;
    assert!(matches!(
        unwrap_contact(run(&q_dot, c).expect_err("body")).1,
        ImpulseError::BodyOutOfRange { body: 7, .. }
    ));
    c = good;
    c.point.p_bq.x = f64::INFINITY;
    assert!(matches!(
        unwrap_contact(run(&q_dot, c).expect_err("p")).1,
        ImpulseError::NonFinite { .. }
    ));
    let bad_options = MultiContactOptions {
        tolerance: 0.0,
        ..options
    };
    assert!(resolve_contacts(&m.tree, &m.ws, &m.inertia, &q_dot, &[good], &bad_options).is_err());
    // Point impulses: NaN impulse, wrong sizes.
    let bad = PointImpulse {
        point: good.point,
        s_w: Vector3::new(0.0, f64::NAN, 0.0),
    };
    assert!(matches!(
        apply_point_impulses(&m.tree, &m.ws, &m.inertia, &q_dot, &[bad]),
        Err(ImpulseError::InContact { contact: 0, .. })
    ));
    assert!(matches!(
        MechanismInertia::from_mass_matrix(3, vec![1.0; 4]),
        Err(ImpulseError::DimensionMismatch { .. })
    ));
    // A contact on a point that cannot move along the normal (on the hinge axis of a single
    // revolute body, moving... never) while "approaching" is impossible: the base itself.
    // A semidefinite mass matrix: a point mass on a spherical joint at its centre.
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Spherical, Isometry3::identity());
    let tree = builder.build().expect("tree");
    let mut ws = tree.workspace();
    tree.update_positions(&mut ws, &[0.0; 3]).expect("q");
    let point_mass = MassProperties {
        mass: 1.0,
        p_oc: Vector3::new(0.0, -1.0, 0.0),
        inertia_c: Matrix3::zeros(),
    };
    let mut mass = TreeMass::new(&tree, vec![point_mass]).expect("mass");
    let err = MechanismInertia::new(&tree, &ws, &mut mass).expect_err("semidefinite");
    assert!(
        matches!(err, ImpulseError::SingularMassMatrix { coordinate: 1, .. }),
        "{err:?}"
    );
    // Contact on a body whose point cannot move along the normal while approaching.
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Revolute { axis: Vector3::z() }, Isometry3::identity());
    let tree = builder.build().expect("tree");
    let disc = solid(1.0, Vector3::new(0.1, 0.1, 0.2), Vector3::zeros(), Vector3::zeros());
    let hinge = Mechanism::new(tree, vec![disc], &[0.0]);
    // The point on the axis never moves: approach is impossible, so u_n = 0 → no impulse,
    // while a moving point on the rim tangent to the normal... the immovable contact case:
    let on_axis = ground_contact(0, Vector3::zeros(), law(0.5, 0.0, RestitutionLaw::Stronge));
    let r = resolve_single_contact(
        &hinge.tree,
        &hinge.ws,
        &hinge.inertia,
        &[2.0],
        &on_axis,
        &ImpactOptions::default(),
    )
    .expect("no approach, no impulse");
    assert_eq!(r.contacts[0].mode, ContactMode::NoImpact);
}

/// Extreme mass ratios along a chain (1e±6 between neighbours): still no energy gain, and the
/// identity holds.
#[test]
fn extreme_mass_ratios() {
    let mut m = chain(&[Joint::Spherical, Joint::Spherical, Joint::Spherical]);
    m.bodies[1].mass = 1e6;
    m.bodies[2].mass = 1e-6;
    let mut mass = TreeMass::new(&m.tree, m.bodies.clone()).expect("mass");
    m.inertia = MechanismInertia::new(&m.tree, &m.ws, &mut mass).expect("inertia");
    let q_dot = [0.2, -0.1, 0.3, 0.5, 0.4, -0.2, 1.0, -2.0, 0.5];
    let contacts = [
        ground_contact(2, Vector3::new(0.0, -0.5, 0.0), law(0.8, 0.5, RestitutionLaw::Stronge)),
        ground_contact(1, Vector3::new(0.0, -0.5, 0.0), law(0.2, 0.9, RestitutionLaw::Stronge)),
    ];
    for cs in [&contacts[..1], &contacts[..]] {
        let r =
            resolve_contacts(&m.tree, &m.ws, &m.inertia, &q_dot, cs, &MultiContactOptions::default()).expect("impact");
        let t = r.energy_before;
        assert!(r.energy_change <= 1e-12 * t, "{}", r.energy_change);
        assert!(r.delta_q_dot.iter().all(|d| d.is_finite()));
    }
}

/// A case from mechanism.proptest-regressions: a hinge and a ball joint, two frictional
/// contacts (f = 0.001 and 1.3) along one tilted normal, six impulse rows on four freedoms.
/// Unchecked, the Gauss–Seidel impulses drift along the Delassus null space to ~1e25 and the
/// energy bookkeeping breaks down (ΔT = −2e50 reported while the velocities gain 1e34); the
/// solve refuses it with a typed error naming the drift.
#[test]
fn redundant_contacts_whose_impulses_drift_are_refused() {
    let joints = [Joint::Revolute { axis: Vector3::z() }, Joint::Spherical];
    let m = chain(&joints);
    let velocity_seed = [-0.8972757371537559, 0.0, -0.720869642308137, -1.1992299891725073];
    let q_dot: Vec<f64> = velocity_seed.iter().cycle().take(m.tree.dof()).copied().collect();
    let normal = Vector3::new(0.41556233059193737, 1.0, 0.25816657241609314).normalize();
    let seeds = [
        (1, 0.038575994818767036, -0.1719104742531726, 0.0, 0.0010237778923716744),
        (0, 0.005263608072098572, 0.0, 0.0, 1.3047750339014481),
    ];
    let contacts: Vec<MechanismContact> = seeds
        .iter()
        .map(|&(b, x, z, e, f)| MechanismContact {
            point: BodyPoint {
                body: b,
                p_bq: Vector3::new(x, -0.5, z),
            },
            other: None,
            normal_w: normal,
            law: ContactLaw::new(e, f, RestitutionLaw::Stronge).expect("law"),
        })
        .collect();
    match resolve_contacts(
        &m.tree,
        &m.ws,
        &m.inertia,
        &q_dot,
        &contacts,
        &MultiContactOptions::default(),
    ) {
        Err(ImpulseError::Singular { value, .. }) => assert!(value > 1e6, "drift ratio {value:e}"),
        Ok(r) => impact_is_energy_safe(&r, &m, &q_dot).expect("a returned impact must be energy safe"),
        Err(other) => panic!("unexpected error {other:?}"),
    }
}

fn impact_is_energy_safe(r: &MechanismImpact, m: &Mechanism, q_dot: &[f64]) -> Result<(), TestCaseError> {
    let t = r.energy_before;
    let scale = t + r
        .contacts
        .iter()
        .map(|c| c.normal_impulse * c.u_before_w.norm())
        .sum::<f64>();
    prop_assert!(
        r.energy_change <= 1e-10 * scale,
        "energy gained: {} (T = {t})",
        r.energy_change
    );
    let dt = m.energy(&r.q_dot_after) - m.energy(q_dot);
    prop_assert!(
        (dt - r.energy_change).abs() <= 1e-9 * scale,
        "identity: {dt} vs {}",
        r.energy_change
    );
    Ok(())
}

fn joint_strategy() -> impl Strategy<Value = Joint> {
    prop_oneof![
        Just(Joint::Spherical),
        (-1.0..1.0f64, -1.0..1.0f64, 0.2..1.0f64).prop_map(|(x, y, z)| Joint::Revolute {
            axis: Vector3::new(x, y, z).normalize()
        }),
        Just(Joint::Revolute { axis: Vector3::z() }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Random chains (1–5 bodies), random velocities and 1–4 random frictional contacts with
    /// the default law (Stronge): energy is never gained and the identity holds; converged
    /// simultaneous impacts meet their residual tolerance.
    #[test]
    fn no_energy_gain_under_default_law(
        joints in prop::collection::vec(joint_strategy(), 1..6),
        seeds in prop::collection::vec((0usize..8, -0.2..0.2f64, -0.2..0.2f64, 0.0..1.0f64, 0.0..2.0f64), 1..5),
        velocity_seed in prop::collection::vec(-2.0..2.0f64, 15),
        tilt in (-0.5..0.5f64, -0.5..0.5f64),
    ) {
        let m = chain(&joints);
        let n = m.tree.dof();
        let q_dot: Vec<f64> = velocity_seed.iter().cycle().take(n).copied().collect();
        let normal = Vector3::new(tilt.0, 1.0, tilt.1).normalize();
        let contacts: Vec<MechanismContact> = seeds
            .iter()
            .map(|&(b, x, z, e, f)| MechanismContact {
                point: BodyPoint { body: b % joints.len(), p_bq: Vector3::new(x, -0.5, z) },
                other: None,
                normal_w: normal,
                law: ContactLaw::new(e, f, RestitutionLaw::Stronge).expect("law"),
            })
            .collect();
        let options = MultiContactOptions::default();
        match resolve_contacts(&m.tree, &m.ws, &m.inertia, &q_dot, &contacts, &options) {
            Ok(r) => {
                impact_is_energy_safe(&r, &m, &q_dot)?;
                if r.converged && r.model == ImpactModel::Simultaneous {
                    let speed = contacts.iter().enumerate().map(|(i, _)| r.contacts[i].u_before_w.norm()).fold(0.0, f64::max);
                    prop_assert!(r.complementarity_residual <= options.tolerance * speed * 1.0000001 + 1e-300);
                }
            }
            // Contacts on a body that cannot move along the normal, frictional jams of the
            // single-contact process, and redundant contacts whose impulses drift along the
            // Delassus null space (the saved regression case) are legitimate typed outcomes.
            Err(ImpulseError::ContactImmovable { .. })
            | Err(ImpulseError::InContact { .. })
            | Err(ImpulseError::Singular { .. }) => {}
            Err(other) => prop_assert!(false, "unexpected error {other:?}"),
        }
    }

    /// Body-to-body contacts inside a random chain (tip against the root body): energy safe.
    #[test]
    fn self_contacts_are_energy_safe(
        joints in prop::collection::vec(joint_strategy(), 2..5),
        velocity_seed in prop::collection::vec(-2.0..2.0f64, 12),
        e in 0.0..1.0f64,
        f in 0.0..1.5f64,
    ) {
        let m = chain(&joints);
        let n = m.tree.dof();
        let q_dot: Vec<f64> = velocity_seed.iter().cycle().take(n).copied().collect();
        let last = joints.len() - 1;
        let contacts = [
            MechanismContact {
                point: BodyPoint { body: last, p_bq: Vector3::new(0.0, -0.5, 0.0) },
                other: Some(BodyPoint { body: 0, p_bq: Vector3::new(0.1, -0.2, 0.0) }),
                normal_w: Vector3::x(),
                law: ContactLaw::new(e, f, RestitutionLaw::Stronge).expect("law"),
            },
            ground_contact(last, Vector3::new(0.0, -0.5, 0.0), ContactLaw::new(e, f, RestitutionLaw::Stronge).expect("law")),
        ];
        for cs in [&contacts[..1], &contacts[..]] {
            match resolve_contacts(&m.tree, &m.ws, &m.inertia, &q_dot, cs, &MultiContactOptions::default()) {
                Ok(r) => impact_is_energy_safe(&r, &m, &q_dot)?,
                Err(ImpulseError::ContactImmovable { .. }) | Err(ImpulseError::InContact { .. }) => {}
                Err(other) => prop_assert!(false, "unexpected error {other:?}"),
            }
        }
    }
}

/// The box of the previous test falling flat while sliding fast along x, with f·h_y < h_x so
/// that all four contacts stay active: friction cannot tip it, so ω⁺ = 0, v_y⁺ = e v_y,
/// Σ p_n = m (1 + e) v_y, and the slip never halts: v_x⁺ = v_x − f (1 + e) v_y. Every contact
/// impulse lies in its friction cone.
#[test]
fn box_sliding_flat_on_four_rough_contacts() {
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Free, Isometry3::identity());
    let tree = builder.build().expect("tree");
    let (mass, hx, hy, hz) = (2.5, 0.4, 0.2, 0.3);
    let diag = Vector3::new(hy * hy + hz * hz, hx * hx + hz * hz, hx * hx + hy * hy) * (mass / 3.0);
    let props = solid(mass, diag, Vector3::zeros(), Vector3::zeros());
    let mech = Mechanism::new(tree, vec![props], &[0.0, hy, 0.0, 0.0, 0.0, 0.0]);
    let (vx, vy, e, f) = (2.0, 1.5, 0.5, 0.3);
    let q_dot = [vx, -vy, 0.0, 0.0, 0.0, 0.0];
    let contacts: Vec<_> = [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)]
        .iter()
        .map(|&(sx, sz)| {
            ground_contact(
                0,
                Vector3::new(sx * hx, -hy, sz * hz),
                law(e, f, RestitutionLaw::Stronge),
            )
        })
        .collect();
    let options = MultiContactOptions::default();
    let r = resolve_contacts(&mech.tree, &mech.ws, &mech.inertia, &q_dot, &contacts, &options).expect("impact");
    assert!(r.converged, "residual {}", r.complementarity_residual);
    assert_eq!(r.restitution_scale, 1.0);
    let tol = 8.0 * options.tolerance * vx.hypot(vy) + 1e-14;
    let (v_after, w_after) = mech.body_velocity(0, &r.q_dot_after);
    let expected = Vector3::new(vx - f * (1.0 + e) * vy, e * vy, 0.0);
    assert!((v_after - expected).norm() <= tol, "{v_after} vs {expected}");
    assert!(w_after.norm() * hx <= tol, "{w_after}");
    for c in &r.contacts {
        assert!(c.normal_impulse > 0.0);
        assert!(c.tangential_impulse_w.norm() <= f * c.normal_impulse * (1.0 + 1e-12));
        assert_eq!(c.mode, ContactMode::Slip);
    }
    assert!(r.energy_change < 0.0);
    let dt = 0.5 * mass * (v_after.norm_squared() - vx * vx - vy * vy);
    assert!((r.energy_change - dt).abs() <= 4.0 * mass * vx * tol);
}

/// No contacts: a zero impact, and the report is still complete.
#[test]
fn no_contacts_is_a_zero_impact() {
    let m = chain(&[Joint::Spherical]);
    let q_dot = [0.1, 0.2, 0.3];
    let r = resolve_contacts(&m.tree, &m.ws, &m.inertia, &q_dot, &[], &MultiContactOptions::default()).expect("empty");
    assert!(r.contacts.is_empty());
    assert_eq!(r.delta_q_dot, vec![0.0; 3]);
    assert_eq!(r.energy_change, 0.0);
    assert_eq!(r.delassus_rank, 0);
}

/// The humanoid-like tree of the benchmark and of tools/impulse_mechanism_pinocchio.py: free
/// torso, head, four limbs of three spherical joints (45 DOF). Returns it at q with all
/// rotation vectors zero and the torso origin at (0, 1, 0), and the hand/foot points.
fn humanoid() -> (Mechanism, Vec<BodyPoint>) {
    let mut builder = TreeBuilder::new();
    let mut bodies = Vec::new();
    let link = |mass: f64, length: f64| {
        let r = 0.05_f64;
        let (ia, it) = (0.5 * mass * r * r, mass * (3.0 * r * r + length * length) / 12.0);
        MassProperties {
            mass,
            p_oc: Vector3::new(0.0, -0.5 * length, 0.0),
            inertia_c: Matrix3::from_diagonal(&Vector3::new(it, ia, it)),
        }
    };
    let torso = builder.add_body(None, Joint::Free, Isometry3::identity());
    bodies.push(MassProperties {
        mass: 30.0,
        p_oc: Vector3::zeros(),
        inertia_c: Matrix3::from_diagonal(&Vector3::new(1.2, 0.6, 1.0)),
    });
    builder.add_body(Some(torso), Joint::Spherical, Isometry3::translation(0.0, 0.3, 0.0));
    bodies.push(MassProperties {
        mass: 5.0,
        p_oc: Vector3::new(0.0, 0.12, 0.0),
        inertia_c: Matrix3::identity() * 0.03,
    });
    let mut ends = Vec::new();
    for (x, y, lengths, masses) in [
        (0.2, 0.25, [0.3, 0.28, 0.08], [2.5, 1.5, 0.5]),
        (-0.2, 0.25, [0.3, 0.28, 0.08], [2.5, 1.5, 0.5]),
        (0.1, -0.3, [0.45, 0.42, 0.1], [8.0, 4.0, 1.2]),
        (-0.1, -0.3, [0.45, 0.42, 0.1], [8.0, 4.0, 1.2]),
    ] {
        let mut parent = torso;
        let mut offset = Vector3::new(x, y, 0.0);
        for k in 0..3 {
            parent = builder.add_body(
                Some(parent),
                Joint::Spherical,
                Isometry3::translation(offset.x, offset.y, 0.0),
            );
            bodies.push(link(masses[k], lengths[k]));
            offset = Vector3::new(0.0, -lengths[k], 0.0);
        }
        ends.push(BodyPoint {
            body: parent,
            p_bq: offset,
        });
    }
    let tree = builder.build().expect("humanoid");
    let mut q = vec![0.0; tree.dof()];
    q[1] = 1.0;
    (Mechanism::new(tree, bodies, &q), ends)
}

/// Pinocchio's impulseDynamics (3-D rigid contacts, r = 0) on the 45-DOF humanoid landing on
/// hands and feet (W of rank 10 < 12 in this straight pose) equals the simultaneous model with e = 0 and f = ∞ (every normal impulse is
/// positive there, so the unilateral and bilateral problems coincide). Reference numbers from
/// tools/impulse_mechanism_pinocchio.py. Tolerance: both results stop the contact points to
/// within their velocity residuals r (Pinocchio's is in the file, ours is reported), so Δq̇
/// differs by at most ‖A⁻¹Jᵀ W⁺‖_F (r_pin + r_ours) √(3m).
#[test]
fn pinocchio_impulse_dynamics_reference() {
    let text = include_str!("../../../tools/impulse_mechanism_pinocchio.out");
    let line = |key: &str| -> Vec<f64> {
        text.lines()
            .find_map(|l| l.strip_prefix(key))
            .expect("key in the reference file")
            .split_whitespace()
            .map(|x| x.parse().expect("number"))
            .collect()
    };
    let reference = line("delta_q_dot ");
    let r_pin = line("residual ")[0];
    let (m, ends) = humanoid();
    let n = m.tree.dof();
    assert_eq!(reference.len(), n);
    let mut q_dot: Vec<f64> = (0..n).map(|k| 0.3 * (1.3 * k as f64).cos()).collect();
    q_dot[1] = -2.0;
    let stick = law(0.0, f64::INFINITY, RestitutionLaw::Poisson);
    let contacts: Vec<MechanismContact> = ends
        .iter()
        .map(|&point| MechanismContact {
            point,
            other: None,
            normal_w: Vector3::y(),
            law: stick,
        })
        .collect();
    let options = MultiContactOptions {
        tolerance: 1e-13,
        ..MultiContactOptions::default()
    };
    let r = resolve_contacts(&m.tree, &m.ws, &m.inertia, &q_dot, &contacts, &options).expect("impact");
    assert!(r.converged, "residual {}", r.complementarity_residual);
    // ‖A⁻¹ Jᵀ W⁺‖_F from the contact space. In this straight pose W is rank deficient (the
    // limbs hang vertically), so W⁺ (SVD, the rank threshold of the crate) maps the residual;
    // the SVD rank must equal the reported one.
    let space = ContactSpace::new(&m.tree, &m.ws, &m.inertia, &q_dot, &contacts).expect("space");
    let a = nalgebra::DMatrix::from_column_slice(n, n, m.inertia.mass_matrix());
    let j = nalgebra::DMatrix::from_column_slice(12, n, space.jacobian());
    let w = nalgebra::DMatrix::from_column_slice(12, 12, space.delassus());
    let svd = w.clone().svd(true, true);
    let cut = DELASSUS_RANK_RELATIVE * svd.singular_values.max();
    assert_eq!(
        svd.singular_values.iter().filter(|s| **s > cut).count(),
        r.delassus_rank
    );
    let w_pinv = svd.pseudo_inverse(cut).expect("pseudo-inverse");
    let map = a.cholesky().expect("A").solve(&j.transpose()) * w_pinv;
    let tol = map.norm() * (r_pin + r.complementarity_residual) * 12f64.sqrt();
    let worst = r
        .delta_q_dot
        .iter()
        .zip(&reference)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    println!(
        "pinocchio: max difference {worst:e}, bound {tol:e}, rank {}",
        r.delassus_rank
    );
    assert!(worst <= tol, "max |Δq̇ − Δq̇_pinocchio| = {worst:e} > {tol:e}");
    for c in &r.contacts {
        assert!(c.normal_impulse > 0.0 && c.mode == ContactMode::Stick);
    }
}
