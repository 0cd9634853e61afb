//! Lagrange's impulse equations for a mechanism in generalized coordinates (7.115–7.117).
//!
//! A kinematic tree with coordinates q and mass matrix A(q) is struck by point impulses S_k
//! at body points x_k. Integrating Lagrange's equations over the vanishing impact time
//! (positions fixed, finite forces contribute nothing) gives
//!
//! ```text
//!   A(q) Δq̇ = Q_S,     Q_S = Σ_k J_kᵀ S_k,     J_k = ∂x_k/∂q     (7.115, 7.117)
//! ```
//!
//! with the point Jacobians J_k of the kinematics crate. [`MechanismInertia`] factors A once
//! per configuration (Cholesky), so every impulse, contact Jacobian and Delassus matrix of
//! that configuration reuses the factor. The energy change is
//! ΔT = Q_S·(q̇⁻ + ½ Δq̇) (the generalized form of 7.107).
//!
//! A(q) is only positive *semi*definite when a coordinate moves no inertia: a rod (zero axial
//! inertia) or a point mass on a spherical or free joint, or a massless leaf link. Lagrange's
//! equations then do not determine that coordinate's velocity jump; the factorisation reports
//! [`ImpulseError::SingularMassMatrix`] naming the coordinate. Model such bodies with a joint
//! that has no coordinate for the missing inertia (e.g. a revolute or universal joint for a rod
//! instead of a spherical one), or give them a small physical axial inertia.

use crate::ImpulseError;
use crate::error::{check_all_finite, check_result};
use mechanica_kinematics::tree::{KinematicTree, Workspace};
use mechanica_mass::mechanism::TreeMass;
use nalgebra::Vector3;

/// Relative Cholesky pivot threshold: coordinate k is singular when its pivot is
/// ≤ `MASS_MATRIX_PIVOT_RELATIVE`·A_kk, i.e. when all but a fraction 1e-12 of its inertia is
/// already carried by the earlier coordinates (≈ 5000 ulps of round-off; a physical rod would
/// need a slenderness of 10⁶ to come this close).
pub const MASS_MATRIX_PIVOT_RELATIVE: f64 = 1e-12;

/// A point fixed in a body of the tree: `body` index and the point's coordinates `p_bq` in the
/// body frame B.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyPoint {
    /// Body index in the tree.
    pub body: usize,
    /// The point in the body frame B (m).
    pub p_bq: Vector3<f64>,
}

/// A point impulse S (world frame, N·s) applied at a body point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointImpulse {
    /// Where the impulse acts.
    pub point: BodyPoint,
    /// The impulse S, world components (N·s).
    pub s_w: Vector3<f64>,
}

/// The mass matrix A(q) of a tree at one configuration and its Cholesky factor
/// P A P = L Lᵀ, with P the reversal of the coordinate order.
///
/// Reversing the order eliminates the leaves of the tree first (coordinates are laid out body
/// by body, parents usually before children), so the factor has no fill-in beyond the
/// ancestor structure of A (Featherstone's LTL idea), and the zeros are skipped. The factor is
/// computed by a plain column Cholesky rather than faer's: it needs a relative pivot test per
/// coordinate (to name the coordinate without inertia) and this sparsity, and mechanisms have
/// a few dozen coordinates, where a blocked dense factorisation brings nothing.
#[derive(Debug, Clone, PartialEq)]
pub struct MechanismInertia {
    n: usize,
    /// A, column-major n×n.
    a: Vec<f64>,
    /// L with P A P = L Lᵀ, column-major n×n, lower triangle (upper part zero).
    l: Vec<f64>,
}

impl MechanismInertia {
    /// A(q) of `tree` at the configuration of the last `update_positions` in `ws`, by the
    /// composite-rigid-body recursion of `mass` (8.28), factored. Fails with
    /// [`ImpulseError::SingularMassMatrix`] when a pivot is ≤ [`MASS_MATRIX_PIVOT_RELATIVE`]·A_kk.
    pub fn new(tree: &KinematicTree, ws: &Workspace, mass: &mut TreeMass) -> Result<Self, ImpulseError> {
        let n = tree.dof();
        let mut a = vec![0.0; n * n];
        mass.mass_matrix(tree, ws, &mut a)?;
        Self::from_mass_matrix(n, a)
    }

