//! Störmer–Verlet (generalized leapfrog) in the variables (q, p = A(q) q̇) (M.8):
//!
//!   p_½ = p₀ + (h/2) F(q₀, A(q₀)⁻¹ p_½)                       (implicit in p_½)
//!   q₁ = q₀ + (h/2) (A(q₀)⁻¹ + A(q₁)⁻¹) p_½                   (implicit in q₁)
//!   p₁ = p_½ + (h/2) F(q₁, A(q₁)⁻¹ p_½)                       (explicit)
//!
//! with ṗ = F(q, q̇) = A q̈ + Ȧ q̇ (M.9), which is −∂H/∂q plus the non-conservative forces.
//! q̈ comes from the dynamics; Ȧ q̇ = (d/ds) A(q + s q̇) q̇ by the five-point central
//! difference of A along q̇ with |s q̇|∞ = 1e-3, whose relative error is about 1e-12 (fourth
//! order in s plus rounding u/s). Both implicit equations are solved by fixed-point iteration
//! to rounding level ([`crate::iteration`]); with a constant A the first converges in one
//! correction and the second is explicit.

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

fn solve(factor: &Cholesky<f64, Dyn>, p: &[f64]) -> Vec<f64> {
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

/// ṗ = A q̈ + Ȧ q̇ at (t, q, q̇) (M.9).
fn momentum_rate(system: &mut System, t: f64, q: &[f64], v: &[f64]) -> Result<Vec<f64>, StepFailure> {
    let mut accel = vec![0.0; q.len()];
    system.acceleration(t, q, v, &mut accel)?;
    let rate = system.mass_matrix(q)? * DVector::from_column_slice(&accel) + mass_rate_times(system, q, v)?;
    let rate = rate.as_slice().to_vec();
    crate::error::check_finite(&rate, "momentum rate")?;
    Ok(rate)
}

/// p_½ from p₀ = A(q₀) q̇₀ by fixed-point iteration of the first half kick.
fn half_kick(
    system: &mut System,
    t: f64,
    q: &[f64],
    factor: &Cholesky<f64, Dyn>,
    p0: &[f64],
    v0: &[f64],
    h: f64,
) -> Result<Vec<f64>, StepFailure> {
    let mut v = v0.to_vec();
    let mut p = p0.to_vec();
    let mut convergence = Convergence::new("Störmer–Verlet half kick");
    loop {
        let rate = momentum_rate(system, t, q, &v)?;
        let next: Vec<f64> = p0.iter().zip(&rate).map(|(a, f)| a + 0.5 * h * f).collect();
        let correction = distance(&next, &p);
        p = next;
        if convergence.done(correction, norm(&p).max(norm(p0)))? {
            return Ok(p);
        }
        v = solve(factor, &p);
    }
}

/// q₁ by fixed-point iteration of the drift.
fn drift(system: &mut System, q0: &[f64], v_start: &[f64], p: &[f64], h: f64) -> Result<Vec<f64>, StepFailure> {
    let mut q1: Vec<f64> = q0.iter().zip(v_start).map(|(x, v)| x + h * v).collect();
    let mut convergence = Convergence::new("Störmer–Verlet drift");
    loop {
        let v_end = solve(&factor_mass(system, &q1)?, p);
        let next: Vec<f64> = (0..q0.len())
            .map(|k| q0[k] + 0.5 * h * (v_start[k] + v_end[k]))
            .collect();
        let correction = distance(&next, &q1);
        q1 = next;
        if convergence.done(correction, norm(&q1).max(norm(q0)))? {
            return Ok(q1);
        }
    }
}

/// One Störmer–Verlet step of size `h` from (t, q, q̇), in place.
pub(crate) fn step(system: &mut System, t: f64, q: &mut [f64], v: &mut [f64], h: f64) -> Result<(), StepFailure> {
    let factor0 = factor_mass(system, q)?;
    let p0 = (factor0.l() * (factor0.l().transpose() * DVector::from_column_slice(v)))
        .as_slice()
        .to_vec();
    let p_half = half_kick(system, t, q, &factor0, &p0, v, h)?;
    let v_start = solve(&factor0, &p_half);
    let q1 = drift(system, q, &v_start, &p_half, h)?;
    let factor1 = factor_mass(system, &q1)?;
    let v_end = solve(&factor1, &p_half);
    let rate = momentum_rate(system, t + h, &q1, &v_end)?;
    let p1: Vec<f64> = p_half.iter().zip(&rate).map(|(a, f)| a + 0.5 * h * f).collect();
    let v1 = solve(&factor1, &p1);
    crate::error::check_finite(&q1, "state q")?;
    crate::error::check_finite(&v1, "state q̇")?;
    q.copy_from_slice(&q1);
    v.copy_from_slice(&v1);
    Ok(())
}
