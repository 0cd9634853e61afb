//! Projections back onto the constraints, for integrators that let f(q) and J q̇ drift.
//!
//! **Positions.** Gauss–Newton on f(q) = 0: q ← q − W⁻¹Jᵀ (J W⁻¹ Jᵀ)⁻¹ f(q), the smallest
//! correction in the metric W (the mass matrix A(q) at each iterate, i.e. the least kinetic
//! "distance", or the identity: plain least squares). It converges quadratically near a
//! regular point of f; it stops when ‖f‖₂ ≤ the tolerance, which defaults to
//! 64·m·u·max_r(the magnitude of the terms of f_r), the rounding level of f.
//!
//! **Velocities.** q̇ ← q̇ − A⁻¹Jᵀ (J A⁻¹ Jᵀ)⁻¹ J q̇: the A-orthogonal projection onto
//! J q̇ = 0, which removes the least kinetic energy (one factorization, two passes: the second
//! removes what the rounding of the first left of J q̇).

use super::ConstrainedDynamics;
use super::evaluate::Evaluated;
use super::forward::norm2;
use super::schur::{Metric, Schur};
use crate::error::DynamicsError;
use faer::Mat;

/// The metric of the position projection.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ProjectionMetric {
    /// The mass matrix A(q): the correction of least kinetic metric.
    #[default]
    MassMatrix,
    /// The identity: the correction of least Euclidean norm in q.
    Euclidean,
}

/// Options of [`ConstrainedDynamics::project_positions`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProjectionOptions {
    /// Maximum Gauss–Newton iterations.
    pub max_iterations: usize,
    /// Tolerance on ‖f‖₂; None for the rounding-level default (module docs).
    pub tolerance: Option<f64>,
    /// The metric.
    pub metric: ProjectionMetric,
}

impl Default for ProjectionOptions {
    fn default() -> Self {
        Self {
            max_iterations: 20,
            tolerance: None,
            metric: ProjectionMetric::MassMatrix,
        }
    }
}

/// The result of [`ConstrainedDynamics::project_positions`].
#[derive(Debug, Clone, PartialEq)]
pub struct PositionProjection {
    /// The projected coordinates.
    pub q: Vec<f64>,
    /// Gauss–Newton iterations done.
    pub iterations: usize,
    /// ‖f(q)‖₂ at the projected q.
    pub residual: f64,
    /// The tolerance used.
    pub tolerance: f64,
}

/// The result of [`ConstrainedDynamics::project_velocities`].
#[derive(Debug, Clone, PartialEq)]
pub struct VelocityProjection {
    /// The projected velocities.
    pub q_dot: Vec<f64>,
    /// ‖J q̇‖₂ before the projection.
    pub removed: f64,
    /// ‖J q̇‖₂ after it.
    pub residual: f64,
}

impl ConstrainedDynamics {
    /// The factored metric and Schur complement at the evaluated q.
    fn factors(
        &mut self,
        q: &[f64],
        metric: ProjectionMetric,
        evaluated: &Evaluated,
    ) -> Result<(Metric, Schur), DynamicsError> {
        let n = self.dof();
        let w = match metric {
            ProjectionMetric::MassMatrix => self.dynamics.mass_matrix(q)?,
            ProjectionMetric::Euclidean => Mat::identity(n, n),
        };
        let metric = Metric::new(w)?;
        let schur = Schur::new(&metric, evaluated, self.pivot_tolerance).map_err(|r| self.redundant(r))?;
        Ok((metric, schur))
    }

    /// q projected onto f(q) = 0 by Gauss–Newton (module docs). Errors:
    /// [`DynamicsError::NotConverged`] when ‖f‖ is above the tolerance after the allowed
    /// iterations, [`DynamicsError::RedundantConstraint`], invalid inputs.
    pub fn project_positions(
        &mut self,
        q: &[f64],
        options: &ProjectionOptions,
    ) -> Result<PositionProjection, DynamicsError> {
        let zeros = vec![0.0; self.dof()];
        let mut q = q.to_vec();
        let mut evaluated = self.evaluate(&q, &zeros)?;
        let tolerance = match options.tolerance {
            Some(t) if t >= 0.0 && t.is_finite() => t,
            Some(t) => {
                return Err(DynamicsError::OutOfRange {
                    what: "projection tolerance",
                    requirement: "finite and ≥ 0",
                    value: t,
                });
            }
            None => super::drift::rounding_level(&evaluated),
        };
        let mut iterations = 0;
        loop {
            let residual = norm2(&evaluated.value);
            if residual <= tolerance {
                return Ok(PositionProjection {
                    q,
                    iterations,
                    residual,
                    tolerance,
                });
            }
            if iterations == options.max_iterations {
                return Err(DynamicsError::NotConverged {
                    what: "position projection",
                    iterations,
                    residual,
                });
            }
            let (_, schur) = self.factors(&q, options.metric, &evaluated)?;
            let mu = schur.solve(&evaluated.value);
            for (k, x) in q.iter_mut().enumerate() {
                *x -= (0..mu.len()).map(|r| schur.y[(k, r)] * mu[r]).sum::<f64>();
            }
            evaluated = self.evaluate(&q, &zeros)?;
            iterations += 1;
        }
    }

    /// q̇ projected A-orthogonally onto J(q) q̇ = 0 (module docs), with one more pass on the
    /// projected q̇ (iterative refinement) against the rounding of an ill-conditioned J A⁻¹ Jᵀ.
    pub fn project_velocities(&mut self, q: &[f64], q_dot: &[f64]) -> Result<VelocityProjection, DynamicsError> {
        let evaluated = self.evaluate(q, q_dot)?;
        let removed = norm2(&evaluated.velocity);
        let (_, schur) = self.factors(q, ProjectionMetric::MassMatrix, &evaluated)?;
        let mut projected = q_dot.to_vec();
        let mut velocity = evaluated.velocity;
        for _ in 0..2 {
            let mu = schur.solve(&velocity);
            for (k, v) in projected.iter_mut().enumerate() {
                *v -= (0..mu.len()).map(|r| schur.y[(k, r)] * mu[r]).sum::<f64>();
            }
            crate::error::check_result(projected.iter(), "projected velocity")?;
            velocity = self.evaluate(q, &projected)?.velocity;
        }
        Ok(VelocityProjection {
            q_dot: projected,
            removed,
            residual: norm2(&velocity),
        })
    }
}