    /// Factors a given symmetric mass matrix `a` (n×n, column-major; only the lower triangle
    /// is read for the factor, the whole matrix is kept for residuals). Fails on a wrong length,
    /// a non-finite entry or a pivot ≤ [`MASS_MATRIX_PIVOT_RELATIVE`]·A_kk
    /// ([`ImpulseError::SingularMassMatrix`]).
    pub fn from_mass_matrix(n: usize, a: Vec<f64>) -> Result<Self, ImpulseError> {
        if a.len() != n * n {
            return Err(ImpulseError::DimensionMismatch {
                what: "mass matrix (n² entries)",
                expected: n * n,
                got: a.len(),
            });
        }
        check_all_finite("mass matrix", a.iter())?;
        // Left-looking column Cholesky: column j of L is a_j − Σ_{k<j} L_jk l_k, scaled;
        // the updates are contiguous axpys, and the zeros that tree topology leaves in L
        // (coordinates on different branches) are skipped.
        let mut l = vec![0.0; n * n];
        for (j, col) in l.chunks_exact_mut(n.max(1)).enumerate().take(n) {
            let source = &a[n * (n - 1 - j)..n * (n - j)];
            for (i, v) in col.iter_mut().enumerate() {
                *v = source[n - 1 - i];
            }
        }
        for j in 0..n {
            let diagonal = a[(n - 1 - j) * (n + 1)];
            let (done, rest) = l.split_at_mut(n * j);
            let col_j = &mut rest[..n];
            for i in 0..j {
                col_j[i] = 0.0;
            }
            for k in 0..j {
                let col_k = &done[n * k..n * k + n];
                let ljk = col_k[j];
                if ljk != 0.0 {
                    for i in j..n {
                        col_j[i] -= col_k[i] * ljk;
                    }
                }
            }
            let d = col_j[j];
            if !(d > MASS_MATRIX_PIVOT_RELATIVE * diagonal && d > 0.0) {
                return Err(ImpulseError::SingularMassMatrix {
                    coordinate: n - 1 - j,
                    pivot: d,
                    diagonal,
                });
            }
            let djj = d.sqrt();
            col_j[j] = djj;
            for v in &mut col_j[j + 1..] {
                *v /= djj;
            }
        }
        Ok(Self { n, a, l })
    }

    /// Number of coordinates n.
    pub fn dof(&self) -> usize {
        self.n
    }

    /// The mass matrix A (column-major n×n).
    pub fn mass_matrix(&self) -> &[f64] {
        &self.a
    }

    /// The Cholesky factor L (column-major n×n, lower triangular) of the reversed matrix:
    /// P A P = L Lᵀ with (P x)_i = x_{n−1−i}.
    pub fn factor(&self) -> &[f64] {
        &self.l
    }

    /// b ← L⁻¹ P b in place (reversal, then forward substitution); the result lives in the
    /// reversed order, where [`Self::backward_in_place`] takes it.
    pub(crate) fn forward_in_place(&self, b: &mut [f64]) {
        b.reverse();
        let start = b.iter().position(|v| *v != 0.0).unwrap_or(self.n);
        self.forward_in_place_from(b, start);
    }

    /// [`Self::forward_in_place`] for b whose entries before `start` are zero (they stay zero).
    fn forward_in_place_from(&self, b: &mut [f64], start: usize) {
        let n = self.n;
        for j in start..n {
            let yj = b[j] / self.l[j + n * j];
            b[j] = yj;
            if yj != 0.0 {
                for (bi, li) in b[j + 1..].iter_mut().zip(&self.l[j + 1 + n * j..n * (j + 1)]) {
                    *bi -= li * yj;
                }
            }
        }
    }

    /// y ← P L⁻ᵀ y in place (back substitution, then reversal to the coordinate order), so
    /// that forward then backward solves A x = b.
    pub(crate) fn backward_in_place(&self, b: &mut [f64]) {
        let n = self.n;
        for j in (0..n).rev() {
            let col = &self.l[n * j..n * j + n];
            let mut s = b[j];
            for i in j + 1..n {
                s -= col[i] * b[i];
            }
            b[j] = s / col[j];
        }
        b.reverse();
    }

