//! The mass-properties value: mass, centre of mass and central inertia tensor; composition,
//! holes, rigid transformation and Steiner's theorem (3.27–3.29).
//!
//! The functions that return a `Result` check their results: a mass, centre or tensor that
//! overflows f64 is [`MassError::NonFiniteResult`]. The infallible ones
//! ([`steiner_term`], [`MassProperties::inertia_about`],
//! [`MassProperties::central_inertia_from`], [`MassProperties::transformed`]) are plain
//! formulas whose result is ±∞ only when its exact value exceeds f64::MAX.

use crate::MassError;
use crate::error::{check_all_finite, check_finite, check_result};
use crate::validity::{self, ValidityTolerance};
use mechanica_kinematics::scaling;
use nalgebra::{Isometry3, Matrix3, Vector3};

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

/// The Steiner term m(|d|² I − d dᵀ) (3.28–3.29): the inertia tensor of a point mass `mass` at
/// offset `d` from the reference point, so that J_A = J₀ + steiner_term(m, x₀ − a).
pub fn steiner_term(mass: f64, d: &Vector3<f64>) -> Matrix3<f64> {
    let mut s = -(d * d.transpose());
    let d2 = d.norm_squared();
    for i in 0..3 {
        s[(i, i)] += d2;
    }
    mass * s
}

impl MassProperties {
    /// No mass at all: the mass properties of a massless frame (mass 0, inertia 0, the centre of
    /// mass at the origin by convention).
    pub const ZERO: MassProperties = MassProperties {
        mass: 0.0,
        p_oc: Vector3::new(0.0, 0.0, 0.0),
        inertia_c: Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    };

