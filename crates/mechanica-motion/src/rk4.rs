//! The classical Runge–Kutta method of order 4 (M.3) on y = (q, q̇), y′ = (q̇, q̈(t, q, q̇)).

use crate::error::StepFailure;
use crate::system::System;

/// Scratch storage of one RK4 step.
#[derive(Debug, Clone)]
pub(crate) struct Rk4 {
    stage_q: Vec<f64>,
    stage_v: Vec<f64>,
    /// Stage slopes of q (velocities) and of q̇ (accelerations), four each.
    slope_q: [Vec<f64>; 4],
    slope_v: [Vec<f64>; 4],
}

impl Rk4 {
    pub(crate) fn new(n: usize) -> Self {
        Self {
            stage_q: vec![0.0; n],
            stage_v: vec![0.0; n],
            slope_q: std::array::from_fn(|_| vec![0.0; n]),
            slope_v: std::array::from_fn(|_| vec![0.0; n]),
        }
    }

    /// One step of size `h` from (t, q, q̇), in place.
    pub(crate) fn step(
        &mut self,
        system: &mut System,
        t: f64,
        q: &mut [f64],
        v: &mut [f64],
        h: f64,
    ) -> Result<(), StepFailure> {
        const NODES: [f64; 4] = [0.0, 0.5, 0.5, 1.0];
        for s in 0..4 {
            let c = NODES[s];
            for k in 0..q.len() {
                let (dq, dv) = if s == 0 {
                    (0.0, 0.0)
                } else {
                    (self.slope_q[s - 1][k], self.slope_v[s - 1][k])
                };
                self.stage_q[k] = q[k] + c * h * dq;
                self.stage_v[k] = v[k] + c * h * dv;
            }
            self.slope_q[s].copy_from_slice(&self.stage_v);
            system.acceleration(t + c * h, &self.stage_q, &self.stage_v, &mut self.slope_v[s])?;
        }
        for k in 0..q.len() {
            let (sq, sv) = (&self.slope_q, &self.slope_v);
            q[k] += h / 6.0 * (sq[0][k] + 2.0 * sq[1][k] + 2.0 * sq[2][k] + sq[3][k]);
            v[k] += h / 6.0 * (sv[0][k] + 2.0 * sv[1][k] + 2.0 * sv[2][k] + sv[3][k]);
        }
        crate::error::check_finite(q, "state q")?;
        crate::error::check_finite(v, "state q̇")
    }
}
