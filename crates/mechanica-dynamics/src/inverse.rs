//! Inverse dynamics by the recursive Newton–Euler algorithm: the generalized forces τ that the
//! joints' actuators must apply for the mechanism to move with q̈ at (q, q̇),
//!
//!   τ = A(q) q̈ + c(q, q̇) + g(q) − Σ Q_loads,
//!
//! Lagrange's equations (7.60) solved for the applied forces, and the wrench each joint
//! transmits (the constraint reactions of FM 4.61 together with the joint's own force).
//!
//! **Forward pass** (kinematics crate): body velocities and accelerations, world components.
//! **Body wrenches**: each body needs the wrench K = m ẍ_C (7.15), M_C = J_C ω̇ + ω × J_C ω
//! (7.22), moved to its origin o_i (7.29); its weight and the loads on it supply part of it.
//! **Backward pass**: the joint of body i transmits W_i = (needed − applied)_i + Σ_children
//! W_c, each child's wrench moved to o_i (7.33–7.36: every freed body obeys the momentum
//! theorems with its reactions as loads). The power of W_i on the motion column (w_k, v_k) of
//! a coordinate k of joint i is the generalized force that the joint carries on k (4.35).
//!
//! Cost: O(n) for τ; the split into c, g and the loads' terms costs two more passes and one
//! per load.

use crate::error::{DynamicsError, check_result, check_vector};
use crate::loads::LoadTerm;
use crate::model::{Dynamics, State};
use crate::spatial::Wrench;
use nalgebra::{Matrix3, Vector3};

/// The transmitted wrenches per body, τ, and τ's rounding estimate per coordinate.
pub(crate) type JointForces = (Vec<Wrench>, Vec<f64>, Vec<f64>);

/// The frame in which a joint reaction is expressed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Frame {
    /// World (base-frame) components.
    World,
    /// The child body's frame B (the frame the joint moves).
    Body,
    /// The joint frame J fixed in the parent (the base frame for the root).
    Joint,
}

/// The wrench that the parent (or the base) exerts on a body through its joint, about the
/// joint origin o_i (the body frame's origin).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointReaction {
    /// The body whose joint it is.
    pub body: usize,
    /// The wrench about o_i, world components.
    pub wrench: Wrench,
}

/// The result of [`Dynamics::inverse_dynamics`].
#[derive(Debug, Clone, PartialEq)]
pub struct InverseDynamics {
    /// τ: the generalized forces the actuators apply (N or N·m per coordinate).
    pub tau: Vec<f64>,
    /// c(q, q̇): the velocity-product (Coriolis and centrifugal) terms, including those of a
    /// rotating frame; the τ needed at q̈ = 0 with no gravity and no loads.
    pub velocity_product: Vec<f64>,
    /// g(q) = ∂U_g/∂q: the generalized force that balances gravity (left-hand side sign).
    pub gravity: Vec<f64>,
    /// Each load's generalized force Q (right-hand side sign).
    pub loads: Vec<LoadTerm>,
    /// The dissipation function D = ½ q̇ᵀ C q̇ of the dampers, W (2D is the power they take).
    pub dissipation: f64,
    /// The wrench each joint transmits, one per body, about the joint origin.
    pub reactions: Vec<JointReaction>,
    /// First-order estimate of the rounding error of each τ_k: 16·(d + 4)·u times the sum of
    /// the magnitudes that τ_k is accumulated from (d the depth of the tree). An estimate, not
    /// a bound.
    pub error_estimate: Vec<f64>,
}

impl Dynamics {
    /// Writes τ_k = (power of the transmitted wrench on column k) after accumulating the
    /// per-body wrenches leaves-to-root: `wrenches` becomes the transmitted wrenches.
    pub(crate) fn accumulate_to_joints(&self, wrenches: &mut [Wrench], tau: &mut [f64]) -> Result<(), DynamicsError> {
        let tree = self.mechanism.tree();
        for &i in tree.topological_order().iter().rev() {
            for k in tree.dof_range(i) {
                let (w, v) = self.ws.motion_column(k)?;
                tau[k] = wrenches[i].power(&w, &v);
            }
            if let Some(p) = tree.parent(i) {
                let r = self.ws.parent_offset(i)?;
                let moved = wrenches[i].shifted_by(&r);
                wrenches[p] += moved;
            }
        }
        Ok(())
    }

