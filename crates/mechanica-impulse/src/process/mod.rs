//! The impulse-parameterised impact process of [`crate::contact_space`] in the contact frame
//! (t₁, t₂, n): its state, the choice between slip, stick and resumed slip, and the
//! termination events of the restitution laws. Segments with a constant impulse ratio are
//! solved in closed form ([`linear`]); swerving slip is integrated ([`swerving`]).
//!
//! # The error bound
//! `error` bounds |P − P*|, P* the impulse of the exact process on the stored W and u⁻, and
//! is reported as `integration_error`. Each segment adds what it can get wrong: the local
//! error estimates of the integration and the slip-halting cut-off, the error bound of a
//! tangential solve ([`crate::tangent_block`]), and for a closed-form segment the error of
//! its length, propagated from the errors of the velocity, the normal rate and the state
//! through the slope of the event that ends it (docs/theory.md, "Error of the impact
//! process"). Velocities and rates are evaluated in compensated arithmetic
//! ([`crate::compensated::dot2`]), so that their own rounding is of the order of their size.

mod linear;
mod swerving;

use crate::ImpulseError;
use crate::compensated::{UNIT_ROUNDOFF, abs_dot, dot2};
use crate::contact_space::{ContactLaw, ContactMode, ImpactOptions, RestitutionLaw};
use crate::tangent_block::{BLOCK_RANK_RELATIVE, Factor2, Solution2, slip_ray};
use linear::Direction;
use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};

/// The state at the end of compression.
#[derive(Debug, Clone, Copy)]
struct Compression {
    /// p_c.
    p: f64,
    /// The compression work ∫₀^{p_c} u_n dp (negative).
    work: f64,
    /// A bound on the error of `work`.
    work_error: f64,
    /// A bound on the error of p_c.
    p_error: f64,
}

/// What a segment of the process ended with.
enum SegmentEnd {
    /// The impact is over.
    Terminated,
    /// The slip halted (|u_T| ≤ η).
    Halted,
}

/// The state of the impulse-parameterised process, in the contact frame (t₁, t₂, n).
pub(crate) struct Process {
    /// W in the contact frame as hi + lo (`w` + `w_lo`): rounding it to one double per entry
    /// would perturb an ill-conditioned tangential block by κ·u.
    w: Matrix3<f64>,
    w_lo: Matrix3<f64>,
    /// u⁻ in the contact frame as hi + lo.
    u0: Vector3<f64>,
    u0_lo: Vector3<f64>,
    f: f64,
    e: f64,
    law: RestitutionLaw,
    tolerance: f64,
    max_steps: usize,
    /// Slip speeds below η = tolerance·|u⁻| count as halted.
    eta: f64,
    /// Impulse scale |u⁻| / max|W_ij| for absolute error control.
    p_scale: f64,
    /// The tangential block W_TT, factored once.
    block: Factor2,
    /// Accumulated normal impulse p.
    pub p: f64,
    /// Accumulated tangential impulse P_T.
    pub q: Vector2<f64>,
    /// Normal work of the current phase: ∫₀^p u_n dp during compression, ∫_{p_c}^p u_n dp
    /// afterwards (kept apart so that Stronge's event e²·|compression work| is not the small
    /// difference of two large works).
    work: f64,
    /// A bound on the error of `work`.
    work_error: f64,
    /// The state at the end of compression.
    compression: Option<Compression>,
    /// A bound on |P − P*| (see the module documentation).
    pub error: f64,
    /// A bound on |p − p*|, the normal impulse alone (≤ `error`).
    p_error: f64,
    /// Integration steps and closed-form segments.
    pub steps: usize,
    halted: bool,
    final_mode: Option<ContactMode>,
}

