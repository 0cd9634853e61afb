//! The Dormand–Prince 5(4) pair (M.4)–(M.5) with PI step-size control (M.6) and the
//! continuous extension of order 4 (M.7), on y = (q, q̇) stored as one vector of 2n entries.

use crate::error::StepFailure;
use crate::system::System;

const C: [f64; 7] = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [0.2, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];
/// b₅ − b₄: the weights of the local error estimate.
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];
/// The weights of the fifth-order term of the continuous extension (M.7).
const D: [f64; 7] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];
const SAFETY: f64 = 0.9;
const BETA: f64 = 0.04;
const MIN_FACTOR: f64 = 0.2;
const MAX_FACTOR: f64 = 10.0;

/// The state of an adaptive run: the proposed step, the previous error for the PI
/// controller, the stage slopes, and the interpolant of the last accepted step.
#[derive(Debug, Clone)]
pub(crate) struct DormandPrince {
    rtol: f64,
    atol: f64,
    h: f64,
    previous_error: f64,
    k: [Vec<f64>; 7],
    k1_valid: bool,
    stage: Vec<f64>,
    next: Vec<f64>,
    dense: [Vec<f64>; 5],
    dense_t0: f64,
    dense_h: f64,
}

/// y′ = (q̇, q̈) at (t, y).
fn derivative(system: &mut System, t: f64, y: &[f64], out: &mut [f64]) -> Result<(), StepFailure> {
    let n = y.len() / 2;
    let (q, v) = y.split_at(n);
    let (dq, dv) = out.split_at_mut(n);
    dq.copy_from_slice(v);
    system.acceleration(t, q, v, dv)
}

impl DormandPrince {
    pub(crate) fn new(n: usize, rtol: f64, atol: f64) -> Self {
        let m = 2 * n;
        Self {
            rtol,
            atol,
            h: 0.0,
            previous_error: 1e-4,
            k: std::array::from_fn(|_| vec![0.0; m]),
            k1_valid: false,
            stage: vec![0.0; m],
            next: vec![0.0; m],
            dense: std::array::from_fn(|_| vec![0.0; m]),
            dense_t0: 0.0,
            dense_h: 0.0,
        }
    }

    /// Forgets the slope at the current state (after the state was changed from outside, as
    /// when charts are re-centred).
    pub(crate) fn invalidate(&mut self) {
        self.k1_valid = false;
    }

    /// The weighted RMS norm ‖x / (atol + rtol·max(|a|, |b|))‖ of (M.5), 0 for empty vectors.
    fn weighted_norm(&self, x: &[f64], a: &[f64], b: &[f64]) -> f64 {
        if x.is_empty() {
            return 0.0; // no coordinates: no error
        }
        let sum: f64 = (0..x.len())
            .map(|i| {
                let scale = self.atol + self.rtol * a[i].abs().max(b[i].abs());
                (x[i] / scale).powi(2)
            })
            .sum();
        (sum / x.len() as f64).sqrt()
    }

    /// A first step from the size of y, y′ and an estimate of y″ (M.6).
    fn initial_step(&mut self, system: &mut System, t: f64, y: &[f64]) -> Result<f64, StepFailure> {
        let d0 = self.weighted_norm(y, y, y);
        let d1 = self.weighted_norm(&self.k[0], y, y);
        let h0 = if d0 < 1e-10 || d1 < 1e-10 { 1e-6 } else { 0.01 * d0 / d1 };
        for i in 0..y.len() {
            self.stage[i] = y[i] + h0 * self.k[0][i];
        }
        // The slope buffer goes back before a failure is returned: a later step reuses it.
        let mut slope = std::mem::take(&mut self.next);
        let result = derivative(system, t + h0, &self.stage, &mut slope);
        self.next = slope;
        result?;
        let diff: Vec<f64> = self.next.iter().zip(&self.k[0]).map(|(a, b)| (a - b) / h0).collect();
        let d2 = self.weighted_norm(&diff, y, y);
        let largest = d1.max(d2);
        let h1 = if largest <= 1e-15 {
            (h0 * 1e-3).max(1e-6)
        } else {
            (0.01 / largest).powf(0.2)
        };
        Ok((100.0 * h0).min(h1))
    }

