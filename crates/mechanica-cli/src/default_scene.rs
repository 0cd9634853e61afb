//! The built-in default scene: a small tour that exercises each capability crate once.
//! It grows as capabilities land.

use crate::report::{Quantity, Report, timed_step};
use mechanica::impulse::point::collide_collinear;
use mechanica::kinematics::nalgebra::{Rotation3, Vector3};
use mechanica::kinematics::rotation::{angular_velocity_from_rate, skew};
use mechanica::mass::MassProperties;

fn q(name: &str, values: Vec<f64>, unit: &str, accuracy: Option<String>) -> Quantity {
    Quantity {
        name: name.into(),
        values,
        unit: unit.into(),
        accuracy,
    }
}

/// Runs the default scene and returns its report.
pub fn run() -> Result<Report, String> {
    let mut steps = Vec::new();

    steps.push(timed_step("kinematics: spin about a tilted axis", || {
        let w = Vector3::new(0.0, 0.6, 0.8) * 2.0;
        let r = Rotation3::from_scaled_axis(Vector3::new(0.3, -0.2, 0.5));
        let r_dot = skew(&w) * r.matrix();
        let omega = angular_velocity_from_rate(&r, &r_dot).map_err(|e| e.to_string())?;
        let error = (omega - w).norm() / w.norm();
        Ok::<_, String>(vec![q(
            "ω from Ω = Ṙ Rᵀ (2.7–2.12)",
            omega.iter().copied().collect(),
            "rad/s",
            Some(format!("relative error vs. prescribed ω: {error:.1e}")),
        )])
    })?);

    steps.push(timed_step("mass properties: point mass, Steiner", || {
        let m = MassProperties::point(2.0, Vector3::new(0.0, 0.0, 1.5)).map_err(|e| e.to_string())?;
        let j = m.inertia_about(&Vector3::zeros());
        Ok::<_, String>(vec![q(
            "J about origin, diagonal (3.27–3.29)",
            vec![j[(0, 0)], j[(1, 1)], j[(2, 2)]],
            "kg·m²",
            None,
        )])
    })?);

    steps.push(timed_step("impulse: billiard balls, λ = 0.9", || {
        let out = collide_collinear(0.17, 2.0, 0.17, 0.0, 0.9).map_err(|e| e.to_string())?;
        Ok::<_, String>(vec![
            q(
                "velocities after impact (5.21–5.22)",
                vec![out.v1_after, out.v2_after],
                "m/s",
                None,
            ),
            q("energy change (5.23)", vec![out.energy_change], "J", None),
        ])
    })?);

    Ok(Report {
        title: "built-in default scene".into(),
        version: mechanica::version().into(),
        steps,
    })
}
