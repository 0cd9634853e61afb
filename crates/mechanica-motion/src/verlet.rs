//! Störmer–Verlet (generalized leapfrog) in the variables (q, p = A(q) q̇) (M.8):
//!
//!   p_½ = p₀ + (h/2) F(q₀, A(q₀)⁻¹ p_½)                       (implicit in p_½)
//!   q₁ = q₀ + (h/2) (A(q₀)⁻¹ + A(q₁)⁻¹) p_½                   (implicit in q₁)
//!   p₁ = p_½ + (h/2) F(q₁, A(q₁)⁻¹ p_½)                       (explicit)
//!
//! with ṗ = F(q, q̇) = A q̈ + Ȧ q̇ (M.9), which is −∂H/∂q plus the non-conservative forces.
//! q̈ comes from the dynamics; Ȧ q̇ = (d/ds) A(q + s q̇) q̇ by the five-point central
//! difference of A along q̇ with |s q̇|∞ = 1e-3, whose relative error is about 1e-12 (fourth
//! order in s plus rounding u/s). Both implicit equations are solved to rounding level
//! ([`crate::iteration`]): the half kick by fixed-point iteration, its corrections measured
//! against the size of the terms p_½ is summed from, ‖p‖ + (h/2)(‖A q̈‖ + 1.5‖A‖‖q̇‖/s); the
//! drift by simplified Newton iteration with a difference Jacobian, which converges also when
//! A(q)⁻¹ varies fast (bodies of very different masses), where a fixed-point iteration
//! would not contract. With a constant A the first converges in one correction and the second
//! is explicit.

use crate::error::StepFailure;
use crate::iteration::{Convergence, distance, norm};
use crate::system::System;
use nalgebra::{Cholesky, DMatrix, DVector, Dyn};

/// The displacement |s q̇|∞ of the difference quotient for Ȧ q̇.
const DIFFERENCE_STEP: f64 = 1e-3;

/// The Cholesky factor of A(q), or [`StepFailure::SingularMassMatrix`].
pub(crate) fn factor_mass(system: &mut System, q: &[f64]) -> Result<Cholesky<f64, Dyn>, StepFailure> {
    Cholesky::new(system.mass_matrix(q)?).ok_or(StepFailure::SingularMassMatrix)
}

pub(crate) fn solve(factor: &Cholesky<f64, Dyn>, p: &[f64]) -> Vec<f64> {
    factor.solve(&DVector::from_column_slice(p)).as_slice().to_vec()
}

fn shifted(q: &[f64], v: &[f64], s: f64) -> Vec<f64> {
    q.iter().zip(v).map(|(x, d)| x + s * d).collect()
}

/// Ȧ q̇ = (d/ds) A(q + s q̇) q̇ at s = 0 by the five-point difference (module docs).
fn mass_rate_times(system: &mut System, q: &[f64], v: &[f64]) -> Result<DVector<f64>, StepFailure> {
    let speed = norm(v);
    let n = q.len();
    if speed == 0.0 {
        return Ok(DVector::zeros(n));
    }
    let s = DIFFERENCE_STEP / speed;
    let mut derivative = DMatrix::<f64>::zeros(n, n);
    for (weight, shift) in [(8.0, 1.0), (-8.0, -1.0), (-1.0, 2.0), (1.0, -2.0)] {
        derivative += system.mass_matrix(&shifted(q, v, shift * s))? * (weight / (12.0 * s));
    }
    Ok(derivative * DVector::from_column_slice(v))
}

/// ṗ = A q̈ + Ȧ q̇ at (t, q, q̇) (M.9), with the size of the terms it is computed from.
#[derive(Debug, Clone)]
pub(crate) struct MomentumRate {
    /// ṗ.
    pub rate: Vec<f64>,
    /// The magnitude whose rounding level bounds the rounding of ṗ: ‖A q̈‖∞ + ‖r‖∞ plus
    /// 1.5‖A‖∞‖q̇‖∞/s for the difference quotient of Ȧ q̇ with displacement s (module docs),
    /// whose rounding is u·Σ|weights|/(12 s) times ‖A‖‖q̇‖.
    pub scale: f64,
}