    /// Stages 2…7 of a step of size h from (t, y) into `self.k`, the new state into `self.next`.
    fn stages(&mut self, system: &mut System, t: f64, y: &[f64], h: f64) -> Result<(), StepFailure> {
        for s in 1..7 {
            for i in 0..y.len() {
                let sum: f64 = (0..s).map(|j| A[s][j] * self.k[j][i]).sum();
                self.stage[i] = y[i] + h * sum;
            }
            let mut slope = std::mem::take(&mut self.k[s]);
            let result = derivative(system, t + C[s] * h, &self.stage, &mut slope);
            self.k[s] = slope;
            result?;
        }
        self.next.copy_from_slice(&self.stage);
        Ok(())
    }

    /// The weighted local error of the last stages (M.5), infinite when they overflowed.
    fn local_error(&self, y: &[f64], h: f64) -> f64 {
        let estimate: Vec<f64> = (0..y.len())
            .map(|i| h * (0..7).map(|s| E[s] * self.k[s][i]).sum::<f64>())
            .collect();
        let error = self.weighted_norm(&estimate, y, &self.next);
        if error.is_finite() { error } else { f64::INFINITY }
    }

    /// Takes one accepted step from (t, y), at most up to `limit`, retrying rejected steps
    /// with smaller sizes; updates t and y and the interpolant of the step.
    pub(crate) fn step(
        &mut self,
        system: &mut System,
        t: &mut f64,
        y: &mut [f64],
        limit: f64,
    ) -> Result<(), StepFailure> {
        if !self.k1_valid {
            let mut slope = std::mem::take(&mut self.k[0]);
            let result = derivative(system, *t, y, &mut slope);
            self.k[0] = slope;
            result?;
            self.k1_valid = true;
        }
        if self.h == 0.0 {
            self.h = self.initial_step(system, *t, y)?;
        }
        let mut rejected = false;
        loop {
            let to_limit = self.h >= limit - *t;
            let h = if to_limit { limit - *t } else { self.h };
            if h.is_nan() || h <= 16.0 * f64::EPSILON * t.abs().max(f64::MIN_POSITIVE) {
                return Err(StepFailure::StepSizeUnderflow { step: h });
            }
            let error = match self.stages(system, *t, y, h) {
                Ok(()) => self.local_error(y, h),
                Err(StepFailure::NonFinite { .. }) => f64::INFINITY,
                Err(other) => return Err(other),
            };
            let growth = error.powf(0.2 - 0.75 * BETA);
            if error <= 1.0 {
                let factor =
                    (growth / self.previous_error.powf(BETA) / SAFETY).clamp(1.0 / MAX_FACTOR, 1.0 / MIN_FACTOR);
                self.previous_error = error.max(1e-4);
                let factor = if rejected { factor.max(1.0) } else { factor };
                self.accept(t, y, h);
                if to_limit {
                    *t = limit; // t + (limit − t) may round below the limit
                }
                self.h = h / factor;
                return Ok(());
            }
            rejected = true;
            let shrink = if error.is_finite() {
                (growth / SAFETY).min(1.0 / MIN_FACTOR)
            } else {
                10.0
            };
            self.h = h / shrink;
        }
    }

    /// Stores the interpolant (M.7) of the step [t, t + h] and moves to its end (the last
    /// stage is the slope there: first same as last).
    fn accept(&mut self, t: &mut f64, y: &mut [f64], h: f64) {
        for i in 0..y.len() {
            let change = self.next[i] - y[i];
            let r3 = h * self.k[0][i] - change;
            self.dense[0][i] = y[i];
            self.dense[1][i] = change;
            self.dense[2][i] = r3;
            self.dense[3][i] = change - h * self.k[6][i] - r3;
            self.dense[4][i] = h * (0..7).map(|s| D[s] * self.k[s][i]).sum::<f64>();
        }
        self.dense_t0 = *t;
        self.dense_h = h;
        y.copy_from_slice(&self.next);
        *t += h;
        let last = std::mem::take(&mut self.k[6]);
        self.k[6] = std::mem::replace(&mut self.k[0], last);
    }

    /// y at `t` inside the last accepted step, from its interpolant (M.7).
    pub(crate) fn interpolate(&self, t: f64, out: &mut [f64]) {
        let theta = ((t - self.dense_t0) / self.dense_h).clamp(0.0, 1.0);
        let theta1 = 1.0 - theta;
        let r = &self.dense;
        for i in 0..out.len() {
            out[i] = r[0][i] + theta * (r[1][i] + theta1 * (r[2][i] + theta * (r[3][i] + theta1 * r[4][i])));
        }
    }
}
