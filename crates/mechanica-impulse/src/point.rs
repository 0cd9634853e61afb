//! Point masses: an impulse on a point (5.10–5.15, 7.106) and collisions of two points,
//! collinear (5.16–5.23) and in 3-D along a contact normal.

use crate::ImpulseError;
use crate::body::unit_vector;
use crate::error::{check_all_finite, check_finite, check_result};
use nalgebra::Vector3;

/// The response of a point mass to an impulse.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointImpulse {
    /// Velocity just after, V = v + S/m (5.13), m/s.
    pub v_after: Vector3<f64>,
    /// ΔT = ½ S·(V + v) (7.106), J.
    pub energy_change: f64,
}

/// Applies the impulse `s` to a point of mass `mass` moving at `v`: the momentum jumps by S
/// (5.13) while the position is continuous (5.15).
pub fn impulse_on_point(mass: f64, v: &Vector3<f64>, s: &Vector3<f64>) -> Result<PointImpulse, ImpulseError> {
    check_finite("mass", mass)?;
    if mass <= 0.0 {
        return Err(ImpulseError::NonPositiveMass {
            what: "mass",
            value: mass,
        });
    }
    check_all_finite("velocity", v.iter())?;
    check_all_finite("impulse", s.iter())?;
    let v_after = v + s / mass;
    let result = PointImpulse {
        v_after,
        energy_change: 0.5 * s.dot(&(v_after + v)),
    };
    check_result("velocity after the impulse", result.v_after.iter())?;
    check_result("energy change", [result.energy_change].iter())?;
    Ok(result)
}

/// The outcome of a 3-D collision of two smooth point masses (spheres) along a normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointImpact {
    /// Velocity of point 1 after the impact.
    pub v1_after: Vector3<f64>,
    /// Velocity of point 2 after the impact.
    pub v2_after: Vector3<f64>,
    /// Impulse on point 2 (point 1 receives its negative), along n (7.95), N·s.
    pub impulse_on_2: Vector3<f64>,
    /// ΔT = −½ (1 − λ²) μ (v_n,1 − v_n,2)² (5.23 with normal components), J.
    pub energy_change: f64,
}

/// Collides point 1 (`m1`, `v1`) with point 2 (`m2`, `v2`) along the unit normal `n` pointing
/// from point 1 to point 2 (the line of centres of two spheres), with restitution λ ∈ [0, 1].
/// The impulse is along n (smooth contact, 7.95); the normal components follow (5.21–5.22)
/// and the tangential components are unchanged. Points that do not approach
/// ((v1 − v2)·n ≤ 0) receive no impulse.
pub fn collide_points(
    m1: f64,
    v1: &Vector3<f64>,
    m2: f64,
    v2: &Vector3<f64>,
    n: &Vector3<f64>,
    restitution: f64,
) -> Result<PointImpact, ImpulseError> {
    check_all_finite("v1", v1.iter())?;
    check_all_finite("v2", v2.iter())?;
    let n = unit_vector("normal", n)?;
    let (u1, u2) = (v1.dot(&n), v2.dot(&n));
    let line = collide_collinear(m1, u1, m2, u2, restitution)?;
    // The velocity changes along n from the line's velocities, not as S/m per component: with
    // a subnormal mass the impulse's components round to the subnormal spacing and the change
    // would leave the normal direction.
    let result = PointImpact {
        v1_after: v1 + n * (line.v1_after - u1),
        v2_after: v2 + n * (line.v2_after - u2),
        impulse_on_2: n * line.impulse_on_2,
        energy_change: line.energy_change,
    };
    check_result(
        "velocities after the collision",
        result.v1_after.iter().chain(result.v2_after.iter()),
    )?;
    check_result("impulse", result.impulse_on_2.iter())?;
    Ok(result)
}

/// The outcome of a collinear two-point collision.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CollinearImpact {
    /// Velocity of point 1 after the impact, V₁ (5.21).
    pub v1_after: f64,
    /// Velocity of point 2 after the impact, V₂ (5.22).
    pub v2_after: f64,
    /// Impulse on point 2 (point 1 receives its negative), S = m₂ (V₂ − v₂).
    pub impulse_on_2: f64,
    /// Kinetic energy change T⁺ − T⁻ (5.23), never positive for λ ≤ 1.
    pub energy_change: f64,
}