    /// Solves A x = b in place (b has n entries).
    pub fn solve_in_place(&self, b: &mut [f64]) -> Result<(), ImpulseError> {
        self.check_len("right-hand side", b.len())?;
        self.forward_in_place(b);
        self.backward_in_place(b);
        check_result("solution of A x = b", b.iter())
    }

    /// A x (n entries) into `out`.
    pub(crate) fn multiply(&self, x: &[f64], out: &mut [f64]) {
        let n = self.n;
        out.fill(0.0);
        for j in 0..n {
            let xj = x[j];
            for i in 0..n {
                out[i] += self.a[i + n * j] * xj;
            }
        }
    }

    /// The kinetic energy T = ½ q̇ᵀ A q̇ (8.27) of a fixed-base tree.
    pub fn kinetic_energy(&self, q_dot: &[f64]) -> Result<f64, ImpulseError> {
        self.check_len("q_dot", q_dot.len())?;
        let mut aq = vec![0.0; self.n];
        self.multiply(q_dot, &mut aq);
        let energy = 0.5 * dot(q_dot, &aq);
        check_result("kinetic energy", [energy].iter())?;
        Ok(energy)
    }

    /// The normwise backward error of a solution x of A x = b:
    /// ‖A x − b‖∞ / (‖A‖∞ ‖x‖∞ + ‖b‖∞) (0 for b = 0).
    pub(crate) fn backward_error(&self, x: &[f64], b: &[f64]) -> f64 {
        let n = self.n;
        let mut ax = vec![0.0; n];
        self.multiply(x, &mut ax);
        let residual = ax.iter().zip(b).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max);
        let norm_a = (0..n)
            .map(|i| (0..n).map(|j| self.a[i + n * j].abs()).sum::<f64>())
            .fold(0.0, f64::max);
        let scale = norm_a * inf_norm(x) + inf_norm(b);
        if scale > 0.0 { residual / scale } else { 0.0 }
    }

    pub(crate) fn check_len(&self, what: &'static str, got: usize) -> Result<(), ImpulseError> {
        if got != self.n {
            return Err(ImpulseError::DimensionMismatch {
                what,
                expected: self.n,
                got,
            });
        }
        Ok(())
    }
}

pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

pub(crate) fn inf_norm(a: &[f64]) -> f64 {
    a.iter().fold(0.0, |m, v| m.max(v.abs()))
}

/// The velocity jump of a mechanism struck by point impulses (7.117).
#[derive(Debug, Clone, PartialEq)]
pub struct GeneralizedImpulseResponse {
    /// The generalized impulse Q_S = Σ J_kᵀ S_k (7.115), one entry per coordinate.
    pub generalized_impulse: Vec<f64>,
    /// Δq̇ = A⁻¹ Q_S.
    pub delta_q_dot: Vec<f64>,
    /// q̇⁺ = q̇⁻ + Δq̇.
    pub q_dot_after: Vec<f64>,
    /// T⁻ = ½ q̇⁻ᵀ A q̇⁻ (J).
    pub energy_before: f64,
    /// ΔT = Q_S·(q̇⁻ + ½ Δq̇) (J).
    pub energy_change: f64,
    /// Normwise backward error of the solve A Δq̇ = Q_S (see [`MechanismInertia`]).
    pub backward_error: f64,
}

/// Checks a body point of `tree` and returns its Jacobian column-major 3×n into `out`.
pub(crate) fn point_jacobian_into(
    tree: &KinematicTree,
    ws: &Workspace,
    what: &'static str,
    point: &BodyPoint,
    out: &mut [f64],
) -> Result<(), ImpulseError> {
    if point.body >= tree.body_count() {
        return Err(ImpulseError::BodyOutOfRange {
            what,
            body: point.body,
            bodies: tree.body_count(),
        });
    }
    check_all_finite(what, point.p_bq.iter())?;
    tree.point_jacobian(ws, point.body, &point.p_bq, out)?;
    Ok(())
}

