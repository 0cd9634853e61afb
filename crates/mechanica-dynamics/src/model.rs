//! [`Dynamics`]: a mechanism with everything its equations of motion need, and the state at
//! which they are evaluated.

use crate::dissipation::Damper;
use crate::error::{DynamicsError, check_vector};
use crate::spatial::{WorldInertia, Wrench};
use crate::velocity_potential::VelocityPotential;
use mechanica_kinematics::tree::{BaseMotion, BaseState, KinematicTree, Workspace};
use mechanica_mechanism::Mechanism;
use nalgebra::{Matrix6, Rotation3, Vector3, Vector6};
use std::sync::Arc;

/// The state (q, q̇) at time t at which the equations of motion are evaluated. Coordinates are
/// those of the tree ([`mechanica_kinematics::tree::Joint`]): q̇ is the time derivative of q.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct State<'a> {
    /// Coordinates q.
    pub q: &'a [f64],
    /// Velocities q̇.
    pub q_dot: &'a [f64],
    /// Time t, s; only time-dependent velocity potentials read it.
    pub t: f64,
}

impl<'a> State<'a> {
    /// The state (q, q̇) at t = 0.
    pub fn new(q: &'a [f64], q_dot: &'a [f64]) -> Self {
        Self { q, q_dot, t: 0.0 }
    }

    /// The same state at time `t`.
    pub fn at_time(self, t: f64) -> Self {
        Self { t, ..self }
    }
}

/// Per-body buffers of the articulated-body recursion.
#[derive(Debug, Clone)]
pub(crate) struct ArticulatedBuffers {
    /// Articulated inertia I^A about o_i, (angular, linear) order.
    pub inertia: Vec<Matrix6<f64>>,
    /// Articulated bias wrench p^A about o_i, (moment, force) order.
    pub bias: Vec<Vector6<f64>>,
    /// Velocity-product acceleration c_i, (angular, linear).
    pub accel_bias: Vec<Vector6<f64>>,
    /// Per coordinate: U_k = I^A S_k.
    pub u_columns: Vec<Vector6<f64>>,
    /// Per body: D⁻¹ = (Sᵀ I^A S)⁻¹ in the top-left d×d block.
    pub d_inverse: Vec<Matrix6<f64>>,
    /// Per coordinate: u = τ − Sᵀ p^A.
    pub u_force: Vec<f64>,
    /// Per body: spatial acceleration (ω̇, a_o).
    pub acceleration: Vec<Vector6<f64>>,
}

/// A mechanism (tree, bodies, gravity, rotating frame, potentials) with its dampers and
/// velocity-dependent potentials, and the preallocated buffers of the recursions.
///
/// All vectors are components in the base frame at the instant of evaluation, called "world"
/// throughout (with a fixed base the two are the same). With a steadily rotating frame
/// ([`mechanica_mechanism::RotatingFrame`]) or a prescribed base motion
/// ([`Dynamics::set_base_motion`]) the coordinates describe the motion relative to the base;
/// the recursions run in an inertial frame that coincides with the base frame at this instant,
/// so the Coriolis, centrifugal and drag terms of the relative motion (§8e, (7.51)–(7.52))
/// appear in the velocity-product terms.
#[derive(Debug, Clone)]
pub struct Dynamics {
    pub(crate) mechanism: Mechanism,
    pub(crate) dampers: Vec<Damper>,
    pub(crate) velocity_potentials: Vec<Arc<dyn VelocityPotential>>,
    pub(crate) ws: Workspace,
    pub(crate) world: Vec<WorldInertia>,
    pub(crate) wrenches: Vec<Wrench>,
    pub(crate) loads: Vec<Wrench>,
    pub(crate) joint_loads: Vec<f64>,
    pub(crate) articulated: ArticulatedBuffers,
    base_motion: Option<PrescribedBase>,
    gravity: Vector3<f64>,
}

impl Dynamics {
    /// The dynamics of `mechanism` (its gravity, rotating frame and potentials are used as they
    /// are), without dampers or velocity potentials.
    pub fn new(mechanism: Mechanism) -> Result<Self, DynamicsError> {
        let tree = mechanism.tree();
        let (bodies, n) = (tree.body_count(), tree.dof());
        let mut ws = tree.workspace();
        let base = base_state(&mechanism);
        ws.set_base(base)?;
        let zero6 = Vector6::zeros();
        Ok(Self {
            dampers: Vec::new(),
            velocity_potentials: Vec::new(),
            world: vec![
                WorldInertia {
                    mass: 0.0,
                    c: Vector3::zeros(),
                    inertia_c: nalgebra::Matrix3::zeros(),
                };
                bodies
            ],
            wrenches: vec![Wrench::zero(); bodies],
            loads: vec![Wrench::zero(); bodies],
            joint_loads: vec![0.0; n],
            articulated: ArticulatedBuffers {
                inertia: vec![Matrix6::zeros(); bodies],
                bias: vec![zero6; bodies],
                accel_bias: vec![zero6; bodies],
                u_columns: vec![zero6; n],
                d_inverse: vec![Matrix6::zeros(); bodies],
                u_force: vec![0.0; n],
                acceleration: vec![zero6; bodies],
            },
            ws,
            base_motion: None,
            gravity: mechanism.gravity(),
            mechanism,
        })
    }

    /// The mechanism.
    pub fn mechanism(&self) -> &Mechanism {
        &self.mechanism
    }

    /// The kinematic tree.
    pub fn tree(&self) -> &KinematicTree {
        self.mechanism.tree()
    }

