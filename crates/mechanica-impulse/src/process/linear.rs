//! Segments of the impact process with a constant impulse ratio dP/dp = d = (d_T, 1): slip in
//! a fixed direction (d_T = −f ŝ) or stick (d_T = t, the ratio that keeps u_T = 0). Along
//! such a segment u_n is linear and the normal work quadratic in p, so every event is found
//! in closed form, and the error of the segment's length follows from the slope of the
//! event at its root.
//!
//! A stick segment whose normal rate b = dᵀ W d vanishes (W has a null vector with a normal
//! component: a hinged body whose contact point moves on a line, a body on a spherical joint)
//! keeps u_n at zero for every further normal impulse: the contact *self-locks*. Compression
//! then ends where the slip stopped; Poisson's law continues along the stick ray to
//! p_f = (1 + e) p_c without changing any velocity, while Newton's and Stronge's laws with
//! e > 0 cannot be met, and the process ends with the frictional-jam error.

use super::{Compression, Process, SegmentEnd};
use crate::ImpulseError;
use crate::compensated::{UNIT_ROUNDOFF, abs_dot, dot2, dot2_split};
use crate::contact_space::RestitutionLaw;
use crate::tangent_block::Solution2;
use nalgebra::{Vector2, Vector3};

/// Relative size of b = dᵀ W d (to |d|²·max|W_ij|) below which a stick segment cannot change
/// the normal velocity (the contact self-locks). The scale of [`crate::body::INERTIA_ZERO_RELATIVE`]
/// and [`crate::tangent_block::BLOCK_RANK_RELATIVE`]: a body whose inertia ratios are above it
/// keeps b at least about that ratio, while a hinge leaves b at the rounding of W.
const SELF_LOCK_RELATIVE: f64 = 1e-12;

/// The impulse ratio d = (d_T, 1) of a segment, with d_T carried as d_T + `d_lo` (so that the
/// normal rate sees it beyond one rounding) and a bound on its error.
#[derive(Debug, Clone, Copy)]
pub(super) struct Direction {
    d: Vector3<f64>,
    d_lo: Vector2<f64>,
    error: f64,
    stick: bool,
}

impl Direction {
    /// Slip along the unit ŝ = `s_hat.x` + `s_hat.lo` with friction `f`: d = (−f ŝ, 1), the
    /// products split exactly.
    pub fn slip(s_hat: &Solution2, f: f64) -> Self {
        let split = |i: usize| {
            let p = f * s_hat.x[i];
            (-p, -(f.mul_add(s_hat.x[i], -p) + f * s_hat.lo[i]))
        };
        let ((d0, lo0), (d1, lo1)) = (split(0), split(1));
        Self {
            d: Vector3::new(d0, d1, 1.0),
            d_lo: Vector2::new(lo0, lo1),
            error: f * s_hat.error,
            stick: false,
        }
    }

    /// True for a stick ratio.
    pub fn is_stick(&self) -> bool {
        self.stick
    }

    /// |d_T|.
    pub fn tangential_norm(&self) -> f64 {
        Vector2::new(self.d.x, self.d.y).norm()
    }

    /// Stick with the solved ratio t: d = (t, 1).
    pub fn stick(t: &Solution2) -> Self {
        Self {
            d: Vector3::new(t.x.x, t.x.y, 1.0),
            d_lo: t.lo,
            error: t.error,
            stick: true,
        }
    }
}

/// The end of a segment: its length in p and a bound on the error of that length.
type Length = (f64, f64);

/// x/y for an error ratio, +∞ when the slope y vanishes under a non-zero error.
fn error_ratio(x: f64, y: f64) -> f64 {
    if x == 0.0 {
        0.0
    } else if y > 0.0 {
        x / y
    } else {
        f64::INFINITY
    }
}

impl Process {
    /// The normal rate b = du_n/dp along `dir` and a bound on its error. For stick, b is the
    /// quadratic form dᵀ W d, which is stationary in the stick ratio (its error is second
    /// order in the ratio's error); for slip it is (W d)_n, first order in the direction's.
    pub(super) fn normal_rate(&self, dir: &Direction) -> (f64, f64) {
        let (d, lo) = (dir.d, dir.d_lo);
        let u = UNIT_ROUNDOFF;
        // (W d)_i as hi + lo, W = w + w_lo and d = (d_T + d_lo, 1).
        let w_d = |i: usize| {
            let w = self.row_terms(i);
            dot2_split(
                &[w[0], w[1], w[2], w[3], w[4], w[5], w[0], w[1]],
                &[d.x, d.y, d.z, d.x, d.y, d.z, lo.x, lo.y],
            )
        };
        let terms = |i: usize| abs_dot(&self.row_terms(i)[..3], d.as_slice());
        if dir.stick {
            // b = d·(W d), the exact form up to u² terms.
            let (y0, y1, y2) = (w_d(0), w_d(1), w_d(2));
            let b = dot2(
                &[d.x, d.y, d.z, lo.x, lo.y, d.x, d.y, d.z],
                &[y0.0, y1.0, y2.0, y0.0, y1.0, y0.1, y1.1, y2.1],
            );
            let magnitude: f64 = (0..3).map(|i| d[i].abs() * terms(i)).sum();
            let second_order = 2.0 * self.block.norm() * dir.error * dir.error;
            (b, 4.0 * u * b.abs() + 8.0 * u * u * magnitude + second_order)
        } else {
            let (b, b_lo) = w_d(2);
            let b = b + b_lo;
            let first_order = Vector2::new(self.w[(2, 0)], self.w[(2, 1)]).norm() * dir.error;
            (b, 4.0 * u * b.abs() + 8.0 * u * u * terms(2) + first_order)
        }
    }

