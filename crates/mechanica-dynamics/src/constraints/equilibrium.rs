//! Equilibria of a constrained mechanism (FM 4.83–4.86): q and λ with
//!
//!   ∇U(q) + J(q)ᵀλ = 0,   f(q) = 0,
//!
//! U the mechanism's potential energy U* ([`mechanica_mechanism::Mechanism::potential`]:
//! gravity, the rotating frame's −T₀, springs, forces). The reactions are −Jᵀλ (FM 4.85 with
//! FM's multiplier −λ), balancing the active forces −∇U (FM 4.86).
//!
//! **Method.** Newton's method on (q, λ) (sequential quadratic programming):
//! [H Jᵀ; J 0] [δq; δλ] = −[∇U + Jᵀλ; f], with H = ∇²U + Σ_r λ_r ∇²f_r the exact Hessian of
//! the Lagrangian U + λᵀf. H comes from the mechanism crate's exact point Hessians: λᵀf is
//! evaluated as one more potential of a copy of the mechanism, a linear function of the
//! points for coincidence and plane constraints and |x_a − x_b| for a rod (stiffness
//! λ(1 − uuᵀ)/|d|). H is shifted by √u·max|H_kl| on its diagonal, so that neutral directions
//! (a body free to spin about a rod's axis) give a bounded step instead of a singular system;
//! the shift slows the final convergence from quadratic to linear with a ratio near √u, and the
//! convergence test is on the residuals, not on the step. The starting multipliers are the least-squares λ of ∇U + Jᵀλ = 0 at q₀.
//! Steps are shortened to ‖δq‖ ≤ `max_step` and backtracked (at most 40 halvings) until the
//! merit ‖∇U + Jᵀλ‖/τ_g + ‖f‖/τ_f decreases. Spherical and free joints are re-centred before
//! every Hessian ([`mechanica_mechanism::Mechanism::rebase`]), so the returned q is in the
//! mechanism's final chart, as in [`mechanica_mechanism::find_equilibrium`].
//!
//! **Convergence test.** ‖∇U + Jᵀλ‖₂ ≤ τ_g and ‖f‖₂ ≤ τ_f, by default
//! τ_g = 64·n·u·(‖H(q₀)‖_F·max(1, ‖q₀‖) + ‖∇U(q₀)‖ + ‖Jᵀλ₀‖) and
//! τ_f = 64·m·u·max_r(the magnitude of the terms of f_r): the rounding levels of both
//! residuals near q₀. Like any Newton method it finds the equilibrium near q₀, stable or not.

use super::ConstrainedDynamics;
use super::evaluate::Evaluated;
use super::forward::norm2;
use super::kinds::Constraint;
use super::reactions::{ConstraintReaction, reactions};
use super::schur::{Metric, Schur};
use crate::error::{DynamicsError, check_vector};
use faer::Mat;
use faer::linalg::solvers::Solve;
use mechanica_kinematics::tree::KinematicTree;
use mechanica_mechanism::{Anchor, Configuration, MechanismError, Potential, PotentialSum};
use nalgebra::{Matrix3, Vector3};

/// Options of [`ConstrainedDynamics::equilibrium`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConstrainedEquilibriumOptions {
    /// Maximum Newton iterations.
    pub max_iterations: usize,
    /// τ_g on ‖∇U + Jᵀλ‖₂; None for the default (module docs).
    pub stationarity_tolerance: Option<f64>,
    /// τ_f on ‖f‖₂; None for the default.
    pub constraint_tolerance: Option<f64>,
    /// Largest ‖δq‖₂ per step (units of q).
    pub max_step: f64,
}

impl Default for ConstrainedEquilibriumOptions {
    fn default() -> Self {
        Self {
            max_iterations: 100,
            stationarity_tolerance: None,
            constraint_tolerance: None,
            max_step: 1.0,
        }
    }
}

