//! Forward dynamics: q̈ = A(q)⁻¹ (τ + Σ Q_loads − c(q, q̇) − g(q)), Lagrange's equations (7.60)
//! solved for the accelerations, by the articulated-body algorithm in O(n).
//!
//! The recursion works in world components about each body's origin (see
//! [`crate::articulated`]). With the spatial acceleration (ω̇, a_o) of each body's origin,
//! body i obeys A_i = X A_parent + S_i q̈_i + c_i, where X moves a motion from the parent's
//! origin, S_i holds the joint's motion columns and c_i the velocity-product terms of
//! [`mechanica_kinematics::tree`]'s acceleration update. Leaves to root, the articulated
//! inertia I^A and bias p^A of each subtree are condensed onto the joint
//! (I^a = I^A − U D⁻¹ Uᵀ, p^a = p^A + I^a c + U D⁻¹ u, with U = I^A S, D = Sᵀ I^A S and
//! u = τ − Sᵀ p^A); root to leaves, q̈_i = D⁻¹ (u − Uᵀ (X A_parent + c_i)).
//!
//! Accuracy: [`Dynamics::forward_dynamics`] checks its q̈ by the inverse dynamics and reports
//! the residual r = τ − RNEA(q, q̇, q̈) and the backward error ‖r‖∞ / scale (the smallest
//! relative change of the forces that makes q̈ exact, up to the rounding of the check). A
//! forward error needs the conditioning of A: [`Dynamics::forward_dynamics_crba`] solves the
//! same equations by the composite-rigid-body mass matrix and Cholesky and reports
//! κ∞(A) and the first-order error estimate κ∞(A)·η·‖q̈‖∞.
//!
//! The articulated-body recursion is not backward stable when the inertias of a tree are
//! graded: condensing a heavy subtree onto a light joint (I^A − U D⁻¹ Uᵀ) cancels, and its
//! backward error grows roughly like u times the mass ratio (about 1e-9 at a ratio of 1e9 on
//! random trees), up to articulated inertias that lose definiteness. The composite-rigid-body
//! route with Cholesky is backward stable at every grading. So [`Dynamics::forward_dynamics`]
//! accepts the recursion's q̈ only when its backward error is at the rounding level of the
//! check, 16·(d + 4)·u, and no joint's articulated pivot is below √u times the inertia of the
//! subtree it moves (a point mass on or near its joint's axis, or joints that together move
//! nothing: A(q) is then ill-conditioned and the backward error says nothing of the forward
//! one), and otherwise solves by the mass matrix, whose report gives κ∞(A) and the forward
//! error estimate; [`ForwardMethod`] says which. Both recursions refuse a pivot below 8u times
//! |s|ᵀ|Iᴬ||s|, the magnitude it was summed from.

use crate::articulated::{
    body_inertia, invert_spd_block, motion_vector, shifted_inertia, shifted_motion, shifted_wrench, wrench_vector,
};
use crate::error::{DynamicsError, check_result, check_vector};
use crate::model::{Dynamics, State};
use nalgebra::{Vector3, Vector6};

/// The smallest ratio of an articulated pivot to the subtree inertia behind it
/// ([`Dynamics::has_weak_pivot`]) at which the checked forward dynamics keeps the articulated
/// body's q̈: √u. Below it A(q) has a condition number above 1/√u, and the mass-matrix route
/// reports it with a forward error estimate.
const WEAK_PIVOT: f64 = 1.490_116_119_384_765_6e-8;

/// The route that produced q̈.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ForwardMethod {
    /// The articulated-body recursion, O(n).
    ArticulatedBody,
    /// The composite-rigid-body mass matrix and Cholesky, O(n³).
    MassMatrix,
}

/// The result of [`Dynamics::forward_dynamics`] and [`Dynamics::forward_dynamics_crba`].
#[derive(Debug, Clone, PartialEq)]
pub struct ForwardDynamics {
    /// q̈, rad/s² or m/s² per coordinate.
    pub q_ddot: Vec<f64>,
    /// The route that produced q̈.
    pub method: ForwardMethod,
    /// r = τ − RNEA(q, q̇, q̈): the residual of the equations of motion at the computed q̈.
    pub residual: Vec<f64>,
    /// ‖r‖∞ / max(max_k scale_k, λ): the relative backward error, with scale_k the magnitude
    /// of the terms that the inverse dynamics sums into τ_k (see
    /// `InverseDynamics::error_estimate`) and λ = f64::MIN_POSITIVE, the smallest normal number
    /// (below it the spacing of doubles is absolute).
    pub backward_error: f64,
    /// κ∞(A) = ‖A‖∞ ‖A⁻¹‖∞, when the mass matrix was formed (the CRBA route).
    pub condition: Option<f64>,
    /// The first-order estimate ‖A⁻¹‖∞ (‖r‖∞ + ρ) / (1 − n·κ∞·u) of the error of q̈ (∞-norm),
    /// ρ the largest rounding estimate of the inverse dynamics that evaluated r and ‖A⁻¹‖∞ that
    /// of the computed Cholesky factor (the division allows for its error); when the mass
    /// matrix was formed. +∞ when n·κ∞·u ≥ 1/2: A is singular to working precision and q̈
    /// may have no correct digit.
    pub error_estimate: Option<f64>,
    /// The dissipation function D of the dampers, W.
    pub dissipation: f64,
}