    /// The generalized force Σ (power on each column) of wrenches applied to the bodies (4.35).
    pub(crate) fn generalized_force_of(&self, applied: &[Wrench]) -> Result<Vec<f64>, DynamicsError> {
        let mut wrenches = applied.to_vec();
        let mut q = vec![0.0; self.dof()];
        self.accumulate_to_joints(&mut wrenches, &mut q)?;
        Ok(q)
    }

    /// Fills `self.wrenches` with each body's needed wrench (momentum rates less weight, with
    /// `gravity`) from the accelerations in the workspace, less `self.loads` when `with_loads`.
    fn body_wrenches(&mut self, gravity: &Vector3<f64>, with_loads: bool) -> Result<(), DynamicsError> {
        for i in 0..self.world.len() {
            let (w, wd, a) = (
                self.ws.angular_velocity(i)?,
                self.ws.angular_acceleration(i)?,
                self.ws.origin_acceleration(i)?,
            );
            self.wrenches[i] = self.world[i].momentum_rate(&w, &wd, &a, gravity);
            if with_loads {
                self.wrenches[i] -= self.loads[i];
            }
        }
        Ok(())
    }

    /// τ = A q̈ + c + g − Σ Q into `tau_out`, allocating nothing when the mechanism has no loads
    /// besides gravity (the recursive Newton–Euler algorithm; see the module docs).
    pub fn rnea_into(
        &mut self,
        q: &[f64],
        q_dot: &[f64],
        q_ddot: &[f64],
        tau_out: &mut [f64],
    ) -> Result<(), DynamicsError> {
        let n = self.dof();
        check_vector(q_ddot, n, "q_ddot")?;
        if tau_out.len() != n {
            return Err(DynamicsError::WrongLength {
                what: "tau output",
                expected: n,
                got: tau_out.len(),
            });
        }
        self.rnea_at(&State::new(q, q_dot), q_ddot, tau_out)
    }

    /// τ at `state` (its time included) into `tau_out`, lengths already checked.
    pub(crate) fn rnea_at(
        &mut self,
        state: &State<'_>,
        q_ddot: &[f64],
        tau_out: &mut [f64],
    ) -> Result<(), DynamicsError> {
        self.update_state(state)?;
        self.rnea_state(state, q_ddot, false)?;
        let mut wrenches = std::mem::take(&mut self.wrenches);
        let result = self.accumulate_to_joints(&mut wrenches, tau_out);
        self.wrenches = wrenches;
        result?;
        for (t, j) in tau_out.iter_mut().zip(&self.joint_loads) {
            *t -= j;
        }
        check_result(tau_out.iter(), "joint force")
    }

    /// Accelerations, the loads, and the body wrenches at `state` and `q_ddot`, after
    /// [`Dynamics::update_state`] at the same state.
    pub(crate) fn rnea_state(
        &mut self,
        state: &State<'_>,
        q_ddot: &[f64],
        detail: bool,
    ) -> Result<(f64, Vec<LoadTerm>), DynamicsError> {
        self.mechanism.tree().update_accelerations(&mut self.ws, q_ddot)?;
        let loads = self.evaluate_loads(state, detail)?;
        let g = self.gravity();
        self.body_wrenches(&g, true)?;
        Ok(loads)
    }

    /// The inverse dynamics at `state` for the accelerations `q_ddot`, with the bias terms
    /// split, each load's generalized force, and the joint reactions (see [`InverseDynamics`]).
    /// The workspace is left with the positions, velocities and accelerations of this motion.
    pub fn inverse_dynamics(&mut self, state: &State<'_>, q_ddot: &[f64]) -> Result<InverseDynamics, DynamicsError> {
        let n = self.dof();
        check_vector(q_ddot, n, "q_ddot")?;
        // The split first, so that the workspace ends with the accelerations at q̈.
        self.update_state(state)?;
        let velocity_product = self.velocity_product_terms()?;
        let gravity = self.gravity_terms()?;
        let (dissipation, loads) = self.rnea_state(state, q_ddot, true)?;
        let (transmitted, tau, error_estimate) = self.joint_forces_with_estimate(q_ddot)?;
        let reactions = transmitted
            .iter()
            .enumerate()
            .map(|(body, wrench)| JointReaction { body, wrench: *wrench })
            .collect();
        Ok(InverseDynamics {
            tau,
            velocity_product,
            gravity,
            loads,
            dissipation,
            reactions,
            error_estimate,
        })
    }