    /// Number of coordinates.
    pub fn dof(&self) -> usize {
        self.mechanism.dof()
    }

    /// The dampers added so far.
    pub fn dampers(&self) -> &[Damper] {
        &self.dampers
    }

    /// Adds a damper after checking it against the tree; returns its index.
    pub fn add_damper(&mut self, damper: Damper) -> Result<usize, DynamicsError> {
        damper.validate(self.mechanism.tree())?;
        self.dampers.push(damper);
        Ok(self.dampers.len() - 1)
    }

    /// The velocity-dependent potentials added so far.
    pub fn velocity_potentials(&self) -> &[Arc<dyn VelocityPotential>] {
        &self.velocity_potentials
    }

    /// Adds a velocity-dependent (generalized) potential after checking it against the tree.
    pub fn add_velocity_potential(
        &mut self,
        potential: impl VelocityPotential + 'static,
    ) -> Result<usize, DynamicsError> {
        potential.validate(self.mechanism.tree())?;
        self.velocity_potentials.push(Arc::new(potential));
        Ok(self.velocity_potentials.len() - 1)
    }

    /// Folds the rotation vectors of `q` into the tree's reference orientations and zeroes
    /// them, without moving any body ([`Mechanism::rebase`]). The velocities of those
    /// coordinates change with the chart: the caller maps φ̇ to J_r(φ) φ̇ (the body-frame
    /// angular velocity relative to the parent, which is φ̇ in the new chart at φ = 0).
    pub fn rebase(&mut self, q: &mut [f64]) -> Result<(), DynamicsError> {
        self.mechanism.rebase(q)?;
        Ok(())
    }

    /// The kinematic workspace of the last evaluation (poses, velocities, accelerations).
    pub fn workspace(&self) -> &Workspace {
        &self.ws
    }

    /// Gravity in base-frame components at the last evaluated instant.
    pub(crate) fn gravity(&self) -> Vector3<f64> {
        self.gravity
    }

    /// Prescribes the motion of the base (rheonomic, (7.51)) as a function of time, or fixes
    /// the base again with `None`. The mechanism's gravity is then read in world components and
    /// turned into the base frame at each instant; everything else (points on the ground,
    /// reported vectors) is in base-frame components at the instant of evaluation. Refused for a
    /// mechanism with a steadily rotating frame, which already prescribes the base.
    pub fn set_base_motion(&mut self, motion: Option<Arc<dyn BaseMotion + Send + Sync>>) -> Result<(), DynamicsError> {
        if motion.is_some() && self.mechanism.rotating_frame().is_some() {
            return Err(DynamicsError::OutOfRange {
                what: "base motion of a mechanism in a rotating frame",
                requirement: "absent (the rotating frame already prescribes the base)",
                value: 1.0,
            });
        }
        self.base_motion = motion.map(PrescribedBase);
        Ok(())
    }

    /// True when a base motion is prescribed.
    pub fn has_base_motion(&self) -> bool {
        self.base_motion.is_some()
    }

    /// The base's state at time t in its own frame (pose at the origin, rates in base
    /// components), and gravity in the same frame.
    fn refresh_base(&mut self, t: f64) -> Result<(), DynamicsError> {
        let Some(motion) = &self.base_motion else { return Ok(()) };
        let world = motion.0.state_at(t);
        let r_t = world.rotation.inverse();
        let base = BaseState {
            omega: r_t * world.omega,
            velocity: r_t * world.velocity,
            omega_dot: r_t * world.omega_dot,
            acceleration: r_t * world.acceleration,
            ..BaseState::default()
        };
        self.ws.set_base(base)?;
        self.gravity = r_t * self.mechanism.gravity();
        crate::error::check_result(self.gravity.iter(), "gravity in the base frame")
    }

    /// Checks the state and runs forward kinematics to velocities, and refreshes the bodies'
    /// world inertias.
    pub(crate) fn update_state(&mut self, state: &State<'_>) -> Result<(), DynamicsError> {
        let n = self.dof();
        check_vector(state.q, n, "q")?;
        check_vector(state.q_dot, n, "q_dot")?;
        if !state.t.is_finite() {
            return Err(DynamicsError::NonFiniteInput {
                what: "time",
                index: 0,
                value: state.t,
            });
        }
        self.refresh_base(state.t)?;
        let tree = self.mechanism.tree();
        tree.update_positions(&mut self.ws, state.q)?;
        tree.update_velocities(&mut self.ws, state.q_dot)?;
        for (i, body) in self.mechanism.bodies().iter().enumerate() {
            self.world[i] = WorldInertia::new(body, self.ws.rotation(i)?.matrix());
        }
        Ok(())
    }
}

/// A prescribed base motion (a wrapper so that [`Dynamics`] can be `Debug`).
#[derive(Clone)]
struct PrescribedBase(Arc<dyn BaseMotion + Send + Sync>);

impl std::fmt::Debug for PrescribedBase {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("PrescribedBase")
    }
}

/// The base state at the instant of evaluation: at rest, or turning at Ω about the rotating
/// frame's axis with the base frame and the world aligned (R_W0 = I).
fn base_state(mechanism: &Mechanism) -> BaseState {
    match mechanism.rotating_frame() {
        Some(frame) => BaseState {
            rotation: Rotation3::identity(),
            omega: frame.axis.into_inner() * frame.rate,
            ..BaseState::default()
        },
        None => BaseState::default(),
    }
}
