//! Joint types and their parametrizations.
//!
//! Each body B hangs from its parent P by a joint. The joint frame J is fixed in P at the
//! placement X_PJ; the body frame B coincides with J at q = 0 and moves relative to it by
//! X_JB(q). Body data (points, centres of mass) are given in B.
//!
//! Every joint has as many coordinates as velocities (nq = nv), and q̇ is the time derivative
//! of q, so q are genuine Lagrangian coordinates: ∂ẋ/∂q̇_k = ∂x/∂q_k (1.40) holds and the mass
//! matrix is α_kl = ∫ρ (∂x/∂q_k, ∂x/∂q_l) dV (8.27–8.28) with the Jacobians of this module.
//!
//! | joint | q | X_JB(q) |
//! |---|---|---|
//! | revolute (axis a) | angle θ | rotation exp(θ a), origin fixed |
//! | prismatic (axis a) | distance s | translation s a |
//! | spherical | rotation vector φ ∈ R³ | rotation R_ref exp(φ), origin fixed |
//! | free | (p ∈ R³, φ ∈ R³) | translation p (in J), rotation R_ref exp(φ) |
//! | planar | (x, y, θ) | translation (x, y, 0) in J, then rotation θ about J's z axis |
//! | fixed | — | identity |
//!
//! **Rotational coordinates of spherical and free joints** are *exponential coordinates
//! about a reference orientation* R_ref (initially I): R_JB = R_ref exp(φ). The body-frame
//! angular velocity relative to J is J_r(φ) φ̇ (see [`crate::rotation::right_jacobian`]). Why
//! this choice rather than a quaternion (nq = 4, nv = 3): a quaternion makes q̇ ≠ v and breaks
//! the Lagrangian identities (1.40–1.41) that the mass, impulse and modal crates rely on
//! (A(q) as a Gram matrix of ∂x/∂q_k, Hessians of U in q). Exponential coordinates are smooth
//! and minimal; they are singular only at |φ| = 2π, and J_r is well conditioned for |φ| < π.
//! Integrators keep |φ| small by calling [`super::KinematicTree::rebase`], which folds exp(φ)
//! into R_ref and sets φ = 0 (and maps φ̇ to the new coordinates), without moving any body.

use nalgebra::Vector3;

/// The kind of joint that connects a body to its parent (see the module docs for q).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Joint {
    /// One rotation about a unit axis fixed in the joint frame J; q = angle (rad).
    Revolute {
        /// Unit axis, J components.
        axis: Vector3<f64>,
    },
    /// One translation along a unit axis fixed in J; q = distance (m).
    Prismatic {
        /// Unit axis, J components.
        axis: Vector3<f64>,
    },
    /// Three rotations about the joint origin; q = rotation vector φ about R_ref.
    Spherical,
    /// Six degrees of freedom; q = (translation p in J, rotation vector φ about R_ref).
    Free,
    /// Motion in J's xy-plane; q = (x, y, θ about J's z axis).
    Planar,
    /// Rigid attachment; no coordinates.
    Fixed,
}

impl Joint {
    /// Number of coordinates (= number of velocities) of the joint.
    pub fn dof(&self) -> usize {
        match self {
            Joint::Revolute { .. } | Joint::Prismatic { .. } => 1,
            Joint::Spherical | Joint::Planar => 3,
            Joint::Free => 6,
            Joint::Fixed => 0,
        }
    }

    /// True for joints whose rotation uses exponential coordinates about R_ref.
    pub fn has_rotation_vector(&self) -> bool {
        matches!(self, Joint::Spherical | Joint::Free)
    }

    /// Offset of the rotation vector within the joint's coordinates (spherical 0, free 3).
    pub(crate) fn rotation_offset(&self) -> usize {
        match self {
            Joint::Free => 3,
            _ => 0,
        }
    }
}
