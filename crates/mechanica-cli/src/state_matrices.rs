//! `run --matrices`: the mass matrix A(q) (8.28), the potential U*(q) = U − T₀ (8.56–8.58) with
//! its gradient ∂U*/∂q and Hessian B(q) = ∂²U*/∂q∂q (8.85), at the state where the run starts
//! (`--q`, or the scene's q0). Without a rotating frame U* = U, the potential energy of gravity,
//! springs and constant forces.
//!
//! The values are the library's (`Mechanism::mass_matrix`, `Mechanism::potential`): A is exact
//! to rounding (composite rigid bodies), the gradient and Hessian are the exact derivatives of
//! U*, evaluated in double precision. Second derivatives in the rotation-vector coordinates of
//! spherical and free joints are exact only at φ = 0, so a state with such a joint is first
//! re-centred (`Mechanism::rebase`): those coordinates are then the rotation vector about the
//! orientation at q, and the record says so.

use crate::mechanism_run::build_mechanism;
use crate::report::text::{Precision, Text, number};
use crate::report::{Step, timed_step};
use crate::scene::Scene;
use crate::scene_run::{Model, coordinate_names};
use serde::Serialize;

/// The matrices of a mechanism at one state, over named coordinates.
#[derive(Debug, Clone, Serialize)]
pub struct StateMatricesRecord {
    /// One name per coordinate, as the build step names them.
    pub coordinates: Vec<String>,
    /// The state q (the coordinates as given, before any re-centring), rad or m.
    pub q: Vec<f64>,
    /// True when spherical or free joints were re-centred: their rotation-vector coordinates
    /// are measured from the orientation at q (φ = 0 there).
    pub recentred: bool,
    /// A(q), kinetic energy T = ½ q̇ᵀ A q̇: one row per coordinate, every entry.
    pub mass_matrix: Vec<Vec<f64>>,
    /// U*(q), J.
    pub potential: f64,
    /// ∂U*/∂q, one entry per coordinate (N·m per rad, N per m).
    pub gradient: Vec<f64>,
    /// B(q) = ∂²U*/∂q∂q, one row per coordinate, every entry.
    pub hessian: Vec<Vec<f64>>,
}

/// The rows of a dense matrix.
fn rows(matrix: &mechanica::modal::faer::Mat<f64>) -> Vec<Vec<f64>> {
    (0..matrix.nrows())
        .map(|i| (0..matrix.ncols()).map(|j| matrix[(i, j)]).collect())
        .collect()
}

/// The timed `--matrices` step of `scene` at the model's start state.
pub fn step(scene: &Scene, model: &Model) -> Result<Step, String> {
    timed_step(
        "matrices at q: A(q) (8.28), grad U* and B = ∂²U*/∂q∂q (8.85)",
        || record(scene, model),
    )
}

/// A(q), U*(q), its gradient and Hessian at the model's q0.
fn record(scene: &Scene, model: &Model) -> Result<StateMatricesRecord, String> {
    let mut mechanism = build_mechanism(scene, model)?;
    let text = |e: mechanica::mechanism::MechanismError| e.to_string();
    let mut q = model.q0.clone();
    let recentred = mechanism.has_rotation_vectors();
    if recentred {
        mechanism.rebase(&mut q).map_err(text)?;
    }
    let mass_matrix = mechanism.mass_matrix(&q).map_err(text)?;
    let potential = mechanism.potential(&q, true).map_err(text)?;
    let hessian = potential
        .hessian
        .as_ref()
        .ok_or("internal: the potential's Hessian was not computed")?;
    Ok(StateMatricesRecord {
        coordinates: coordinate_names(model),
        q: model.q0.clone(),
        recentred,
        mass_matrix: rows(&mass_matrix),
        potential: potential.value,
        gradient: potential.gradient.clone(),
        hessian: rows(hessian),
    })
}

impl StateMatricesRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        out.named("at q", &self.coordinates, &self.q, "rad | m", Precision::Exact);
        if self.recentred {
            out.note("rotation vectors of spherical and free joints measured from the orientation at q");
        }
        self.write_matrix(out, "A(q), T = ½ q̇ᵀA q̇ (8.28)", &self.mass_matrix);
        out.value("U*(q)", self.potential, "J", Precision::Exact);
        out.named(
            "∂U*/∂q",
            &self.coordinates,
            &self.gradient,
            "N·m | N (per rad | per m)",
            Precision::Exact,
        );
        self.write_matrix(out, "B(q) = ∂²U*/∂q∂q (8.85)", &self.hessian);
    }

    /// A matrix, one line per row labelled by its coordinate, the columns in coordinate order.
    fn write_matrix(&self, out: &mut Text, title: &str, matrix: &[Vec<f64>]) {
        out.line(title, &format!("rows and columns: {}", self.coordinates.join(", ")));
        for (name, row) in self.coordinates.iter().zip(matrix) {
            let shown: Vec<String> = row.iter().map(|&v| number(v, Precision::Exact.digits(v))).collect();
            out.line(&format!("  {name}"), &format!("[{}]", shown.join(", ")));
        }
    }
}
