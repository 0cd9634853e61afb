//! Damped and gyroscopic small oscillations of a mechanism about a configuration q₀:
//! A δ̈ + (C + G) δ̇ + B δ = 0 (FM 4.62–4.66, §8e, §8g) with A = A(q₀) (8.28), C = C(q₀) the
//! dampers' matrix (FM 4.64), G = G(q₀) the gyroscopic matrix of a rotating frame and
//! B = ∂²U*/∂q² (8.85), solved as det(s²A + s(C + G) + B) = 0 by the modal crate's certified
//! quadratic eigensolver: every eigenvalue s = σ + iω with its backward error and bound, every
//! mode with its natural frequency, damped frequency and damping ratio, classified as
//! underdamped, overdamped, critical, rigid, unstable, neutral or infinite.
//!
//! The linearization is exact when q₀ is an equilibrium (grad U* = 0), which
//! [`DampedModes::gradient_norm`] reports; elsewhere it is the linearization of the forces
//! about q₀ at rest. Velocity-dependent potentials and a prescribed base motion make the
//! problem depend on more than (A, C, G, B) or on time, and are refused.

use crate::error::{DynamicsError, check_vector};
use crate::model::Dynamics;
use faer::Mat;
use mechanica_modal::{QuadraticModes, QuadraticOptions, quadratic_modes};

/// The damped modes of a mechanism about q₀.
#[derive(Debug, Clone)]
pub struct DampedModes {
    /// q₀ in charts re-centred at it: the rotation vectors of spherical and free joints are
    /// zero, the other coordinates as given. The matrices and shapes are in these charts; the
    /// dynamics the modes were asked of keeps its own.
    pub q: Vec<f64>,
    /// A(q₀).
    pub mass_matrix: Mat<f64>,
    /// C(q₀), the dampers' matrix.
    pub damping_matrix: Mat<f64>,
    /// G(q₀), the gyroscopic matrix (zero without a rotating frame).
    pub gyroscopic_matrix: Mat<f64>,
    /// B(q₀) = ∂²U*/∂q².
    pub stiffness_matrix: Mat<f64>,
    /// ‖grad U*(q₀)‖: how far q₀ is from an equilibrium.
    pub gradient_norm: f64,
    /// The eigenvalues, their bounds and the modes (with shapes when asked).
    pub solution: QuadraticModes,
}

impl Dynamics {
    /// The damped and gyroscopic modes about `q0` (module docs). The Hessian needs the rotation
    /// vectors of spherical and free joints at φ = 0, so with such joints the modes are those of
    /// a copy of the dynamics whose charts are re-centred at q₀ (same poses, q₀'s rotation
    /// vectors zeroed, [`DampedModes::q`]). `self` keeps its charts: q₀ names the same
    /// configuration before and after the call, and identical calls give identical results.
    pub fn damped_modes(&mut self, q0: &[f64], options: &QuadraticOptions) -> Result<DampedModes, DynamicsError> {
        check_vector(q0, self.dof(), "q0")?;
        if !self.velocity_potentials.is_empty() {
            return Err(DynamicsError::OutOfRange {
                what: "velocity-dependent potentials in damped modes",
                requirement: "absent (their linearization is not modelled)",
                value: self.velocity_potentials.len() as f64,
            });
        }
        if self.has_base_motion() {
            return Err(DynamicsError::OutOfRange {
                what: "prescribed base motion in damped modes",
                requirement: "absent (the linearized problem would depend on time)",
                value: 1.0,
            });
        }
        let mut q = q0.to_vec();
        if self.mechanism.has_rotation_vectors() {
            let mut recentred = self.clone();
            recentred.mechanism.rebase(&mut q)?;
            return recentred.linearized_modes(q, options);
        }
        self.linearized_modes(q, options)
    }

    /// The modes of the linearization about `q`, whose rotation vectors (if any) are zero.
    fn linearized_modes(&mut self, q: Vec<f64>, options: &QuadraticOptions) -> Result<DampedModes, DynamicsError> {
        let potential = self.mechanism.potential(&q, true)?;
        let stiffness_matrix = potential.hessian.ok_or(DynamicsError::NonFiniteResult {
            what: "stiffness matrix",
        })?;
        let gradient_norm = potential.gradient.iter().map(|g| g * g).sum::<f64>().sqrt();
        let mass_matrix = self.mechanism.mass_matrix(&q)?;
        let gyroscopic_matrix = self.mechanism.gyroscopic_matrix(&q)?;
        let damping_matrix = self.damping_matrix(&q)?;
        let velocity_matrix = &damping_matrix + &gyroscopic_matrix;
        let solution = quadratic_modes(
            mass_matrix.as_ref(),
            velocity_matrix.as_ref(),
            stiffness_matrix.as_ref(),
            options,
        )?;
        Ok(DampedModes {
            q,
            mass_matrix,
            damping_matrix,
            gyroscopic_matrix,
            stiffness_matrix,
            gradient_norm,
            solution,
        })
    }
}