impl Process {
    /// The process for the contact-frame mobility W = `w.0` + `w.1` and approach velocity
    /// u⁻ = `u0.0` + `u0.1` (unevaluated sums).
    pub fn new(
        (w, w_lo): (Matrix3<f64>, Matrix3<f64>),
        (u0, u0_lo): (Vector3<f64>, Vector3<f64>),
        law: &ContactLaw,
        options: &ImpactOptions,
    ) -> Result<Self, ImpulseError> {
        let w_max = w.amax();
        if w[(2, 2)] <= 1e-14 * w_max {
            return Err(ImpulseError::Singular {
                what: "both bodies are immovable along the contact normal while approaching (W_nn)",
                value: w[(2, 2)],
            });
        }
        let speed = u0.norm();
        let block = |m: &Matrix3<f64>| m.fixed_view::<2, 2>(0, 0).into_owned();
        Ok(Self {
            w,
            w_lo,
            u0,
            u0_lo,
            f: law.friction,
            e: law.restitution,
            law: law.law,
            tolerance: options.tolerance,
            max_steps: options.max_steps,
            eta: options.tolerance * speed,
            p_scale: speed / w_max,
            block: Factor2::new(&block(&w), &block(&w_lo), BLOCK_RANK_RELATIVE * w_max),
            p: 0.0,
            q: Vector2::zeros(),
            work: 0.0,
            work_error: 0.0,
            compression: None,
            error: 0.0,
            p_error: 0.0,
            steps: 0,
            halted: false,
            final_mode: None,
        })
    }

    /// The normal impulse at the end of compression (the final one if it never ended).
    pub fn compression_impulse(&self) -> f64 {
        self.compression.map_or(self.p, |c| c.p)
    }

    /// Row i of W as the six terms (hi, lo) that multiply (P, P).
    fn row_terms(&self, i: usize) -> [f64; 6] {
        let (w, lo) = (&self.w, &self.w_lo);
        [w[(i, 0)], w[(i, 1)], w[(i, 2)], lo[(i, 0)], lo[(i, 1)], lo[(i, 2)]]
    }

    /// u(p, q) = u⁻ + W (q, p), each component in compensated arithmetic.
    fn velocity(&self, p: f64, q: &Vector2<f64>) -> Vector3<f64> {
        let x = [q.x, q.y, p, q.x, q.y, p, 1.0, 1.0];
        let row = |i: usize| {
            let w = self.row_terms(i);
            dot2(&[w[0], w[1], w[2], w[3], w[4], w[5], self.u0[i], self.u0_lo[i]], &x)
        };
        Vector3::new(row(0), row(1), row(2))
    }

    /// The current normal velocity a = u_n and a bound on its error: the state error
    /// propagated through row n of W, plus the rounding of the compensated evaluation.
    fn normal_velocity(&self) -> (f64, f64) {
        let a = self.velocity(self.p, &self.q).z;
        let terms = self.u0.z.abs() + abs_dot(&self.row_terms(2)[..3], &[self.q.x, self.q.y, self.p]);
        let u = UNIT_ROUNDOFF;
        let row = self.w.row(2).norm();
        (a, row * self.error + 4.0 * u * a.abs() + 8.0 * u * u * terms)
    }

    fn w_tt(&self) -> Matrix2<f64> {
        self.w.fixed_view::<2, 2>(0, 0).into_owned()
    }

    fn w_tt_lo(&self) -> Matrix2<f64> {
        self.w_lo.fixed_view::<2, 2>(0, 0).into_owned()
    }

    fn w_tn(&self) -> Vector2<f64> {
        self.w.fixed_view::<2, 1>(0, 2).into_owned()
    }

    fn w_tn_lo(&self) -> Vector2<f64> {
        self.w_lo.fixed_view::<2, 1>(0, 2).into_owned()
    }

    /// The stick ratio t with W_TT t = −W_Tn, refined, with its error bound.
    fn stick_ratio(&self) -> Solution2 {
        self.block.solve(&-self.w_tn(), &-self.w_tn_lo())
    }

    /// The contact mode reached.
    pub fn mode(&self) -> ContactMode {
        self.final_mode.unwrap_or(ContactMode::Slip)
    }