    /// 16·(d + 4)·u with d the depth of the tree: the factor of the rounding estimate.
    pub(crate) fn estimate_factor(&self) -> f64 {
        let tree = self.tree();
        let depth = (0..tree.body_count()).filter_map(|i| tree.depth(i)).max().unwrap_or(0);
        16.0 * (depth as f64 + 4.0) * f64::EPSILON
    }

    /// From the body wrenches of the last `rnea_state` at `q_ddot`: the transmitted wrenches, τ
    /// and its rounding estimate per coordinate (see [`InverseDynamics::error_estimate`]).
    pub(crate) fn joint_forces_with_estimate(&self, q_ddot: &[f64]) -> Result<JointForces, DynamicsError> {
        let mut transmitted = self.wrenches.clone();
        let mut tau = vec![0.0; self.dof()];
        self.accumulate_to_joints(&mut transmitted, &mut tau)?;
        let magnitudes = self.magnitudes(q_ddot)?;
        for (t, j) in tau.iter_mut().zip(&self.joint_loads) {
            *t -= j;
        }
        let factor = self.estimate_factor();
        let error_estimate = magnitudes
            .iter()
            .zip(&self.joint_loads)
            .map(|(m, j)| factor * (m + j.abs()))
            .collect();
        check_result(tau.iter(), "joint force")?;
        Ok((transmitted, tau, error_estimate))
    }

    /// c(q, q̇): the needed forces at q̈ = 0 without gravity or loads (positions and
    /// velocities in place).
    fn velocity_product_terms(&mut self) -> Result<Vec<f64>, DynamicsError> {
        let n = self.dof();
        let zeros = vec![0.0; n];
        self.mechanism.tree().update_accelerations(&mut self.ws, &zeros)?;
        self.body_wrenches(&Vector3::zeros(), false)?;
        let mut wrenches = self.wrenches.clone();
        let mut c = vec![0.0; n];
        self.accumulate_to_joints(&mut wrenches, &mut c)?;
        Ok(c)
    }

    /// g(q) = −Σ J_Cᵀ m g, the generalized force that balances the weights (positions in place).
    fn gravity_terms(&self) -> Result<Vec<f64>, DynamicsError> {
        let g = self.gravity();
        let weights: Vec<Wrench> = self
            .world
            .iter()
            .map(|body| Wrench::of_force_at(-g * body.mass, &body.c))
            .collect();
        self.generalized_force_of(&weights)
    }

    /// Per coordinate, the scale of τ_k's rounding: the products of the norms of everything the
    /// transmitted wrench is summed from (a running-error estimate). Body motions enter by the
    /// sums of magnitudes of the terms they are accumulated from ([`Dynamics::motion_magnitudes`]),
    /// not by their computed values, which cancel when joint rates or accelerations of opposite
    /// signs nearly annul each other. The norms are 1-norms: they bound the Euclidean ones and,
    /// unlike a sum of squares, neither underflow for forces near 1e-300 nor overflow near
    /// 1e200. Needs the accelerations of the last `rnea_state` at `q_ddot` in the workspace and
    /// the loads in `self.loads`.
    fn magnitudes(&self, q_ddot: &[f64]) -> Result<Vec<f64>, DynamicsError> {
        let tree = self.mechanism.tree();
        let g = self.gravity().lp_norm(1);
        let motion = self.motion_magnitudes(q_ddot)?;
        let bodies = self.world.len();
        let (mut f_mag, mut m_mag) = (vec![0.0; bodies], vec![0.0; bodies]);
        for (i, body) in self.world.iter().enumerate() {
            let MotionMagnitude { w, wd, a, .. } = motion[i];
            let c = body.c.lp_norm(1);
            f_mag[i] = body.mass * (a + (wd + w * w) * c + g) + self.loads[i].force.lp_norm(1);
            m_mag[i] = body.inertia_c.lp_norm(1) * (wd + w * w) + c * f_mag[i] + self.loads[i].moment.lp_norm(1);
        }
        let mut out = vec![0.0; self.dof()];
        for &i in tree.topological_order().iter().rev() {
            for k in tree.dof_range(i) {
                let (w, v) = self.ws.motion_column(k)?;
                out[k] = w.lp_norm(1) * m_mag[i] + v.lp_norm(1) * f_mag[i];
            }
            if let Some(p) = tree.parent(i) {
                let r = self.ws.parent_offset(i)?.lp_norm(1);
                m_mag[p] += m_mag[i] + r * f_mag[i];
                f_mag[p] += f_mag[i];
            }
        }
        Ok(out)
    }

