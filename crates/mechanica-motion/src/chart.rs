//! Charts of rotation vectors (spherical and free joints).
//!
//! A spherical joint turns its body by R = R_ref exp(φ); the coordinates φ are a chart about
//! R_ref that degrades as |φ| grows (J_r(φ) becomes singular at |φ| = 2π). The integrators
//! re-centre the charts before every step (`recentre`, (M.14)): R_ref ← R_ref exp(φ), φ ← 0,
//! which moves no body. The rates must follow: the body-frame angular velocity relative to
//! the parent is ω = J_r(φ) φ̇ in either chart, and J_r(0) = I, so the new rates are
//! φ̇′ = J_r(φ) φ̇. Leaving φ̇ unchanged would change the angular velocity and the energy.
//!
//! The states a run reports are in the *reporting chart*, the charts of the mechanism as it
//! was given (`ReportingChart`): φ_r = log(R_ref,0ᵀ R_ref exp(φ)) with |φ_r| ≤ π and
//! φ̇_r = J_r(φ_r)⁻¹ ω. The mechanism that integrates keeps its own moving charts.

use crate::error::StepFailure;
use crate::system::System;
use mechanica_kinematics::rotation::{exp_map, log_map, right_jacobian};
use mechanica_kinematics::tree::KinematicTree;
use nalgebra::{Rotation3, Vector3};

/// The first coordinate of each rotation vector of the tree (the last three coordinates of a
/// spherical or free joint) with its body.
fn rotation_blocks(tree: &KinematicTree) -> Vec<(usize, usize)> {
    (0..tree.body_count())
        .filter(|&b| tree.joint(b).is_some_and(|j| j.has_rotation_vector()))
        .map(|b| (b, tree.dof_range(b).end - 3))
        .collect()
}

/// True when coordinate `index` belongs to the rotation vector of a spherical or free joint.
pub(crate) fn is_rotation_coordinate(tree: &KinematicTree, index: usize) -> bool {
    rotation_blocks(tree).iter().any(|&(_, s)| (s..s + 3).contains(&index))
}

fn block(values: &[f64], s: usize) -> Vector3<f64> {
    Vector3::new(values[s], values[s + 1], values[s + 2])
}

/// Re-centres every rotation-vector chart at the current orientation (module docs): φ ← 0,
/// φ̇ ← J_r(φ) φ̇. Does nothing for a mechanism without spherical or free joints.
pub(crate) fn recentre(system: &mut System, q: &mut [f64], q_dot: &mut [f64]) -> Result<(), StepFailure> {
    let blocks = rotation_blocks(system.dynamics().tree());
    if blocks.is_empty() {
        return Ok(());
    }
    for &(_, s) in &blocks {
        let w = right_jacobian(&block(q, s)) * block(q_dot, s);
        q_dot[s..s + 3].copy_from_slice(w.as_slice());
    }
    system.dynamics_mut().rebase(q)?;
    crate::error::check_finite(q_dot, "re-centred rates")
}

/// The charts of the mechanism as given: the reference orientation of every rotation vector.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ReportingChart {
    references: Vec<(usize, usize, Rotation3<f64>)>,
}

impl ReportingChart {
    /// The charts of `tree` now.
    pub(crate) fn of(tree: &KinematicTree) -> Self {
        let references = rotation_blocks(tree)
            .into_iter()
            .map(|(b, s)| (b, s, tree.reference_rotation(b).unwrap_or_else(Rotation3::identity)))
            .collect();
        Self { references }
    }

    /// (q, q̇) given in the charts of `tree` rewritten in the reporting chart (module docs).
    pub(crate) fn report(&self, tree: &KinematicTree, q: &mut [f64], q_dot: &mut [f64]) -> Result<(), StepFailure> {
        for &(body, s, r0) in &self.references {
            let phi = block(q, s);
            let r_now = tree.reference_rotation(body).unwrap_or_else(Rotation3::identity);
            let exp = exp_map(&phi).map_err(mechanica_dynamics::DynamicsError::from)?;
            let phi_r = log_map(&(r0.inverse() * r_now * exp));
            let omega = right_jacobian(&phi) * block(q_dot, s);
            let rate = right_jacobian(&phi_r).try_inverse().ok_or(StepFailure::NonFinite {
                what: "rate in the reporting chart",
            })? * omega;
            q[s..s + 3].copy_from_slice(phi_r.as_slice());
            q_dot[s..s + 3].copy_from_slice(rate.as_slice());
        }
        crate::error::check_finite(q, "reported q")?;
        crate::error::check_finite(q_dot, "reported q̇")
    }

    /// True when the mechanism has no rotation vectors (the charts never move).
    pub(crate) fn is_trivial(&self) -> bool {
        self.references.is_empty()
    }
}