    /// Runs the process to the end of the impact.
    pub fn run(&mut self) -> Result<(), ImpulseError> {
        if self.f == 0.0 {
            self.final_mode = Some(ContactMode::Frictionless);
            let none = Solution2 {
                x: Vector2::zeros(),
                lo: Vector2::zeros(),
                error: 0.0,
            };
            self.linear(Direction::slip(&none, 0.0), (f64::INFINITY, 0.0))?;
            return Ok(());
        }
        if self.f == f64::INFINITY {
            return self.run_without_slip();
        }
        let u = self.velocity(self.p, &self.q);
        let ut = Vector2::new(u.x, u.y);
        let speed = ut.norm();
        if speed <= self.eta {
            return self.continue_from_rest();
        }
        let end = self.first_slip(&ut, speed)?;
        match end {
            SegmentEnd::Terminated => {
                self.final_mode = Some(ContactMode::Slip);
                Ok(())
            }
            SegmentEnd::Halted => {
                self.halted = true;
                self.continue_from_rest()
            }
        }
    }

    /// The limit f → ∞: any slip is stopped at once by a tangential impulse at zero normal
    /// impulse (it does no normal work), then the contact sticks.
    fn run_without_slip(&mut self) -> Result<(), ImpulseError> {
        let u = self.velocity(0.0, &self.q);
        let ut = Vector2::new(u.x, u.y);
        if ut.norm() > 0.0 {
            let stop = self.block.solve(&-ut, &Vector2::zeros());
            self.q = stop.x;
            self.add_error(stop.error);
        }
        self.final_mode = Some(ContactMode::Stick);
        self.linear_stick(Direction::stick(&self.stick_ratio()))?;
        Ok(())
    }

    /// The slip that the initial tangential velocity `ut` (of length `speed`) starts: straight
    /// (closed form) when its direction cannot swerve, integrated otherwise.
    fn first_slip(&mut self, ut: &Vector2<f64>, speed: f64) -> Result<SegmentEnd, ImpulseError> {
        let s_hat = ut / speed;
        let rate = self.w_tn() - self.f * self.w_tt() * s_hat;
        let swerve = rate.x * s_hat.y - rate.y * s_hat.x;
        if swerve.abs() > 8.0 * f64::EPSILON * rate.norm() {
            return self.integrate_swerving();
        }
        self.straight_slip(&s_hat, speed, 4.0 * UNIT_ROUNDOFF)
    }

    /// Slip that keeps its direction ŝ (error bound `s_error`): u_T stays along ŝ and |u_T|
    /// changes at the constant rate ŝ·(W_Tn − f W_TT ŝ), so it halts, if at all, after
    /// Δp = `speed`/|ŝ·rate|, located in closed form.
    fn straight_slip(&mut self, s_hat: &Vector2<f64>, speed: f64, s_error: f64) -> Result<SegmentEnd, ImpulseError> {
        let along = s_hat.dot(&(self.w_tn() - self.f * self.w_tt() * s_hat));
        let u = UNIT_ROUNDOFF;
        let halt = if along < 0.0 {
            let speed_error = 4.0 * u * speed;
            let along_error = 4.0 * u * (self.w_tn().norm() + self.f * self.block.norm());
            (speed / -along, (speed_error + speed / -along * along_error) / -along)
        } else {
            (f64::INFINITY, 0.0)
        };
        self.steps += 1;
        let direction = Solution2 {
            x: *s_hat,
            lo: Vector2::zeros(),
            error: s_error,
        };
        self.linear(Direction::slip(&direction, self.f), halt)
    }