/// A converged constrained equilibrium.
#[derive(Debug, Clone, PartialEq)]
pub struct ConstrainedEquilibrium {
    /// The coordinates (in the mechanism's chart after re-centring).
    pub q: Vec<f64>,
    /// λ, one per equation.
    pub multipliers: Vec<f64>,
    /// Each constraint's reaction at q.
    pub reactions: Vec<ConstraintReaction>,
    /// U at q.
    pub potential: f64,
    /// ‖∇U + Jᵀλ‖₂.
    pub stationarity: f64,
    /// ‖f(q)‖₂.
    pub constraint_norm: f64,
    /// τ_g used.
    pub stationarity_tolerance: f64,
    /// τ_f used.
    pub constraint_tolerance: f64,
    /// Newton iterations.
    pub iterations: usize,
}

/// λᵀf(q) as a potential of the mechanism, for the Lagrangian's gradient and exact Hessian.
#[derive(Debug, Clone)]
struct ConstraintWork {
    constraints: Vec<Constraint>,
    multipliers: Vec<f64>,
}

impl Potential for ConstraintWork {
    fn name(&self) -> String {
        "constraint multipliers".into()
    }

    fn validate(&self, _tree: &KinematicTree) -> Result<(), MechanismError> {
        Ok(())
    }

    fn accumulate(&self, config: &Configuration<'_>, sum: &mut PotentialSum) -> Result<(), MechanismError> {
        let mut rows = self.multipliers.iter();
        let zero = Matrix3::zeros();
        for constraint in &self.constraints {
            match constraint {
                Constraint::PointsCoincide { a, b, directions } => {
                    let d = config.point(a.body, &a.point)? - config.point(b.body, &b.point)?;
                    let force = directions
                        .iter()
                        .fold(Vector3::zeros(), |f, n| f + n * rows.next().copied().unwrap_or(0.0));
                    sum.add_point_potential(config, &[(*a, 1.0), (*b, -1.0)], force.dot(&d), &force, &zero)?;
                }
                Constraint::PointOnPlane { point, normal, offset } => {
                    let lambda = rows.next().copied().unwrap_or(0.0);
                    let value = normal.dot(&config.point(point.body, &point.point)?) - offset;
                    sum.add_point_potential(config, &[(*point, 1.0)], lambda * value, &(normal * lambda), &zero)?;
                }
                Constraint::Distance { a, b, length } => {
                    let lambda = rows.next().copied().unwrap_or(0.0);
                    add_rod(config, sum, (a, b), *length, lambda)?;
                }
                Constraint::Coordinate { index, value } => {
                    let lambda = rows.next().copied().unwrap_or(0.0);
                    sum.value += lambda * (config.q[*index] - value);
                    sum.gradient[*index] += lambda;
                }
            }
        }
        Ok(())
    }
}

/// Adds λ(|x_a − x_b| − L): force λu, stiffness λ(1 − uuᵀ)/|d|.
fn add_rod(
    config: &Configuration<'_>,
    sum: &mut PotentialSum,
    (a, b): (&Anchor, &Anchor),
    length: f64,
    lambda: f64,
) -> Result<(), MechanismError> {
    let d = config.point(a.body, &a.point)? - config.point(b.body, &b.point)?;
    let distance = d.norm();
    if !(distance > 0.0 && distance.is_finite()) {
        return Err(MechanismError::Numerical("the points of a rod constraint coincide"));
    }
    let u = d / distance;
    let stiffness = (Matrix3::identity() - u * u.transpose()) * (lambda / distance);
    sum.add_point_potential(
        config,
        &[(*a, 1.0), (*b, -1.0)],
        lambda * (distance - length),
        &(u * lambda),
        &stiffness,
    )
}

/// The current iterate and its residuals.
struct Iterate {
    q: Vec<f64>,
    lambda: Vec<f64>,
    evaluated: Evaluated,
    lagrangian: PotentialSum,
}

impl Iterate {
    fn merit(&self, tolerances: (f64, f64)) -> f64 {
        norm2(&self.lagrangian.gradient) / tolerances.0 + norm2(&self.evaluated.value) / tolerances.1
    }
}

impl ConstrainedDynamics {
    /// U + λᵀf with its gradient and, when asked, its Hessian.
    fn lagrangian(&self, q: &[f64], lambda: &[f64], hessian: bool) -> Result<PotentialSum, DynamicsError> {
        let mut mechanism = self.dynamics.mechanism.clone();
        mechanism.add_potential(ConstraintWork {
            constraints: self.constraints.clone(),
            multipliers: lambda.to_vec(),
        })?;
        Ok(mechanism.potential(q, hessian)?)
    }