/// ṗ at (t, q, q̇) (M.9). With `reaction` None, q̈ is the system's acceleration (with the
/// constraints' reactions when it has constraints); with Some(r), q̈ is the acceleration
/// without the constraints and the generalized force r is added to ṗ (M.17).
pub(crate) fn momentum_rate(
    system: &mut System,
    t: f64,
    q: &[f64],
    v: &[f64],
    reaction: Option<&[f64]>,
) -> Result<MomentumRate, StepFailure> {
    let mut accel = vec![0.0; q.len()];
    match reaction {
        None => system.acceleration(t, q, v, &mut accel)?,
        Some(_) => system.free_acceleration(t, q, v, &mut accel)?,
    }
    let a = system.mass_matrix(q)?;
    let inertial = &a * DVector::from_column_slice(&accel);
    let mut rate = (&inertial + mass_rate_times(system, q, v)?).as_slice().to_vec();
    let mut scale = inertial.amax() + 1.5 * a.abs().row_sum().amax() * norm(v) * norm(v) / DIFFERENCE_STEP;
    if let Some(r) = reaction {
        rate.iter_mut().zip(r).for_each(|(x, f)| *x += f);
        scale += norm(r);
    }
    crate::error::check_finite(&rate, "momentum rate")?;
    Ok(MomentumRate { rate, scale })
}

/// The start of a step: q₀, the factor of A(q₀), p₀ = A(q₀) q̇₀ and q̇₀.
pub(crate) struct Start<'a> {
    pub q: &'a [f64],
    pub factor: &'a Cholesky<f64, Dyn>,
    pub p: &'a [f64],
    pub v: &'a [f64],
}

/// p_½ from p₀ = A(q₀) q̇₀ by fixed-point iteration of the first half kick, with the extra
/// generalized force `reaction` when given (see [`momentum_rate`]).
pub(crate) fn half_kick(
    system: &mut System,
    t: f64,
    start: &Start<'_>,
    h: f64,
    reaction: Option<&[f64]>,
) -> Result<Vec<f64>, StepFailure> {
    let Start {
        q,
        factor,
        p: p0,
        v: v0,
    } = *start;
    let mut v = v0.to_vec();
    let mut p = p0.to_vec();
    let mut convergence = Convergence::new("Störmer–Verlet half kick");
    loop {
        let rate = momentum_rate(system, t, q, &v, reaction)?;
        let next: Vec<f64> = p0.iter().zip(&rate.rate).map(|(a, f)| a + 0.5 * h * f).collect();
        let correction = distance(&next, &p);
        p = next;
        if convergence.done(correction, norm(&p).max(norm(p0)) + 0.5 * h * rate.scale)? {
            return Ok(p);
        }
        v = solve(factor, &p);
    }
}

/// The residual R(q₁) = q₁ − q₀ − (h/2)(v₀ + A(q₁)⁻¹p) of the drift, with A(q₁)⁻¹p.
fn drift_residual(
    system: &mut System,
    (q0, v_start, p): (&[f64], &[f64], &[f64]),
    q1: &[f64],
    h: f64,
) -> Result<(DVector<f64>, Vec<f64>), StepFailure> {
    let v_end = solve(&factor_mass(system, q1)?, p);
    let residual = DVector::from_fn(q0.len(), |k, _| q1[k] - q0[k] - 0.5 * h * (v_start[k] + v_end[k]));
    Ok((residual, v_end))
}

