//! The records of a scene's own steps: the model built, the mass properties at q0 and the
//! plots written.

use crate::report::text::{Precision, Text};
use serde::Serialize;

/// One body of a scene: its name and mass.
#[derive(Debug, Clone, Serialize)]
pub struct BodyRecord {
    /// The scene's (or the URDF link's) name.
    pub name: String,
    /// Mass, kg.
    pub mass: f64,
}

/// The model of a scene: bodies, coordinates and the start of every analysis.
#[derive(Debug, Clone, Serialize)]
pub struct BuildRecord {
    /// The bodies, in scene order.
    pub bodies: Vec<BodyRecord>,
    /// Degrees of freedom.
    pub dof: usize,
    /// One name per coordinate: the joint's name, `joint[i]` for a joint of several.
    pub coordinates: Vec<String>,
    /// q0 per coordinate, rad or m.
    pub q0: Vec<f64>,
}

impl BuildRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        let names: Vec<String> = self.bodies.iter().map(|b| b.name.clone()).collect();
        let masses: Vec<f64> = self.bodies.iter().map(|b| b.mass).collect();
        out.named("body masses", &names, &masses, "kg", Precision::Exact);
        out.count("degrees of freedom", self.dof);
        out.named(
            "q0, the start of every analysis",
            &self.coordinates,
            &self.q0,
            "rad | m",
            Precision::Exact,
        );
    }
}

/// Total mass properties of a scene at q0, in the world frame.
#[derive(Debug, Clone, Serialize)]
pub struct MassRecord {
    /// Total mass, kg.
    pub total_mass: f64,
    /// Centre of mass, m.
    pub centre_of_mass: [f64; 3],
    /// Principal moments about the centre of mass (3.20), ascending, kg·m².
    pub principal_moments: [f64; 3],
    /// ‖RᵀJR − diag‖ / ‖J‖ of the principal axes.
    pub principal_relative_residual: f64,
    /// U = −m g·x₀, J, when the scene has gravity.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gravitational_potential: Option<f64>,
}

impl MassRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        out.value("total mass", self.total_mass, "kg", Precision::Exact);
        out.values("centre of mass (world)", &self.centre_of_mass, "m", Precision::Exact);
        let scale = self.principal_moments.iter().fold(0.0, |a: f64, b| a.max(b.abs()));
        out.values(
            "principal moments about the centre of mass (3.20)",
            &self.principal_moments,
            "kg·m²",
            Precision::Absolute(self.principal_relative_residual * scale),
        );
        if let Some(u) = self.gravitational_potential {
            out.value("gravitational potential U = −m g·x₀", u, "J", Precision::Exact);
        }
    }
}

/// The SVG files written by `--plot`.
#[derive(Debug, Clone, Serialize)]
pub struct PlotsRecord {
    /// Paths of the files written.
    pub files: Vec<String>,
}

impl PlotsRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        for file in &self.files {
            out.note(&format!("wrote {file}"));
        }
    }
}
