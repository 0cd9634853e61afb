//! One frictional point impact in contact space: given the 3×3 contact mobility W (Delassus
//! matrix, u⁺ = u⁻ + W P) and the pre-impact relative velocity u⁻ of the contact point, find
//! the impulse P with restitution and isotropic Coulomb friction (7.94–7.99).
//!
//! # The impulse-parameterised process (Routh, Keller, Stronge)
//! The impact is followed as a function of the accumulated normal impulse p, which grows
//! monotonically (Keller 1986; Stronge, *Impact Mechanics*, ch. 5). With P = (P_T, p) in the
//! contact frame (t₁, t₂, n) and u(p) = u⁻ + W P(p):
//! - while the contact slips (u_T ≠ 0) the friction impulse opposes the slip at its limit,
//!   dP_T/dp = −f u_T/|u_T| (7.97, 7.99); in 3-D the slip direction can *swerve*, and this
//!   ODE is integrated with an embedded Dormand–Prince 5(4) pair whose local error estimates
//!   are summed into the reported `integration_error`. When the swerve vanishes (planar
//!   impacts, decoupled W) the slip direction is constant and the segment is solved exactly;
//! - when the slip halts (|u_T| reaches 0) the contact sticks if the impulse ratio needed to
//!   keep u_T = 0, t = −W_TT⁻¹ W_Tn, lies in the friction cone |t| ≤ f (7.98); otherwise slip
//!   resumes along the unique ray ŝ with (W_Tn − f W_TT ŝ) ∥ ŝ ("reversed" slip);
//! - compression ends when u_n = 0, at p = p_c;
//! - restitution ends the impact at p_f, by the selected [`RestitutionLaw`].
//!
//! # Restitution laws and energy
//! - **Newton** (kinematic, 7.94): u_n⁺ = −e u_n⁻. With friction it can *gain* energy when the
//!   slip halts or reverses (Kane's paradox, Kane & Levinson 1985).
//! - **Poisson** (kinetic): p_f = (1 + e) p_c.
//! - **Stronge** (energetic, the default): the work of the normal impulse during restitution
//!   is e² times the work absorbed during compression: ∫_{p_c}^{p_f} u_n dp = −e² ∫_0^{p_c} u_n dp.
//!   Friction work is never positive and the normal work is −(1 − e²)·(compression work) ≤ 0,
//!   so this law never gains energy for e ≤ 1. All three laws coincide for frictionless
//!   contacts and whenever the friction impulse keeps a constant ratio to the normal impulse.
//!
//! The energy change is reported by the exact identity ΔT = P·(u⁻ + ½ W P).

use crate::ImpulseError;
use crate::body::{check_symmetric_psd, orthonormal_complement, unit_vector};
use crate::error::{check_all_finite, check_finite};
use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};

/// Which relation ends the restitution phase of a frictional impact.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum RestitutionLaw {
    /// Newton's kinematic law (7.94): u_n⁺ = −e u_n⁻. May gain energy with friction.
    Newton,
    /// Poisson's kinetic law: the normal impulse of restitution is e times that of compression.
    Poisson,
    /// Stronge's energetic law: the normal work of restitution is −e² times that of
    /// compression. Never gains energy; the default.
    #[default]
    Stronge,
}

/// The material law of a contact: restitution coefficient e ∈ [0, 1], Coulomb friction
/// coefficient f ≥ 0 (f = +∞ means no slip) and the restitution law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactLaw {
    /// Coefficient of restitution λ (syllabus notation), e ∈ [0, 1].
    pub restitution: f64,
    /// Isotropic Coulomb friction coefficient f ≥ 0; `f64::INFINITY` for a contact that cannot slip.
    pub friction: f64,
    /// The relation that ends restitution.
    pub law: RestitutionLaw,
}

impl ContactLaw {
    /// A validated contact law.
    pub fn new(restitution: f64, friction: f64, law: RestitutionLaw) -> Result<Self, ImpulseError> {
        let value = Self {
            restitution,
            friction,
            law,
        };
        value.validate()?;
        Ok(value)
    }