    /// The iterate at (q, λ), with the Hessian when asked.
    fn iterate_at(&mut self, q: Vec<f64>, lambda: Vec<f64>, hessian: bool) -> Result<Iterate, DynamicsError> {
        let evaluated = self.evaluate(&q, &vec![0.0; q.len()])?;
        let lagrangian = self.lagrangian(&q, &lambda, hessian)?;
        Ok(Iterate {
            q,
            lambda,
            evaluated,
            lagrangian,
        })
    }

    /// The least-squares λ of ∇U + Jᵀλ = 0 (J Jᵀ λ = −J ∇U), with the redundancy test.
    fn least_squares_multipliers(&self, evaluated: &Evaluated, gradient: &[f64]) -> Result<Vec<f64>, DynamicsError> {
        let n = gradient.len();
        let identity = Metric::new(Mat::identity(n, n))?;
        let schur = Schur::new(&identity, evaluated, self.pivot_tolerance).map_err(|r| self.redundant(r))?;
        let j = &evaluated.jacobian;
        let rhs: Vec<f64> = (0..j.nrows())
            .map(|r| -(0..n).map(|k| j[(r, k)] * gradient[k]).sum::<f64>())
            .collect();
        Ok(schur.solve(&rhs))
    }

    /// An equilibrium near `q0` (module docs). Errors: invalid inputs,
    /// [`DynamicsError::RedundantConstraint`], [`DynamicsError::NotConverged`] with the last
    /// merit (‖∇U + Jᵀλ‖/τ_g + ‖f‖/τ_f) when the iteration stalls or runs out.
    pub fn equilibrium(
        &mut self,
        q0: &[f64],
        options: &ConstrainedEquilibriumOptions,
    ) -> Result<ConstrainedEquilibrium, DynamicsError> {
        check_vector(q0, self.dof(), "q0")?;
        check_options(options)?;
        let mut q = q0.to_vec();
        let rebase = self.dynamics.mechanism.has_rotation_vectors();
        if rebase {
            self.dynamics.mechanism.rebase(&mut q)?;
        }
        let evaluated = self.evaluate(&q, &vec![0.0; q.len()])?;
        let start = self.dynamics.mechanism.potential(&q, false)?;
        let lambda = self.least_squares_multipliers(&evaluated, &start.gradient)?;
        let mut current = self.iterate_at(q, lambda, true)?;
        let tolerances = self.default_tolerances(&current, &start.gradient, options);
        for iteration in 0..=options.max_iterations {
            let stationarity = norm2(&current.lagrangian.gradient);
            let constraint_norm = norm2(&current.evaluated.value);
            if stationarity <= tolerances.0 && constraint_norm <= tolerances.1 {
                return self.converged(current, tolerances, iteration);
            }
            if iteration == options.max_iterations {
                break;
            }
            let Some(mut next) = self.newton_step(&current, tolerances, options.max_step)? else {
                break;
            };
            if rebase {
                self.dynamics.mechanism.rebase(&mut next.q)?;
            }
            current = self.iterate_at(next.q, next.lambda, true)?;
        }
        Err(DynamicsError::NotConverged {
            what: "constrained equilibrium",
            iterations: options.max_iterations,
            residual: current.merit(tolerances),
        })
    }

    /// (τ_g, τ_f): the given ones or the defaults of the module docs.
    fn default_tolerances(
        &self,
        start: &Iterate,
        potential_gradient: &[f64],
        options: &ConstrainedEquilibriumOptions,
    ) -> (f64, f64) {
        let n = start.q.len().max(1) as f64;
        let m = start.evaluated.equations().max(1) as f64;
        let hessian_norm = start.lagrangian.hessian.as_ref().map_or(0.0, |h| h.norm_l2());
        let reaction: Vec<f64> = start
            .lagrangian
            .gradient
            .iter()
            .zip(potential_gradient)
            .map(|(l, u)| l - u)
            .collect();
        let g = 64.0
            * n
            * f64::EPSILON
            * (hessian_norm * norm2(&start.q).max(1.0) + norm2(potential_gradient) + norm2(&reaction))
            + f64::MIN_POSITIVE;
        let scale = start.evaluated.value_scale.iter().fold(0.0f64, |a, s| a.max(*s));
        let f = 64.0 * m * f64::EPSILON * scale + f64::MIN_POSITIVE;
        (
            options.stationarity_tolerance.unwrap_or(g),
            options.constraint_tolerance.unwrap_or(f),
        )
    }

