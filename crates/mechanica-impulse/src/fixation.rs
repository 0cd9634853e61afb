//! Fixation of a body point (7.100–7.108): a single impulse S at the body point X brings X
//! to rest at once.
//!
//! The syllabus solves J_X Ω = J₀ ω + (x₀ − x) × m v₀ (7.105) with J_X from Steiner. Here the
//! same condition is written in contact space, which also covers hinged bodies and bodies
//! with infinite mass or degenerate inertia: v_X⁺ = v_X⁻ + W_X S = 0 with the point mobility
//! W_X = J_X G J_Xᵀ. For a free body of finite mass W_X is split in the lever's frame, where
//! its component along the lever is exactly the inverse mass (docs/theory.md §7i); otherwise
//! it is solved by Cholesky (W_X is positive definite for any body of finite mass) or, when
//! singular, by its pseudo-inverse with a residual check.

use crate::ImpulseError;
use crate::body::{RigidBody, orthonormal_complement};
use crate::error::{check_all_finite, check_result};
use mechanica_kinematics::scaling;
use nalgebra::{Matrix2, Vector2, Vector3};

/// The outcome of fixing a body point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fixation {
    /// The impulse S applied at X (W frame, N·s) (7.100, 7.103).
    pub impulse_w: Vector3<f64>,
    /// Velocity of the centre of mass after fixation, V₀ (7.102).
    pub v_wc_after: Vector3<f64>,
    /// Angular velocity after fixation, Ω (7.105).
    pub w_w_after: Vector3<f64>,
    /// ΔT = ½ S·v (7.108), v the velocity of X before fixation, J.
    pub energy_change: f64,
    /// |v_X| after fixation as computed (a backward check of the solve, m/s).
    pub residual: f64,
}

/// The largest speed left at a fixed point, relative to its speed before, that
/// [`fix_point`] accepts.
pub const FIXATION_RESIDUAL: f64 = 1e-8;

/// Brings the body point at `p_wx` (world frame) to rest by a single impulse at that point
/// (7.100–7.108). The result reports the velocity left at X as [`Fixation::residual`].
///
/// Errors: a non-finite point, [`ImpulseError::ZeroInertiaAxisExcited`] for a point off a
/// zero-inertia axis, and [`ImpulseError::Singular`] when W_X is singular and the
/// pseudo-inverse leaves |v_X| > 1e-9·|v_X⁻| (X cannot be stopped by an impulse at X), or when
/// the solve leaves |v_X| > [`FIXATION_RESIDUAL`]·|v_X⁻|. A free body of finite mass is
/// solved in the lever's frame (docs/theory.md §7i), which stays accurate for points any
/// distance away; hinged bodies and infinite masses go through W_X in world axes.
pub fn fix_point(body: &RigidBody, p_wx: &Vector3<f64>) -> Result<Fixation, ImpulseError> {
    check_all_finite("fixed point", p_wx.iter())?;
    body.check_impulse_point("fixed point", p_wx)?;
    let v = body.velocity_at(p_wx);
    let lever = p_wx - body.p_wc();
    let (impulse, moment, energy_change) = match free_body_fixation(body, &lever) {
        Some(fixation) => fixation,
        None => {
            let impulse = general_fixation(body, p_wx, &v)?;
            (impulse, lever.cross(&impulse), 0.5 * impulse.dot(&v))
        }
    };
    check_result("fixation impulse", impulse.iter().chain(moment.iter()))?;
    let response = body.respond(&impulse, &moment);
    response.check_finite()?;
    // Norms without squares: the speeds of a body moving at 1e-308 would square to zero.
    let residual = scaling::norm(&(response.v_wc_after + response.w_w_after.cross(&lever)));
    check_result("energy change", [energy_change, residual].iter())?;
    // ΔT = ½ S·(u⁻ + u⁺) exactly; the reported ½ S·u⁻ holds only while the point is at rest
    // after. A point left moving at more than 1e-8 of its speed before (a mobility too
    // ill-conditioned to solve, or an impulse below the double range) is refused.
    if residual > FIXATION_RESIDUAL * scaling::norm(&v) {
        return Err(ImpulseError::Singular {
            what: "fixation: the point cannot be brought to rest in double precision (an ill-conditioned mobility or an impulse below the double range; speed left)",
            value: residual,
        });
    }
    Ok(Fixation {
        impulse_w: impulse,
        v_wc_after: response.v_wc_after,
        w_w_after: response.w_w_after,
        energy_change,
        residual,
    })
}

