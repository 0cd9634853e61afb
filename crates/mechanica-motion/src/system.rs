//! The mechanical system integrated in time: the state y = (q, q̇), its acceleration
//! q̈ = A(q)⁻¹(τ − h(q, q̇, t)) from the dynamics crate (7.60), or with holonomic constraints
//! the q̈ of [A Jᵀ; J 0] [q̈; λ] = [τ − h; γ] (M.18), the mass matrix, the conserved quantity
//! H = ½ q̇ᵀA q̇ + U*(q) − τ_c·q (M.1) and the constraint drift (M.20).

use crate::error::{StepFailure, check_finite};
use crate::forcing::Forcing;
use crate::monitors::Measurement;
use mechanica_dynamics::{ConstrainedDynamics, Dynamics, State};
use mechanica_kinematics::tree::Workspace;
use nalgebra::{DMatrix, DVector};

/// A [`Dynamics`] with its holonomic constraints (none for an unconstrained mechanism), its
/// applied forces and scratch storage for τ.
#[derive(Debug, Clone)]
pub(crate) struct System {
    model: ConstrainedDynamics,
    forcing: Forcing,
    tau: Vec<f64>,
    /// For the momenta of the whole mechanism (base at rest).
    momentum_workspace: Workspace,
}

impl System {
    /// The system of `dynamics` driven by `forcing` (already validated).
    pub(crate) fn new(model: ConstrainedDynamics, forcing: Forcing) -> Self {
        let n = model.dof();
        let momentum_workspace = model.dynamics().tree().workspace();
        Self {
            model,
            forcing,
            tau: vec![0.0; n],
            momentum_workspace,
        }
    }

    /// Number of coordinates.
    pub(crate) fn dof(&self) -> usize {
        self.model.dof()
    }

    /// True when the mechanism has holonomic constraints.
    pub(crate) fn is_constrained(&self) -> bool {
        self.model.equation_count() > 0
    }

    /// The number of constraint equations m.
    pub(crate) fn constraints_equations(&self) -> usize {
        self.model.equation_count()
    }

    /// The dynamics with its constraints.
    pub(crate) fn constraints_mut(&mut self) -> &mut ConstrainedDynamics {
        &mut self.model
    }

    /// The dynamics (its mechanism carries the current charts of rotation vectors).
    pub(crate) fn dynamics(&self) -> &Dynamics {
        self.model.dynamics()
    }

    /// The dynamics, for re-centring charts.
    pub(crate) fn dynamics_mut(&mut self) -> &mut Dynamics {
        self.model.dynamics_mut()
    }

    /// q̈ at (t, q, q̇) into `out`: with constraints, the q̈ of the multiplier equations (M.18)
    /// (the index-1 form, exact for any state, on the manifold or off it); without, the
    /// articulated-body algorithm.
    pub(crate) fn acceleration(
        &mut self,
        t: f64,
        q: &[f64],
        q_dot: &[f64],
        out: &mut [f64],
    ) -> Result<(), StepFailure> {
        if !self.is_constrained() {
            return self.free_acceleration(t, q, q_dot, out);
        }
        check_finite(q, "state q")?;
        check_finite(q_dot, "state q̇")?;
        self.forcing.evaluate(t, q, q_dot, &mut self.tau)?;
        let state = State::new(q, q_dot).at_time(t);
        let forward = self.model.forward_dynamics(&state, &self.tau)?;
        out.copy_from_slice(&forward.q_ddot);
        check_finite(out, "acceleration")
    }

    /// q̈ at (t, q, q̇) into `out` without the constraints' reactions, by the articulated-body
    /// algorithm.
    pub(crate) fn free_acceleration(
        &mut self,
        t: f64,
        q: &[f64],
        q_dot: &[f64],
        out: &mut [f64],
    ) -> Result<(), StepFailure> {
        check_finite(q, "state q")?;
        check_finite(q_dot, "state q̇")?;
        self.forcing.evaluate(t, q, q_dot, &mut self.tau)?;
        let state = State::new(q, q_dot).at_time(t);
        self.model.dynamics_mut().aba_state_into(&state, &self.tau, out)?;
        check_finite(out, "acceleration")
    }

    /// The mass matrix A(q) (8.28).
    pub(crate) fn mass_matrix(&mut self, q: &[f64]) -> Result<DMatrix<f64>, StepFailure> {
        let a = self.model.dynamics_mut().mass_matrix(q)?;
        let n = a.nrows();
        Ok(DMatrix::from_fn(n, n, |i, j| a[(i, j)]))
    }

    /// U*(q) − τ_c·q: the mechanism's potentials (with −T₀ in a rotating frame, (8.56)) and
    /// the potential of a constant applied force.
    pub(crate) fn potential_energy(&self, q: &[f64]) -> Result<f64, StepFailure> {
        let u = self
            .model
            .dynamics()
            .mechanism()
            .potential(q, false)
            .map_err(mechanica_dynamics::DynamicsError::from)?
            .value;
        Ok(u + self.forcing.potential(q))
    }

    /// H (M.1), T₂ and the generalized momenta p = A(q) q̇ from one mass matrix, and the
    /// momenta P, L of the whole mechanism (M.15)–(M.16), in the current charts.
    pub(crate) fn measure(&mut self, q: &[f64], q_dot: &[f64]) -> Result<Measurement, StepFailure> {
        let a = self.mass_matrix(q)?;
        let v = DVector::from_column_slice(q_dot);
        let p = &a * &v;
        let kinetic = 0.5 * v.dot(&p);
        let energy = kinetic + self.potential_energy(q)?;
        if !energy.is_finite() {
            return Err(StepFailure::NonFinite { what: "energy" });
        }
        let constraint_drift = self.constraint_drift(q, q_dot)?;
        let mechanism = self.model.dynamics().mechanism();
        let momentum = crate::momentum::momentum_into(
            mechanism.tree(),
            mechanism.bodies(),
            &mut self.momentum_workspace,
            q,
            q_dot,
        )?;
        Ok(Measurement {
            energy,
            kinetic,
            p: p.as_slice().to_vec(),
            momentum,
            constraint_drift,
        })
    }

    /// ‖f(q)‖₂ and ‖J q̇‖₂ (M.20), zero without constraints.
    pub(crate) fn constraint_drift(&mut self, q: &[f64], q_dot: &[f64]) -> Result<(f64, f64), StepFailure> {
        if !self.is_constrained() {
            return Ok((0.0, 0.0));
        }
        let drift = self.model.drift(q, q_dot)?;
        Ok((drift.position, drift.velocity))
    }
}
