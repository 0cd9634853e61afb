//! RATTLE (Andersen 1983; Hairer, Lubich & Wanner, *Geometric Numerical Integration*,
//! VII.1.4) for mechanisms with holonomic constraints f(q) = 0, in the variables
//! (q, p = A(q) q̇) of Störmer–Verlet (M.8), with J = ∂f/∂q and the reactions −Jᵀλ (M.17):
//!
//!   p_½ = p₀ + (h/2) (F(q₀, A(q₀)⁻¹p_½) − J(q₀)ᵀλ)
//!   q₁ = q₀ + (h/2) (A(q₀)⁻¹ + A(q₁)⁻¹) p_½,        f(q₁) = 0
//!   p₁ = p_½ + (h/2) (F(q₁, A(q₁)⁻¹p_½) − J(q₁)ᵀμ),  J(q₁) A(q₁)⁻¹ p₁ = 0
//!
//! with F the forces without the constraints' reactions (M.9).
//!
//! **Positions.** For a given λ the first two lines are Störmer–Verlet's half kick and drift
//! with the constant extra force −J(q₀)ᵀλ, solved by the same fixed-point iterations to
//! rounding level. λ solves f(q₁(λ)) = 0 by the simplified Newton iteration
//! λ ← λ + (2/h²) S₀⁻¹ f(q₁(λ)), S₀ = J(q₀) A(q₀)⁻¹ J(q₀)ᵀ, from ∂q₁/∂λ ≈ −(h²/2) A⁻¹J(q₀)ᵀ,
//! which contracts by O(h) per iteration when A varies slowly; whenever an iteration reduces
//! ‖f(q₁)‖ by less than 4, the matrix −(h²/2) S₀ is replaced by ∂f(q₁(λ))/∂λ formed by
//! forward differences (m more half kicks and drifts). It starts from the previous step's λ
//! and stops when
//! ‖f(q₁)‖₂ is at most the rounding level of f at q₁ (64·m·u times the size of the terms of
//! f, [`mechanica_dynamics::constraints::drift`]), or when it stalls below the rounding of
//! q₁ = q₀ + h v itself, 64·m·u·max|J₀|·(max|q₀| + h·max|q̇₀|) (a coordinate held near zero,
//! whose own terms are tiny); after [`MAX_NEWTON_ITERATIONS`] it fails with
//! [`StepFailure::ConstraintNotMet`].
//!
//! **Velocities.** The last line is linear in μ: with p̃ = p_½ + (h/2) F(q₁, A(q₁)⁻¹p_½) and
//! ṽ = A(q₁)⁻¹p̃, it gives q̇₁ = ṽ − A⁻¹Jᵀ(J A⁻¹ Jᵀ)⁻¹ J ṽ at q₁: the A-orthogonal
//! projection of ṽ onto J(q₁) q̇ = 0, which
//! [`mechanica_dynamics::ConstrainedDynamics::project_velocities`] computes.
//!
//! The map is symplectic on the constraint manifold's cotangent bundle and of order 2
//! (HLW VII.1.4), so for a conservative system the energy error stays bounded.

use crate::error::StepFailure;
use crate::system::System;
use crate::verlet::{Start, drift, factor_mass, half_kick, momentum, momentum_rate, solve};
use nalgebra::{Cholesky, DMatrix, DVector, Dyn};

/// The most simplified Newton iterations for λ in one step.
pub const MAX_NEWTON_ITERATIONS: usize = 50;

/// J(q) as an m×n matrix.
fn jacobian(system: &mut System, q: &[f64]) -> Result<DMatrix<f64>, StepFailure> {
    let n = q.len();
    let rows = system.constraints_mut().constraint_jacobian(q)?;
    Ok(DMatrix::from_row_slice(rows.len() / n.max(1), n, &rows))
}

/// The data of the multiplier iteration at q₀: J(q₀) and the factor of S₀ = J A⁻¹ Jᵀ.
struct Multipliers {
    j0: DMatrix<f64>,
    schur: Cholesky<f64, Dyn>,
}

