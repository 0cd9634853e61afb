//! Velocity-dependent (generalized) potentials U(x, ẋ, t) on body points (FM 4.90): loads
//! whose generalized force is Q_k = d/dt ∂U/∂q̇_k − ∂U/∂q_k, so that Lagrange's equations keep
//! their form with L = T − U (FM 4.105; the sign is that of a potential energy).
//!
//! The worked example is a charge e at a body point in an electromagnetic field given by its
//! potentials φ(x, t) and 𝐀(x, t) (SI units): U = e (φ − ẋ·𝐀). With ẋ = Σ J_k q̇_k and
//! ∂ẋ/∂q_k = J̇_k (1.41), the terms in 𝐀·J̇_k cancel and
//!
//!   Q_k = e J_k·[−∇φ − ∂𝐀/∂t + (Gᵀ − G) ẋ],  G = ∂𝐀/∂x,
//!
//! which is the Lorentz force e (E + ẋ × B) with E = −∇φ − ∂𝐀/∂t and B = ∇ × 𝐀, because
//! ((Gᵀ − G) ẋ)_i = Σ_j (∂A_j/∂x_i − ∂A_i/∂x_j) ẋ_j = (ẋ × (∇ × 𝐀))_i. [`ChargedPoint`]
//! evaluates the force from the potentials by that formula, so a gauge change
//! (φ, 𝐀) → (φ − ∂χ/∂t, 𝐀 + ∇χ) leaves it unchanged.

use crate::error::DynamicsError;
use mechanica_kinematics::tree::{KinematicTree, Workspace};
use mechanica_mechanism::PointForce;
use nalgebra::{Matrix3, Vector3};
use std::sync::Arc;

/// A velocity-dependent potential acting through body points: it reports, at the current
/// positions and velocities, the forces whose generalized force is
/// Q = d/dt ∂U/∂q̇ − ∂U/∂q (FM 4.90).
pub trait VelocityPotential: Send + Sync + std::fmt::Debug {
    /// A short name for reports and errors.
    fn name(&self) -> String;

    /// Checks body indices and parameters once, when the potential is added.
    fn validate(&self, tree: &KinematicTree) -> Result<(), DynamicsError>;

    /// Appends the point forces at time `t`; `ws` holds positions and velocities (world).
    fn point_forces(&self, ws: &Workspace, t: f64, out: &mut Vec<PointForce>) -> Result<(), DynamicsError>;

    /// The value U(x, ẋ, t), J.
    fn value(&self, ws: &Workspace, t: f64) -> Result<f64, DynamicsError>;
}

/// The potentials of an electromagnetic field at one point and time (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldPotentials {
    /// Scalar potential φ, V.
    pub phi: f64,
    /// ∇φ, V/m.
    pub grad_phi: Vector3<f64>,
    /// Vector potential 𝐀, T·m.
    pub a: Vector3<f64>,
    /// G = ∂𝐀/∂x: G\[(i, j)\] = ∂A_i/∂x_j, T.
    pub grad_a: Matrix3<f64>,
    /// ∂𝐀/∂t, T·m/s.
    pub a_t: Vector3<f64>,
}

/// An electromagnetic field described by its potentials (world components).
pub trait ElectromagneticField: Send + Sync + std::fmt::Debug {
    /// The potentials and their derivatives at the world point `x` and time `t`.
    fn potentials(&self, x: &Vector3<f64>, t: f64) -> FieldPotentials;
}

/// Uniform static fields E and B in the gauge φ = −E·x, 𝐀 = ½ B × x.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UniformFields {
    /// Electric field E, V/m.
    pub electric: Vector3<f64>,
    /// Magnetic flux density B, T.
    pub magnetic: Vector3<f64>,
}

impl ElectromagneticField for UniformFields {
    fn potentials(&self, x: &Vector3<f64>, _t: f64) -> FieldPotentials {
        let b = self.magnetic;
        // 𝐀 = ½ B × x = −½ [x]× B = ½ [B]× x, so G = ½ [B]×.
        FieldPotentials {
            phi: -self.electric.dot(x),
            grad_phi: -self.electric,
            a: b.cross(x) * 0.5,
            grad_a: Matrix3::new(0.0, -b.z, b.y, b.z, 0.0, -b.x, -b.y, b.x, 0.0) * 0.5,
            a_t: Vector3::zeros(),
        }
    }
}

/// A charge e carried by a body point in an electromagnetic field: U = e (φ − ẋ·𝐀) (FM 4.105).
#[derive(Debug, Clone)]
pub struct ChargedPoint {
    /// The body.
    pub body: usize,
    /// The point in body coordinates, m.
    pub point: Vector3<f64>,
    /// The charge e, C.
    pub charge: f64,
    /// The field.
    pub field: Arc<dyn ElectromagneticField>,
}

impl ChargedPoint {
    fn motion(&self, ws: &Workspace) -> Result<(Vector3<f64>, Vector3<f64>), DynamicsError> {
        Ok((
            ws.point_position(self.body, &self.point)?,
            ws.point_velocity(self.body, &self.point)?,
        ))
    }
}

impl VelocityPotential for ChargedPoint {
    fn name(&self) -> String {
        format!("charge {} C on body {}", self.charge, self.body)
    }

    fn validate(&self, tree: &KinematicTree) -> Result<(), DynamicsError> {
        if self.body >= tree.body_count() {
            return Err(DynamicsError::NoSuchBody {
                what: "charged point",
                body: self.body,
                bodies: tree.body_count(),
            });
        }
        crate::error::check_input(self.point.as_slice(), "charged point")?;
        crate::error::check_input(&[self.charge], "charge")
    }

    /// The Lagrangian force e [−∇φ − ∂𝐀/∂t + (Gᵀ − G) ẋ] (module docs).
    fn point_forces(&self, ws: &Workspace, t: f64, out: &mut Vec<PointForce>) -> Result<(), DynamicsError> {
        let (x, v) = self.motion(ws)?;
        let p = self.field.potentials(&x, t);
        let g = p.grad_a;
        let force = (-p.grad_phi - p.a_t + (g.transpose() - g) * v) * self.charge;
        crate::error::check_result(force.iter(), "electromagnetic force")?;
        out.push(PointForce {
            body: self.body,
            point: x,
            force,
        });
        Ok(())
    }

    fn value(&self, ws: &Workspace, t: f64) -> Result<f64, DynamicsError> {
        let (x, v) = self.motion(ws)?;
        let p = self.field.potentials(&x, t);
        Ok(self.charge * (p.phi - v.dot(&p.a)))
    }
}
