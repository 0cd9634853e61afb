//! Slip whose direction swerves (3-D impacts whose tangential block couples the slip
//! direction to its rate): dP_T/dp = −f u_T/|u_T| with the normal work, integrated by an
//! embedded Dormand–Prince 5(4) pair with events located by Illinois iteration. The local
//! error estimates and the slip-halting cut-off are added to the process's error bound.

use super::{Process, SegmentEnd};
use crate::ImpulseError;
use nalgebra::{Vector2, Vector3};

impl Process {
    /// Right-hand side of the slip ODE in the state y = (q₁, q₂, work) with parameter p.
    fn slip_rate(&self, p: f64, y: &Vector3<f64>, fallback: &Vector2<f64>) -> Vector3<f64> {
        let q = Vector2::new(y.x, y.y);
        let u = self.velocity(p, &q);
        let ut = Vector2::new(u.x, u.y);
        let speed = ut.norm();
        let s_hat = if speed > 0.0 { ut / speed } else { *fallback };
        Vector3::new(-self.f * s_hat.x, -self.f * s_hat.y, u.z)
    }

    /// One Dormand–Prince 5(4) step of size h from (p, y): the new state and the error estimate.
    fn dp45_step(&self, p: f64, y: &Vector3<f64>, h: f64, fallback: &Vector2<f64>) -> (Vector3<f64>, Vector3<f64>) {
        let k1 = self.slip_rate(p, y, fallback);
        let k2 = self.slip_rate(p + h / 5.0, &(y + k1 * (h / 5.0)), fallback);
        let k3 = self.slip_rate(
            p + 0.3 * h,
            &(y + (k1 * (3.0 / 40.0) + k2 * (9.0 / 40.0)) * h),
            fallback,
        );
        let k4 = self.slip_rate(
            p + 0.8 * h,
            &(y + (k1 * (44.0 / 45.0) - k2 * (56.0 / 15.0) + k3 * (32.0 / 9.0)) * h),
            fallback,
        );
        let k5 = self.slip_rate(
            p + 8.0 / 9.0 * h,
            &(y + (k1 * (19372.0 / 6561.0) - k2 * (25360.0 / 2187.0) + k3 * (64448.0 / 6561.0) - k4 * (212.0 / 729.0))
                * h),
            fallback,
        );
        let k6 = self.slip_rate(
            p + h,
            &(y + (k1 * (9017.0 / 3168.0) - k2 * (355.0 / 33.0) + k3 * (46732.0 / 5247.0) + k4 * (49.0 / 176.0)
                - k5 * (5103.0 / 18656.0))
                * h),
            fallback,
        );
        let y5 = y
            + (k1 * (35.0 / 384.0) + k3 * (500.0 / 1113.0) + k4 * (125.0 / 192.0) - k5 * (2187.0 / 6784.0)
                + k6 * (11.0 / 84.0))
                * h;
        let k7 = self.slip_rate(p + h, &y5, fallback);
        let err = (k1 * (71.0 / 57600.0) - k3 * (71.0 / 16695.0) + k4 * (71.0 / 1920.0) - k5 * (17253.0 / 339200.0)
            + k6 * (22.0 / 525.0)
            - k7 * (1.0 / 40.0))
            * h;
        (y5, err)
    }

    /// Fails when the step budget is spent or the normal impulse exceeds `p_max`.
    fn check_budget(&self, p_max: f64) -> Result<(), ImpulseError> {
        let reason = if self.steps >= self.max_steps {
            "step budget exhausted in swerving slip"
        } else if self.p > p_max {
            "the normal impulse grows without bound (frictional jam)"
        } else {
            return Ok(());
        };
        Err(ImpulseError::NotConverged {
            reason,
            steps: self.steps,
            normal_impulse: self.p,
        })
    }

    /// The end of the swerving slip at the current state (direction `s_hat`, slip speed
    /// `speed`, du_T/dp = `rate`), if any: the slip has halted (speed ≤ η), or it halts so soon
    /// that its direction turns by less than the tolerance before (angle ≈ |swerve|/|along|),
    /// and is finished as a straight slip.
    fn halting_end(
        &mut self,
        s_hat: &Vector2<f64>,
        speed: f64,
        rate: &Vector2<f64>,
    ) -> Option<Result<SegmentEnd, ImpulseError>> {
        let along = s_hat.dot(rate);
        if speed <= self.eta {
            // Halting cut-off: the rest of the slip (≈ speed/|rate| in p) is replaced by the
            // stick or ray segment; bound the impulse difference by 2 f Δp (+ 1 for p).
            if along < 0.0 {
                self.add_error((2.0 * self.f + 1.0) * speed / -along);
            }
            return Some(Ok(SegmentEnd::Halted));
        }
        // The friction impulse a straight finish misdirects, f Δp·angle, is added to the error.
        let swerve = rate.x * s_hat.y - rate.y * s_hat.x;
        if along < 0.0 && swerve.abs() <= self.tolerance * -along {
            self.add_error(2.0 * self.f * (speed / -along) * (swerve.abs() / -along));
            return Some(self.straight_slip(s_hat, speed, swerve.abs() / -along));
        }
        None
    }

