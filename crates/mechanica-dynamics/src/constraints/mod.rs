//! Loop closures and prescribed motions by Lagrange multipliers: a [`Dynamics`] with
//! holonomic constraints f(q) = 0 ([`Constraint`]) that the tree coordinates do not satisfy by
//! themselves (FM 4.61, 4.83–4.86; `docs/theory.md`, "Constraints by multipliers").
//!
//! With J = ∂f/∂q and γ = −J̇ q̇, the equations of motion (7.60) with the reactions of the
//! constraints are
//!
//!   A q̈ + h + Jᵀλ = τ + Q,   J q̈ = γ,   i.e.   [A Jᵀ; J 0] [q̈; λ] = [τ + Q − h; γ],
//!
//! with h = c + g. The reactions' generalized force is −Jᵀλ, and the force a constraint applies
//! at a point x is −Σ_r λ_r ∇_x f_r: FM 4.61 with FM's multiplier equal to −λ (FM write the
//! potential with the opposite sign, F = +∇U). So a rod's λ is its tension and a plane's λ is
//! minus the normal force along n.
//!
//! - [`ConstrainedDynamics`] holds the [`Dynamics`] and the constraints. It is a separate
//!   struct rather than a field of [`Dynamics`] so that the unconstrained recursions stay as
//!   they are and need not check constraints; [`ConstrainedDynamics::dynamics_mut`] reaches
//!   the dampers and velocity potentials.
//! - [`ConstrainedDynamics::forward_dynamics`] ([`forward`]): q̈ and λ by A = LLᵀ and the
//!   Schur complement S = J A⁻¹ Jᵀ, a redundancy test ([`schur`]), the reactions
//!   ([`ConstraintReaction`]), the drift and an accuracy report.
//! - [`ConstrainedDynamics::project_positions`] and
//!   [`ConstrainedDynamics::project_velocities`] ([`projection`]): back onto f = 0 and
//!   J q̇ = 0 for integrators.
//! - [`ConstrainedDynamics::drift`] ([`drift`]): f(q), J q̇ and the rounding level of f.
//! - [`ConstrainedDynamics::equilibrium`] ([`equilibrium`]): ∇U + Jᵀλ = 0, f = 0 (FM 4.83–4.86)
//!   by Newton's method on (q, λ) with the exact Hessian of the Lagrangian.

pub mod drift;
pub mod equilibrium;
mod evaluate;
pub mod forward;
pub mod kinds;
pub mod projection;
pub mod reactions;
pub mod schur;

pub use drift::ConstraintDrift;
pub use equilibrium::{ConstrainedEquilibrium, ConstrainedEquilibriumOptions};
pub use forward::{Baumgarte, ConstrainedForward};
pub use kinds::Constraint;
pub use projection::{PositionProjection, ProjectionMetric, ProjectionOptions, VelocityProjection};
pub use reactions::ConstraintReaction;

use crate::error::DynamicsError;
use crate::model::Dynamics;
use evaluate::Evaluated;
use mechanica_kinematics::tree::Workspace;

/// A [`Dynamics`] with holonomic constraints solved by multipliers (module docs).
///
/// Equations are numbered in the order the constraints were added, each constraint's
/// equations contiguous ([`ConstrainedDynamics::equation_range`]); λ follows that order.
#[derive(Debug, Clone)]
pub struct ConstrainedDynamics {
    dynamics: Dynamics,
    names: Vec<String>,
    constraints: Vec<Constraint>,
    baumgarte: Option<Baumgarte>,
    pivot_tolerance: f64,
    /// The base frame's view (base at rest) for f, J and γ.
    ws: Workspace,
}

impl ConstrainedDynamics {
    /// `dynamics` without constraints, Baumgarte stabilisation off, the default pivot
    /// tolerance [`schur::DEFAULT_PIVOT_TOLERANCE`].
    pub fn new(dynamics: Dynamics) -> Self {
        let ws = dynamics.tree().workspace();
        Self {
            dynamics,
            names: Vec::new(),
            constraints: Vec::new(),
            baumgarte: None,
            pivot_tolerance: schur::DEFAULT_PIVOT_TOLERANCE,
            ws,
        }
    }

    /// The unconstrained dynamics.
    pub fn dynamics(&self) -> &Dynamics {
        &self.dynamics
    }

    /// The unconstrained dynamics, to add dampers or velocity potentials.
    pub fn dynamics_mut(&mut self) -> &mut Dynamics {
        &mut self.dynamics
    }

    /// The unconstrained dynamics, giving up the constraints.
    pub fn into_dynamics(self) -> Dynamics {
        self.dynamics
    }

