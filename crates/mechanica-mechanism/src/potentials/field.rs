//! Uniform gravity and the centrifugal potential of a steadily rotating base frame, through
//! the subtree mass moments (no per-point work).

use super::{Potential, PotentialSum};
use crate::{Configuration, MechanismError};
use mechanica_kinematics::tree::KinematicTree;
use nalgebra::{Matrix3, Vector3};

/// The field potential U = ∫ρ (½ xᵀKx − g·x) dV over all bodies, for a uniform gravity g and a
/// constant symmetric K. Gravity alone is K = 0 (U = −Σ m g·c). In a base frame turning at the
/// constant rate Ω about the unit axis a through its origin (§8e), the centrifugal potential
/// U_rot = −T_sl = −½ ∫ρ |Ω × x|² dV (8.56–8.58) is K = −Ω² (1 − a aᵀ).
///
/// With the subtree moments (m, h, S) of [`crate::configuration::Moments`] and the
/// origin-referred columns (w, a) of [`Configuration`]:
/// - U = ½ tr(K S) − g·h over the whole tree;
/// - ∂U/∂q_k = w_k·(ax(K S) − h × g) + (K h − m g)·a_k over the subtree of k's body, with
///   ax(M) = (M₃₂ − M₂₃, M₁₃ − M₃₁, M₂₁ − M₁₂);
/// - ∂²U/∂q_k∂q_l = ∫ρ (∂x/∂q_k)ᵀ K ∂x/∂q_l + ∫ρ (Kx − g)·∂²x/∂q_k∂q_l over the subtree of the
///   later of k and l, both integrals in closed form in (m, h, S).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UniformField {
    /// Gravitational acceleration g (world, m/s²).
    pub gravity: Vector3<f64>,
    /// K (world, 1/s²), symmetric.
    pub k: Matrix3<f64>,
}

impl UniformField {
    /// Gravity alone.
    pub fn gravity(gravity: Vector3<f64>) -> Self {
        Self {
            gravity,
            k: Matrix3::zeros(),
        }
    }

    /// Gravity plus the centrifugal potential of rotation at `rate` (rad/s) about the unit
    /// `axis` through the base origin.
    pub fn rotating(gravity: Vector3<f64>, axis: &Vector3<f64>, rate: f64) -> Self {
        let projector = Matrix3::identity() - axis * axis.transpose();
        Self {
            gravity,
            k: projector * (-rate * rate),
        }
    }
}

fn axial(m: &Matrix3<f64>) -> Vector3<f64> {
    Vector3::new(m[(2, 1)] - m[(1, 2)], m[(0, 2)] - m[(2, 0)], m[(1, 0)] - m[(0, 1)])
}

/// tr(P S) for 3×3 matrices without forming P S.
fn trace_of_product(p: &Matrix3<f64>, s: &Matrix3<f64>) -> f64 {
    p.component_mul(&s.transpose()).sum()
}

impl Potential for UniformField {
    fn name(&self) -> String {
        if self.k == Matrix3::zeros() {
            "gravity".into()
        } else {
            "gravity and centrifugal field".into()
        }
    }

    fn validate(&self, _tree: &KinematicTree) -> Result<(), MechanismError> {
        crate::error::check_all_finite(self.gravity.iter(), "gravity")?;
        crate::error::check_all_finite(self.k.iter(), "field stiffness")
    }

    fn accumulate(&self, config: &Configuration<'_>, sum: &mut PotentialSum) -> Result<(), MechanismError> {
        let (g, k) = (&self.gravity, &self.k);
        let total = config.total_moments();
        sum.value += 0.5 * trace_of_product(k, &total.second) - g.dot(&total.first);
        let n = config.dof();
        let tree = config.tree;
        let body_of = |c: usize| tree.dof_body(c).unwrap_or(0);
        for c in 0..n {
            let m = config.subtree_moments(body_of(c));
            let col = config.column(c);
            sum.gradient[c] +=
                col.w.dot(&(axial(&(k * m.second)) - m.first.cross(g))) + (k * m.first - g * m.mass).dot(&col.a);
        }
        let Some(hessian) = sum.hessian.as_mut() else {
            return Ok(());
        };
        for c in 0..n {
            for d in c..n {
                let (bc, bd) = (body_of(c), body_of(d));
                let (early, late, block) = if tree.is_ancestor_or_self(bc, bd) || tree.is_ancestor_or_self(bd, bc) {
                    config.ordered(c, d)
                } else {
                    continue;
                };
                if block {
                    config.require_rebased(c)?;
                }
                let m = config.subtree_moments(body_of(late));
                let (ce, cl) = (config.column(early), config.column(late));
                let (we, wl) = (ce.w.cross_matrix(), cl.w.cross_matrix());
                // ∫ρ J_eᵀ K J_l for J = W x + a.
                let gram = trace_of_product(&(we.transpose() * k * wl), &m.second)
                    + ce.a.dot(&(k * wl * m.first))
                    + (we * m.first).dot(&(k * cl.a))
                    + m.mass * ce.a.dot(&(k * cl.a));
                // ∫ρ (Kx − g)·(w_e × ∂x/∂q_l), symmetrised inside one rotation vector.
                let curvature = |e: &Matrix3<f64>, l: &Matrix3<f64>, la: &Vector3<f64>| {
                    trace_of_product(&(k * e * l), &m.second) + (k * m.first).dot(&(e * la))
                        - g.dot(&(e * l * m.first))
                        - m.mass * g.dot(&(e * la))
                };
                let second = if block {
                    0.5 * (curvature(&we, &wl, &cl.a) + curvature(&wl, &we, &ce.a))
                } else {
                    curvature(&we, &wl, &cl.a)
                };
                let value = gram + second;
                hessian[(c, d)] += value;
                if c != d {
                    hessian[(d, c)] += value;
                }
            }
        }
        Ok(())
    }
}
