//! Kane's paradox on a mechanism: a double pendulum whose tip strikes a rough floor (Kane &
//! Levinson 1985), resolved with each restitution law by
//! [`crate::mechanism_contact::resolve_single_contact`].
//!
//! Two uniform rods of mass 1 kg and length 1 m hang from a fixed hinge at the origin and are
//! joined by a second hinge, both about the world z axis; θ₁ and θ₂ are the hinge angles
//! (θ₂ relative to rod 1), zero hanging straight down. At the instant of impact the tip lies
//! on the floor y = y_tip with unit normal +y, the contact has restitution e = 0.5 and friction
//! f = 0.5, and the rods swing so that the tip approaches the floor while slipping along it.
//! During the impact the slip halts and reverses: Newton's kinematic law u_n⁺ = −e u_n⁻ then
//! returns more energy than the compression absorbed, so the pendulum *gains* kinetic energy;
//! Poisson's and Stronge's laws do not.

use crate::mechanism::{BodyPoint, MechanismInertia};
use crate::mechanism_contact::{MechanismContact, resolve_single_contact};
use crate::{ContactLaw, ImpactOptions, ImpulseError, RestitutionLaw};
use mechanica_kinematics::tree::{Joint, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mass::mechanism::TreeMass;
use nalgebra::{Isometry3, Matrix3, Vector3};

/// The configuration of the showcase: hinge angles (rad) and rates (rad/s).
pub const KANE_STATE: ([f64; 2], [f64; 2]) = ([-0.16, -0.24], [-0.5, 2.0]);

/// The outcome of the showcase under one restitution law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LawOutcome {
    /// Name of the law ("Newton", "Poisson", "Stronge").
    pub law: &'static str,
    /// Kinetic energy before the impact, T⁻ (J).
    pub energy_before: f64,
    /// ΔT = T⁺ − T⁻ (J): positive means energy was created.
    pub energy_change: f64,
    /// Normal impulse on the tip (N·s).
    pub normal_impulse: f64,
    /// Friction impulse on the tip along the floor (N·s, world x).
    pub tangential_impulse: f64,
    /// Normal velocity of the tip after the impact (m/s).
    pub normal_velocity_after: f64,
}

/// The double pendulum of Kane & Levinson striking a rough floor at angles `theta` and rates
/// `theta_dot`, with restitution `restitution` and friction `friction`, under each of the
/// three restitution laws (Newton, Poisson, Stronge, in that order).
pub fn kane_double_pendulum(
    theta: [f64; 2],
    theta_dot: [f64; 2],
    restitution: f64,
    friction: f64,
) -> Result<Vec<LawOutcome>, ImpulseError> {
    let length = 1.0;
    let mass = 1.0;
    let mut builder = TreeBuilder::new();
    let z = Joint::Revolute { axis: Vector3::z() };
    let upper = builder.add_body(None, z, Isometry3::identity());
    let lower = builder.add_body(Some(upper), z, Isometry3::translation(0.0, -length, 0.0));
    let tree = builder.build()?;
    let rod = MassProperties {
        mass,
        p_oc: Vector3::new(0.0, -0.5 * length, 0.0),
        inertia_c: Matrix3::from_diagonal(&Vector3::new(1.0, 0.0, 1.0)) * (mass * length * length / 12.0),
    };
    let mut tree_mass = TreeMass::new(&tree, vec![rod, rod])?;
    let mut ws = tree.workspace();
    tree.update_positions(&mut ws, &theta)?;
    let inertia = MechanismInertia::new(&tree, &ws, &mut tree_mass)?;
    let mut out = Vec::with_capacity(3);
    for (name, law) in [
        ("Newton", RestitutionLaw::Newton),
        ("Poisson", RestitutionLaw::Poisson),
        ("Stronge", RestitutionLaw::Stronge),
    ] {
        let contact = MechanismContact {
            point: BodyPoint {
                body: lower,
                p_bq: Vector3::new(0.0, -length, 0.0),
            },
            other: None,
            normal_w: Vector3::y(),
            law: ContactLaw::new(restitution, friction, law)?,
        };
        let impact = resolve_single_contact(&tree, &ws, &inertia, &theta_dot, &contact, &ImpactOptions::default())?;
        let c = &impact.contacts[0];
        out.push(LawOutcome {
            law: name,
            energy_before: impact.energy_before,
            energy_change: impact.energy_change,
            normal_impulse: c.normal_impulse,
            tangential_impulse: c.tangential_impulse_w.x,
            normal_velocity_after: c.u_after_w.y,
        });
    }
    Ok(out)
}

/// [`kane_double_pendulum`] at the showcase state [`KANE_STATE`] with e = 0.5 and f = 0.5:
/// one row per law, for the CLI report.
pub fn kane_double_pendulum_demo() -> Result<Vec<LawOutcome>, ImpulseError> {
    kane_double_pendulum(KANE_STATE.0, KANE_STATE.1, 0.5, 0.5)
}