/// Applies the point impulses `impulses` to the tree at the configuration of `ws` (positions
/// updated) moving with `q_dot`, through Lagrange's impulse equations (7.115–7.117), with the
/// factored mass matrix `inertia` of the same configuration. Lengths of `q_dot` and of the
/// factor must match the tree's dof; every impulse is checked (body index, finite values).
/// The accuracy of the solve A Δq̇ = Q_S is reported as
/// [`GeneralizedImpulseResponse::backward_error`].
pub fn apply_point_impulses(
    tree: &KinematicTree,
    ws: &Workspace,
    inertia: &MechanismInertia,
    q_dot: &[f64],
    impulses: &[PointImpulse],
) -> Result<GeneralizedImpulseResponse, ImpulseError> {
    let n = tree.dof();
    inertia.check_len("mass matrix dimension (tree dof)", n)?;
    inertia.check_len("q_dot", q_dot.len())?;
    check_all_finite("q_dot", q_dot.iter())?;
    let mut q = vec![0.0; n];
    let mut jac = vec![0.0; 3 * n];
    for (index, impulse) in impulses.iter().enumerate() {
        let in_contact = |source| ImpulseError::InContact {
            contact: index,
            source: Box::new(source),
        };
        check_all_finite("impulse", impulse.s_w.iter()).map_err(in_contact)?;
        point_jacobian_into(tree, ws, "impulse point", &impulse.point, &mut jac).map_err(in_contact)?;
        for k in 0..n {
            q[k] += jac[3 * k] * impulse.s_w.x + jac[3 * k + 1] * impulse.s_w.y + jac[3 * k + 2] * impulse.s_w.z;
        }
    }
    let mut dq = q.clone();
    inertia.solve_in_place(&mut dq)?;
    let backward_error = inertia.backward_error(&dq, &q);
    let energy_before = inertia.kinetic_energy(q_dot)?;
    let energy_change = q.iter().zip(q_dot).zip(&dq).map(|((s, v), d)| s * (v + 0.5 * d)).sum();
    let q_dot_after: Vec<f64> = q_dot.iter().zip(&dq).map(|(v, d)| v + d).collect();
    check_result("generalized impulse", q.iter())?;
    check_result("velocities after the impulse", q_dot_after.iter())?;
    check_result("energy change", [energy_change, backward_error].iter())?;
    Ok(GeneralizedImpulseResponse {
        generalized_impulse: q,
        delta_q_dot: dq,
        q_dot_after,
        energy_before,
        energy_change,
        backward_error,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A dense SPD matrix A = B Bᵀ + I: the factor reproduces P A P = L Lᵀ and solves A x = b
    /// with a backward error at round-off level (n·u).
    #[test]
    fn factor_and_solve_dense() {
        let n = 7;
        let b: Vec<f64> = (0..n * n).map(|k| ((k as f64) * 0.731).sin()).collect();
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                a[i + n * j] =
                    (0..n).map(|k| b[i + n * k] * b[j + n * k]).sum::<f64>() + if i == j { 1.0 } else { 0.0 };
            }
        }
        let inertia = MechanismInertia::from_mass_matrix(n, a.clone()).expect("SPD");
        let l = inertia.factor();
        for i in 0..n {
            for j in 0..n {
                let llt: f64 = (0..n).map(|k| l[i + n * k] * l[j + n * k]).sum();
                let pap = a[(n - 1 - i) + n * (n - 1 - j)];
                assert!((llt - pap).abs() <= 8.0 * n as f64 * f64::EPSILON * pap.abs().max(1.0));
            }
        }
        let rhs: Vec<f64> = (0..n).map(|k| 1.0 + k as f64).collect();
        let mut x = rhs.clone();
        inertia.solve_in_place(&mut x).expect("solve");
        assert!(inertia.backward_error(&x, &rhs) <= 4.0 * n as f64 * f64::EPSILON);
        // A rank-deficient matrix is rejected, naming the coordinate.
        let mut singular = a.clone();
        for k in 0..n {
            singular[2 + n * k] = 0.0;
            singular[k + n * 2] = 0.0;
        }
        assert!(matches!(
            MechanismInertia::from_mass_matrix(n, singular),
            Err(ImpulseError::SingularMassMatrix { coordinate: 2, .. })
        ));
    }
}