/// The fixation of a free body of finite mass at lever r = x − x₀, solved in the frame
/// (e, f₁, f₂) with e = r/|r| (docs/theory.md §7i, "Fixation in the lever's frame"). There W_X = γI +
/// |r|² Pᵀ W P has no coupling between e and the plane (f₁, f₂): S_e = −u_e/γ with u_e = e·v₀
/// (ω × r has no component along r), and the plane's 2×2 block γ/|r|² I + Ŵ is well
/// conditioned when W is, however long the lever. The moment r × S = |r|(S₁ f₂ − S₂ f₁) is
/// formed in the same frame, so a large S_e along r adds no rounding to it. Returns the
/// impulse, its moment about the centre of mass and ΔT = ½ S·u⁻; None for a hinged body, an
/// infinite mass, a point at the centre of mass or a singular plane block.
fn free_body_fixation(body: &RigidBody, lever: &Vector3<f64>) -> Option<(Vector3<f64>, Vector3<f64>, f64)> {
    let (gamma, w) = body.free_mobility()?;
    let length = scaling::norm(lever);
    if length == 0.0 || !length.is_finite() {
        return None;
    }
    let e = lever / length;
    let (f1, f2) = orthonormal_complement(&e); // e × f₁ = f₂
    let (v0, w0) = (body.v_wc(), body.w_w());
    let u_e = e.dot(&v0);
    let u_plane = Vector2::new(f1.dot(&v0) + length * w0.dot(&f2), f2.dot(&v0) - length * w0.dot(&f1));
    let (w_f1, w_f2) = (w * f1, w * f2);
    let coupling = -f1.dot(&w_f2);
    let plane = Matrix2::new(f2.dot(&w_f2), coupling, coupling, f1.dot(&w_f1));
    let block = plane + Matrix2::identity() * (gamma / length / length);
    let s_plane = -block.cholesky()?.solve(&(u_plane / length / length));
    let s_e = -u_e / gamma;
    let impulse = e * s_e + f1 * s_plane.x + f2 * s_plane.y;
    let moment = (f2 * s_plane.x - f1 * s_plane.y) * length;
    let energy_change = 0.5 * (s_e * u_e + s_plane.dot(&u_plane));
    Some((impulse, moment, energy_change))
}

/// The fixation impulse of any body from its point mobility W_X: by Cholesky, or when W_X is
/// singular by its pseudo-inverse with a residual check.
fn general_fixation(body: &RigidBody, p_wx: &Vector3<f64>, v: &Vector3<f64>) -> Result<Vector3<f64>, ImpulseError> {
    let w = body.point_mobility(p_wx);
    let impulse = match w.cholesky() {
        Some(chol) => -chol.solve(v),
        None => {
            let scale = w.amax();
            let pinv = if scale > 0.0 {
                w.svd(true, true)
                    .pseudo_inverse(1e-12 * scale)
                    .map_err(|_| ImpulseError::Singular {
                        what: "fixation: point mobility SVD did not converge",
                        value: scale,
                    })?
            } else {
                nalgebra::Matrix3::zeros()
            };
            let s = -pinv * v;
            let left = scaling::norm(&(v + w * s));
            if left > 1e-9 * scaling::norm(v) {
                return Err(ImpulseError::Singular {
                    what: "fixation: the point cannot be brought to rest by an impulse there (|v_X| left)",
                    value: left,
                });
            }
            s
        }
    };
    Ok(impulse)
}

#[cfg(test)]
mod tests {
    use super::*;
    use mechanica_mass::MassProperties;
    use nalgebra::Matrix3;

