//! Collinear collision of two point masses (5.16–5.23).

use crate::ImpulseError;

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
    Ok(CollinearImpact {
        v1_after: v1 - impulse_on_2 / m1,
        v2_after: v2 + impulse_on_2 / m2,
        impulse_on_2,
        energy_change: -0.5 * (1.0 - restitution * restitution) * reduced_mass * approach * approach,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

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
    fn restitution_outside_the_unit_interval_is_rejected() {
        assert_eq!(
            collide_collinear(1.0, 1.0, 1.0, 0.0, 1.5),
            Err(ImpulseError::RestitutionOutOfRange(1.5))
        );
    }
}