    /// A smooth contact (f = 0) with restitution `e` (7.95); the law does not matter.
    pub fn smooth(restitution: f64) -> Result<Self, ImpulseError> {
        Self::new(restitution, 0.0, RestitutionLaw::Stronge)
    }

    pub(crate) fn validate(&self) -> Result<(), ImpulseError> {
        check_finite("restitution", self.restitution)?;
        if !(0.0..=1.0).contains(&self.restitution) {
            return Err(ImpulseError::RestitutionOutOfRange(self.restitution));
        }
        if self.friction.is_nan() || self.friction == f64::NEG_INFINITY {
            return Err(ImpulseError::NonFinite {
                what: "friction",
                value: self.friction,
            });
        }
        if self.friction < 0.0 {
            return Err(ImpulseError::NegativeFriction(self.friction));
        }
        Ok(())
    }
}

/// Accuracy and budget of the impact process.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImpactOptions {
    /// Relative tolerance of the swerving-slip integration and of slip halting (default 1e-10).
    pub tolerance: f64,
    /// Maximum number of integration steps (default 100 000).
    pub max_steps: usize,
}

impl Default for ImpactOptions {
    fn default() -> Self {
        Self {
            tolerance: 1e-10,
            max_steps: 100_000,
        }
    }
}

/// How the contact behaved during the impact.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactMode {
    /// No impulse: the contact was separating or grazing (u_n⁻ ≥ 0).
    NoImpact,
    /// Smooth contact (f = 0): no tangential impulse.
    Frictionless,
    /// The contact stuck from the start (or f = ∞).
    Stick,
    /// The contact slipped throughout (possibly swerving).
    Slip,
    /// The contact slipped, the slip halted and it stuck for the rest of the impact.
    SlipThenStick,
    /// The contact slipped, the slip halted and resumed in a new direction (reversal).
    Reversed,
}

/// The result of one point impact in contact space (world frame W).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactImpulse {
    /// Total impulse P on body 2 (body 1 receives −P), N·s.
    pub impulse_w: Vector3<f64>,
    /// Normal impulse p_f = P·n ≥ 0 (S_n in 7.96).
    pub normal_impulse: f64,
    /// Tangential (friction) impulse P − p_f n (W t in 7.96).
    pub tangential_impulse_w: Vector3<f64>,
    /// Normal impulse at the end of compression, p_c.
    pub compression_impulse: f64,
    /// Relative velocity of the contact point after the impact, u⁺ = u⁻ + W P.
    pub u_after_w: Vector3<f64>,
    /// The contact mode.
    pub mode: ContactMode,
    /// Energy change ΔT = P·(u⁻ + ½ W P), J.
    pub energy_change: f64,
    /// Estimated error of the impulse (N·s) from the swerving-slip integration and the slip
    /// halting cut-off; 0 when every segment was solved in closed form.
    pub integration_error: f64,
    /// Number of integration steps (accepted and rejected) plus closed-form segments.
    pub steps: usize,
}

/// Resolves one impact in contact space: `w_w` is the contact mobility W (symmetric positive
/// semidefinite, W frame), `u_w` the relative velocity u⁻ of body 2's contact point with
/// respect to body 1's, `n_w` the unit normal pointing into body 2 (7.72). Approach means
/// u⁻·n < 0; a grazing or separating contact receives no impulse. The accuracy of the
/// impulse is reported as [`ContactImpulse::integration_error`] (0 for closed-form segments).
///
/// Errors: non-finite input, a W that is not symmetric PSD, a normal that is not a unit
/// vector, an invalid [`ContactLaw`], [`ImpulseError::Singular`] when no impulse can stop the
/// approach (W_nn ≈ 0) or the tolerance is not positive, and [`ImpulseError::NotConverged`] when the process jams or exceeds
/// [`ImpactOptions::max_steps`].
pub fn resolve_in_contact_space(
    w_w: &Matrix3<f64>,
    u_w: &Vector3<f64>,
    n_w: &Vector3<f64>,
    law: &ContactLaw,
    options: &ImpactOptions,
) -> Result<ContactImpulse, ImpulseError> {
    check_all_finite("contact mobility", w_w.iter())?;
    check_symmetric_psd("contact mobility", w_w)?;
    check_all_finite("relative velocity", u_w.iter())?;
    let n = unit_vector("contact normal", n_w)?;
    law.validate()?;
    resolve_validated(w_w, u_w, &n, law, options)
}

