//! Momentum, angular momentum and kinetic energy of a rigid body (3.4–3.7, 3.32, 3.37–3.41).
//!
//! Here the [`MassProperties`] describe the body at the current instant in an inertial
//! frame W: `p_oc` is the position of the centre of mass and `inertia_c` the central tensor,
//! both expressed in W. Velocities are absolute and expressed in W.

use crate::MassProperties;
use mechanica_kinematics::scaling;
use nalgebra::Vector3;

impl MassProperties {
    /// The momentum p = m v₀ (3.4), from the velocity `v_c` of the centre of mass.
    pub fn linear_momentum(&self, v_c: &Vector3<f64>) -> Vector3<f64> {
        self.mass * v_c
    }

    /// The angular momentum D_A = ∫ρ (x − a) × v dV (3.5) about the point A at `p_oa` (fixed
    /// or moving: only its current position enters), from the centre velocity `v_c` and the
    /// angular velocity `omega`: D_A = J₀ ω + (x₀ − a) × m v₀ (3.6–3.7, 3.11–3.12).
    pub fn angular_momentum_about(
        &self,
        p_oa: &Vector3<f64>,
        v_c: &Vector3<f64>,
        omega: &Vector3<f64>,
    ) -> Vector3<f64> {
        self.inertia_c * omega + (self.p_oc - p_oa).cross(&(self.mass * v_c))
    }

    /// The angular momentum about the body point A at `p_oa` moving with velocity `v_a`:
    /// D_A = J_A ω + m (x₀ − a) × v_A (3.32). With v_A = 0 (a fixed point) this is J_A ω.
    pub fn angular_momentum_about_body_point(
        &self,
        p_oa: &Vector3<f64>,
        v_a: &Vector3<f64>,
        omega: &Vector3<f64>,
    ) -> Vector3<f64> {
        self.inertia_about(p_oa) * omega + self.mass * (self.p_oc - p_oa).cross(v_a)
    }

    /// The kinetic energy T = ½ m v₀·v₀ + ½ ω·J₀ ω (König, 3.37, 3.41).
    /// Each term is formed on data scaled by powers of two and scaled back by an exponent-kept
    /// product, so it under- or overflows only when its exact value does (a heavy body moving
    /// at 1e-160 m/s has a normal T although |v|² underflows).
    pub fn kinetic_energy(&self, v_c: &Vector3<f64>, omega: &Vector3<f64>) -> f64 {
        let speed = scaling::norm(v_c);
        let translational = scaling::product(&[0.5, self.mass, speed, speed]);
        let w_scale = scaling::power_of_two_above(omega.amax());
        let j_scale = scaling::power_of_two_above(self.inertia_c.amax());
        let w = omega / w_scale;
        let rotational = scaling::product(&[0.5, w.dot(&(self.inertia_c / j_scale * w)), j_scale, w_scale, w_scale]);
        translational + rotational
    }

    /// The kinetic energy of a body turning with `omega` about the fixed point A at `p_oa`:
    /// T = ½ ω·J_A ω (3.39).
    pub fn kinetic_energy_about_fixed_point(&self, p_oa: &Vector3<f64>, omega: &Vector3<f64>) -> f64 {
        0.5 * omega.dot(&(self.inertia_about(p_oa) * omega))
    }
}

#[cfg(test)]
mod tests {
    //! Reference: the body as a cloud of point masses, whose momenta and energy are direct sums
    //! Σ mᵢ vᵢ, Σ (xᵢ − a) × mᵢ vᵢ, Σ ½ mᵢ vᵢ² with vᵢ = v_a + ω × (xᵢ − a) (2.19).
    use super::*;
    use proptest::prelude::*;

    fn cloud_strategy() -> impl Strategy<Value = Vec<(f64, [f64; 3])>> {
        proptest::collection::vec((0.1f64..5.0, proptest::array::uniform3(-2.0f64..2.0)), 2..12)
    }

    fn vec3() -> impl Strategy<Value = Vector3<f64>> {
        proptest::array::uniform3(-3.0f64..3.0).prop_map(Vector3::from)
    }

    proptest! {
        #[test]
        fn momenta_and_energy_equal_the_sums_over_a_point_cloud(
            cloud in cloud_strategy(), a in vec3(), v_a in vec3(), omega in vec3(),
        ) {
            let points: Vec<MassProperties> = cloud
                .iter()
                .map(|(m, x)| MassProperties::point(*m, Vector3::from(*x)).expect("valid"))
                .collect();
            let body = MassProperties::sum(&points).expect("positive mass");
            let vel = |x: &Vector3<f64>| v_a + omega.cross(&(x - a));
            let (mut p, mut d, mut t) = (Vector3::zeros(), Vector3::zeros(), 0.0);
            for q in &points {
                let v = vel(&q.p_oc);
                p += q.mass * v;
                d += (q.p_oc - a).cross(&(q.mass * v));
                t += 0.5 * q.mass * v.norm_squared();
            }
            let v_c = vel(&body.p_oc);
            let scale = body.mass * 100.0;
            let tol = 1e-12 * scale;
            prop_assert!((body.linear_momentum(&v_c) - p).norm() <= tol);
            prop_assert!((body.angular_momentum_about(&a, &v_c, &omega) - d).norm() <= tol);
            prop_assert!((body.angular_momentum_about_body_point(&a, &v_a, &omega) - d).norm() <= tol);
            prop_assert!((body.kinetic_energy(&v_c, &omega) - t).abs() <= tol * 10.0);
            // Fixed point: v_A = 0.
            let t_fixed: f64 = points
                .iter()
                .map(|q| 0.5 * q.mass * omega.cross(&(q.p_oc - a)).norm_squared())
                .sum();
            prop_assert!((body.kinetic_energy_about_fixed_point(&a, &omega) - t_fixed).abs() <= tol * 10.0);
        }
    }

    #[test]
    fn angular_momenta_about_two_points_differ_by_p_cross_offset() {
        // D_A − D_B = p × (a − b) (3.6).
        let body = MassProperties {
            mass: 2.0,
            p_oc: Vector3::new(1.0, 2.0, 3.0),
            inertia_c: nalgebra::Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, 2.5)),
        };
        let (v, w) = (Vector3::new(0.5, -1.0, 2.0), Vector3::new(0.1, 0.2, -0.3));
        let (a, b) = (Vector3::new(3.0, 0.0, 1.0), Vector3::new(-1.0, 4.0, 0.0));
        let lhs = body.angular_momentum_about(&a, &v, &w) - body.angular_momentum_about(&b, &v, &w);
        let rhs = body.linear_momentum(&v).cross(&(a - b));
        assert!((lhs - rhs).norm() <= 1e-14 * rhs.norm());
    }
}
