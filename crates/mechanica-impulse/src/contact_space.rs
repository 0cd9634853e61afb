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
//!   resumes along the unique ray ŝ with (W_Tn − f W_TT ŝ) ∥ ŝ ("reversed" slip). Both are
//!   solved on the tangential block W_TT factored by LDLᵀ with pivoting and a rank check
//!   (a block of condition above 1e12 is singular: its minimum-norm solution is taken), and
//!   refined in compensated arithmetic;
//! - compression ends when u_n = 0, at p = p_c;
//! - restitution ends the impact at p_f, by the selected [`RestitutionLaw`].
//!
//! # Self-locking
//! When the stick ratio t makes d = (t, 1) a null vector of W (a hinged body whose contact
//! point moves on a line, with f γ > |g_n| in the notation of docs/theory.md), sticking keeps
//! u_n at zero whatever the normal impulse: the contact self-locks. Compression ends there;
//! Poisson's law is met by continuing along d to p_f = (1 + e) p_c, which changes no
//! velocity; Newton's and Stronge's laws with e > 0 cannot be met, and the impact is reported
//! as a frictional jam ([`ImpulseError::NotConverged`]). With e = 0 every law ends at p_c.
//!
//! # Accuracy
//! W and u⁻ are taken into a contact frame kept to twice the working precision, velocities
//! and normal rates are evaluated in compensated arithmetic, and closed-form segments are
//! located from their start; `integration_error` bounds |P − P*| against the exact process on
//! the given W, u⁻ and normal (docs/theory.md, "Error of the impact process").
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
use crate::body::{check_symmetric_psd, unit_vector};
use crate::compensated::dot2;
use crate::contact_frame::{ContactFrame, FrameMatrix, FrameVector};
use crate::error::{check_all_finite, check_finite, check_result};
use crate::process::Process;
use nalgebra::{Matrix3, Vector3};

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
    /// Relative tolerance of the swerving-slip integration and of slip halting (default 1e-10;
    /// at most [`MAX_IMPACT_TOLERANCE`]: a slip slower than tolerance·|u⁻| counts as halted, so
    /// a larger value would end a slip that is still going on).
    pub tolerance: f64,
    /// Maximum number of integration steps (default 100 000).
    pub max_steps: usize,
}

/// The largest relative tolerance [`ImpactOptions`] accepts.
pub const MAX_IMPACT_TOLERANCE: f64 = 1e-2;

impl ImpactOptions {
    /// Ok when 0 < tolerance ≤ [`MAX_IMPACT_TOLERANCE`] and at least one step is allowed;
    /// [`ImpulseError::InvalidOption`] otherwise.
    pub fn check(&self) -> Result<(), ImpulseError> {
        if !(self.tolerance > 0.0 && self.tolerance <= MAX_IMPACT_TOLERANCE) {
            return Err(ImpulseError::InvalidOption {
                what: "tolerance",
                range: "(0, 1e-2]",
                value: self.tolerance,
            });
        }
        if self.max_steps == 0 {
            return Err(ImpulseError::InvalidOption {
                what: "max_steps",
                range: "[1, usize::MAX]",
                value: 0.0,
            });
        }
        Ok(())
    }
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
    /// A bound on the error of the impulse (N·s) against the exact process for the given W, u⁻
    /// and normal: the local error estimates of the swerving-slip integration, the slip-halting
    /// and rest cut-offs, and the rounding of every closed-form segment and tangential solve,
    /// propagated through the slopes of the events (docs/theory.md, "Error of the impact
    /// process"). A few ulps of |P| when no segment was integrated.
    pub integration_error: f64,
    /// Number of integration steps (accepted and rejected) plus closed-form segments.
    pub steps: usize,
}

/// Resolves one impact in contact space: `w_w` is the contact mobility W (symmetric positive
/// semidefinite, W frame), `u_w` the relative velocity u⁻ of body 2's contact point with
/// respect to body 1's, `n_w` the unit normal pointing into body 2 (7.72). Approach means
/// u⁻·n < 0; a grazing or separating contact receives no impulse. The accuracy of the
/// impulse is bounded by [`ContactImpulse::integration_error`].
///
/// Errors: non-finite input, a W that is not symmetric PSD, a normal that is not a unit
/// vector, an invalid [`ContactLaw`], [`ImpulseError::Singular`] when no impulse can stop the
/// approach (W_nn ≈ 0) or the tolerance is not positive, [`ImpulseError::NotConverged`] when
/// the process jams (the normal velocity cannot grow along the way the contact must go: a
/// slip with a non-positive normal rate, or a self-locked stick under Newton's or Stronge's
/// law with e > 0) or exceeds [`ImpactOptions::max_steps`], and
/// [`ImpulseError::NonFiniteResult`] when the impulse or a velocity overflows f64.
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
    unit_vector("contact normal", n_w)?;
    law.validate()?;
    resolve_validated(w_w, u_w, n_w, law, options)
}