    /// The damped Newton step from `current`, or None when no step decreases the merit.
    fn newton_step(
        &mut self,
        current: &Iterate,
        tolerances: (f64, f64),
        max_step: f64,
    ) -> Result<Option<Iterate>, DynamicsError> {
        let (n, m) = (current.q.len(), current.lambda.len());
        let hessian = current
            .lagrangian
            .hessian
            .as_ref()
            .ok_or(DynamicsError::NonFiniteResult {
                what: "Lagrangian Hessian",
            })?;
        let identity = Metric::new(Mat::identity(n, n))?;
        Schur::new(&identity, &current.evaluated, self.pivot_tolerance).map_err(|r| self.redundant(r))?;
        let j = &current.evaluated.jacobian;
        let size = (0..n)
            .flat_map(|r| (0..n).map(move |c| (r, c)))
            .fold(0.0f64, |a, rc| a.max(hessian[rc].abs()));
        let shift = f64::EPSILON.sqrt() * size;
        let kkt = Mat::from_fn(n + m, n + m, |r, c| match (r < n, c < n) {
            (true, true) => hessian[(r, c)] + if r == c { shift } else { 0.0 },
            (true, false) => j[(c - n, r)],
            (false, true) => j[(r - n, c)],
            (false, false) => 0.0,
        });
        let rhs = Mat::from_fn(n + m, 1, |r, _| {
            if r < n {
                -current.lagrangian.gradient[r]
            } else {
                -current.evaluated.value[r - n]
            }
        });
        let step = kkt.partial_piv_lu().solve(&rhs);
        let mut step: Vec<f64> = (0..n + m).map(|r| step[(r, 0)]).collect();
        if step.iter().any(|x| !x.is_finite()) {
            return Ok(None);
        }
        let length = norm2(&step[..n]);
        if length > max_step {
            step.iter_mut().for_each(|x| *x *= max_step / length);
        }
        let merit = current.merit(tolerances);
        let mut alpha = 1.0;
        for _ in 0..40 {
            let q: Vec<f64> = current.q.iter().zip(&step).map(|(x, d)| x + alpha * d).collect();
            let lambda: Vec<f64> = current
                .lambda
                .iter()
                .zip(&step[n..])
                .map(|(x, d)| x + alpha * d)
                .collect();
            if let Ok(trial) = self.iterate_at(q, lambda, false)
                && trial.merit(tolerances) < (1.0 - 1e-4 * alpha) * merit
            {
                return Ok(Some(trial));
            }
            alpha *= 0.5;
        }
        Ok(None)
    }

    /// The report at the converged iterate.
    fn converged(
        &self,
        current: Iterate,
        tolerances: (f64, f64),
        iterations: usize,
    ) -> Result<ConstrainedEquilibrium, DynamicsError> {
        let potential = self.dynamics.mechanism.potential(&current.q, false)?.value;
        Ok(ConstrainedEquilibrium {
            reactions: reactions(&current.evaluated, &current.lambda),
            potential,
            stationarity: norm2(&current.lagrangian.gradient),
            constraint_norm: norm2(&current.evaluated.value),
            stationarity_tolerance: tolerances.0,
            constraint_tolerance: tolerances.1,
            iterations,
            q: current.q,
            multipliers: current.lambda,
        })
    }
}

/// Ok when the step bound is positive and the tolerances, if given, are positive.
fn check_options(options: &ConstrainedEquilibriumOptions) -> Result<(), DynamicsError> {
    let checks = [
        ("maximum equilibrium step", Some(options.max_step)),
        ("stationarity tolerance", options.stationarity_tolerance),
        ("constraint tolerance", options.constraint_tolerance),
    ];
    for (what, value) in checks {
        if let Some(value) = value
            && !(value > 0.0 && value.is_finite())
        {
            return Err(DynamicsError::OutOfRange {
                what,
                requirement: "finite and > 0",
                value,
            });
        }
    }
    Ok(())
}