impl Multipliers {
    fn at(system: &mut System, q0: &[f64], factor0: &Cholesky<f64, Dyn>) -> Result<Self, StepFailure> {
        let j0 = jacobian(system, q0)?;
        let y0 = factor0.solve(&j0.transpose());
        let schur = Cholesky::new(&j0 * y0).ok_or(StepFailure::SingularConstraints)?;
        Ok(Self { j0, schur })
    }

    /// −J(q₀)ᵀλ.
    fn reaction(&self, lambda: &[f64]) -> Vec<f64> {
        (-(self.j0.transpose() * DVector::from_column_slice(lambda)))
            .as_slice()
            .to_vec()
    }
}

/// q₁(λ), p_½(λ) and f(q₁) with its norm and rounding level, for one λ.
struct Landing {
    q1: Vec<f64>,
    p_half: Vec<f64>,
    values: DVector<f64>,
    residual: f64,
    rounding_level: f64,
    /// 64·m·u·max|J₀|·(max|q₀| + h·max|q̇₀|): how far f moves when q₁ = q₀ + h v is rounded,
    /// the floor of ‖f‖ where the terms of f are themselves small (a coordinate held near zero).
    /// From the step's start, so that a diverging λ cannot raise it.
    landing_level: f64,
}

/// The half kick and drift for the multipliers `lambda`, and f at their end.
fn land(
    system: &mut System,
    (t, h): (f64, f64),
    start: &Start<'_>,
    multipliers: &Multipliers,
    lambda: &[f64],
) -> Result<Landing, StepFailure> {
    let reaction = multipliers.reaction(lambda);
    let p_half = half_kick(system, t, start, h, Some(&reaction))?;
    let v_start = solve(start.factor, &p_half);
    let q1 = drift(system, start.q, &v_start, &p_half, h)?;
    let zeros = vec![0.0; q1.len()];
    let drift_at = system.constraints_mut().drift(&q1, &zeros)?;
    let amax = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let equations = drift_at.values.len() as f64;
    let landing_level = 64.0 * equations * f64::EPSILON * multipliers.j0.amax() * (amax(start.q) + h * amax(start.v));
    Ok(Landing {
        q1,
        p_half,
        values: DVector::from_column_slice(&drift_at.values),
        residual: drift_at.position,
        rounding_level: drift_at.rounding_level,
        landing_level,
    })
}

/// ∂f(q₁(λ))/∂λ by forward differences with steps δ_r = √u·max(|λ_r|, `size`).
fn multiplier_matrix(
    system: &mut System,
    (t, h): (f64, f64),
    start: &Start<'_>,
    multipliers: &Multipliers,
    (lambda, at): (&[f64], &Landing),
    size: f64,
) -> Result<DMatrix<f64>, StepFailure> {
    let m = lambda.len();
    let mut matrix = DMatrix::zeros(m, m);
    for r in 0..m {
        let delta = f64::EPSILON.sqrt() * lambda[r].abs().max(size).max(f64::MIN_POSITIVE.sqrt());
        let mut shifted = lambda.to_vec();
        shifted[r] += delta;
        let moved = land(system, (t, h), start, multipliers, &shifted)?;
        matrix.set_column(r, &((moved.values - &at.values) / delta));
    }
    Ok(matrix)
}

