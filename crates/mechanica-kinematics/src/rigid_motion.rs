//! Rigid motion x = R X + c (1.5) and its velocity and acceleration fields (2.13–2.19).
//!
//! All vectors are fixed-frame (world) components unless named `_B`. `c` is the world position
//! of the body's reference point (the origin of the body frame), ω the angular velocity, which
//! is the same whichever body point is taken as reference (2.14–2.16). Units are SI (m, m/s,
//! m/s², rad/s, rad/s²); the fields are evaluated by their closed forms, exact up to rounding.
//! They are plain formulas: a result whose exact value exceeds f64::MAX comes out as ±∞.
//! [`crate::relative_motion::decompose`] and the C functions built on them check their
//! results and report such an overflow as [`KinematicsError::NonFiniteResult`].

use crate::KinematicsError;
use crate::rotation::check_finite_vec;
use nalgebra::{Rotation3, Vector3};

/// The instantaneous state of a rigid motion x(t) = R(t) X + c(t), all in world components.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidMotion {
    /// Orientation R = R_WB.
    pub rotation: Rotation3<f64>,
    /// Position c of the reference point (body origin).
    pub c: Vector3<f64>,
    /// Velocity ċ of the reference point.
    pub c_dot: Vector3<f64>,
    /// Acceleration c̈ of the reference point.
    pub c_ddot: Vector3<f64>,
    /// Angular velocity ω.
    pub omega: Vector3<f64>,
    /// Angular acceleration ω̇.
    pub omega_dot: Vector3<f64>,
}

impl RigidMotion {
    /// Builds a motion, rejecting non-finite vectors.
    pub fn new(
        rotation: Rotation3<f64>,
        c: Vector3<f64>,
        c_dot: Vector3<f64>,
        c_ddot: Vector3<f64>,
        omega: Vector3<f64>,
        omega_dot: Vector3<f64>,
    ) -> Result<Self, KinematicsError> {
        check_finite_vec(&c, "reference point position")?;
        check_finite_vec(&c_dot, "reference point velocity")?;
        check_finite_vec(&c_ddot, "reference point acceleration")?;
        check_finite_vec(&omega, "angular velocity")?;
        check_finite_vec(&omega_dot, "angular acceleration")?;
        Ok(RigidMotion {
            rotation,
            c,
            c_dot,
            c_ddot,
            omega,
            omega_dot,
        })
    }

    /// The world position x = R X + c of the body point with body coordinates X (1.5).
    pub fn position(&self, x_body: &Vector3<f64>) -> Vector3<f64> {
        self.rotation * x_body + self.c
    }

    /// The velocity of the body point at world position x: v = ω × (x − c) + ċ (2.13).
    pub fn velocity_at(&self, x: &Vector3<f64>) -> Vector3<f64> {
        velocity_field(&self.omega, &self.c, &self.c_dot, x)
    }

    /// The acceleration of the body point at world position x (2.18).
    pub fn acceleration_at(&self, x: &Vector3<f64>) -> Vector3<f64> {
        acceleration_field(&self.omega, &self.omega_dot, &self.c, &self.c_ddot, x)
    }

    /// The same motion described from another body point a (world position) as reference:
    /// ω and ω̇ are unchanged (2.14–2.16); c, ċ, c̈ become a and its velocity and acceleration.
    /// The body frame's orientation is kept, so body coordinates change by X ↦ X − Rᵀ(a − c).
    pub fn with_reference_point(&self, a: &Vector3<f64>) -> RigidMotion {
        RigidMotion {
            rotation: self.rotation,
            c: *a,
            c_dot: self.velocity_at(a),
            c_ddot: self.acceleration_at(a),
            omega: self.omega,
            omega_dot: self.omega_dot,
        }
    }
}

/// Velocity field of a rigid body, v(x) = ω × (x − c) + ċ (2.13).
pub fn velocity_field(omega: &Vector3<f64>, c: &Vector3<f64>, c_dot: &Vector3<f64>, x: &Vector3<f64>) -> Vector3<f64> {
    omega.cross(&(x - c)) + c_dot
}

/// Acceleration field of a rigid body,
/// a(x) = ω̇ × (x − c) + ω × (ω × (x − c)) + c̈ (2.18).
pub fn acceleration_field(
    omega: &Vector3<f64>,
    omega_dot: &Vector3<f64>,
    c: &Vector3<f64>,
    c_ddot: &Vector3<f64>,
    x: &Vector3<f64>,
) -> Vector3<f64> {
    let r = x - c;
    omega_dot.cross(&r) + omega.cross(&omega.cross(&r)) + c_ddot
}

/// Two points of one body (2.17): v_q = v_p + ω × (x_q − x_p).
pub fn velocity_transfer(
    v_p: &Vector3<f64>,
    omega: &Vector3<f64>,
    x_p: &Vector3<f64>,
    x_q: &Vector3<f64>,
) -> Vector3<f64> {
    v_p + omega.cross(&(x_q - x_p))
}