    fn rod_along_x(mass: f64, length: f64) -> MassProperties {
        let mut props = MassProperties::point(mass, Vector3::zeros()).expect("valid");
        props.inertia_c = Matrix3::from_diagonal(&Vector3::new(0.0, 1.0, 1.0)) * (mass * length * length / 12.0);
        props
    }

    #[test]
    fn fixing_the_end_of_a_translating_rod_gives_three_quarters_of_the_energy() {
        // Classic: rod of length L translating at v ⟂ to itself; fix one end.
        // J_X Ω = m (L/2) v with J_X = mL²/3 → Ω = 3v/(2L), T⁺/T⁻ = (½·mL²/3·Ω²)/(½mv²) = 3/4.
        let (m, l, v) = (2.5, 1.6, 3.0);
        let body = RigidBody::from_mass_properties(&rod_along_x(m, l), Vector3::new(0.0, v, 0.0), Vector3::zeros())
            .expect("ok");
        let fix = fix_point(&body, &Vector3::new(-l / 2.0, 0.0, 0.0)).expect("ok");
        let omega = 3.0 * v / (2.0 * l);
        assert!((fix.w_w_after - Vector3::new(0.0, 0.0, omega)).norm() < 1e-13 * omega);
        let t_before = 0.5 * m * v * v;
        let t_after = 0.5 * m * fix.v_wc_after.norm_squared() + 0.5 * (m * l * l / 12.0) * fix.w_w_after.norm_squared();
        assert!((t_after / t_before - 0.75).abs() < 1e-14);
        assert!((fix.energy_change - (t_after - t_before)).abs() < 1e-13 * t_before);
        // The impulse: S = m(V₀ − v₀) = m(ΩL/2 − v) ŷ = −m v/4 ŷ.
        assert!((fix.impulse_w - Vector3::new(0.0, -m * v / 4.0, 0.0)).norm() < 1e-13);
        assert!(fix.residual < 1e-14 * v);
    }

    /// A body moving at 1e-308 fixed at a point 5.8e30 m away (found by the fuzz target
    /// `abi_impulse`): the impulse that would stop the point is below the double range, and the
    /// point's speed after, 8e-278, was formed from squares that underflowed, so it was reported
    /// at rest (residual 0). Either the point is stopped to 1e-8 of its speed, measured without
    /// squares, or the fixation is refused.
    #[test]
    fn a_point_left_moving_below_the_range_of_squares_is_not_reported_at_rest() {
        let inverse_inertia = Matrix3::new(1.367, -0.0138, 0.0812, -0.0138, 1.362, -0.0512, 0.0812, -0.0512, 1.531);
        let speed = Vector3::new(1e-308, 1e-308, 1e-308);
        let centre = Vector3::new(0.53533935546875, 0.5333251953125, -0.1854248046875);
        let body = RigidBody::from_inverse(0.42355696723258346, &inverse_inertia, centre, speed, speed).expect("ok");
        let point = Vector3::new(1e-308, 0.0, -5.7734375e30);
        let before = scaling::norm(&body.velocity_at(&point));
        match fix_point(&body, &point) {
            Ok(fix) => {
                let lever = point - centre;
                let after = scaling::norm(&(fix.v_wc_after + fix.w_w_after.cross(&lever)));
                assert!(after <= FIXATION_RESIDUAL * before, "left at {after:e} of {before:e}");
                assert_eq!(fix.residual, after);
            }
            Err(error) => assert!(matches!(error, ImpulseError::Singular { .. }), "{error}"),
        }
    }

