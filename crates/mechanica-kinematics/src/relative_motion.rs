//! Relative motion in a moving frame x = R ξ + c (2.22–2.35): the absolute velocity and
//! acceleration of a point split into drag ("sleep"), Coriolis and relative parts.
//!
//! The moving frame is a [`RigidMotion`]; the point's relative motion ξ, ξ̇, ξ̈ is given in
//! moving-frame components. Results are world components, SI units, exact up to rounding.

use crate::KinematicsError;
use crate::rigid_motion::RigidMotion;
use crate::rotation::{check_finite_vec, check_result};
use nalgebra::Vector3;

/// A point's motion relative to a moving frame, in that frame's components.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RelativeMotion {
    /// Relative position ξ.
    pub xi: Vector3<f64>,
    /// Relative velocity ξ̇.
    pub xi_dot: Vector3<f64>,
    /// Relative acceleration ξ̈.
    pub xi_ddot: Vector3<f64>,
}

/// The absolute motion of the point, decomposed (world components).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DecomposedMotion {
    /// Position x = R ξ + c.
    pub position: Vector3<f64>,
    /// Drag velocity v_sl = ω × (x − c) + ċ: the velocity of the frame point that coincides with x (2.24).
    pub v_drag: Vector3<f64>,
    /// Relative velocity v_rel = R ξ̇ (2.25).
    pub v_rel: Vector3<f64>,
    /// Drag acceleration a_sl = ω̇ × (x − c) + ω × (ω × (x − c)) + c̈ (2.29).
    pub a_drag: Vector3<f64>,
    /// Coriolis acceleration a_cor = 2 ω × v_rel (2.30).
    pub a_coriolis: Vector3<f64>,
    /// Relative acceleration a_rel = R ξ̈ (2.31).
    pub a_rel: Vector3<f64>,
}

impl DecomposedMotion {
    /// Absolute velocity v = v_sl + v_rel (2.26).
    pub fn velocity(&self) -> Vector3<f64> {
        self.v_drag + self.v_rel
    }
    /// Absolute acceleration a = a_sl + a_cor + a_rel (2.32).
    pub fn acceleration(&self) -> Vector3<f64> {
        self.a_drag + self.a_coriolis + self.a_rel
    }
}

/// Decomposes the absolute motion of a point moving relative to `frame` (2.22–2.32).
/// Fails on a non-finite input and with [`KinematicsError::NonFiniteResult`] naming the
/// first part that overflows f64.
pub fn decompose(frame: &RigidMotion, rel: &RelativeMotion) -> Result<DecomposedMotion, KinematicsError> {
    check_finite_vec(&rel.xi, "relative position")?;
    check_finite_vec(&rel.xi_dot, "relative velocity")?;
    check_finite_vec(&rel.xi_ddot, "relative acceleration")?;
    let x = frame.rotation * rel.xi + frame.c;
    let v_rel = frame.rotation * rel.xi_dot;
    let d = DecomposedMotion {
        position: x,
        v_drag: frame.velocity_at(&x),
        v_rel,
        a_drag: frame.acceleration_at(&x),
        a_coriolis: 2.0 * frame.omega.cross(&v_rel),
        a_rel: frame.rotation * rel.xi_ddot,
    };
    for (part, quantity) in [
        (&d.position, "position"),
        (&d.v_drag, "drag velocity"),
        (&d.v_rel, "relative velocity"),
        (&d.a_drag, "drag acceleration"),
        (&d.a_coriolis, "Coriolis acceleration"),
        (&d.a_rel, "relative acceleration"),
        (&d.velocity(), "absolute velocity"),
        (&d.acceleration(), "absolute acceleration"),
    ] {
        check_result(part.iter(), quantity)?;
    }
    Ok(d)
}