    /// A sticking segment along `dir` to the end of the impact, or the self-locked end when
    /// the normal velocity cannot change along it (module documentation).
    pub(super) fn linear_stick(&mut self, dir: Direction) -> Result<SegmentEnd, ImpulseError> {
        if !self.self_locks(&dir) {
            return self.linear(dir, (f64::INFINITY, 0.0));
        }
        self.self_locked(dir)
    }

    /// True when the normal rate along the stick ratio `dir` vanishes to within
    /// [`SELF_LOCK_RELATIVE`]: the contact self-locks.
    pub(super) fn self_locks(&self, dir: &Direction) -> bool {
        dir.stick && self.normal_rate(dir).0.abs() <= SELF_LOCK_RELATIVE * self.w.amax() * dir.d.norm_squared()
    }

    /// The end of an impact whose contact self-locks (module documentation). The residual
    /// |u_n| left by the slip-halting cut-off is added to the error as the impulse |u_n|/W_nn.
    fn self_locked(&mut self, dir: Direction) -> Result<SegmentEnd, ImpulseError> {
        let (a, a_error) = self.normal_velocity();
        let slack = a_error + self.eta * dir.d.norm();
        let jam = |reason: &'static str, p: f64, steps: usize| ImpulseError::NotConverged {
            reason,
            steps,
            normal_impulse: p,
        };
        if self.compression.is_none() {
            if a < -slack {
                return Err(jam(
                    "the contact sticks while still approaching and no impulse changes its normal velocity (frictional jam)",
                    self.p,
                    self.steps,
                ));
            }
            self.add_error(a.abs() / self.w[(2, 2)]);
            self.mark_compression();
            self.work = 0.0;
            self.work_error = 0.0;
        }
        let Some(compression) = self.compression else {
            return Ok(SegmentEnd::Terminated);
        };
        let met = match self.law {
            RestitutionLaw::Newton => -self.e * self.u0.z - a <= slack,
            RestitutionLaw::Stronge => {
                let e2 = self.e * self.e;
                let c = compression;
                let work_slack = self.work_error + e2 * c.work_error + 4.0 * UNIT_ROUNDOFF * e2 * c.work.abs();
                -e2 * c.work - self.work <= work_slack
            }
            RestitutionLaw::Poisson => {
                let start = Start::of(self);
                let length = self.poisson_length(&compression);
                let rate = self.normal_rate(&dir);
                self.move_along(&start, &dir, length, (a, a_error), rate);
                true
            }
        };
        if met {
            Ok(SegmentEnd::Terminated)
        } else {
            Err(jam(
                "the contact self-locks: friction holds it at rest, the normal velocity stays zero and the \
                 restitution law cannot be met (frictional jam)",
                self.p,
                self.steps,
            ))
        }
    }

    /// A segment with constant impulse ratio `dir`, at most `limit` long in p (with the error
    /// bound of that limit). Every event is located in closed form from the segment's start,
    /// whose normal velocity a₀ is evaluated once: u_n = a₀ + b s and the work are exact
    /// functions of the distance s along the segment, so an event never inherits the
    /// rounding of an intermediate state.
    pub(super) fn linear(&mut self, dir: Direction, limit: Length) -> Result<SegmentEnd, ImpulseError> {
        let rate = self.normal_rate(&dir);
        // The phase origin: the state, its normal velocity and its distance from the start.
        let mut origin = (Start::of(self), self.normal_velocity(), 0.0);
        let mut done = 0.0;
        loop {
            let (start, velocity, offset) = &origin;
            let local = done - offset;
            let a = rate.0.mul_add(local, velocity.0);
            let a_error = velocity.1 + local * rate.1 + 2.0 * UNIT_ROUNDOFF * a.abs();
            let (s, s_error) = self.event_length((a, a_error), rate);
            if s.is_infinite() && rate.0 > 0.0 {
                // The normal velocity does grow; the impulse to the event overflows f64.
                return Err(ImpulseError::NonFiniteResult { quantity: "impulse" });
            }
            if s.is_infinite() || done + s > limit.0 {
                if limit.0.is_infinite() {
                    return Err(ImpulseError::NotConverged {
                        reason: "the normal velocity does not increase with the normal impulse (frictional jam)",
                        steps: self.steps,
                        normal_impulse: self.p,
                    });
                }
                self.move_along(start, &dir, (limit.0 - offset, limit.1), *velocity, rate);
                return Ok(SegmentEnd::Halted);
            }
            done += s;
            self.move_along(start, &dir, (done - offset, s_error), *velocity, rate);
            if self.compression.is_some() || self.compress_here() {
                return Ok(SegmentEnd::Terminated);
            }
            // Restitution starts where compression ended, with the model's u_n there (≈ 0).
            let a_c = rate.0.mul_add(done - offset, velocity.0);
            let a_c_error = a_error + s * rate.1 + rate.0.abs() * s_error + 2.0 * UNIT_ROUNDOFF * a_c.abs();
            origin = (Start::of(self), (a_c, a_c_error), done);
        }
    }

    /// The distance in p from the current state to the next event along a segment with normal
    /// velocity a and rate b (each with its error bound), and the error of that distance:
    /// the error of the event function at the root over its slope there.
    fn event_length(&self, (a, a_error): (f64, f64), (b, b_error): (f64, f64)) -> Length {
        let u = UNIT_ROUNDOFF;
        let velocity_event = |target: f64| {
            if a >= target {
                (0.0, 0.0)
            } else if b > 0.0 {
                let s = (target - a) / b;
                let g_error = a_error + 2.0 * u * target.abs() + s * b_error;
                (s, error_ratio(g_error, b) + u * s)
            } else {
                (f64::INFINITY, 0.0)
            }
        };
        let Some(c) = self.compression else {
            return velocity_event(0.0);
        };
        match self.law {
            RestitutionLaw::Newton => velocity_event(-self.e * self.u0.z),
            RestitutionLaw::Poisson => self.poisson_length(&c),
            RestitutionLaw::Stronge => {
                // The restitution work still missing: e²·|compression work| − work so far.
                let e2 = self.e * self.e;
                let delta = -e2 * c.work - self.work;
                if delta <= 0.0 {
                    return (0.0, 0.0);
                }
                // ½ b s² + a s = delta, smallest positive root, stable form.
                let disc = a * a + 2.0 * b * delta;
                if disc < 0.0 || (a <= 0.0 && b <= 0.0) {
                    return (f64::INFINITY, 0.0);
                }
                let s = 2.0 * delta / (a + disc.sqrt());
                let delta_error = e2 * c.work_error + self.work_error + 2.0 * u * (e2 * c.work.abs() + self.work.abs());
                let g_error = delta_error + s * a_error + 0.5 * s * s * b_error;
                (s, error_ratio(g_error, (a + b * s).abs()) + u * s)
            }
        }
    }

    /// The distance to Poisson's end p_f = (1 + e) p_c and its error, from the error bounds of
    /// p_c and of the current p.
    fn poisson_length(&self, c: &Compression) -> Length {
        let target = (1.0 + self.e) * c.p;
        let s = (target - self.p).max(0.0);
        let error = (1.0 + self.e) * c.p_error + self.p_error + 2.0 * UNIT_ROUNDOFF * (target + self.p);
        (s, if s > 0.0 { error } else { 0.0 })
    }

    /// Sets the state to the point at distance `s` (with the error bound of that distance)
    /// along `dir` from the segment's `start`, where the normal velocity was a₀ and the rate
    /// b, and sets the impulse and work error bounds accordingly.
    fn move_along(
        &mut self,
        start: &Start,
        dir: &Direction,
        (s, s_error): Length,
        (a, a_error): (f64, f64),
        (b, b_error): (f64, f64),
    ) {
        let d = dir.d;
        self.p = start.p + s;
        self.q = start.q + (Vector2::new(d.x, d.y) + dir.d_lo) * s;
        self.work = start.work + a * s + 0.5 * b * s * s;
        let u = UNIT_ROUNDOFF;
        self.work_error = start.work_error
            + s * a_error
            + 0.5 * s * s * b_error
            + 2.0 * u * (a.abs() * s + 0.5 * b.abs() * s * s)
            + (a + b * s).abs() * s_error;
        self.error = start.error + d.norm() * s_error + s * dir.error + 2.0 * u * s * d.norm();
        self.p_error = start.p_error + s_error + u * self.p;
    }
}

/// The state at the start of a segment.
struct Start {
    p: f64,
    q: Vector2<f64>,
    work: f64,
    error: f64,
    p_error: f64,
    work_error: f64,
}

impl Start {
    fn of(process: &Process) -> Self {
        Self {
            p: process.p,
            q: process.q,
            work: process.work,
            error: process.error,
            p_error: process.p_error,
            work_error: process.work_error,
        }
    }
}