    /// Points 10^k m from a body of 1 m (k up to 150, random directions, speeds up to 1e30 m/s):
    /// every point is brought to rest (|v_X⁺| ≤ 1e-12 |v_X⁻|), the energies T⁺ − T⁻ computed
    /// directly from the velocities after match the reported ΔT (7.108) to 1e-9 of T⁻, and the
    /// body never gains energy. Solving W_X S = −v_X in world axes failed this from about 1e7 m
    /// (ΔT off by 0.6 %) and at 1e100 m left the point moving at 1e23 times its speed.
    #[test]
    fn far_points_are_fixed_with_the_energy_they_report() {
        let mut props = MassProperties::point(2.7, Vector3::new(0.9, 0.9, -0.4)).expect("ok");
        props.inertia_c = Matrix3::new(2.1, 0.2, 0.8, 0.2, 3.1, -0.2, 0.8, -0.2, 2.5);
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for case in 0..600 {
            let k = (case % 150) as f64 + next();
            let direction = Vector3::new(next(), next(), next()).normalize();
            let v0 = Vector3::new(next(), next(), next()) * 10f64.powf(30.0 * (next() + 0.5));
            let w0 = Vector3::new(next(), next(), next()) * 8.0;
            let body = RigidBody::from_mass_properties(&props, v0, w0).expect("ok");
            let x = props.p_oc + direction * 10f64.powf(k);
            let energy = |v: &Vector3<f64>, w: &Vector3<f64>| {
                0.5 * props.mass * v.norm_squared() + 0.5 * w.dot(&(props.inertia_c * w))
            };
            let fix = fix_point(&body, &x).unwrap_or_else(|e| panic!("case {case} (10^{k:.1} m): {e}"));
            let speed = body.velocity_at(&x).norm();
            assert!(
                fix.residual <= 1e-12 * speed,
                "case {case}: {:e} of {speed:e} left",
                fix.residual
            );
            let (before, after) = (energy(&v0, &w0), energy(&fix.v_wc_after, &fix.w_w_after));
            assert!(
                after <= before * (1.0 + 1e-12),
                "case {case}: gained {:e} of {before:e}",
                after - before
            );
            let direct = after - before;
            assert!(
                (direct - fix.energy_change).abs() <= 1e-9 * before,
                "case {case} (10^{k:.1} m): ΔT {:e} reported, {direct:e} from the velocities",
                fix.energy_change
            );
        }
    }

    #[test]
    fn general_fixation_satisfies_7_105_and_7_108() {
        let mut props = MassProperties::point(1.7, Vector3::new(0.2, -0.1, 0.4)).expect("ok");
        props.inertia_c = Matrix3::new(0.9, 0.1, -0.05, 0.1, 1.3, 0.2, -0.05, 0.2, 0.7);
        let v0 = Vector3::new(0.5, -1.2, 0.8);
        let w0 = Vector3::new(2.0, -0.3, 1.1);
        let body = RigidBody::from_mass_properties(&props, v0, w0).expect("ok");
        let x = Vector3::new(0.9, 0.4, -0.2);
        let fix = fix_point(&body, &x).expect("ok");
        // (7.105): J_X Ω = J₀ ω + (x₀ − x) × m v₀, with J_X by Steiner.
        let j_x = props.inertia_about(&x);
        let rhs = props.inertia_c * w0 + (props.p_oc - x).cross(&(props.mass * v0));
        assert!((j_x * fix.w_w_after - rhs).norm() < 1e-13 * rhs.norm());
        // (7.108) against the direct kinetic energies.
        let t = |v: &Vector3<f64>, w: &Vector3<f64>| {
            0.5 * props.mass * v.norm_squared() + 0.5 * w.dot(&(props.inertia_c * w))
        };
        let direct = t(&fix.v_wc_after, &fix.w_w_after) - t(&v0, &w0);
        assert!((fix.energy_change - direct).abs() < 1e-13 * t(&v0, &w0));
    }

    #[test]
    fn a_static_body_cannot_be_fixed_unless_it_is_at_rest() {
        let ground = RigidBody::fixed(Vector3::zeros()).expect("ok");
        let fix = fix_point(&ground, &Vector3::new(1.0, 0.0, 0.0)).expect("at rest");
        assert_eq!(fix.impulse_w, Vector3::zeros());
        let moving = RigidBody::from_inverse(0.0, &Matrix3::zeros(), Vector3::zeros(), Vector3::x(), Vector3::zeros())
            .expect("ok");
        assert!(matches!(
            fix_point(&moving, &Vector3::zeros()),
            Err(ImpulseError::Singular { .. })
        ));
    }
}
