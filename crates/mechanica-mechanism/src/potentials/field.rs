//! Uniform gravity and the centrifugal potential of a steadily rotating base frame, through
//! the subtree mass moments (no per-point work).

use super::{Potential, PotentialSum};
use crate::arithmetic::{Arithmetic, Values};
use crate::configuration::{Column, Moments};
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
///   later of k and l, both integrals in closed form in (m, h, S). Both are linear in the
///   earlier column, so each later coordinate l gives two vectors once and every pair costs
///   two dot products: the Hessian takes O(n·depth) operations.
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

impl UniformField {
    /// The vectors (p, r) with ∂²U/∂q_e∂q_l = w_e·p + a_e·r for every coordinate e that carries
    /// l (outside one rotation vector), from l's column (w_l, a_l) and the moments (m, h, S) of
    /// l's subtree. The Gram part ∫ρ J_eᵀ K J_l and the curvature part ∫ρ (Kx − g)·(w_e × J_l)
    /// (module docs) are both linear in (w_e, a_e); with tr([w]× M) = −w·ax(M):
    /// p = ax(K W_l S) − ax(W_l S K) + h × K a_l + a_l × K h − (w_l × h) × g − m a_l × g and
    /// r = K (w_l × h) + m K a_l. In [`Magnitudes`](crate::arithmetic::Magnitudes), on the
    /// magnitudes of the field, moments and column, the same formula gives the magnitudes of
    /// its terms.
    pub(crate) fn pair_weights<E: Arithmetic>(&self, m: &Moments, late: &Column) -> (Vector3<f64>, Vector3<f64>) {
        let (g, k) = (&self.gravity, &self.k);
        let wl = E::skew(&late.w);
        let spin_h = E::cross(&late.w, &m.first);
        let crossed = E::difference(E::axial(&(k * wl * m.second)), E::axial(&(wl * m.second * k)))
            + E::cross(&m.first, &(k * late.a))
            + E::cross(&late.a, &(k * m.first));
        let on_w = E::difference(
            E::difference(crossed, E::cross(&spin_h, g)),
            E::cross(&late.a, g) * m.mass,
        );
        let on_a = k * spin_h + k * late.a * m.mass;
        (on_w, on_a)
    }

    /// ∂²U/∂q_e∂q_l for two coordinates of one rotation vector at φ = 0: the Gram part plus
    /// the symmetric part of the curvature (see [`Configuration`]), over l's subtree moments;
    /// in [`Magnitudes`](crate::arithmetic::Magnitudes), the magnitudes of its terms.
    pub(crate) fn rotation_block_entry<E: Arithmetic>(&self, m: &Moments, early: &Column, late: &Column) -> f64 {
        let (g, k) = (&self.gravity, &self.k);
        let (we, wl) = (E::skew(&early.w), E::skew(&late.w));
        let gram = trace_of_product(&(we.transpose() * k * wl), &m.second)
            + early.a.dot(&(k * wl * m.first))
            + (we * m.first).dot(&(k * late.a))
            + m.mass * early.a.dot(&(k * late.a));
        let curvature = |e: &Matrix3<f64>, l: &Matrix3<f64>, la: &Vector3<f64>| {
            let first = trace_of_product(&(k * e * l), &m.second) + (k * m.first).dot(&(e * la));
            E::difference(
                E::difference(first, g.dot(&(e * l * m.first))),
                m.mass * g.dot(&(e * la)),
            )
        };
        gram + 0.5 * (curvature(&we, &wl, &late.a) + curvature(&wl, &we, &early.a))
    }

    /// The field with every component replaced by its magnitude.
    pub(crate) fn magnitudes(&self) -> Self {
        Self {
            gravity: self.gravity.abs(),
            k: self.k.abs(),
        }
    }
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
            sum.gradient[c] += col.w.dot(&(Values::axial(&(k * m.second)) - m.first.cross(g)))
                + (k * m.first - g * m.mass).dot(&col.a);
        }
        let Some(hessian) = sum.hessian.as_mut() else {
            return Ok(());
        };
        for late in 0..n {
            let m = config.subtree_moments(body_of(late));
            let cl = config.column(late);
            let (on_w, on_a) = self.pair_weights::<Values>(&m, &cl);
            for early in config.carriers(late) {
                let ce = config.column(early);
                let value = if config.same_rotation_block(early, late) {
                    config.require_rebased(early)?;
                    self.rotation_block_entry::<Values>(&m, &ce, &cl)
                } else {
                    ce.w.dot(&on_w) + ce.a.dot(&on_a)
                };
                hessian[(early, late)] += value;
                if early != late {
                    hessian[(late, early)] += value;
                }
            }
        }
        Ok(())
    }
}
