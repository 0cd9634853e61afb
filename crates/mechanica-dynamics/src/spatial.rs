//! Wrenches and rigid-body inertia in world components, referred to a body's origin.
//!
//! Every spatial quantity of this crate has world components and is referred to the origin
//! o_i of the body it belongs to (the joint origin), never to the world origin: a mechanism far
//! from the origin keeps the rounding of its moments relative to its own size. Moving a
//! reference point is a pure translation r = o_child − o_parent:
//! a motion (ω, v_o) becomes (ω, v_o + ω × r) and a wrench (F, M_o) becomes (F, M_o + r × F).

use mechanica_mass::MassProperties;
use nalgebra::{Matrix3, Vector3};

/// A force F and a moment M about a named reference point, world components (N, N·m).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Wrench {
    /// Resultant force F (world), N.
    pub force: Vector3<f64>,
    /// Moment M about the reference point (world), N·m.
    pub moment: Vector3<f64>,
}

impl Wrench {
    /// The zero wrench.
    pub fn zero() -> Self {
        Self::default()
    }

    /// A force applied at a point `r` from the reference point: (F, r × F).
    pub fn of_force_at(force: Vector3<f64>, r: &Vector3<f64>) -> Self {
        Self {
            force,
            moment: r.cross(&force),
        }
    }

    /// The same wrench about a point O when its current reference point lies at r = P − O:
    /// M_O = M_P + r × F (7.29).
    pub fn shifted_by(&self, r: &Vector3<f64>) -> Self {
        Self {
            force: self.force,
            moment: self.moment + r.cross(&self.force),
        }
    }

    /// The power ω·M + v·F against the motion column (w, v) referred to the same point, which is
    /// the generalized force of the wrench on that coordinate (4.35), (7.44).
    pub fn power(&self, w: &Vector3<f64>, v: &Vector3<f64>) -> f64 {
        w.dot(&self.moment) + v.dot(&self.force)
    }
}

impl std::ops::AddAssign for Wrench {
    fn add_assign(&mut self, other: Self) {
        self.force += other.force;
        self.moment += other.moment;
    }
}

impl std::ops::SubAssign for Wrench {
    fn sub_assign(&mut self, other: Self) {
        self.force -= other.force;
        self.moment -= other.moment;
    }
}

/// A body's mass properties in world components, referred to its origin o: mass m, centre
/// offset c = x_C − o, central tensor J_C (world).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct WorldInertia {
    pub mass: f64,
    pub c: Vector3<f64>,
    pub inertia_c: Matrix3<f64>,
}

impl WorldInertia {
    /// The body `body` (body-frame mass properties) turned by R_WB.
    pub fn new(body: &MassProperties, rotation: &Matrix3<f64>) -> Self {
        Self {
            mass: body.mass,
            c: rotation * body.p_oc,
            inertia_c: rotation * body.inertia_c * rotation.transpose(),
        }
    }

    /// The wrench about o that moves the body with angular velocity ω, angular acceleration ω̇
    /// and origin acceleration a_o, less the weight m g: the rates of momentum and angular
    /// momentum, K = m ẍ_C (7.15) and M_C = J_C ω̇ + ω × J_C ω (7.22), moved to o by (7.29), with
    /// ẍ_C = a_o + ω̇ × c + ω × (ω × c) (7.9).
    pub fn momentum_rate(
        &self,
        omega: &Vector3<f64>,
        omega_dot: &Vector3<f64>,
        a_o: &Vector3<f64>,
        gravity: &Vector3<f64>,
    ) -> Wrench {
        let a_c = a_o + omega_dot.cross(&self.c) + omega.cross(&omega.cross(&self.c));
        let force = (a_c - gravity) * self.mass;
        let m_c = self.inertia_c * omega_dot + omega.cross(&(self.inertia_c * omega));
        Wrench {
            force,
            moment: m_c + self.c.cross(&force),
        }
    }
}
