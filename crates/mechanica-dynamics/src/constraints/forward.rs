//! Forward dynamics with multipliers: [A Jᵀ; J 0] [q̈; λ] = [τ + Q − h; γ].
//!
//! **Solve.** A = LLᵀ (composite-rigid-body mass matrix, Cholesky), Y = A⁻¹Jᵀ and the Schur
//! complement S = J Y factored in the order of the equations with the redundancy test of
//! [`super::schur`]; then z = A⁻¹(τ + Q − h), λ = S⁻¹(J z − γ), q̈ = z − Y λ, so that
//! J q̈ = γ. One step of iterative refinement on the full system follows (the same factors,
//! residuals with A and J as formed), which brings the backward error to the rounding level
//! unless A or S is extremely ill-conditioned.
//!
//! **Accuracy report.** The residual r = [τ + Q − h − A q̈ − Jᵀλ; γ − J q̈] and its row-wise
//! backward error η: each |r_i| against the size of the terms of its row, with q̈ measured by
//! s = max(‖q̈‖∞, ‖A⁻¹(τ + Q − h)‖∞) (a q̈_k that should vanish, or a linkage held at rest by
//! its constraints, is judged against the accelerations the forces would cause) and each λ_r
//! by itself (the multipliers of different constraints carry different units):
//! η = max over rows of |r_k| / (Σ_l |A_kl| s + Σ_r |J_rk λ_r| + |b_k|) and
//! |r_r| / (Σ_k |J_rk| s + |γ_r|), with κ∞(A) and κ∞(S). The forward error of q̈ and λ is
//! roughly η times the conditioning of the KKT matrix, which grows with κ(A)·κ(S).
//!
//! **Drift.** f(q) and J q̇ are not zero along a numerically integrated motion; the report
//! gives ‖f‖₂ and ‖J q̇‖₂ (mixed units when rows mix lengths and angles).
//! [`Baumgarte`] stabilisation replaces γ by γ − 2α J q̇ − β² f, so that the constraint error
//! obeys ë + 2α ė + β² e = 0 instead of ë = 0 (drift decays instead of growing linearly). It is
//! off by default: it changes the accelerations of any state that is off the constraint
//! manifold, so the q̈ of such a state is no longer the exact one, and its gains depend on the
//! step size of the integrator; [`super::ConstrainedDynamics::project_positions`] and
//! [`super::ConstrainedDynamics::project_velocities`] are the exact alternative.

use super::ConstrainedDynamics;
use super::evaluate::Evaluated;
use super::reactions::{ConstraintReaction, reactions};
use super::schur::{Metric, Schur};
use crate::error::{DynamicsError, check_input, check_result, check_vector};
use crate::model::State;
use faer::Mat;

/// Baumgarte gains α, β (1/s): the constraint error e = f(q) obeys ë + 2α ė + β² e = 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Baumgarte {
    /// α ≥ 0, 1/s.
    pub alpha: f64,
    /// β ≥ 0, 1/s.
    pub beta: f64,
}

impl Baumgarte {
    pub(crate) fn validate(&self) -> Result<(), DynamicsError> {
        check_input(&[self.alpha, self.beta], "Baumgarte gains")?;
        for (what, value) in [("Baumgarte alpha", self.alpha), ("Baumgarte beta", self.beta)] {
            if value < 0.0 {
                return Err(DynamicsError::OutOfRange {
                    what,
                    requirement: "≥ 0",
                    value,
                });
            }
        }
        Ok(())
    }
}

/// The result of [`ConstrainedDynamics::forward_dynamics`].
#[derive(Debug, Clone, PartialEq)]
pub struct ConstrainedForward {
    /// q̈ per coordinate.
    pub q_ddot: Vec<f64>,
    /// λ, one per equation (see the sign convention of [`super`]).
    pub multipliers: Vec<f64>,
    /// Each constraint's reaction.
    pub reactions: Vec<ConstraintReaction>,
    /// ‖f(q)‖₂.
    pub position_drift: f64,
    /// ‖J q̇‖₂.
    pub velocity_drift: f64,
    /// The KKT residual r (n entries of forces, then m of constraint accelerations).
    pub residual: Vec<f64>,
    /// The row-wise backward error η of the KKT solve (module docs).
    pub backward_error: f64,
    /// s = max(‖q̈‖∞, ‖A⁻¹(τ + Q − h)‖∞): the size of q̈ in η.
    pub acceleration_scale: f64,
    /// κ∞(A).
    pub mass_condition: f64,
    /// κ∞(J A⁻¹ Jᵀ).
    pub schur_condition: f64,
}

/// [q̈; λ] of the KKT system for the right-hand side [r1; r2] with the factors at hand.
fn kkt_solve(metric: &Metric, schur: &Schur, j: &Mat<f64>, r1: &[f64], r2: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let z = metric.solve(&Mat::from_fn(r1.len(), 1, |k, _| r1[k]));
    let jz: Vec<f64> = (0..j.nrows())
        .map(|r| (0..j.ncols()).map(|k| j[(r, k)] * z[(k, 0)]).sum::<f64>() - r2[r])
        .collect();
    let lambda = schur.solve(&jz);
    let x = (0..r1.len())
        .map(|k| z[(k, 0)] - (0..lambda.len()).map(|r| schur.y[(k, r)] * lambda[r]).sum::<f64>())
        .collect();
    (x, lambda)
}