    /// Checked constructor: finite inputs, positive mass, and a physically valid central
    /// inertia (symmetric, positive semidefinite, triangle inequality; see
    /// [`crate::validity::check`] with the default tolerance).
    pub fn new(mass: f64, p_oc: Vector3<f64>, inertia_c: Matrix3<f64>) -> Result<Self, MassError> {
        check_finite(mass, "mass")?;
        check_all_finite(p_oc.iter(), "centre of mass")?;
        check_all_finite(inertia_c.iter(), "inertia tensor")?;
        if mass <= 0.0 {
            return Err(MassError::NonPositiveMass(mass));
        }
        let props = Self { mass, p_oc, inertia_c };
        validity::check(&props, &ValidityTolerance::default())?;
        Ok(props)
    }

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
        self.inertia_c + steiner_term(self.mass, &(self.p_oc - p_oa))
    }

    /// Steiner in the other direction: the central tensor J₀ = J_A − m(|d|² I − d dᵀ),
    /// d = x₀ − a, of a body of mass `mass` with centre `p_oc` whose tensor about the point
    /// `p_oa` is `inertia_a` (3.27–3.29).
    pub fn central_inertia_from(
        mass: f64,
        p_oc: &Vector3<f64>,
        inertia_a: &Matrix3<f64>,
        p_oa: &Vector3<f64>,
    ) -> Matrix3<f64> {
        inertia_a - steiner_term(mass, &(p_oc - p_oa))
    }

    /// Builds mass properties from the tensor `inertia_a` about an arbitrary point `p_oa`
    /// (e.g. a URDF or CAD value about a body origin), by reverse Steiner, then checks them
    /// as [`MassProperties::new`] does.
    pub fn from_inertia_about(
        mass: f64,
        p_oc: Vector3<f64>,
        inertia_a: Matrix3<f64>,
        p_oa: Vector3<f64>,
    ) -> Result<Self, MassError> {
        check_all_finite(p_oa.iter(), "reference point")?;
        check_all_finite(inertia_a.iter(), "inertia tensor")?;
        check_all_finite(p_oc.iter(), "centre of mass")?;
        check_finite(mass, "mass")?;
        let central = Self::central_inertia_from(mass, &p_oc, &inertia_a, &p_oa);
        check_result(central.iter(), "central inertia tensor")?;
        Self::new(mass, p_oc, central)
    }

    /// The moment of inertia (e, J_A e) about the line through `p_oa` with direction
    /// `direction` (normalised here; 3.22–3.23, 3.30).
    pub fn moment_about_line(&self, p_oa: &Vector3<f64>, direction: &Vector3<f64>) -> Result<f64, MassError> {
        check_all_finite(p_oa.iter(), "point on the line")?;
        check_all_finite(direction.iter(), "line direction")?;
        let e = mechanica_kinematics::scaling::unit(direction).ok_or(MassError::ZeroDirection("line direction"))?;
        // Moment about the parallel line through the centre, plus m·(distance between lines)².
        let d = self.p_oc - p_oa;
        let d_perp = d - e * e.dot(&d);
        let moment = e.dot(&(self.inertia_c * e)) + self.mass * d_perp.norm_squared();
        check_result([moment].iter(), "moment of inertia about the line")?;
        Ok(moment)
    }

    /// The same body after the rigid motion `pose` (x ↦ R x + t): p_OC ↦ R p_OC + t and
    /// J₀ ↦ R J₀ Rᵀ. Read passively, this re-expresses properties given in frame B in frame
    /// F when `pose` = X_FB is the pose of B in F.
    pub fn transformed(&self, pose: &Isometry3<f64>) -> Self {
        let r = pose.rotation.to_rotation_matrix();
        let r = r.matrix();
        let j = r * self.inertia_c * r.transpose();
        Self {
            mass: self.mass,
            p_oc: pose.transform_point(&self.p_oc.into()).coords,
            // Keep the tensor exactly symmetric after the product.
            inertia_c: (j + j.transpose()) * 0.5,
        }
    }

    /// The properties of the union of `parts` (all expressed in one frame): total mass, the
    /// mass-weighted centre (1.24), and Σ (J₀ᵢ + Steiner to the common centre) (3.27–3.29).
    /// Fails for an empty list or a non-positive total mass.
    pub fn sum<'a>(parts: impl IntoIterator<Item = &'a MassProperties>) -> Result<Self, MassError> {
        let parts: Vec<&MassProperties> = parts.into_iter().collect();
        let Some(first) = parts.first() else {
            return Err(MassError::NonPositiveTotalMass(0.0));
        };
        // Moments relative to the first part's centre keep the sum accurate far from the origin;
        // the weights are the masses over a power of two, so that subnormal masses weigh with
        // their full value.
        let origin = first.p_oc;
        let weight = scaling::power_of_two_above(parts.iter().fold(0.0, |m: f64, p| m.max(p.mass.abs())));
        let mut mass = 0.0;
        let mut first_moment = Vector3::zeros();
        for p in &parts {
            mass += p.mass;
            first_moment += (p.mass / weight) * (p.p_oc - origin);
        }
        check_result([mass].iter(), "total mass")?;
        if mass <= 0.0 {
            return Err(MassError::NonPositiveTotalMass(mass));
        }
        let c_rel = first_moment / (mass / weight);
        let mut inertia = Matrix3::zeros();
        for p in &parts {
            inertia += p.inertia_c + steiner_term(p.mass, &(p.p_oc - origin - c_rel));
        }
        let sum = Self {
            mass,
            p_oc: origin + c_rel,
            inertia_c: inertia,
        };
        sum.check_results()?;
        Ok(sum)
    }

    /// Fails with [`MassError::NonFiniteResult`] naming the first part that is not finite.
    fn check_results(&self) -> Result<(), MassError> {
        check_result([self.mass].iter(), "total mass")?;
        check_result(self.p_oc.iter(), "centre of mass")?;
        check_result(self.inertia_c.iter(), "inertia tensor")
    }

    /// The union of bodies placed at poses: each `(X_FB, properties in B)` is moved into the
    /// common frame F by [`MassProperties::transformed`], then summed by [`MassProperties::sum`].
    pub fn compose(parts: &[(Isometry3<f64>, MassProperties)]) -> Result<Self, MassError> {
        let placed: Vec<MassProperties> = parts.iter().map(|(x, p)| p.transformed(x)).collect();
        for part in &placed {
            part.check_results()?;
        }
        Self::sum(&placed)
    }

    /// This body with the material of `hole` (expressed in the same frame) removed: the
    /// inverse of [`MassProperties::sum`]. Fails when the hole is as heavy as the body, and
    /// with [`MassError::InvalidInertia`] when the result is not a valid body (a hole that does
    /// not fit inside).
    pub fn subtract(&self, hole: &MassProperties) -> Result<Self, MassError> {
        let mass = self.mass - hole.mass;
        check_result([mass].iter(), "total mass")?;
        if mass <= 0.0 {
            return Err(MassError::NonPositiveTotalMass(mass));
        }
        let origin = self.p_oc;
        let weight = scaling::power_of_two_above(self.mass.max(hole.mass));
        let c_rel = -((hole.mass / weight) * (hole.p_oc - origin)) / (mass / weight);
        let inertia = self.inertia_c + steiner_term(self.mass, &(-c_rel))
            - hole.inertia_c
            - steiner_term(hole.mass, &(hole.p_oc - origin - c_rel));
        let props = Self {
            mass,
            p_oc: origin + c_rel,
            inertia_c: inertia,
        };
        props.check_results()?;
        validity::check(&props, &ValidityTolerance::default())?;
        Ok(props)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};

    fn box_props(m: f64, a: f64, b: f64, c: f64, p: Vector3<f64>) -> MassProperties {
        // Textbook: I_xx = m (b² + c²)/12 for a solid box with sides a, b, c.
        MassProperties {
            mass: m,
            p_oc: p,
            inertia_c: Matrix3::from_diagonal(&Vector3::new(
                m * (b * b + c * c) / 12.0,
                m * (a * a + c * c) / 12.0,
                m * (a * a + b * b) / 12.0,
            )),
        }
    }

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

    #[test]
    fn three_stacked_unit_cubes_equal_one_1x3x1_box() {
        let cubes: Vec<_> = (0..3)
            .map(|k| box_props(1.0, 1.0, 1.0, 1.0, Vector3::new(0.5, 0.5 + k as f64, 0.5)))
            .collect();
        let sum = MassProperties::sum(&cubes).expect("three cubes");
        let expected = box_props(3.0, 1.0, 3.0, 1.0, Vector3::new(0.5, 1.5, 0.5));
        assert!((sum.p_oc - expected.p_oc).norm() <= 4.0 * f64::EPSILON);
        assert!((sum.inertia_c - expected.inertia_c).norm() <= 8.0 * f64::EPSILON);
    }

    #[test]
    fn steiner_both_ways_round_trips_and_from_inertia_about_recovers_the_centre() {
        let b = box_props(2.0, 1.0, 2.0, 3.0, Vector3::new(1.0, -2.0, 0.5));
        let a = Vector3::new(5.0, 1.0, -3.0);
        let j_a = b.inertia_about(&a);
        let back = MassProperties::central_inertia_from(b.mass, &b.p_oc, &j_a, &a);
        assert!((back - b.inertia_c).norm() <= 1e-13 * j_a.norm());
        let rebuilt = MassProperties::from_inertia_about(b.mass, b.p_oc, j_a, a).expect("valid");
        assert!((rebuilt.inertia_c - b.inertia_c).norm() <= 1e-13 * j_a.norm());
    }

    #[test]
    fn moment_about_line_ignores_the_scale_of_the_direction() {
        let body = MassProperties {
            mass: 4.0,
            p_oc: Vector3::new(0.8, -0.7, 0.03),
            inertia_c: Matrix3::new(2.3, -0.2, -0.03, -0.2, 0.97, 0.14, -0.03, 0.14, 3.2),
        };
        let point = Vector3::new(0.1, 0.2, -0.3);
        for direction in [Vector3::new(1.0, 0.5, -0.25), Vector3::new(1.0, 5e-155, 0.0)] {
            let reference = body.moment_about_line(&point, &direction).expect("line");
            // Scalings by powers of two reaching the subnormal range and near f64::MAX.
            for k in [-1040, -1000, -530, -100, 100, 1000] {
                let half = 2f64.powi(k / 2);
                let scaled = direction * half * half;
                let moment = body.moment_about_line(&point, &scaled).expect("line");
                assert!(
                    (moment - reference).abs() <= 8.0 * f64::EPSILON * reference,
                    "2^{k}: {moment} vs {reference}"
                );
            }
        }
    }

    #[test]
    fn moment_about_line_matches_the_parallel_axis_for_a_rod_end() {
        // A thin rod along z, length L, about a perpendicular axis through its end: m L²/3.
        let l = 2.0;
        let rod = MassProperties {
            mass: 3.0,
            p_oc: Vector3::zeros(),
            inertia_c: Matrix3::from_diagonal(&Vector3::new(3.0 * l * l / 12.0, 3.0 * l * l / 12.0, 0.0)),
        };
        let i = rod
            .moment_about_line(&Vector3::new(0.0, 0.0, -l / 2.0), &Vector3::new(0.0, 7.0, 0.0))
            .expect("line");
        assert!((i - 3.0 * l * l / 3.0).abs() <= 1e-15 * i);
        // The line along the rod carries no moment, wherever its point lies on the axis.
        let i = rod
            .moment_about_line(&Vector3::new(0.0, 0.0, 5.0), &Vector3::new(0.0, 0.0, -1.0))
            .expect("line");
        assert_eq!(i, 0.0);
        assert_eq!(
            rod.moment_about_line(&Vector3::zeros(), &Vector3::zeros()),
            Err(MassError::ZeroDirection("line direction"))
        );
    }

    #[test]
    fn rotated_off_origin_box_equals_r_diag_rt() {
        let b = box_props(5.0, 1.0, 2.0, 3.0, Vector3::zeros());
        let q = UnitQuaternion::from_euler_angles(0.3, -1.1, 2.0);
        let t = Vector3::new(10.0, -3.0, 7.0);
        let moved = b.transformed(&Isometry3::from_parts(Translation3::from(t), q));
        let r = q.to_rotation_matrix();
        let expected = r.matrix() * b.inertia_c * r.matrix().transpose();
        assert!((moved.inertia_c - expected).norm() <= 1e-14 * expected.norm());
        assert!((moved.p_oc - t).norm() <= 1e-14 * t.norm());
    }

    #[test]
    fn a_hole_undoes_a_sum() {
        let body = box_props(8.0, 2.0, 2.0, 2.0, Vector3::zeros());
        let part = box_props(1.0, 1.0, 1.0, 1.0, Vector3::new(0.5, 0.5, 0.5));
        let rest = body.subtract(&part).expect("fits");
        let again = MassProperties::sum(&[rest, part]).expect("sum");
        assert!((again.mass - 8.0).abs() <= 1e-15 * 8.0);
        assert!(again.p_oc.norm() <= 1e-15);
        assert!((again.inertia_c - body.inertia_c).norm() <= 1e-14 * body.inertia_c.norm());
        // Seven unit cubes (the rest) equal the sum of the seven cubes other than the removed one.
        let seven: Vec<_> = (0..8)
            .filter(|&k| k != 7)
            .map(|k| {
                let s = |bit: i32| if k & bit != 0 { 0.5 } else { -0.5 };
                box_props(1.0, 1.0, 1.0, 1.0, Vector3::new(s(1), s(2), s(4)))
            })
            .collect();
        let direct = MassProperties::sum(&seven).expect("sum");
        assert!((direct.p_oc - rest.p_oc).norm() <= 1e-15);
        assert!((direct.inertia_c - rest.inertia_c).norm() <= 1e-14 * direct.inertia_c.norm());
        assert_eq!(body.subtract(&body), Err(MassError::NonPositiveTotalMass(0.0)));
        // A "hole" far outside the body leaves a tensor that no body has.
        let outside = box_props(1.0, 1.0, 1.0, 1.0, Vector3::new(10.0, 0.0, 0.0));
        assert!(matches!(body.subtract(&outside), Err(MassError::InvalidInertia(_))));
    }

    #[test]
    fn composition_at_poses_far_from_the_origin_keeps_accuracy() {
        // Two unit cubes side by side at 1e6 from the origin form a 2×1×1 box.
        let cube = box_props(1.0, 1.0, 1.0, 1.0, Vector3::zeros());
        let base = Vector3::new(1e6, 1e6, 1e6);
        let parts = [
            (Isometry3::translation(base.x, base.y, base.z), cube),
            (Isometry3::translation(base.x + 1.0, base.y, base.z), cube),
        ];
        let sum = MassProperties::compose(&parts).expect("sum");
        let expected = box_props(2.0, 2.0, 1.0, 1.0, Vector3::zeros());
        assert!((sum.inertia_c - expected.inertia_c).norm() <= 1e-15 * expected.inertia_c.norm());
        assert_eq!(sum.p_oc, base + Vector3::new(0.5, 0.0, 0.0));
    }
}