/// Two points of one body (2.19): a_q = a_p + ω̇ × (x_q − x_p) + ω × (ω × (x_q − x_p)).
pub fn acceleration_transfer(
    a_p: &Vector3<f64>,
    omega: &Vector3<f64>,
    omega_dot: &Vector3<f64>,
    x_p: &Vector3<f64>,
    x_q: &Vector3<f64>,
) -> Vector3<f64> {
    let r = x_q - x_p;
    a_p + omega_dot.cross(&r) + omega.cross(&omega.cross(&r))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::{exp_unchecked, log_map};

    // A prescribed motion: R(t) = exp(φ0 + φ1 t + φ2 t²), c(t) = c0 + c1 t + c2 t².
    fn path(t: f64) -> (Rotation3<f64>, Vector3<f64>) {
        let phi =
            Vector3::new(0.3, -0.7, 0.2) + Vector3::new(1.1, 0.4, -0.6) * t + Vector3::new(-0.2, 0.3, 0.5) * t * t;
        let c = Vector3::new(1.0, 2.0, -0.5) + Vector3::new(0.3, -0.1, 0.8) * t + Vector3::new(0.7, 0.2, -0.4) * t * t;
        (exp_unchecked(&phi), c)
    }

    fn motion_at(t: f64, h: f64) -> RigidMotion {
        // ω, ω̇, ċ, c̈ by central differences of the path (ω from the relative rotation log).
        let (r, c) = path(t);
        let omega_at = |s: f64| log_map(&(path(s + h).0 * path(s - h).0.inverse())) / (2.0 * h);
        RigidMotion {
            rotation: r,
            c,
            c_dot: (path(t + h).1 - path(t - h).1) / (2.0 * h),
            c_ddot: (path(t + h).1 - 2.0 * c + path(t - h).1) / (h * h),
            omega: omega_at(t),
            omega_dot: (omega_at(t + h) - omega_at(t - h)) / (2.0 * h),
        }
    }

    #[test]
    fn fields_match_finite_differences_of_x_of_t() {
        // x(t) = R(t) X + c(t) for a fixed body point X; compare (2.13)/(2.18) built from ω, ω̇
        // (themselves differenced with step h1) with direct differences of x(t) (step h2).
        // Error budget: O(h²) truncation + O(eps/h²) rounding of the second differences.
        let h = 1e-4;
        let m = motion_at(0.4, h);
        let body_point = Vector3::new(0.5, -1.5, 2.0);
        let x = |t: f64| {
            let (r, c) = path(t);
            r * body_point + c
        };
        let x0 = m.position(&body_point);
        let v_fd = (x(0.4 + h) - x(0.4 - h)) / (2.0 * h);
        let a_fd = (x(0.4 + h) - 2.0 * x0 + x(0.4 - h)) / (h * h);
        let tol_v = 100.0 * (h * h + f64::EPSILON / h);
        let tol_a = 100.0 * (h * h + 10.0 * f64::EPSILON / (h * h));
        assert!((m.velocity_at(&x0) - v_fd).norm() < tol_v);
        assert!(
            (m.acceleration_at(&x0) - a_fd).norm() < tol_a,
            "{}",
            (m.acceleration_at(&x0) - a_fd).norm()
        );
    }

    #[test]
    fn changing_the_reference_point_keeps_the_fields() {
        let m = RigidMotion::new(
            exp_unchecked(&Vector3::new(0.1, 0.2, 0.3)),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.0, 2.0, 0.0),
            Vector3::new(0.5, 0.0, -1.0),
            Vector3::new(0.0, 0.0, 3.0),
            Vector3::new(1.0, -1.0, 0.0),
        )
        .expect("finite");
        let a = Vector3::new(-2.0, 1.0, 4.0);
        let moved = m.with_reference_point(&a);
        for x in [Vector3::new(3.0, -1.0, 0.5), Vector3::new(0.0, 0.0, 0.0)] {
            assert!((moved.velocity_at(&x) - m.velocity_at(&x)).norm() < 1e-13);
            assert!((moved.acceleration_at(&x) - m.acceleration_at(&x)).norm() < 1e-13);
            let vq = velocity_transfer(&m.velocity_at(&a), &m.omega, &a, &x);
            assert!((vq - m.velocity_at(&x)).norm() < 1e-13);
            let aq = acceleration_transfer(&m.acceleration_at(&a), &m.omega, &m.omega_dot, &a, &x);
            assert!((aq - m.acceleration_at(&x)).norm() < 1e-13);
        }
        // (2.13) for a pure spin: v = ω × r, orthogonal to both.
        let x = Vector3::new(2.0, 0.0, 0.0);
        let spin = RigidMotion::new(
            Rotation3::identity(),
            Vector3::zeros(),
            Vector3::zeros(),
            Vector3::zeros(),
            Vector3::new(0.0, 0.0, 3.0),
            Vector3::zeros(),
        )
        .expect("finite");
        assert_eq!(spin.velocity_at(&x), Vector3::new(0.0, 6.0, 0.0));
        assert_eq!(spin.acceleration_at(&x), Vector3::new(-18.0, 0.0, 0.0));
        assert!(
            RigidMotion::new(
                Rotation3::identity(),
                Vector3::new(f64::NAN, 0.0, 0.0),
                Vector3::zeros(),
                Vector3::zeros(),
                Vector3::zeros(),
                Vector3::zeros()
            )
            .is_err()
        );
    }
}
