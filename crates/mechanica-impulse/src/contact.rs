//! Two rigid bodies B₁ and B₂ meeting at one point R with normal n (7.72–7.99), free or hinged
//! (7.87*–7.91*).
//!
//! The impulse S₁₂ = P acts on B₂ at R and S₂₁ = −P on B₁ (7.73); each body responds through
//! its mobility (7.88–7.91), so the relative velocity u = v₂(R) − v₁(R) (7.92) jumps by
//! W P with the contact mobility (Delassus matrix) W = W₁ + W₂, W_k = J_R,k G_k J_R,kᵀ. The
//! impulse itself is found in contact space ([`crate::contact_space`]).

use crate::ImpulseError;
use crate::body::{BodyResponse, RigidBody, unit_vector};
use crate::contact_space::{ContactImpulse, ContactLaw, ImpactOptions, resolve_validated};
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
    let contact = resolve_validated(&w, &u, n_w, law, options)?;
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