impl Dynamics {
    /// Articulated inertia, bias wrench and acceleration bias of every body, from the state in
    /// the workspace and the loads.
    fn init_articulated(&mut self) -> Result<(), DynamicsError> {
        let tree = self.mechanism.tree();
        let g = self.gravity();
        let base = *self.ws.base();
        for i in 0..self.world.len() {
            let w = self.ws.angular_velocity(i)?;
            let mut bias = self.world[i].momentum_rate(&w, &Vector3::zeros(), &Vector3::zeros(), &g);
            bias -= self.loads[i];
            self.articulated.inertia[i] = body_inertia(&self.world[i]);
            self.articulated.bias[i] = wrench_vector(&bias);
            let (w_p, v_p) = match tree.parent(i) {
                Some(p) => (self.ws.angular_velocity(p)?, self.ws.origin_velocity(p)?),
                None => (base.omega, base.velocity),
            };
            let mut c_w = Vector3::zeros();
            let mut c_v = w_p.cross(&(self.ws.origin_velocity(i)? - v_p));
            for k in tree.dof_range(i) {
                let (wd, vd) = self.ws.motion_column_rate(k)?;
                c_w += wd * self.ws.q_dot()[k];
                c_v += vd * self.ws.q_dot()[k];
            }
            self.articulated.accel_bias[i] = motion_vector(&c_w, &c_v);
        }
        Ok(())
    }

    /// Leaves to root: U, D⁻¹ and u of every joint, condensing each subtree onto its parent.
    fn condense(&mut self, tau: &[f64]) -> Result<(), DynamicsError> {
        let order: Vec<usize> = self
            .mechanism
            .tree()
            .topological_order()
            .iter()
            .rev()
            .copied()
            .collect();
        for i in order {
            let range = self.mechanism.tree().dof_range(i);
            let (start, dim) = (range.start, range.len());
            let ia = self.articulated.inertia[i];
            let pa = self.articulated.bias[i];
            let mut d = nalgebra::Matrix6::zeros();
            // The pivots are refused below 8u·|s|ᵀ|Iᴬ||s|, the size of their rounding (what
            // sᵀIᴬs is summed from). That magnitude is formed only when a pivot fails against
            // its cheap bound ‖s‖₁²·max_k Iᴬ_kk (|Iᴬ_kl| ≤ max_k Iᴬ_kk for a semidefinite Iᴬ).
            let diagonal_largest = (0..6).map(|k| ia[(k, k)].abs()).fold(0.0_f64, f64::max);
            let mut bound = 0.0_f64;
            for (a, k) in range.clone().enumerate() {
                let (w, v) = self.ws.motion_column(k)?;
                let s = motion_vector(&w, &v);
                let u = ia * s;
                bound = bound.max(s.lp_norm(1).powi(2) * diagonal_largest);
                self.articulated.u_columns[k] = u;
                self.articulated.u_force[k] = tau[k] + self.joint_loads[k] - s.dot(&pa);
                for (b, l) in range.clone().enumerate() {
                    let (wl, vl) = self.ws.motion_column(l)?;
                    d[(b, a)] = motion_vector(&wl, &vl).dot(&u);
                }
            }
            let d_inv = match invert_spd_block(&d, dim, bound) {
                Ok(d_inv) => d_inv,
                Err(_) => invert_spd_block(&d, dim, self.pivot_magnitude(i, &ia)?).map_err(|(pivot, scale)| {
                    DynamicsError::SingularArticulatedInertia {
                        body: i,
                        first_coordinate: start,
                        pivot,
                        scale,
                    }
                })?,
            };
            self.articulated.d_inverse[i] = d_inv;
            let Some(p) = self.mechanism.tree().parent(i) else {
                continue;
            };
            let mut i_small = ia;
            let mut p_small = pa + ia * self.articulated.accel_bias[i];
            for a in 0..dim {
                let ua = self.articulated.u_columns[start + a];
                for b in 0..dim {
                    let ub = self.articulated.u_columns[start + b];
                    i_small -= ua * ub.transpose() * d_inv[(a, b)];
                    p_small += ua * (d_inv[(a, b)] * self.articulated.u_force[start + b]);
                }
            }
            // p^a = p^A + I^a c + U D⁻¹ u: the I^a c term uses the condensed inertia.
            for a in 0..dim {
                let ua = self.articulated.u_columns[start + a];
                for b in 0..dim {
                    let ub = self.articulated.u_columns[start + b];
                    p_small -= ua * (d_inv[(a, b)] * ub.dot(&self.articulated.accel_bias[i]));
                }
            }
            let r = self.ws.parent_offset(i)?;
            self.articulated.inertia[p] += shifted_inertia(&i_small, &r);
            self.articulated.bias[p] += shifted_wrench(&p_small, &r);
        }
        Ok(())
    }

