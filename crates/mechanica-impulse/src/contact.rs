//! Two rigid bodies B₁ and B₂ meeting at one point R with normal n (7.72–7.99), free or hinged
//! (7.87*–7.91*).
//!
//! The impulse S₁₂ = P acts on B₂ at R and S₂₁ = −P on B₁ (7.73); each body responds through
//! its mobility (7.88–7.91), so the relative velocity u = v₂(R) − v₁(R) (7.92) jumps by
//! W P with the contact mobility (Delassus matrix) W = W₁ + W₂, W_k = J_R,k G_k J_R,kᵀ. The
//! impulse itself is found in contact space ([`crate::contact_space`]).

use crate::ImpulseError;
use crate::body::{BodyResponse, RigidBody, unit_vector};
use crate::compensated::two_sum;
use crate::contact_frame::ContactFrame;
use crate::contact_space::{ContactImpulse, ContactLaw, FramedContact, ImpactOptions, resolve_framed};
use crate::error::{check_all_finite, check_result};
use nalgebra::{Matrix3, Vector3};

/// The outcome of a two-body point impact (world frame W).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwoBodyImpact {
    /// The contact impulse P on body 2 and the process report (mode, ΔT, error).
    pub contact: ContactImpulse,
    /// Body 1 after receiving −P at R.
    pub body1: BodyResponse,
    /// Body 2 after receiving P at R.
    pub body2: BodyResponse,
    /// The contact mobility W used (W frame).
    pub mobility_w: Matrix3<f64>,
    /// The relative velocity u⁻ = v₂(R) − v₁(R) before the impact.
    pub u_before_w: Vector3<f64>,
}

/// Resolves the impact of `body1` and `body2` at the point `p_wr` with the unit normal `n_w`
/// pointing from body 1 into body 2 (7.72), under the contact law `law`.
///
/// Returns the impulse, the post-impact velocities of both bodies and ΔT (7.107 summed over
/// both bodies, equal to P·(u⁻ + ½ W P)). Bodies with zero-inertia axes (rods, points) must
/// be struck on those axes ([`ImpulseError::ZeroInertiaAxisExcited`] otherwise).
pub fn resolve_contact(
    body1: &RigidBody,
    body2: &RigidBody,
    p_wr: &Vector3<f64>,
    n_w: &Vector3<f64>,
    law: &ContactLaw,
    options: &ImpactOptions,
) -> Result<TwoBodyImpact, ImpulseError> {
    check_all_finite("contact point", p_wr.iter())?;
    unit_vector("contact normal", n_w)?;
    law.validate()?;
    body1.check_impulse_point("body 1 contact", p_wr)?;
    body2.check_impulse_point("body 2 contact", p_wr)?;
    let w = body1.point_mobility(p_wr) + body2.point_mobility(p_wr);
    let u = body2.velocity_at(p_wr) - body1.velocity_at(p_wr);
    let contact = resolve_framed(&framed_contact(body1, body2, p_wr, n_w, &u), law, options)?;
    let p = contact.impulse_w;
    let body2_response = body2.respond(&p, &(p_wr - body2.p_wc()).cross(&p));
    let body1_response = body1.respond(&-p, &(p_wr - body1.p_wc()).cross(&-p));
    body1_response.check_finite()?;
    body2_response.check_finite()?;
    check_result("contact mobility", w.iter())?;
    Ok(TwoBodyImpact {
        contact,
        body1: body1_response,
        body2: body2_response,
        mobility_w: w,
        u_before_w: u,
    })
}

/// The contact in its frame, W = W₁ + W₂ and u⁻ = v₂(R) − v₁(R) formed from the bodies to about
/// twice the working precision ([`RigidBody::contact_terms`]), so that the impulse does not
/// inherit the rounding of a W that is large along a direction the contact barely moves in.
fn framed_contact(
    body1: &RigidBody,
    body2: &RigidBody,
    p_wr: &Vector3<f64>,
    n_w: &Vector3<f64>,
    u_w: &Vector3<f64>,
) -> FramedContact {
    let frame = ContactFrame::new(n_w);
    let ((w1, w1_lo), (u1, u1_lo)) = body1.contact_terms(&frame, p_wr);
    let ((w2, w2_lo), (u2, u2_lo)) = body2.contact_terms(&frame, p_wr);
    let (mut w, mut w_lo) = (Matrix3::zeros(), Matrix3::zeros());
    for k in 0..9 {
        let (h, e) = two_sum(w1[k], w2[k]);
        let (hi, lo) = two_sum(h, e + w1_lo[k] + w2_lo[k]);
        (w[k], w_lo[k]) = (hi, lo);
    }
    let (mut u, mut u_lo) = (Vector3::zeros(), Vector3::zeros());
    for k in 0..3 {
        let (h, e) = two_sum(u2[k], -u1[k]);
        let (hi, lo) = two_sum(h, e + u2_lo[k] - u1_lo[k]);
        (u[k], u_lo[k]) = (hi, lo);
    }
    FramedContact {
        frame,
        w: (w, w_lo),
        u: (u, u_lo),
        u_w: *u_w,
    }
}