/// The position part of a step (module docs): q₁ on f = 0 and p_½, with λ updated in place.
/// The simplified Newton matrix −(h²/2) S₀ is replaced by the difference Jacobian
/// ∂f(q₁)/∂λ, formed at the best λ so far (smallest ‖f(q₁)‖), whenever an iteration reduces
/// ‖f‖ by less than 4 (fast-varying A(q)⁻¹, high speeds), and re-formed on the same rule.
fn positions(
    system: &mut System,
    t: f64,
    start: &Start<'_>,
    h: f64,
    lambda: &mut [f64],
) -> Result<(Vec<f64>, Vec<f64>), StepFailure> {
    let multipliers = Multipliers::at(system, start.q, start.factor)?;
    let mut differences: Option<nalgebra::LU<f64, Dyn, Dyn>> = None;
    let mut best = (lambda.to_vec(), f64::INFINITY);
    let mut at = land(system, (t, h), start, &multipliers, lambda).map_err(|failure| diverged(failure, &best, 0.0))?;
    best.1 = at.residual;
    let (mut previous, mut last_change) = (f64::INFINITY, 0.0f64);
    for _ in 0..MAX_NEWTON_ITERATIONS {
        if at.residual <= at.rounding_level {
            return Ok((at.q1, at.p_half));
        }
        if !at.residual.is_finite() {
            break;
        }
        if at.residual < best.1 {
            best = (lambda.to_vec(), at.residual);
        }
        if at.residual > 0.25 * previous && at.residual <= at.landing_level {
            // Stalled at the rounding of q₁ itself.
            return Ok((at.q1, at.p_half));
        }
        if at.residual > 0.25 * previous {
            if at.residual > best.1 {
                lambda.copy_from_slice(&best.0);
                at = land(system, (t, h), start, &multipliers, lambda)?;
            }
            let size = lambda.iter().fold(last_change, |m, l| m.max(l.abs()));
            let matrix = multiplier_matrix(system, (t, h), start, &multipliers, (lambda, &at), size)
                .map_err(|failure| diverged(failure, &best, at.rounding_level))?;
            differences = Some(matrix.lu());
        }
        previous = at.residual;
        let change = match &differences {
            None => multipliers.schur.solve(&at.values) * (2.0 / (h * h)),
            Some(lu) => -lu.solve(&at.values).ok_or(StepFailure::SingularConstraints)?,
        };
        last_change = change.amax();
        lambda.iter_mut().zip(change.iter()).for_each(|(l, c)| *l += c);
        at = land(system, (t, h), start, &multipliers, lambda)
            .map_err(|failure| diverged(failure, &best, at.rounding_level))?;
    }
    if at.residual <= at.rounding_level.max(at.landing_level) {
        return Ok((at.q1, at.p_half));
    }
    Err(StepFailure::ConstraintNotMet {
        iterations: MAX_NEWTON_ITERATIONS,
        residual: at.residual,
        tolerance: at.rounding_level,
    })
}

/// A multiplier iterate far from the constraints can drive the dynamics out of range: that is
/// the constraint not met (with the best residual reached), not an input out of range.
fn diverged(failure: StepFailure, best: &(Vec<f64>, f64), tolerance: f64) -> StepFailure {
    match failure {
        StepFailure::Dynamics(_) | StepFailure::NonFinite { .. } => StepFailure::ConstraintNotMet {
            iterations: MAX_NEWTON_ITERATIONS,
            residual: best.1,
            tolerance,
        },
        other => other,
    }
}

/// One RATTLE step of size `h` from (t, q, q̇), in place; `lambda` (one entry per constraint
/// equation) is the starting guess of the multipliers and receives the step's λ.
pub(crate) fn step(
    system: &mut System,
    t: f64,
    (q, v): (&mut [f64], &mut [f64]),
    h: f64,
    lambda: &mut [f64],
) -> Result<(), StepFailure> {
    let factor0 = factor_mass(system, q)?;
    let p0 = momentum(&factor0, v);
    let start = Start {
        q,
        factor: &factor0,
        p: &p0,
        v,
    };
    let (q1, p_half) = positions(system, t, &start, h, lambda)?;
    let factor1 = factor_mass(system, &q1)?;
    let v_end = solve(&factor1, &p_half);
    let zeros = vec![0.0; q.len()];
    let rate = momentum_rate(system, t + h, &q1, &v_end, Some(&zeros))?.rate;
    let p_tilde: Vec<f64> = p_half.iter().zip(&rate).map(|(a, f)| a + 0.5 * h * f).collect();
    let v_tilde = solve(&factor1, &p_tilde);
    let v1 = system.constraints_mut().project_velocities(&q1, &v_tilde)?.q_dot;
    crate::error::check_finite(&q1, "state q")?;
    crate::error::check_finite(&v1, "state q̇")?;
    q.copy_from_slice(&q1);
    v.copy_from_slice(&v1);
    Ok(())
}