    /// Number of coordinates n.
    pub fn dof(&self) -> usize {
        self.dynamics.dof()
    }

    /// Adds a constraint named `name` after checking it against the tree (see
    /// [`Constraint`]); returns its index. Directions and normals are stored normalised.
    pub fn add_constraint(&mut self, name: impl Into<String>, constraint: Constraint) -> Result<usize, DynamicsError> {
        let checked = constraint.checked(self.dynamics.tree())?;
        self.constraints.push(checked);
        self.names.push(name.into());
        Ok(self.constraints.len() - 1)
    }

    /// The constraints (normalised), in the order added.
    pub fn constraints(&self) -> &[Constraint] {
        &self.constraints
    }

    /// The name of constraint `index`, if it exists.
    pub fn constraint_name(&self, index: usize) -> Option<&str> {
        self.names.get(index).map(String::as_str)
    }

    /// The total number of equations m (the length of λ).
    pub fn equation_count(&self) -> usize {
        self.constraints.iter().map(Constraint::equation_count).sum()
    }

    /// The equations (rows of f, J and λ) of constraint `index`, if it exists.
    pub fn equation_range(&self, index: usize) -> Option<std::ops::Range<usize>> {
        let constraint = self.constraints.get(index)?;
        let start: usize = self.constraints[..index].iter().map(Constraint::equation_count).sum();
        Some(start..start + constraint.equation_count())
    }

    /// The Baumgarte gains, None when stabilisation is off (the default).
    pub fn baumgarte(&self) -> Option<Baumgarte> {
        self.baumgarte
    }

    /// Turns Baumgarte stabilisation on with `gains` (checked: finite, ≥ 0), or off with None.
    pub fn set_baumgarte(&mut self, gains: Option<Baumgarte>) -> Result<(), DynamicsError> {
        if let Some(g) = gains {
            g.validate()?;
        }
        self.baumgarte = gains;
        Ok(())
    }

    /// The relative pivot tolerance ε of the redundancy test ([`schur`]).
    pub fn pivot_tolerance(&self) -> f64 {
        self.pivot_tolerance
    }

    /// Sets ε (0 ≤ ε < 1).
    pub fn set_pivot_tolerance(&mut self, tolerance: f64) -> Result<(), DynamicsError> {
        if !(0.0..1.0).contains(&tolerance) {
            return Err(DynamicsError::OutOfRange {
                what: "pivot tolerance",
                requirement: "in [0, 1)",
                value: tolerance,
            });
        }
        self.pivot_tolerance = tolerance;
        Ok(())
    }

    /// f(q), one entry per equation.
    pub fn constraint_values(&mut self, q: &[f64]) -> Result<Vec<f64>, DynamicsError> {
        let zeros = vec![0.0; self.dof()];
        Ok(self.evaluate(q, &zeros)?.value)
    }

    /// J(q) = ∂f/∂q as an m×n row-major array (row r = ∂f_r/∂q).
    pub fn constraint_jacobian(&mut self, q: &[f64]) -> Result<Vec<f64>, DynamicsError> {
        let zeros = vec![0.0; self.dof()];
        let j = self.evaluate(q, &zeros)?.jacobian;
        Ok((0..j.nrows())
            .flat_map(|r| (0..j.ncols()).map(move |k| (r, k)))
            .map(|(r, k)| j[(r, k)])
            .collect())
    }

    /// f, J, γ at (q, q̇) after checking both.
    pub(crate) fn evaluate(&mut self, q: &[f64], q_dot: &[f64]) -> Result<Evaluated, DynamicsError> {
        let n = self.dof();
        crate::error::check_vector(q, n, "q")?;
        crate::error::check_vector(q_dot, n, "q_dot")?;
        let tree = self.dynamics.mechanism.tree();
        tree.update_positions(&mut self.ws, q)?;
        tree.update_velocities(&mut self.ws, q_dot)?;
        evaluate::evaluate(tree, &self.ws, &self.constraints)
    }

    /// The typed error for the redundant row `row` (pivot against scale).
    pub(crate) fn redundant(&self, (row, pivot, scale): schur::Redundant) -> DynamicsError {
        let mut start = 0;
        for (index, constraint) in self.constraints.iter().enumerate() {
            let count = constraint.equation_count();
            if row < start + count {
                return DynamicsError::RedundantConstraint {
                    constraint: row,
                    name: format!(
                        "{}: constraint {index}, {}, equation {} of {count}",
                        self.names[index],
                        constraint.kind_name(),
                        row - start + 1
                    ),
                    pivot,
                    scale,
                };
            }
            start += count;
        }
        DynamicsError::RedundantConstraint {
            constraint: row,
            name: String::new(),
            pivot,
            scale,
        }
    }
}