    /// max_a |s_a|ᵀ|Iᴬ||s_a| over the motion columns s_a of body `i`'s joint, for its
    /// articulated inertia `ia`: the magnitude its pivots are summed from.
    fn pivot_magnitude(&self, i: usize, ia: &nalgebra::Matrix6<f64>) -> Result<f64, DynamicsError> {
        let mut magnitude = 0.0_f64;
        for k in self.mechanism.tree().dof_range(i) {
            let (w, v) = self.ws.motion_column(k)?;
            let s = motion_vector(&w, &v).abs();
            magnitude = magnitude.max(s.dot(&(ia.abs() * s)));
        }
        Ok(magnitude)
    }

    /// Root to leaves: q̈ of every joint and the spatial accelerations.
    fn propagate(&mut self, q_ddot: &mut [f64]) -> Result<(), DynamicsError> {
        let base = *self.ws.base();
        let base_accel = motion_vector(&base.omega_dot, &base.acceleration);
        let order: Vec<usize> = self.mechanism.tree().topological_order().to_vec();
        for i in order {
            let parent_accel = match self.mechanism.tree().parent(i) {
                Some(p) => self.articulated.acceleration[p],
                None => base_accel,
            };
            let r = self.ws.parent_offset(i)?;
            let mut accel = shifted_motion(&parent_accel, &r) + self.articulated.accel_bias[i];
            let range = self.mechanism.tree().dof_range(i);
            let (start, dim) = (range.start, range.len());
            let d_inv = self.articulated.d_inverse[i];
            let mut rhs = Vector6::zeros();
            for a in 0..dim {
                rhs[a] = self.articulated.u_force[start + a] - self.articulated.u_columns[start + a].dot(&accel);
            }
            for a in 0..dim {
                q_ddot[start + a] = (0..dim).map(|b| d_inv[(a, b)] * rhs[b]).sum();
            }
            for k in range {
                let (w, v) = self.ws.motion_column(k)?;
                accel += motion_vector(&w, &v) * q_ddot[k];
            }
            self.articulated.acceleration[i] = accel;
        }
        Ok(())
    }

    /// q̈ for the applied forces `tau` at (q, q̇) and t = 0, into `q_ddot_out`, by the
    /// articulated-body algorithm (module docs); allocates nothing when the mechanism has no loads besides
    /// gravity. When an articulated inertia is singular to working precision (strongly graded
    /// trees), it solves by the mass matrix instead, which allocates. No accuracy report, and
    /// the backward error grows with the grading: see [`Dynamics::forward_dynamics`]. On an
    /// error the contents of `q_ddot_out` are unspecified.
    pub fn aba_into(
        &mut self,
        q: &[f64],
        q_dot: &[f64],
        tau: &[f64],
        q_ddot_out: &mut [f64],
    ) -> Result<(), DynamicsError> {
        self.aba_state_into(&State::new(q, q_dot), tau, q_ddot_out)
    }

    /// As [`Dynamics::aba_into`] at the time of `state` (read by a prescribed base motion and
    /// by time-dependent velocity potentials).
    pub fn aba_state_into(
        &mut self,
        state: &State<'_>,
        tau: &[f64],
        q_ddot_out: &mut [f64],
    ) -> Result<(), DynamicsError> {
        let n = self.dof();
        check_vector(tau, n, "tau")?;
        if q_ddot_out.len() != n {
            return Err(DynamicsError::WrongLength {
                what: "q_ddot output",
                expected: n,
                got: q_ddot_out.len(),
            });
        }
        match self.aba_state(state, tau, q_ddot_out) {
            Err(DynamicsError::SingularArticulatedInertia { .. }) => {
                let solved = self.forward_dynamics_crba(state, tau)?;
                q_ddot_out.copy_from_slice(&solved.q_ddot);
                Ok(())
            }
            other => other.map(|_| ()),
        }
    }