/// Collides point 1 (mass `m1`, velocity `v1`) with point 2 along one line, with Newton's
/// restitution coefficient `restitution` = λ ∈ [0, 1] (5.19–5.23).
///
/// The points approach when v₁ > v₂ (point 1 behind point 2). Separating or grazing
/// points (v₁ ≤ v₂) receive no impulse.
pub fn collide_collinear(
    m1: f64,
    v1: f64,
    m2: f64,
    v2: f64,
    restitution: f64,
) -> Result<CollinearImpact, ImpulseError> {
    for (what, value) in [
        ("m1", m1),
        ("v1", v1),
        ("m2", m2),
        ("v2", v2),
        ("restitution", restitution),
    ] {
        if !value.is_finite() {
            return Err(ImpulseError::NonFinite { what, value });
        }
    }
    for (what, value) in [("m1", m1), ("m2", m2)] {
        if value <= 0.0 {
            return Err(ImpulseError::NonPositiveMass { what, value });
        }
    }
    if !(0.0..=1.0).contains(&restitution) {
        return Err(ImpulseError::RestitutionOutOfRange(restitution));
    }
    let approach = v1 - v2;
    if approach <= 0.0 {
        return Ok(CollinearImpact {
            v1_after: v1,
            v2_after: v2,
            impulse_on_2: 0.0,
            energy_change: 0.0,
        });
    }
    // Reduced mass written so that a 1e12 mass ratio loses no digits: μ = m₁ m₂ / (m₁ + m₂).
    let reduced_mass = m1 / (1.0 + m1 / m2);
    let impulse_on_2 = (1.0 + restitution) * reduced_mass * approach;
    let result = CollinearImpact {
        v1_after: v1 - impulse_on_2 / m1,
        v2_after: v2 + impulse_on_2 / m2,
        impulse_on_2,
        energy_change: -0.5 * (1.0 - restitution * restitution) * reduced_mass * approach * approach,
    };
    check_result(
        "velocities after the collision",
        [result.v1_after, result.v2_after].iter(),
    )?;
    check_result("impulse", [result.impulse_on_2].iter())?;
    check_result("energy change", [result.energy_change].iter())?;
    Ok(result)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A point of subnormal mass (1e-321…1e-310) hitting one of 0.01–10 kg along random normals:
    /// both velocities change along the normal only (the impulse's components, rounded to the
    /// subnormal spacing, once turned point 1's change off the normal by 0.4 %).
    #[test]
    fn a_subnormal_mass_changes_velocity_along_the_normal_only() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for case in 0..500 {
            let m1 = 10f64.powf(-321.0 + 11.0 * next());
            let m2 = 10f64.powf(-2.0 + 3.0 * next());
            let v = |next: &mut dyn FnMut() -> f64| Vector3::new(next() - 0.5, next() - 0.5, next() - 0.5) * 6.0;
            let (v1, v2) = (v(&mut next), v(&mut next));
            let n = v(&mut next).normalize();
            let out = collide_points(m1, &v1, m2, &v2, &n, next()).expect("valid");
            for (before, after) in [(v1, out.v1_after), (v2, out.v2_after)] {
                let change = after - before;
                let off_normal = (change - n * change.dot(&n)).norm();
                assert!(
                    off_normal <= 1e-15 * (v1.norm() + v2.norm()),
                    "case {case}: {off_normal:e} off the normal"
                );
            }
        }
    }

    #[test]
    fn equal_elastic_billiard_balls_exchange_velocities() {
        let out = collide_collinear(0.17, 2.0, 0.17, 0.0, 1.0).expect("valid");
        assert!((out.v1_after - 0.0).abs() < 1e-15 && (out.v2_after - 2.0).abs() < 1e-15);
        assert_eq!(out.energy_change, 0.0);
    }

    #[test]
    fn energy_change_matches_the_before_after_difference() {
        let (m1, v1, m2, v2, l) = (3.0, 1.5, 5.0, -0.5, 0.4);
        let out = collide_collinear(m1, v1, m2, v2, l).expect("valid");
        let t_before = 0.5 * m1 * v1 * v1 + 0.5 * m2 * v2 * v2;
        let t_after = 0.5 * m1 * out.v1_after.powi(2) + 0.5 * m2 * out.v2_after.powi(2);
        assert!((t_after - t_before - out.energy_change).abs() < 1e-14);
        // Momentum (5.17–5.18) and restitution (5.19).
        assert!((m1 * v1 + m2 * v2 - m1 * out.v1_after - m2 * out.v2_after).abs() < 1e-14);
        assert!(((out.v2_after - out.v1_after) + l * (v2 - v1)).abs() < 1e-14);
    }

    #[test]
    fn a_wall_of_mass_1e12_reflects_the_ball() {
        let out = collide_collinear(1.0, 1.0, 1e12, 0.0, 1.0).expect("valid");
        assert!((out.v1_after + 1.0).abs() < 1e-11);
    }

    #[test]
    fn an_impulse_on_a_point_changes_its_momentum_by_the_impulse() {
        let (m, v, s) = (2.0, Vector3::new(1.0, -2.0, 0.5), Vector3::new(0.4, 1.0, -3.0));
        let r = impulse_on_point(m, &v, &s).expect("valid");
        assert!((m * (r.v_after - v) - s).norm() < 1e-15);
        let direct = 0.5 * m * (r.v_after.norm_squared() - v.norm_squared());
        assert!((r.energy_change - direct).abs() < 1e-14);
        assert!(matches!(
            impulse_on_point(-1.0, &v, &s),
            Err(ImpulseError::NonPositiveMass { .. })
        ));
        assert!(matches!(
            impulse_on_point(1.0, &v, &Vector3::new(f64::INFINITY, 0.0, 0.0)),
            Err(ImpulseError::NonFinite { .. })
        ));
    }

    #[test]
    fn oblique_elastic_billiard_balls_leave_at_right_angles() {
        // Equal masses, elastic, target at rest: the velocities after are perpendicular and
        // the cue ball keeps only its tangential component.
        let n = Vector3::new(1.0, 1.0, 0.0).normalize();
        let v1 = Vector3::new(2.0, 0.0, 0.0);
        let r = collide_points(0.17, &v1, 0.17, &Vector3::zeros(), &n, 1.0).expect("valid");
        assert!(r.v1_after.dot(&r.v2_after).abs() < 1e-15);
        assert!((r.v2_after - n * v1.dot(&n)).norm() < 1e-15);
        assert!((r.v1_after - (v1 - n * v1.dot(&n))).norm() < 1e-15);
        assert_eq!(r.energy_change, 0.0);
        // Momentum (5.17).
        assert!((0.17 * (r.v1_after + r.v2_after) - 0.17 * v1).norm() < 1e-15);
    }

    #[test]
    fn separating_and_grazing_points_and_bad_normals() {
        let n = Vector3::x();
        let r = collide_points(1.0, &Vector3::new(0.0, 1.0, 0.0), 1.0, &Vector3::zeros(), &n, 0.5).expect("ok");
        assert_eq!(r.impulse_on_2, Vector3::zeros());
        let bad = collide_points(1.0, &Vector3::x(), 1.0, &Vector3::zeros(), &Vector3::zeros(), 0.5);
        assert!(matches!(bad, Err(ImpulseError::NotUnit { .. })));
        let bad = collide_points(1.0, &Vector3::x(), 1.0, &Vector3::zeros(), &(n * 1.01), 0.5);
        assert!(matches!(bad, Err(ImpulseError::NotUnit { .. })));
    }

    #[test]
    fn restitution_outside_the_unit_interval_is_rejected() {
        assert_eq!(
            collide_collinear(1.0, 1.0, 1.0, 0.0, 1.5),
            Err(ImpulseError::RestitutionOutOfRange(1.5))
        );
    }
}
