//! The mechanical system integrated in time: the state y = (q, q̇), its acceleration
//! q̈ = A(q)⁻¹(τ − h(q, q̇, t)) from the dynamics crate (7.60), the mass matrix, and the
//! conserved quantity H = ½ q̇ᵀA q̇ + U*(q) − τ_c·q (M.1).

use crate::error::{StepFailure, check_finite};
use crate::forcing::Forcing;
use crate::monitors::Measurement;
use mechanica_dynamics::{Dynamics, State};
use mechanica_kinematics::tree::Workspace;
use nalgebra::{DMatrix, DVector};

/// A [`Dynamics`] with its applied forces and scratch storage for τ.
#[derive(Debug, Clone)]
pub(crate) struct System {
    dynamics: Dynamics,
    forcing: Forcing,
    tau: Vec<f64>,
    /// For the momenta of the whole mechanism (base at rest).
    momentum_workspace: Workspace,
}

impl System {
    /// The system of `dynamics` driven by `forcing` (already validated).
    pub(crate) fn new(dynamics: Dynamics, forcing: Forcing) -> Self {
        let n = dynamics.dof();
        let momentum_workspace = dynamics.tree().workspace();
        Self {
            dynamics,
            forcing,
            tau: vec![0.0; n],
            momentum_workspace,
        }
    }

    /// Number of coordinates.
    pub(crate) fn dof(&self) -> usize {
        self.dynamics.dof()
    }

    /// The dynamics (its mechanism carries the current charts of rotation vectors).
    pub(crate) fn dynamics(&self) -> &Dynamics {
        &self.dynamics
    }

    /// The dynamics, for re-centring charts.
    pub(crate) fn dynamics_mut(&mut self) -> &mut Dynamics {
        &mut self.dynamics
    }

    /// q̈ at (t, q, q̇) into `out` by the articulated-body algorithm.
    pub(crate) fn acceleration(
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
        self.dynamics.aba_state_into(&state, &self.tau, out)?;
        check_finite(out, "acceleration")
    }

    /// The mass matrix A(q) (8.28).
    pub(crate) fn mass_matrix(&mut self, q: &[f64]) -> Result<DMatrix<f64>, StepFailure> {
        let a = self.dynamics.mass_matrix(q)?;
        let n = a.nrows();
        Ok(DMatrix::from_fn(n, n, |i, j| a[(i, j)]))
    }

    /// U*(q) − τ_c·q: the mechanism's potentials (with −T₀ in a rotating frame, (8.56)) and
    /// the potential of a constant applied force.
    pub(crate) fn potential_energy(&self, q: &[f64]) -> Result<f64, StepFailure> {
        let u = self
            .dynamics
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
        let mechanism = self.dynamics.mechanism();
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
        })
    }
}
