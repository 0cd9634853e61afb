//! Forward dynamics by the composite-rigid-body mass matrix and Cholesky: q̈ = A⁻¹ (τ − h)
//! with h = RNEA(q, q̇, 0) = c + g − Σ Q_loads. O(n³), independent of the articulated-body
//! recursion, and the route that measures the conditioning of A.

use crate::error::{DynamicsError, check_result, check_vector};
use crate::forward::{ForwardDynamics, ForwardMethod};
use crate::model::{Dynamics, State};
use faer::linalg::solvers::{DenseSolveCore, Solve};
use faer::{Mat, Side};

/// ‖M‖∞ (largest row sum of magnitudes).
fn norm_inf(m: &Mat<f64>) -> f64 {
    (0..m.nrows())
        .map(|i| (0..m.ncols()).map(|j| m[(i, j)].abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

impl Dynamics {
    /// The mass matrix A(q) (8.28) by the composite-rigid-body recursion.
    pub fn mass_matrix(&mut self, q: &[f64]) -> Result<Mat<f64>, DynamicsError> {
        Ok(self.mechanism.mass_matrix(q)?)
    }

    /// A(q) (8.28) into `out` (dof × dof, column-major, every entry overwritten) by the
    /// composite-rigid-body recursion on this model's own workspace, allocating nothing: for
    /// simulators' inner loops. Exact up to rounding and symmetric by construction.
    pub fn mass_matrix_into(&mut self, q: &[f64], out: &mut [f64]) -> Result<(), DynamicsError> {
        let n = self.dof();
        check_vector(q, n, "q")?;
        if out.len() != n * n {
            return Err(DynamicsError::WrongLength {
                what: "mass matrix output (dof²)",
                expected: n * n,
                got: out.len(),
            });
        }
        Ok(self.mechanism.mass_matrix_into(q, &mut self.ws, out)?)
    }

    /// q̈ for the applied forces `tau` at `state` by A(q) and Cholesky, with κ∞(A) and the
    /// error estimate of q̈ (see [`ForwardDynamics`]). Fails with
    /// [`DynamicsError::SingularMassMatrix`] when A is not positive definite.
    pub fn forward_dynamics_crba(&mut self, state: &State<'_>, tau: &[f64]) -> Result<ForwardDynamics, DynamicsError> {
        let n = self.dof();
        check_vector(tau, n, "tau")?;
        let mut h = vec![0.0; n];
        self.rnea_at(state, &vec![0.0; n], &mut h)?;
        let dissipation = self.evaluate_loads(state, false)?.0;
        let a = self.mass_matrix(state.q)?;
        let llt = a.llt(Side::Lower).map_err(|e| {
            let faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index } = e;
            DynamicsError::SingularMassMatrix {
                pivot: index,
                value: a[(index, index)],
            }
        })?;
        let rhs = Mat::from_fn(n, 1, |k, _| tau[k] - h[k]);
        let solution = llt.solve(&rhs);
        let q_ddot: Vec<f64> = (0..n).map(|k| solution[(k, 0)]).collect();
        check_result(q_ddot.iter(), "joint acceleration")?;
        let inverse_norm = norm_inf(&llt.inverse());
        let condition = norm_inf(&a) * inverse_norm;
        let (residual, backward_error, rounding) = self.residual_of(state, tau, &q_ddot)?;
        let residual_norm = residual.iter().fold(0.0f64, |m, r| m.max(r.abs()));
        // The computed ‖A⁻¹‖ is that of a matrix within about n·u·‖A‖ of A: ‖A⁻¹‖ is at most
        // it over 1 − x, x = n·κ·u, while x < 1; beyond x = 1/2 nothing is inferred.
        let x = n as f64 * condition * f64::EPSILON;
        let error_estimate = if x < 0.5 {
            inverse_norm * (residual_norm + rounding) / (1.0 - x)
        } else {
            f64::INFINITY
        };
        Ok(ForwardDynamics {
            q_ddot,
            method: ForwardMethod::MassMatrix,
            residual,
            backward_error,
            condition: Some(condition),
            error_estimate: Some(error_estimate),
            dissipation,
        })
    }
}