    /// Integrates a slip whose direction swerves, until the impact terminates or the slip halts.
    pub(super) fn integrate_swerving(&mut self) -> Result<SegmentEnd, ImpulseError> {
        let speed_scale = self.u0.norm();
        let atol_q = self.tolerance * self.p_scale;
        let atol_w = self.tolerance * self.p_scale * speed_scale;
        let p_max = 1e12 * self.p_scale;
        let mut h = 1e-2 * self.p_scale;
        let max_rate = self.w_tn().norm() + self.f * self.w_tt().norm();
        loop {
            self.check_budget(p_max)?;
            let u = self.velocity(self.p, &self.q);
            let ut = Vector2::new(u.x, u.y);
            let speed = ut.norm();
            let s_hat = ut / speed;
            let rate = self.w_tn() - self.f * self.w_tt() * s_hat;
            let along = s_hat.dot(&rate);
            if let Some(end) = self.halting_end(&s_hat, speed, &rate) {
                return end;
            }
            // Cap the step at 80 % of the linearly predicted halting distance, and so that u_T
            // cannot change by more than half its length in one step whatever its direction
            // (|du_T/dp| ≤ |W_Tn| + f‖W_TT‖): near a halt the slip direction turns quickly,
            // and a step across u_T = 0 would leave the smooth part of the slip ODE.
            if along < 0.0 {
                h = h.min(0.8 * speed / -along).min(0.5 * speed / max_rate);
            }
            let y = Vector3::new(self.q.x, self.q.y, self.work);
            let (y_new, err) = self.dp45_step(self.p, &y, h, &s_hat);
            self.steps += 1;
            let ratio = (err.x.hypot(err.y) / atol_q).max(err.z.abs() / atol_w);
            let u_new = self.velocity(self.p + h, &Vector2::new(y_new.x, y_new.y));
            let flipped = Vector2::new(u_new.x, u_new.y).dot(&ut) <= 0.0;
            if ratio > 1.0 || flipped || !ratio.is_finite() {
                h *= if ratio.is_finite() {
                    (0.9 * ratio.powf(-0.2)).clamp(0.1, 0.5)
                } else {
                    0.1
                };
                continue;
            }
            // Locate an event inside the step by Illinois iteration on the step length.
            let g0 = self.event(self.p, &self.q, self.work);
            let g1 = self.event(self.p + h, &Vector2::new(y_new.x, y_new.y), y_new.z);
            let (h_acc, y_acc, err_acc, hit) = if g1 >= 0.0 {
                let (hh, yy, ee) = self.locate(h, &y, g0, g1, &s_hat);
                (hh, yy, ee, true)
            } else {
                (h, y_new, err, false)
            };
            self.add_error(err_acc.x.hypot(err_acc.y) + err_acc.z.abs() / speed_scale.max(f64::MIN_POSITIVE));
            self.p += h_acc;
            self.q = Vector2::new(y_acc.x, y_acc.y);
            self.work = y_acc.z;
            if hit {
                if self.compression.is_none() {
                    if self.compress_here() {
                        return Ok(SegmentEnd::Terminated);
                    }
                } else {
                    return Ok(SegmentEnd::Terminated);
                }
            }
            h *= (0.9 * ratio.max(1e-10).powf(-0.2)).clamp(0.2, 5.0);
        }
    }

    /// Finds the step length h* ∈ (0, h] at which the event function crosses zero.
    fn locate(
        &mut self,
        h: f64,
        y: &Vector3<f64>,
        g0: f64,
        g1: f64,
        s_hat: &Vector2<f64>,
    ) -> (f64, Vector3<f64>, Vector3<f64>) {
        let (mut lo, mut hi, mut g_lo, mut g_hi) = (0.0, h, g0, g1);
        let mut best = self.dp45_step(self.p, y, h, s_hat);
        let mut best_h = h;
        let mut side = 0;
        for _ in 0..100 {
            if g_hi == 0.0 || (hi - lo) <= 4.0 * f64::EPSILON * (self.p + hi) {
                break;
            }
            let mut mid = hi - g_hi * (hi - lo) / (g_hi - g_lo);
            if !(mid > lo && mid < hi) {
                mid = 0.5 * (lo + hi);
            }
            let (ym, em) = self.dp45_step(self.p, y, mid, s_hat);
            self.steps += 1;
            let gm = self.event(self.p + mid, &Vector2::new(ym.x, ym.y), ym.z);
            if gm >= 0.0 {
                hi = mid;
                g_hi = gm;
                best = (ym, em);
                best_h = mid;
                if side == 1 {
                    g_lo *= 0.5;
                }
                side = 1;
            } else {
                lo = mid;
                g_lo = gm;
                if side == -1 {
                    g_hi *= 0.5;
                }
                side = -1;
            }
        }
        (best_h, best.0, best.1)
    }
}
