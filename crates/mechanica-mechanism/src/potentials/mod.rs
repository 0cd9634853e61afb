//! Potentials U(q) on a kinematic tree with exact gradients and Hessians (no finite
//! differences): the [`Potential`] trait, the accumulator [`PotentialSum`], and the built-in
//! potentials (uniform gravity and centrifugal fields, joint springs, point springs, constant
//! forces).
//!
//! A potential that depends on q only through body points (a spring, a force, a contact
//! penalty) needs only ∂U/∂x and ∂²U/∂x² of those points: [`PotentialSum::add_point_potential`]
//! chains them through the exact point derivatives of [`Configuration`]. User potentials
//! implement [`Potential`] the same way.

mod constant_force;
mod field;
mod joint_spring;
mod point_spring;

pub use constant_force::{ConstantForce, GeneralizedForce};
pub use field::UniformField;
pub use joint_spring::JointSpring;
pub use point_spring::PointSpring;

use crate::{Configuration, MechanismError};
use faer::Mat;
use nalgebra::{Matrix3, Vector3};

/// A conservative load on a mechanism: U(q) with exact derivatives.
pub trait Potential: Send + Sync + std::fmt::Debug {
    /// A short name for reports and errors.
    fn name(&self) -> String;

    /// Checks the potential against the tree (body and coordinate indices) once, when it is
    /// added to a mechanism.
    fn validate(&self, tree: &mechanica_kinematics::tree::KinematicTree) -> Result<(), MechanismError>;

    /// Adds U, ∂U/∂q and, when `sum.hessian` is present, ∂²U/∂q∂q at `config`.
    fn accumulate(&self, config: &Configuration<'_>, sum: &mut PotentialSum) -> Result<(), MechanismError>;
}

/// A point of a body (body coordinates) or of the ground (world coordinates, `body = None`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Anchor {
    /// The body, or None for the ground.
    pub body: Option<usize>,
    /// Body coordinates of the point (world coordinates for the ground).
    pub point: Vector3<f64>,
}

impl Anchor {
    /// Checks the body index against the tree and the point for finiteness.
    pub(crate) fn validate(
        &self,
        tree: &mechanica_kinematics::tree::KinematicTree,
        what: &'static str,
    ) -> Result<(), MechanismError> {
        crate::error::check_all_finite(self.point.iter(), what)?;
        match self.body {
            Some(body) if body >= tree.body_count() => Err(MechanismError::NoSuchBody {
                what,
                body,
                bodies: tree.body_count(),
            }),
            _ => Ok(()),
        }
    }
}

/// A force −∂U/∂x that a potential applies at one point of a body (world components).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointForce {
    /// The body that carries the point.
    pub body: usize,
    /// The point's world position x, m.
    pub point: Vector3<f64>,
    /// The force on the body at x, N (world components).
    pub force: Vector3<f64>,
}

/// U, ∂U/∂q and (optionally) ∂²U/∂q∂q summed over potentials.
#[derive(Debug, Clone)]
pub struct PotentialSum {
    /// U.
    pub value: f64,
    /// ∂U/∂q (the negative generalized force).
    pub gradient: Vec<f64>,
    /// ∂²U/∂q∂q, when asked for.
    pub hessian: Option<Mat<f64>>,
    /// The point forces −∂U/∂x_j of the potentials that act through body points
    /// ([`PotentialSum::add_point_potential`]); forces on ground points are not listed. The
    /// rest of −∂U/∂q acts on the coordinates themselves (joint springs, generalized forces).
    pub point_forces: Vec<PointForce>,
}

impl PotentialSum {
    /// Zero, for `dof` coordinates, with or without a Hessian.
    pub fn new(dof: usize, with_hessian: bool) -> Self {
        Self {
            value: 0.0,
            gradient: vec![0.0; dof],
            hessian: with_hessian.then(|| Mat::zeros(dof, dof)),
            point_forces: Vec::new(),
        }
    }

    /// Adds a potential that depends on q through d = Σ c_j x_j, a linear combination of body
    /// points x_j (`points` = (anchor, c_j)): U = `energy`, ∂U/∂d = `force`, ∂²U/∂d² =
    /// `stiffness`. By the chain rule, ∂U/∂q = J_dᵀ f and
    /// ∂²U/∂q∂q = J_dᵀ K J_d + Σ_j c_j f·∂²x_j/∂q∂q (see [`Configuration`]).
    pub fn add_point_potential(
        &mut self,
        config: &Configuration<'_>,
        points: &[(Anchor, f64)],
        energy: f64,
        force: &Vector3<f64>,
        stiffness: &Matrix3<f64>,
    ) -> Result<(), MechanismError> {
        let n = config.dof();
        let mut jacobian = vec![0.0; 3 * n];
        let mut world = Vec::with_capacity(points.len());
        for (anchor, c) in points {
            let x = config.point(anchor.body, &anchor.point)?;
            config.add_point_jacobian(anchor.body, &x, *c, &mut jacobian);
            if let Some(body) = anchor.body {
                self.point_forces.push(PointForce {
                    body,
                    point: x,
                    force: -force * *c,
                });
            }
            world.push(x);
        }
        self.value += energy;
        let column = |k: usize| Vector3::new(jacobian[3 * k], jacobian[3 * k + 1], jacobian[3 * k + 2]);
        for k in 0..n {
            self.gradient[k] += force.dot(&column(k));
        }
        if let Some(hessian) = self.hessian.as_mut() {
            let moved: Vec<usize> = (0..n).filter(|&k| column(k) != Vector3::zeros()).collect();
            // One triangle, mirrored: the two orders of c_lᵀ K c_k round differently, and with
            // stiff springs on long lever arms the difference is not small next to the result.
            for (i, &k) in moved.iter().enumerate() {
                let kj = stiffness * column(k);
                for &l in &moved[i..] {
                    let value = column(l).dot(&kj);
                    hessian[(l, k)] += value;
                    if l != k {
                        hessian[(k, l)] += value;
                    }
                }
            }
            for ((anchor, c), x) in points.iter().zip(&world) {
                config.add_point_hessian(anchor.body, x, &(force * *c), hessian)?;
            }
        }
        Ok(())
    }
}