    /// The contact has no slip: stick if the cone allows it, otherwise slip along the ray.
    /// The tangential velocity left below the rest threshold η is neglected, and the error
    /// this makes is added to the bound ([`Process::rest_cutoff_error`]).
    fn continue_from_rest(&mut self) -> Result<(), ImpulseError> {
        let u = self.velocity(self.p, &self.q);
        let ut = Vector2::new(u.x, u.y);
        let t_stick = self.stick_ratio();
        self.steps += 1;
        let (direction, mode) = if t_stick.x.norm() <= self.f * (1.0 + 1e-12) {
            let mode = if self.halted {
                ContactMode::SlipThenStick
            } else {
                ContactMode::Stick
            };
            (Direction::stick(&t_stick), mode)
        } else {
            let ray = slip_ray((&self.w_tt(), &self.w_tt_lo()), (&self.w_tn(), &self.w_tn_lo()), self.f);
            let mode = if self.halted {
                ContactMode::Reversed
            } else {
                ContactMode::Slip
            };
            (Direction::slip(&ray, self.f), mode)
        };
        self.add_error(self.rest_cutoff_error(&ut, &direction));
        self.final_mode = Some(mode);
        if direction.is_stick() {
            self.linear_stick(direction)?;
        } else {
            self.linear(direction, (f64::INFINITY, 0.0))?;
        }
        Ok(())
    }

    /// The error of treating the tangential velocity `ut` (at most η) as rest before a segment
    /// along `dir`. The exact process would first slip along ŝ = u_T/|u_T|; when that slip
    /// halts (ŝ·(W_Tn − f W_TT ŝ) < 0) it lasts Δp = |u_T|/|ŝ·rate| and changes the tangential
    /// impulse by at most (f + |d_T|) Δp, and through row n of W the normal impulse by
    /// |W_nT| (f + |d_T|) Δp / b (not at all when the contact self-locks); when it would not
    /// halt, the impulse (1 + f)|W_TT⁺ u_T| that stops it at once takes the place of
    /// (f + |d_T|) Δp.
    fn rest_cutoff_error(&self, ut: &Vector2<f64>, dir: &Direction) -> f64 {
        let speed = ut.norm();
        if speed == 0.0 {
            return 0.0;
        }
        let s_hat = ut / speed;
        let along = s_hat.dot(&(self.w_tn() - self.w_tt() * s_hat * self.f));
        let d_t = dir.tangential_norm();
        let tangential = if along < 0.0 {
            (self.f + d_t) * speed / -along
        } else {
            (1.0 + self.f) * self.block.solve(ut, &Vector2::zeros()).x.norm()
        };
        if self.self_locks(dir) {
            // The normal velocity cannot change along this ratio: no normal impulse moves.
            return tangential;
        }
        let b = self.normal_rate(dir).0.abs();
        let w_nt = Vector2::new(self.w[(2, 0)], self.w[(2, 1)]).norm();
        tangential * (1.0 + w_nt * (1.0 + d_t) / b.max(f64::MIN_POSITIVE))
    }

    /// The termination event function: negative before the event, ≥ 0 at and after it.
    /// Before compression ends it is u_n; afterwards it is the restitution law's.
    fn event(&self, p: f64, q: &Vector2<f64>, work: f64) -> f64 {
        let u_n = self.velocity(p, q).z;
        match self.compression {
            None => u_n,
            Some(c) => match self.law {
                RestitutionLaw::Newton => u_n + self.e * self.u0.z,
                RestitutionLaw::Poisson => p - (1.0 + self.e) * c.p,
                RestitutionLaw::Stronge => work + self.e * self.e * c.work,
            },
        }
    }

    /// Adds `error` to the bounds of the impulse and of the normal impulse.
    fn add_error(&mut self, error: f64) {
        self.error += error;
        self.p_error += error;
    }

    /// Records the current state as the end of compression.
    fn mark_compression(&mut self) {
        self.compression = Some(Compression {
            p: self.p,
            work: self.work,
            work_error: self.work_error,
            p_error: self.p_error,
        });
    }

    /// Marks the end of compression at the current state and starts the restitution work at
    /// zero; true when the impact also ends here.
    fn compress_here(&mut self) -> bool {
        self.mark_compression();
        self.work = 0.0;
        self.work_error = 0.0;
        self.event(self.p, &self.q, self.work) >= 0.0
    }
}