/// [`resolve_in_contact_space`] for inputs already validated (W symmetric PSD and finite,
/// u finite, n unit, law valid).
pub(crate) fn resolve_validated(
    w_w: &Matrix3<f64>,
    u_w: &Vector3<f64>,
    n: &Vector3<f64>,
    law: &ContactLaw,
    options: &ImpactOptions,
) -> Result<ContactImpulse, ImpulseError> {
    let n = *n;
    check_finite("tolerance", options.tolerance)?;
    if options.tolerance <= 0.0 {
        return Err(ImpulseError::Singular {
            what: "tolerance must be positive",
            value: options.tolerance,
        });
    }
    let u_n = u_w.dot(&n);
    if u_n >= 0.0 {
        return Ok(ContactImpulse {
            impulse_w: Vector3::zeros(),
            normal_impulse: 0.0,
            tangential_impulse_w: Vector3::zeros(),
            compression_impulse: 0.0,
            u_after_w: *u_w,
            mode: ContactMode::NoImpact,
            energy_change: 0.0,
            integration_error: 0.0,
            steps: 0,
        });
    }
    let (t1, t2) = orthonormal_complement(&n);
    let r = Matrix3::from_columns(&[t1, t2, n]);
    let w_sym = (w_w + w_w.transpose()) * 0.5;
    let w = r.transpose() * w_sym * r;
    let u0 = r.transpose() * u_w;
    let mut process = Process::new(w, u0, law, options)?;
    process.run()?;
    let p_c = Vector3::new(process.q.x, process.q.y, process.p);
    let impulse_w = r * p_c;
    let normal_impulse = process.p;
    let u_after_w = u_w + w_sym * impulse_w;
    let energy_change = impulse_w.dot(&(u_w + w_sym * impulse_w * 0.5));
    if let Some(value) = impulse_w
        .iter()
        .chain(u_after_w.iter())
        .copied()
        .find(|v| !v.is_finite())
    {
        return Err(ImpulseError::NotConverged {
            reason: "the impulse overflowed (inputs too large for f64)",
            steps: process.steps,
            normal_impulse: value,
        });
    }
    Ok(ContactImpulse {
        impulse_w,
        normal_impulse,
        tangential_impulse_w: impulse_w - n * normal_impulse,
        compression_impulse: process.compression.map_or(process.p, |(p, _)| p),
        u_after_w,
        mode: process.mode(),
        energy_change,
        integration_error: process.error,
        steps: process.steps,
    })
}

/// What a segment of the process ended with.
enum SegmentEnd {
    /// The impact is over.
    Terminated,
    /// The slip halted (|u_T| ≤ η).
    Halted,
}

/// The state of the impulse-parameterised process, in the contact frame (t₁, t₂, n).
struct Process {
    w: Matrix3<f64>,
    u0: Vector3<f64>,
    f: f64,
    e: f64,
    law: RestitutionLaw,
    tolerance: f64,
    max_steps: usize,
    /// Slip speeds below η = tolerance·|u⁻| count as halted.
    eta: f64,
    /// Impulse scale |u⁻| / max|W_ij| for absolute error control.
    p_scale: f64,
    p: f64,
    q: Vector2<f64>,
    /// Normal work ∫₀^p u_n dp.
    work: f64,
    compression: Option<(f64, f64)>,
    error: f64,
    steps: usize,
    halted: bool,
    final_mode: Option<ContactMode>,
}

impl Process {
    fn new(w: Matrix3<f64>, u0: Vector3<f64>, law: &ContactLaw, options: &ImpactOptions) -> Result<Self, ImpulseError> {
        let w_max = w.amax();
        if w[(2, 2)] <= 1e-14 * w_max {
            return Err(ImpulseError::Singular {
                what: "both bodies are immovable along the contact normal while approaching (W_nn)",
                value: w[(2, 2)],
            });
        }
        let speed = u0.norm();
        Ok(Self {
            w,
            u0,
            f: law.friction,
            e: law.restitution,
            law: law.law,
            tolerance: options.tolerance,
            max_steps: options.max_steps,
            eta: options.tolerance * speed,
            p_scale: speed / w_max,
            p: 0.0,
            q: Vector2::zeros(),
            work: 0.0,
            compression: None,
            error: 0.0,
            steps: 0,
            halted: false,
            final_mode: None,
        })
    }

