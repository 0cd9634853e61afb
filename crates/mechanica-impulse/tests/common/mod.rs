//! Shared builders for the integration tests: bodies with known mass properties and their
//! kinetic energy and momenta computed directly (independently of the crate's ΔT).
#![allow(dead_code)]

pub mod dd;

use mechanica_impulse::{BodyResponse, RigidBody};
use mechanica_mass::MassProperties;
use nalgebra::{Matrix3, Vector3};

/// A body with its mass properties kept for direct energy/momentum computations.
#[derive(Debug, Clone)]
pub struct Body {
    pub props: MassProperties,
    pub v: Vector3<f64>,
    pub w: Vector3<f64>,
}

impl Body {
    pub fn new(mass: f64, p_wc: Vector3<f64>, inertia: Matrix3<f64>, v: Vector3<f64>, w: Vector3<f64>) -> Self {
        let mut props = MassProperties::point(mass, p_wc).expect("valid mass");
        props.inertia_c = inertia;
        Self { props, v, w }
    }
    pub fn sphere(mass: f64, radius: f64, p_wc: Vector3<f64>, v: Vector3<f64>, w: Vector3<f64>) -> Self {
        Self::new(mass, p_wc, Matrix3::identity() * (0.4 * mass * radius * radius), v, w)
    }
    /// A thin rod of length `length` along the unit `axis` (zero axial inertia).
    pub fn rod(
        mass: f64,
        length: f64,
        p_wc: Vector3<f64>,
        axis: Vector3<f64>,
        v: Vector3<f64>,
        w: Vector3<f64>,
    ) -> Self {
        let a = axis.normalize();
        let inertia = (Matrix3::identity() - a * a.transpose()) * (mass * length * length / 12.0);
        Self::new(mass, p_wc, inertia, v, w)
    }
    pub fn rigid(&self) -> RigidBody {
        RigidBody::from_mass_properties(&self.props, self.v, self.w).expect("valid body")
    }
    pub fn energy(&self, v: &Vector3<f64>, w: &Vector3<f64>) -> f64 {
        0.5 * self.props.mass * v.norm_squared() + 0.5 * w.dot(&(self.props.inertia_c * w))
    }
    pub fn energy_before(&self) -> f64 {
        self.energy(&self.v, &self.w)
    }
    pub fn energy_after(&self, r: &BodyResponse) -> f64 {
        self.energy(&r.v_wc_after, &r.w_w_after)
    }
    pub fn momentum(&self, v: &Vector3<f64>) -> Vector3<f64> {
        self.props.mass * v
    }
    /// Angular momentum about the world point `a`: J₀ω + (x₀ − a) × m v (7.30).
    pub fn angular_momentum_about(&self, a: &Vector3<f64>, v: &Vector3<f64>, w: &Vector3<f64>) -> Vector3<f64> {
        self.props.inertia_c * w + (self.props.p_oc - a).cross(&(self.props.mass * v))
    }
    /// The point mobility 1/m I − [d]× J⁻¹ [d]× for an invertible central inertia.
    pub fn point_mobility(&self, r: &Vector3<f64>) -> Matrix3<f64> {
        let d = (r - self.props.p_oc).cross_matrix();
        let j_inv = self.props.inertia_c.try_inverse().expect("invertible inertia");
        Matrix3::identity() / self.props.mass - d * j_inv * d
    }
}