    /// Per body, the sums of the 1-norms of the terms that the forward recursion adds into its
    /// angular velocity ω, origin velocity v, angular acceleration ω̇ and origin acceleration a
    /// (the base's own motion, each joint's columns times |q̇_k| and |q̈_k|, and the transport
    /// terms ω̇_P × r and ω_P × (v − v_P)), using |x × y|₁ ≤ |x|₁|y|₁. They bound the computed
    /// vectors' sizes and set the scale of their rounding.
    fn motion_magnitudes(&self, q_ddot: &[f64]) -> Result<Vec<MotionMagnitude>, DynamicsError> {
        let tree = self.mechanism.tree();
        let base = self.ws.base();
        let at_base = MotionMagnitude {
            w: base.omega.lp_norm(1),
            v: base.velocity.lp_norm(1),
            wd: base.omega_dot.lp_norm(1),
            a: base.acceleration.lp_norm(1),
        };
        let q_dot = self.ws.q_dot();
        let mut out = vec![at_base; self.world.len()];
        for &b in tree.topological_order() {
            let parent = tree.parent(b).map_or(at_base, |p| out[p]);
            let r = self.ws.parent_offset(b)?.lp_norm(1);
            let mut m = MotionMagnitude {
                w: parent.w,
                v: parent.v + parent.w * r,
                wd: parent.wd,
                a: parent.a + parent.wd * r,
            };
            for k in tree.dof_range(b) {
                let (cw, cv) = self.ws.motion_column(k)?;
                let (dw, dv) = self.ws.motion_column_rate(k)?;
                let (rate, acceleration) = (q_dot[k].abs(), q_ddot[k].abs());
                m.w += cw.lp_norm(1) * rate;
                m.v += cv.lp_norm(1) * rate;
                m.wd += dw.lp_norm(1) * rate + cw.lp_norm(1) * acceleration;
                m.a += dv.lp_norm(1) * rate + cv.lp_norm(1) * acceleration;
            }
            // ω_P × (v − v_P), with v − v_P formed from the two computed velocities.
            m.a += parent.w * (m.v + parent.v);
            out[b] = m;
        }
        Ok(out)
    }
}

/// Sums of the magnitudes of the terms of one body's ω, v, ω̇ and a
/// ([`Dynamics::motion_magnitudes`]).
#[derive(Debug, Clone, Copy)]
struct MotionMagnitude {
    w: f64,
    v: f64,
    wd: f64,
    a: f64,
}

impl JointReaction {
    /// The reaction's force and moment (about the joint origin) in `frame`, using the poses in
    /// `dynamics`'s workspace from its last evaluation.
    pub fn expressed_in(&self, dynamics: &Dynamics, frame: Frame) -> Result<Wrench, DynamicsError> {
        let r: Matrix3<f64> = match frame {
            Frame::World => Matrix3::identity(),
            Frame::Body => *dynamics.ws.rotation(self.body)?.matrix(),
            Frame::Joint => {
                let tree = dynamics.tree();
                let (r_pj, _) = tree.placement(self.body).ok_or(DynamicsError::NoSuchBody {
                    what: "joint reaction",
                    body: self.body,
                    bodies: tree.body_count(),
                })?;
                let r_wp = match tree.parent(self.body) {
                    Some(p) => *dynamics.ws.rotation(p)?.matrix(),
                    None => *dynamics.ws.base().rotation.matrix(),
                };
                r_wp * r_pj
            }
        };
        Ok(Wrench {
            force: r.transpose() * self.wrench.force,
            moment: r.transpose() * self.wrench.moment,
        })
    }
}