/// [`resolve_in_contact_space`] for inputs already validated (W symmetric PSD and finite,
/// u finite, n unit, law valid).
///
/// `n_raw` is the normal as given (of unit length within the tolerance of
/// [`crate::body::UNIT_TOLERANCE`]); the contact frame uses it normalised.
pub(crate) fn resolve_validated(
    w_w: &Matrix3<f64>,
    u_w: &Vector3<f64>,
    n_raw: &Vector3<f64>,
    law: &ContactLaw,
    options: &ImpactOptions,
) -> Result<ContactImpulse, ImpulseError> {
    let frame = ContactFrame::new(n_raw);
    let w_sym = (w_w + w_w.transpose()) * 0.5;
    let contact = FramedContact {
        w: frame.congruence(&w_sym),
        u: frame.components(u_w),
        frame,
        u_w: *u_w,
    };
    resolve_framed(&contact, law, options)
}

/// A contact expressed in its frame: W and u⁻ there as (hi, lo) pairs, and u⁻ in world
/// components for the report of a contact that does not approach.
pub(crate) struct FramedContact {
    /// The contact frame.
    pub frame: ContactFrame,
    /// RᵀWR.
    pub w: FrameMatrix,
    /// Rᵀu⁻.
    pub u: FrameVector,
    /// u⁻ (world).
    pub u_w: Vector3<f64>,
}

/// Resolves the impact of a contact given in its frame (validated law and tolerance checked
/// here): the process of [`crate::process`], and the results in world components, with
/// u⁺ = u⁻ + W P and ΔT = ½ P·(u⁻ + u⁺) evaluated in the frame in compensated arithmetic.
pub(crate) fn resolve_framed(
    contact: &FramedContact,
    law: &ContactLaw,
    options: &ImpactOptions,
) -> Result<ContactImpulse, ImpulseError> {
    check_finite("tolerance", options.tolerance)?;
    options.check()?;
    let (w, u) = (&contact.w, &contact.u);
    if u.0.z + u.1.z >= 0.0 {
        return Ok(ContactImpulse {
            impulse_w: Vector3::zeros(),
            normal_impulse: 0.0,
            tangential_impulse_w: Vector3::zeros(),
            compression_impulse: 0.0,
            u_after_w: contact.u_w,
            mode: ContactMode::NoImpact,
            energy_change: 0.0,
            integration_error: 0.0,
            steps: 0,
        });
    }
    let mut process = Process::new(*w, *u, law, options)?;
    process.run()?;
    let p_c = Vector3::new(process.q.x, process.q.y, process.p);
    let r = contact.frame.hi;
    let impulse_w = r * p_c;
    let u_after_c = Vector3::from_fn(|i, _| {
        dot2(
            &[
                u.0[i],
                u.1[i],
                w.0[(i, 0)],
                w.0[(i, 1)],
                w.0[(i, 2)],
                w.1[(i, 0)],
                w.1[(i, 1)],
                w.1[(i, 2)],
            ],
            &[1.0, 1.0, p_c.x, p_c.y, p_c.z, p_c.x, p_c.y, p_c.z],
        )
    });
    // ΔT = P·(u⁻ + ½ W P) = ½ P·(u⁻ + u⁺), at the scale of |P|·|u| however W cancels.
    let energy_change = 0.5 * dot2(p_c.as_slice(), (u.0 + u.1 + u_after_c).as_slice());
    let result = ContactImpulse {
        impulse_w,
        normal_impulse: process.p,
        tangential_impulse_w: r.column(0) * p_c.x + r.column(1) * p_c.y,
        compression_impulse: process.compression_impulse(),
        u_after_w: r * u_after_c,
        mode: process.mode(),
        energy_change,
        integration_error: process.error,
        steps: process.steps,
    };
    result.check_finite()?;
    Ok(result)
}

impl ContactImpulse {
    /// Fails with [`ImpulseError::NonFiniteResult`] naming the first quantity that overflowed.
    pub(crate) fn check_finite(&self) -> Result<(), ImpulseError> {
        check_result("impulse", self.impulse_w.iter().chain(self.tangential_impulse_w.iter()))?;
        check_result("normal impulse", [self.normal_impulse, self.compression_impulse].iter())?;
        check_result("relative velocity after the impact", self.u_after_w.iter())?;
        check_result("energy change", [self.energy_change].iter())?;
        check_result("impulse error bound", [self.integration_error].iter())
    }
}