    fn velocity(&self, p: f64, q: &Vector2<f64>) -> Vector3<f64> {
        self.u0 + self.w * Vector3::new(q.x, q.y, p)
    }

    fn w_tt(&self) -> Matrix2<f64> {
        self.w.fixed_view::<2, 2>(0, 0).into_owned()
    }

    fn w_tn(&self) -> Vector2<f64> {
        self.w.fixed_view::<2, 1>(0, 2).into_owned()
    }

    fn mode(&self) -> ContactMode {
        self.final_mode.unwrap_or(ContactMode::Slip)
    }

    fn run(&mut self) -> Result<(), ImpulseError> {
        if self.f == 0.0 {
            self.final_mode = Some(ContactMode::Frictionless);
            self.linear(Vector2::zeros(), f64::INFINITY)?;
            return Ok(());
        }
        if self.f == f64::INFINITY {
            // The limit f → ∞: any slip is stopped at once by a tangential impulse at zero
            // normal impulse (it does no normal work), then the contact sticks.
            let u = self.velocity(0.0, &self.q);
            let ut = Vector2::new(u.x, u.y);
            if ut.norm() > 0.0 {
                self.q = -pseudo_inverse2(&self.w_tt()) * ut;
            }
            self.final_mode = Some(ContactMode::Stick);
            let t = -pseudo_inverse2(&self.w_tt()) * self.w_tn();
            self.linear_stick(t)?;
            return Ok(());
        }
        let u = self.velocity(self.p, &self.q);
        let ut = Vector2::new(u.x, u.y);
        let speed = ut.norm();
        if speed <= self.eta {
            return self.continue_from_rest();
        }
        let s_hat = ut / speed;
        let rate = self.w_tn() - self.f * self.w_tt() * s_hat;
        let swerve = rate.x * s_hat.y - rate.y * s_hat.x;
        let end = if swerve.abs() <= 8.0 * f64::EPSILON * rate.norm() {
            // Straight slip: u_T stays along ŝ, |u_T| changes at the constant rate ŝ·rate.
            let along = s_hat.dot(&rate);
            let halt = if along < 0.0 { speed / -along } else { f64::INFINITY };
            self.steps += 1;
            self.linear(-self.f * s_hat, halt)?
        } else {
            self.integrate_swerving()?
        };
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

    /// The contact has no slip: stick if the cone allows it, otherwise slip along the ray.
    fn continue_from_rest(&mut self) -> Result<(), ImpulseError> {
        let t_stick = -pseudo_inverse2(&self.w_tt()) * self.w_tn();
        self.steps += 1;
        if t_stick.norm() <= self.f * (1.0 + 1e-12) {
            self.final_mode = Some(if self.halted {
                ContactMode::SlipThenStick
            } else {
                ContactMode::Stick
            });
            self.linear_stick(t_stick)?;
        } else {
            let s_hat = ray_direction(&self.w_tt(), &self.w_tn(), self.f);
            self.final_mode = Some(if self.halted {
                ContactMode::Reversed
            } else {
                ContactMode::Slip
            });
            self.linear(-self.f * s_hat, f64::INFINITY)?;
        }
        Ok(())
    }

    /// The termination event function: negative before the event, ≥ 0 at and after it.
    /// Before compression ends it is u_n; afterwards it is the restitution law's.
    fn event(&self, p: f64, q: &Vector2<f64>, work: f64) -> f64 {
        let u_n = self.velocity(p, q).z;
        match self.compression {
            None => u_n,
            Some((p_c, work_c)) => match self.law {
                RestitutionLaw::Newton => u_n + self.e * self.u0.z,
                RestitutionLaw::Poisson => p - (1.0 + self.e) * p_c,
                RestitutionLaw::Stronge => work - (1.0 - self.e * self.e) * work_c,
            },
        }
    }

    /// Marks the end of compression at the current state; true when the impact also ends here.
    fn compress_here(&mut self) -> bool {
        self.compression = Some((self.p, self.work));
        self.event(self.p, &self.q, self.work) >= 0.0
    }

    /// A sticking segment with the impulse ratio `t` that keeps u_T = 0, to the end of the
    /// impact. When W has a null vector with a normal component (a contact point that can only
    /// move in a plane or on a line: a body on a spherical joint, a planar mechanism), the
    /// normal velocity cannot change along this ray (W_nn − W_nT W_TT⁺ W_Tn = 0) and u lies in
    /// range(W), so u_n is zero as soon as u_T is: the point is stopped for good and the impact
    /// ends here; the residual |u_n| (from the slip-halting cut-off) is added to the error as
    /// the impulse |u_n|/W_nn.
    fn linear_stick(&mut self, t: Vector2<f64>) -> Result<SegmentEnd, ImpulseError> {
        let b = (self.w * Vector3::new(t.x, t.y, 1.0)).z;
        if b.abs() <= 1e-9 * self.w.amax() {
            let a = self.velocity(self.p, &self.q).z;
            self.error += a.abs() / self.w[(2, 2)];
            if self.compression.is_none() {
                self.compression = Some((self.p, self.work));
            }
            return Ok(SegmentEnd::Terminated);
        }
        self.linear(t, f64::INFINITY)
    }

    /// A segment with constant impulse ratio dP/dp = (t, 1), at most `limit` long in p. Every
    /// event is located in closed form (u_n is linear and the work quadratic in p).
    fn linear(&mut self, t: Vector2<f64>, limit: f64) -> Result<SegmentEnd, ImpulseError> {
        let d = Vector3::new(t.x, t.y, 1.0);
        let b = (self.w * d).z;
        let mut remaining = limit;
        loop {
            let a = self.velocity(self.p, &self.q).z;
            let s = match self.compression {
                None => {
                    if a >= 0.0 {
                        0.0
                    } else if b > 0.0 {
                        -a / b
                    } else {
                        f64::INFINITY
                    }
                }
                Some((p_c, work_c)) => match self.law {
                    RestitutionLaw::Newton => {
                        let target = -self.e * self.u0.z;
                        if a >= target {
                            0.0
                        } else if b > 0.0 {
                            (target - a) / b
                        } else {
                            f64::INFINITY
                        }
                    }
                    RestitutionLaw::Poisson => ((1.0 + self.e) * p_c - self.p).max(0.0),
                    RestitutionLaw::Stronge => {
                        let delta = (1.0 - self.e * self.e) * work_c - self.work;
                        if delta <= 0.0 {
                            0.0
                        } else {
                            // ½ b s² + a s = delta, smallest positive root, stable form.
                            let disc = a * a + 2.0 * b * delta;
                            if disc < 0.0 || (a <= 0.0 && b <= 0.0) {
                                f64::INFINITY
                            } else {
                                2.0 * delta / (a + disc.sqrt())
                            }
                        }
                    }
                },
            };
            if s.is_infinite() || s > remaining {
                if remaining.is_infinite() {
                    return Err(ImpulseError::NotConverged {
                        reason: "the normal velocity does not increase with the normal impulse (frictional jam)",
                        steps: self.steps,
                        normal_impulse: self.p,
                    });
                }
                self.advance(&d, remaining, a, b);
                return Ok(SegmentEnd::Halted);
            }
            self.advance(&d, s, a, b);
            remaining -= s;
            if self.compression.is_none() {
                if self.compress_here() {
                    return Ok(SegmentEnd::Terminated);
                }
            } else {
                return Ok(SegmentEnd::Terminated);
            }
        }
    }

    fn advance(&mut self, d: &Vector3<f64>, s: f64, a: f64, b: f64) {
        self.p += s;
        self.q += Vector2::new(d.x, d.y) * s;
        self.work += a * s + 0.5 * b * s * s;
    }

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

    /// Integrates a slip whose direction swerves, until the impact terminates or the slip halts.
    fn integrate_swerving(&mut self) -> Result<SegmentEnd, ImpulseError> {
        let speed_scale = self.u0.norm();
        let atol_q = self.tolerance * self.p_scale;
        let atol_w = self.tolerance * self.p_scale * speed_scale;
        let p_max = 1e12 * self.p_scale;
        let mut h = 1e-2 * self.p_scale;
        let max_rate = self.w_tn().norm() + self.f * self.w_tt().norm();
        loop {
            if self.steps >= self.max_steps {
                return Err(ImpulseError::NotConverged {
                    reason: "step budget exhausted in swerving slip",
                    steps: self.steps,
                    normal_impulse: self.p,
                });
            }
            if self.p > p_max {
                return Err(ImpulseError::NotConverged {
                    reason: "the normal impulse grows without bound (frictional jam)",
                    steps: self.steps,
                    normal_impulse: self.p,
                });
            }
            let u = self.velocity(self.p, &self.q);
            let ut = Vector2::new(u.x, u.y);
            let speed = ut.norm();
            let s_hat = ut / speed;
            let rate = self.w_tn() - self.f * self.w_tt() * s_hat;
            let along = s_hat.dot(&rate);
            if speed <= self.eta {
                // Halting cut-off: the rest of the slip (≈ speed/|rate| in p) is replaced by
                // the stick or ray segment; bound the impulse difference by 2 f Δp (+ 1 for p).
                if along < 0.0 {
                    self.error += (2.0 * self.f + 1.0) * speed / -along;
                }
                return Ok(SegmentEnd::Halted);
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
            self.error += err_acc.x.hypot(err_acc.y) + err_acc.z.abs() / speed_scale.max(f64::MIN_POSITIVE);
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

/// The pseudo-inverse of a symmetric PSD 2×2 matrix (eigenvalues ≤ 1e-12·λ_max dropped).
fn pseudo_inverse2(m: &Matrix2<f64>) -> Matrix2<f64> {
    let eig = m.symmetric_eigen();
    let max = eig.eigenvalues.max();
    let mut inverse = Matrix2::zeros();
    for k in 0..2 {
        let lambda = eig.eigenvalues[k];
        if lambda > 1e-12 * max && lambda > 0.0 {
            let v = eig.eigenvectors.column(k);
            inverse += v * v.transpose() / lambda;
        }
    }
    inverse
}

/// The unit direction ŝ of resumed slip: (W_Tn − f W_TT ŝ) = α ŝ with α > 0, when sticking is
/// impossible (|W_TT⁻¹ W_Tn| > f). With W_TT = V diag(λ) Vᵀ and c = Vᵀ W_Tn, ŝ = V c/(fλ + α)
/// normalised, where α ∈ (0, |W_Tn|] solves Σ cᵢ²/(fλᵢ + α)² = 1 (monotone; safeguarded Newton).
fn ray_direction(w_tt: &Matrix2<f64>, w_tn: &Vector2<f64>, f: f64) -> Vector2<f64> {
    let eig = w_tt.symmetric_eigen();
    let c = eig.eigenvectors.transpose() * w_tn;
    let lam = eig.eigenvalues.map(|l| (f * l).max(0.0));
    let norm_at = |alpha: f64| (c.x / (lam.x + alpha)).hypot(c.y / (lam.y + alpha));
    let (mut lo, mut hi) = (0.0_f64, w_tn.norm());
    let mut alpha = 0.5 * hi;
    for _ in 0..200 {
        let s = norm_at(alpha);
        let psi = 1.0 / s - 1.0;
        if psi < 0.0 {
            lo = alpha;
        } else {
            hi = alpha;
        }
        if psi.abs() <= 4.0 * f64::EPSILON || hi - lo <= 4.0 * f64::EPSILON * hi {
            break;
        }
        let d3 = c.x * c.x / (lam.x + alpha).powi(3) + c.y * c.y / (lam.y + alpha).powi(3);
        let dpsi = d3 / (s * s * s);
        let next = alpha - psi / dpsi;
        alpha = if next > lo && next < hi && dpsi.is_finite() {
            next
        } else {
            0.5 * (lo + hi)
        };
    }
    let s = eig.eigenvectors * Vector2::new(c.x / (lam.x + alpha), c.y / (lam.y + alpha));
    let norm = s.norm();
    if norm > 0.0 { s / norm } else { Vector2::new(1.0, 0.0) }
}
