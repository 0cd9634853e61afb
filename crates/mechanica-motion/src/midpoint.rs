//! The implicit midpoint rule (M.10) for stiff springs: with the unknown velocity change
//! Δ = q̇₁ − q̇₀, the midpoint state is q_m = q₀ + (h/2)(q̇₀ + Δ/2), q̇_m = q̇₀ + Δ/2, and
//!
//!   R(Δ) = Δ − h q̈(t + h/2, q_m, q̇_m) = 0,   q₁ = q₀ + h q̇_m,   q̇₁ = q̇₀ + Δ.
//!
//! R = 0 is solved by Newton's method (M.11). Its Jacobian I − h((h/4) ∂q̈/∂q + ½ ∂q̈/∂q̇) is
//! formed by forward differences of the acceleration, one evaluation per column along the
//! direction (h/4, ½)·e_k with a relative step √u. The Jacobian only sets the rate of
//! convergence: the iteration stops when the correction is at rounding level
//! ([`crate::iteration`]), so the step solves the midpoint equations themselves, not a
//! linearisation. The Jacobian is re-formed whenever an iteration contracts by less than 4.

use crate::error::StepFailure;
use crate::iteration::{Convergence, norm};
use crate::system::System;
use nalgebra::{DMatrix, DVector};

/// The midpoint state (q_m, q̇_m) for the velocity change Δ.
fn midpoint_state(q0: &[f64], v0: &[f64], delta: &[f64], h: f64) -> (Vec<f64>, Vec<f64>) {
    let vm: Vec<f64> = v0.iter().zip(delta).map(|(v, d)| v + 0.5 * d).collect();
    let qm = q0.iter().zip(&vm).map(|(q, v)| q + 0.5 * h * v).collect();
    (qm, vm)
}

/// The Newton matrix ∂R/∂Δ by forward differences (module docs), given q̈ at Δ.
fn newton_matrix(
    system: &mut System,
    t: f64,
    (q0, v0): (&[f64], &[f64]),
    delta: &[f64],
    accel: &[f64],
    h: f64,
) -> Result<DMatrix<f64>, StepFailure> {
    let n = q0.len();
    let scale = norm(v0).max(norm(delta)).max(h * norm(accel)).max(f64::MIN_POSITIVE);
    let mut jacobian = DMatrix::<f64>::identity(n, n);
    let mut shifted_accel = vec![0.0; n];
    for k in 0..n {
        let eps = f64::EPSILON.sqrt() * delta[k].abs().max(scale);
        let mut shifted = delta.to_vec();
        shifted[k] += eps;
        let (qm, vm) = midpoint_state(q0, v0, &shifted, h);
        system.acceleration(t, &qm, &vm, &mut shifted_accel)?;
        for i in 0..n {
            jacobian[(i, k)] -= h * (shifted_accel[i] - accel[i]) / eps;
        }
    }
    Ok(jacobian)
}

/// One implicit-midpoint step of size `h` from (t, q, q̇), in place.
pub(crate) fn step(system: &mut System, t: f64, q: &mut [f64], v: &mut [f64], h: f64) -> Result<(), StepFailure> {
    let n = q.len();
    if n == 0 {
        return Ok(()); // no coordinates: nothing moves (and no Newton matrix to factor)
    }
    let tm = t + 0.5 * h;
    let mut accel = vec![0.0; n];
    system.acceleration(t, q, v, &mut accel)?;
    let mut delta: Vec<f64> = accel.iter().map(|a| h * a).collect();
    let mut convergence = Convergence::new("implicit midpoint Newton iteration");
    let mut lu = None;
    let mut previous = f64::INFINITY;
    loop {
        let (qm, vm) = midpoint_state(q, v, &delta, h);
        system.acceleration(tm, &qm, &vm, &mut accel)?;
        if lu.is_none() {
            lu = Some(newton_matrix(system, tm, (q, v), &delta, &accel, h)?.lu());
        }
        let residual = DVector::from_iterator(n, (0..n).map(|i| delta[i] - h * accel[i]));
        let correction = lu
            .as_ref()
            .and_then(|f| f.solve(&residual))
            .ok_or(StepFailure::NotConverged {
                what: "implicit midpoint Newton iteration (singular Newton matrix)",
                iterations: 0,
                correction: f64::INFINITY,
            })?;
        for i in 0..n {
            delta[i] -= correction[i];
        }
        let size = correction.amax();
        if convergence.done(size, norm(&delta).max(norm(v)))? {
            break;
        }
        if size > 0.25 * previous {
            lu = None;
        }
        previous = size;
    }
    let (_, vm) = midpoint_state(q, v, &delta, h);
    for i in 0..n {
        q[i] += h * vm[i];
        v[i] += delta[i];
    }
    crate::error::check_finite(q, "state q")?;
    crate::error::check_finite(v, "state q̇")
}
