//! The reaction of each constraint from its multipliers (FM 4.61): the force −Σ_r λ_r ∇_x f_r
//! at its point (the opposite at the second point of a pair) and its generalized force −J_iᵀλ_i.

use super::evaluate::Evaluated;
use nalgebra::Vector3;

/// What one constraint applies to the mechanism, world components.
///
/// Point constraints transmit a pure force (a pin, a plane contact and a rod exert no couple):
/// `force` acts at `point` and −`force` at `opposite_point` (for a pair; on the ground when
/// that point is a ground point). A coordinate constraint acts only through
/// `generalized_force`.
#[derive(Debug, Clone, PartialEq)]
pub struct ConstraintReaction {
    /// The constraint's index.
    pub constraint: usize,
    /// Its equations: λ[first_equation .. first_equation + equations].
    pub first_equation: usize,
    /// Its number of equations.
    pub equations: usize,
    /// The force on the first point (a, or the plane's point), N; zero for a coordinate.
    pub force: Vector3<f64>,
    /// World position of the first point; None for a coordinate constraint.
    pub point: Option<Vector3<f64>>,
    /// World position of the second point of a pair, where −`force` acts.
    pub opposite_point: Option<Vector3<f64>>,
    /// −J_iᵀλ_i: the generalized force of the reaction (N or N·m per coordinate).
    pub generalized_force: Vec<f64>,
}

/// The reactions of all constraints for the multipliers `lambda`.
pub(crate) fn reactions(evaluated: &Evaluated, lambda: &[f64]) -> Vec<ConstraintReaction> {
    let j = &evaluated.jacobian;
    let mut first = 0;
    let mut out = Vec::with_capacity(evaluated.geometry.len());
    for (index, geometry) in evaluated.geometry.iter().enumerate() {
        let equations = geometry.gradients.len().max(1);
        let rows = first..first + equations;
        let force = geometry
            .gradients
            .iter()
            .zip(&lambda[rows.clone()])
            .fold(Vector3::zeros(), |f, (g, l)| f - g * *l);
        let generalized_force = (0..j.ncols())
            .map(|k| -rows.clone().map(|r| j[(r, k)] * lambda[r]).sum::<f64>())
            .collect();
        out.push(ConstraintReaction {
            constraint: index,
            first_equation: first,
            equations,
            force,
            point: geometry.point,
            opposite_point: geometry.opposite_point,
            generalized_force,
        });
        first += equations;
    }
    out
}