/// The KKT system's data: A, J, the right-hand side [b; γ].
struct Kkt<'a> {
    a: &'a Mat<f64>,
    j: &'a Mat<f64>,
    b: &'a [f64],
    gamma: &'a [f64],
    /// ‖A⁻¹ b‖∞, the unconstrained acceleration.
    acceleration_scale: f64,
}

impl Kkt<'_> {
    /// The residual [b − A x − Jᵀλ; γ − J x] and its row-wise backward error (module docs).
    fn residual(&self, x: &[f64], lambda: &[f64]) -> (Vec<f64>, f64) {
        let (n, m) = (x.len(), lambda.len());
        let x_norm = x.iter().fold(self.acceleration_scale, |a, v| a.max(v.abs()));
        let mut r = Vec::with_capacity(n + m);
        let mut eta = 0.0f64;
        let mut ratio = |residual: f64, size: f64| {
            let value = if residual == 0.0 { 0.0 } else { residual.abs() / size };
            eta = eta.max(if value.is_nan() { f64::INFINITY } else { value });
        };
        for k in 0..n {
            let (mut value, mut size) = (self.b[k], self.b[k].abs());
            for l in 0..n {
                value -= self.a[(k, l)] * x[l];
                size += self.a[(k, l)].abs() * x_norm;
            }
            for (row, l) in lambda.iter().enumerate() {
                value -= self.j[(row, k)] * l;
                size += (self.j[(row, k)] * l).abs();
            }
            ratio(value, size);
            r.push(value);
        }
        for row in 0..m {
            let (mut value, mut size) = (self.gamma[row], self.gamma[row].abs());
            for (k, xk) in x.iter().enumerate() {
                value -= self.j[(row, k)] * xk;
                size += self.j[(row, k)].abs() * x_norm;
            }
            ratio(value, size);
            r.push(value);
        }
        (r, eta)
    }
}

impl ConstrainedDynamics {
    /// γ, or its Baumgarte-stabilised form γ − 2α J q̇ − β² f.
    fn stabilised_bias(&self, evaluated: &Evaluated) -> Vec<f64> {
        let Some(Baumgarte { alpha, beta }) = self.baumgarte else {
            return evaluated.bias.clone();
        };
        (0..evaluated.equations())
            .map(|r| evaluated.bias[r] - 2.0 * alpha * evaluated.velocity[r] - beta * beta * evaluated.value[r])
            .collect()
    }

    /// q̈, λ, the reactions, the drift and the accuracy report at `state` for the applied
    /// forces `tau` (module docs). Errors: wrong lengths or non-finite inputs, a singular mass
    /// matrix, [`DynamicsError::RedundantConstraint`] for the first equation that depends on
    /// the earlier ones, non-finite results.
    pub fn forward_dynamics(&mut self, state: &State<'_>, tau: &[f64]) -> Result<ConstrainedForward, DynamicsError> {
        let n = self.dof();
        check_vector(tau, n, "tau")?;
        let evaluated = self.evaluate(state.q, state.q_dot)?;
        let h = self.dynamics.inverse_dynamics(state, &vec![0.0; n])?.tau;
        let b: Vec<f64> = tau.iter().zip(&h).map(|(t, h)| t - h).collect();
        let metric = Metric::new(self.dynamics.mass_matrix(state.q)?)?;
        let schur = Schur::new(&metric, &evaluated, self.pivot_tolerance).map_err(|r| self.redundant(r))?;
        let gamma = self.stabilised_bias(&evaluated);
        let unconstrained = metric.solve(&Mat::from_fn(n, 1, |k, _| b[k]));
        let kkt = Kkt {
            a: metric.matrix(),
            j: &evaluated.jacobian,
            b: &b,
            gamma: &gamma,
            acceleration_scale: (0..n).fold(0.0f64, |m, k| m.max(unconstrained[(k, 0)].abs())),
        };
        let (mut q_ddot, mut lambda) = kkt_solve(&metric, &schur, kkt.j, &b, &gamma);
        let (r, _) = kkt.residual(&q_ddot, &lambda);
        let (dq, dl) = kkt_solve(&metric, &schur, kkt.j, &r[..n], &r[n..]);
        q_ddot.iter_mut().zip(&dq).for_each(|(x, d)| *x += d);
        lambda.iter_mut().zip(&dl).for_each(|(x, d)| *x += d);
        check_result(q_ddot.iter().chain(&lambda), "constrained acceleration")?;
        let (residual, backward_error) = kkt.residual(&q_ddot, &lambda);
        Ok(ConstrainedForward {
            reactions: reactions(&evaluated, &lambda),
            position_drift: norm2(&evaluated.value),
            velocity_drift: norm2(&evaluated.velocity),
            residual,
            backward_error,
            acceleration_scale: q_ddot.iter().fold(kkt.acceleration_scale, |m, x| m.max(x.abs())),
            mass_condition: metric.condition(),
            schur_condition: schur.condition(),
            q_ddot,
            multipliers: lambda,
        })
    }
}

/// ‖v‖₂.
pub(crate) fn norm2(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}