/// The rate-of-change rule for any vector q = R η carried by a frame rotating at ω (2.36):
/// q̇ = ω × q + q̇_rel, with q̇_rel = R η̇ the rate seen in the moving frame.
pub fn rate_in_fixed_frame(omega: &Vector3<f64>, q: &Vector3<f64>, q_dot_rel: &Vector3<f64>) -> Vector3<f64> {
    omega.cross(q) + q_dot_rel
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::exp_unchecked;
    use nalgebra::Rotation3;

    #[test]
    fn coriolis_on_a_rotating_disc() {
        // A disc spins at constant Ω about z with centre fixed at the origin; a point runs
        // outward along a radial groove: ξ(t) = (r0 + u t, 0, 0). Closed form in world
        // components at time t (φ = Ω t, e_r = (cos φ, sin φ, 0), e_φ = (−sin φ, cos φ, 0)):
        //   v = u e_r + Ω r e_φ,   a = −Ω² r e_r + 2 Ω u e_φ   (r = r0 + u t, ξ̈ = 0),
        // drag acceleration = −Ω² r e_r, Coriolis = 2 Ω u e_φ.
        let (omega, r0, u, t): (f64, f64, f64, f64) = (2.5, 0.4, 0.7, 0.3);
        let phi = omega * t;
        let r = r0 + u * t;
        let e_r = Vector3::new(phi.cos(), phi.sin(), 0.0);
        let e_phi = Vector3::new(-phi.sin(), phi.cos(), 0.0);
        let frame = RigidMotion::new(
            Rotation3::from_axis_angle(&Vector3::z_axis(), phi),
            Vector3::zeros(),
            Vector3::zeros(),
            Vector3::zeros(),
            Vector3::new(0.0, 0.0, omega),
            Vector3::zeros(),
        )
        .expect("finite");
        let rel = RelativeMotion {
            xi: Vector3::new(r, 0.0, 0.0),
            xi_dot: Vector3::new(u, 0.0, 0.0),
            xi_ddot: Vector3::zeros(),
        };
        let d = decompose(&frame, &rel).expect("finite");
        let tol = 8.0 * f64::EPSILON * 10.0;
        assert!((d.v_drag - omega * r * e_phi).norm() < tol);
        assert!((d.v_rel - u * e_r).norm() < tol);
        assert!((d.a_drag + omega * omega * r * e_r).norm() < tol);
        assert!((d.a_coriolis - 2.0 * omega * u * e_phi).norm() < tol);
        assert_eq!(d.a_rel, Vector3::zeros());
        // Against finite differences of x(t) = Rz(Ω t)(r0 + u t, 0, 0).
        let x = |s: f64| Rotation3::from_axis_angle(&Vector3::z_axis(), omega * s) * Vector3::new(r0 + u * s, 0.0, 0.0);
        let h = 1e-4;
        let v_fd = (x(t + h) - x(t - h)) / (2.0 * h);
        let a_fd = (x(t + h) - 2.0 * x(t) + x(t - h)) / (h * h);
        assert!((d.velocity() - v_fd).norm() < 100.0 * (h * h + f64::EPSILON / h));
        assert!((d.acceleration() - a_fd).norm() < 100.0 * (h * h + 10.0 * f64::EPSILON / (h * h)));
    }

    #[test]
    fn general_moving_frame_matches_finite_differences() {
        // Frame: R(t) = exp(φ0 + φ1 t), c(t) = c0 + c1 t + c2 t²; point ξ(t) = ξ0 + ξ1 t + ξ2 t².
        let frame_at = |t: f64| {
            (
                exp_unchecked(&(Vector3::new(0.2, 0.5, -0.3) + Vector3::new(0.9, -0.4, 1.3) * t)),
                Vector3::new(1.0, -2.0, 0.5) + Vector3::new(0.3, 0.2, -0.1) * t + Vector3::new(-0.6, 0.4, 0.2) * t * t,
            )
        };
        let xi_at = |t: f64| {
            Vector3::new(0.5, 1.0, -0.2) + Vector3::new(-0.3, 0.8, 0.1) * t + Vector3::new(0.4, 0.0, -0.7) * t * t
        };
        let t = 0.6;
        let (r, c) = frame_at(t);
        // ω is constant in the body frame for R = exp(φ0 + φ1 t)? No: use ω = R J_r(φ) φ1 via
        // differences of R; ω̇ by differences of ω.
        let h = 1e-4;
        let omega_at = |s: f64| {
            let d = frame_at(s + h).0.matrix() - frame_at(s - h).0.matrix();
            crate::rotation::vee(&(d * frame_at(s).0.matrix().transpose())) / (2.0 * h)
        };
        let frame = RigidMotion::new(
            r,
            c,
            (frame_at(t + h).1 - frame_at(t - h).1) / (2.0 * h),
            Vector3::new(-1.2, 0.8, 0.4),
            omega_at(t),
            (omega_at(t + h) - omega_at(t - h)) / (2.0 * h),
        )
        .expect("finite");
        let rel = RelativeMotion {
            xi: xi_at(t),
            xi_dot: Vector3::new(-0.3, 0.8, 0.1) + Vector3::new(0.8, 0.0, -1.4) * t,
            xi_ddot: Vector3::new(0.8, 0.0, -1.4),
        };
        let d = decompose(&frame, &rel).expect("finite");
        let x = |s: f64| {
            let (r, c) = frame_at(s);
            r * xi_at(s) + c
        };
        let v_fd = (x(t + h) - x(t - h)) / (2.0 * h);
        let a_fd = (x(t + h) - 2.0 * x(t) + x(t - h)) / (h * h);
        assert!((d.velocity() - v_fd).norm() < 100.0 * (h * h + f64::EPSILON / h));
        assert!((d.acceleration() - a_fd).norm() < 1000.0 * (h * h + 10.0 * f64::EPSILON / (h * h)));
        // (2.36) with q = R ξ: q̇ = ω × q + R ξ̇.
        let q = r * rel.xi;
        let q_fd = (frame_at(t + h).0 * xi_at(t + h) - frame_at(t - h).0 * xi_at(t - h)) / (2.0 * h);
        let rule = rate_in_fixed_frame(&frame.omega, &q, &d.v_rel);
        assert!((rule - q_fd).norm() < 100.0 * (h * h + f64::EPSILON / h));
    }
}