    fn aba_state(&mut self, state: &State<'_>, tau: &[f64], q_ddot: &mut [f64]) -> Result<f64, DynamicsError> {
        self.update_state(state)?;
        let (dissipation, _) = self.evaluate_loads(state, false)?;
        self.init_articulated()?;
        self.condense(tau)?;
        self.propagate(q_ddot)?;
        check_result(q_ddot.iter(), "joint acceleration")?;
        Ok(dissipation)
    }

    /// q̈ for the applied forces `tau` at `state`: by the articulated-body algorithm when the
    /// inverse dynamics confirms it to the rounding level and A(q) is not ill-conditioned by
    /// the articulated pivots' measure, by the mass matrix otherwise (module docs). Fails with
    /// [`DynamicsError::SingularMassMatrix`] when A(q) is singular.
    pub fn forward_dynamics(&mut self, state: &State<'_>, tau: &[f64]) -> Result<ForwardDynamics, DynamicsError> {
        let n = self.dof();
        check_vector(tau, n, "tau")?;
        let mut q_ddot = vec![0.0; n];
        match self.aba_state(state, tau, &mut q_ddot) {
            Ok(dissipation) => {
                let (residual, backward_error, _) = self.residual_of(state, tau, &q_ddot)?;
                if backward_error <= self.estimate_factor() && !self.has_weak_pivot()? {
                    return Ok(ForwardDynamics {
                        q_ddot,
                        method: ForwardMethod::ArticulatedBody,
                        residual,
                        backward_error,
                        condition: None,
                        error_estimate: None,
                        dissipation,
                    });
                }
            }
            Err(DynamicsError::SingularArticulatedInertia { .. }) => {}
            Err(other) => return Err(other),
        }
        self.forward_dynamics_crba(state, tau)
    }

    /// Whether some joint's articulated pivot, 1/(D⁻¹)_aa of the last recursion, is below
    /// [`WEAK_PIVOT`] times sᵀIᶜs, the composite rigid inertia of the subtree it moves along
    /// that motion column s = (w, v), with Iᶜ the subtree's spatial inertia about the joint's
    /// body origin (the bodies' inertias shifted and summed, as the composite-rigid-body
    /// algorithm does): the diagonal entry A_kk of the mass matrix. The pivots are those of an LDLᵀ of A(q)
    /// (eliminated from the leaves), each at least λ_min(A), and A_kk ≤ λ_max(A): a ratio below
    /// √u means κ₂(A) above 1/√u (a point mass near its joint's axis, or joints that together
    /// move nothing), where a small backward error says nothing of the forward error.
    fn has_weak_pivot(&self) -> Result<bool, DynamicsError> {
        let tree = self.mechanism.tree();
        let mut composite: Vec<nalgebra::Matrix6<f64>> = self.world.iter().map(body_inertia).collect();
        for &i in tree.topological_order().iter().rev() {
            let d_inverse = &self.articulated.d_inverse[i];
            for (a, k) in tree.dof_range(i).enumerate() {
                let (w, v) = self.ws.motion_column(k)?;
                let s = motion_vector(&w, &v);
                let pivot = 1.0 / d_inverse[(a, a)];
                if pivot.is_nan() || pivot <= WEAK_PIVOT * s.dot(&(composite[i] * s)) {
                    return Ok(true);
                }
            }
            if let Some(p) = tree.parent(i) {
                let shifted = shifted_inertia(&composite[i], &self.ws.parent_offset(i)?);
                composite[p] += shifted;
            }
        }
        Ok(false)
    }

    /// r = τ − RNEA(q, q̇, q̈), the backward error ‖r‖∞ / max scale, and the largest rounding
    /// estimate of the inverse dynamics that evaluated r.
    pub(crate) fn residual_of(
        &mut self,
        state: &State<'_>,
        tau: &[f64],
        q_ddot: &[f64],
    ) -> Result<(Vec<f64>, f64, f64), DynamicsError> {
        // τ and its rounding estimate only: the split of the full inverse dynamics is not needed.
        self.update_state(state)?;
        self.rnea_state(state, q_ddot, false)?;
        let (_, check_tau, check_estimate) = self.joint_forces_with_estimate(q_ddot)?;
        let residual: Vec<f64> = tau.iter().zip(&check_tau).map(|(t, c)| t - c).collect();
        let scale = check_estimate
            .iter()
            .zip(tau)
            .map(|(e, t)| e / self.estimate_factor() + t.abs())
            .fold(0.0, f64::max);
        let norm = residual.iter().fold(0.0f64, |m, r| m.max(r.abs()));
        // Below the normal range the absolute spacing, not a relative one, limits every term.
        let eta = norm / scale.max(f64::MIN_POSITIVE);
        let rounding = check_estimate.iter().fold(0.0f64, |m, e| m.max(*e));
        Ok((residual, eta, rounding))
    }
}
