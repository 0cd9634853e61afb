//! The mass-properties value: mass, centre of mass and central inertia tensor.

use crate::MassError;
use nalgebra::{Matrix3, Vector3};

/// Mass `mass`, centre of mass `p_OC` (from the frame origin O, expressed in that frame)
/// and the inertia tensor `inertia_C` about the centre of mass, in the same frame (3.17).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassProperties {
    /// Total mass m = ∫ρ dV (1.18–1.23), kg.
    pub mass: f64,
    /// Centre of mass, m x₀ = ∫ρ x dV (1.24), in metres.
    pub p_oc: Vector3<f64>,
    /// Central inertia tensor J₀ (3.17–3.18), kg·m².
    pub inertia_c: Matrix3<f64>,
}

impl MassProperties {
    /// A point mass `mass` at `p_oc`: its central inertia is zero (semidefinite, remark after 3.14).
    pub fn point(mass: f64, p_oc: Vector3<f64>) -> Result<Self, MassError> {
        if !mass.is_finite() {
            return Err(MassError::NonFinite {
                what: "mass",
                value: mass,
            });
        }
        if mass <= 0.0 {
            return Err(MassError::NonPositiveMass(mass));
        }
        if let Some(value) = p_oc.iter().copied().find(|v| !v.is_finite()) {
            return Err(MassError::NonFinite {
                what: "centre of mass",
                value,
            });
        }
        Ok(Self {
            mass,
            p_oc,
            inertia_c: Matrix3::zeros(),
        })
    }

    /// The inertia tensor about the point `p_oa`, by Steiner: J_A = J₀ + m(|d|² I − d dᵀ)
    /// with d = x₀ − a (3.27–3.29).
    pub fn inertia_about(&self, p_oa: &Vector3<f64>) -> Matrix3<f64> {
        let d = self.p_oc - p_oa;
        self.inertia_c + self.mass * (Matrix3::identity() * d.norm_squared() - d * d.transpose())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steiner_of_a_point_mass_is_m_r_squared_about_perpendicular_axes() {
        let m = MassProperties::point(2.0, Vector3::new(3.0, 0.0, 0.0)).expect("valid point");
        let j = m.inertia_about(&Vector3::zeros());
        assert_eq!(j, Matrix3::from_diagonal(&Vector3::new(0.0, 18.0, 18.0)));
    }

    #[test]
    fn negative_and_nan_masses_are_rejected() {
        assert_eq!(
            MassProperties::point(-1.0, Vector3::zeros()),
            Err(MassError::NonPositiveMass(-1.0))
        );
        assert!(matches!(
            MassProperties::point(f64::NAN, Vector3::zeros()),
            Err(MassError::NonFinite { .. })
        ));
    }
}