/// The Newton matrix ∂R/∂q₁ = I − (h/2) ∂(A(q₁)⁻¹p)/∂q₁ of the drift by forward differences
/// (relative step √u), given A(q₁)⁻¹p.
fn drift_matrix(
    system: &mut System,
    q1: &[f64],
    p: &[f64],
    v_end: &[f64],
    h: f64,
) -> Result<DMatrix<f64>, StepFailure> {
    let n = q1.len();
    let reach = 0.5 * h * norm(v_end);
    let mut matrix = DMatrix::<f64>::identity(n, n);
    for k in 0..n {
        let eps = f64::EPSILON.sqrt() * q1[k].abs().max(reach).max(f64::MIN_POSITIVE.sqrt());
        let mut shifted = q1.to_vec();
        shifted[k] += eps;
        let v_shifted = solve(&factor_mass(system, &shifted)?, p);
        for i in 0..n {
            matrix[(i, k)] -= 0.5 * h * (v_shifted[i] - v_end[i]) / eps;
        }
    }
    Ok(matrix)
}

/// q₁ of the drift q₁ = q₀ + (h/2)(v₀ + A(q₁)⁻¹p) by simplified Newton iteration from the
/// explicit guess q₀ + h v₀, with the Newton matrix by differences re-formed whenever an
/// iteration contracts by less than 4; it stops at rounding level ([`crate::iteration`]).
/// With a constant A the matrix is I and one correction solves the drift.
pub(crate) fn drift(
    system: &mut System,
    q0: &[f64],
    v_start: &[f64],
    p: &[f64],
    h: f64,
) -> Result<Vec<f64>, StepFailure> {
    let mut q1: Vec<f64> = q0.iter().zip(v_start).map(|(x, v)| x + h * v).collect();
    let mut convergence = Convergence::new("Störmer–Verlet drift");
    let mut lu = None;
    let mut previous = f64::INFINITY;
    loop {
        let (residual, v_end) = drift_residual(system, (q0, v_start, p), &q1, h)?;
        if lu.is_none() {
            lu = Some(drift_matrix(system, &q1, p, &v_end, h)?.lu());
        }
        let correction = lu
            .as_ref()
            .and_then(|f| f.solve(&residual))
            .ok_or(StepFailure::NotConverged {
                what: "Störmer–Verlet drift (singular Newton matrix)",
                iterations: 0,
                correction: f64::INFINITY,
            })?;
        q1.iter_mut().zip(correction.iter()).for_each(|(x, c)| *x -= c);
        let size = correction.amax();
        if convergence.done(size, norm(&q1).max(norm(q0)))? {
            return Ok(q1);
        }
        if size > 0.25 * previous {
            lu = None;
        }
        previous = size;
    }
}

/// p = A q̇ = L Lᵀ q̇ from the factor of A.
pub(crate) fn momentum(factor: &Cholesky<f64, Dyn>, v: &[f64]) -> Vec<f64> {
    (factor.l() * (factor.l().transpose() * DVector::from_column_slice(v)))
        .as_slice()
        .to_vec()
}

/// One Störmer–Verlet step of size `h` from (t, q, q̇), in place.
pub(crate) fn step(system: &mut System, t: f64, q: &mut [f64], v: &mut [f64], h: f64) -> Result<(), StepFailure> {
    let factor0 = factor_mass(system, q)?;
    let p0 = momentum(&factor0, v);
    let start = Start {
        q,
        factor: &factor0,
        p: &p0,
        v,
    };
    let p_half = half_kick(system, t, &start, h, None)?;
    let v_start = solve(&factor0, &p_half);
    let q1 = drift(system, q, &v_start, &p_half, h)?;
    let factor1 = factor_mass(system, &q1)?;
    let v_end = solve(&factor1, &p_half);
    let rate = momentum_rate(system, t + h, &q1, &v_end, None)?.rate;
    let p1: Vec<f64> = p_half.iter().zip(&rate).map(|(a, f)| a + 0.5 * h * f).collect();
    let v1 = solve(&factor1, &p1);
    crate::error::check_finite(&q1, "state q")?;
    crate::error::check_finite(&v1, "state q̇")?;
    q.copy_from_slice(&q1);
    v.copy_from_slice(&v1);
    Ok(())
}
