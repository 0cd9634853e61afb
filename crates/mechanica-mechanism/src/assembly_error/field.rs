//! The rounding of the field's Hessian, entry by entry (docs/theory.md, "Assembly error of A
//! and B").
//!
//! [`UniformField`] forms ∂²U/∂q_e∂q_l = w_e·p_l + a_e·r_l for every coordinate e that carries
//! l, from l's subtree moments and the origin-referred columns, and the pairs inside one
//! rotation vector by their own formula. Every quantity there is a sum of rounded terms, so
//! the rounding of an entry is bounded by γ times the same formulas evaluated on magnitudes
//! ([`Magnitudes`]): Ē_el = |w_e|·p̄_l + ā_e·r̄_l, with p̄_l, r̄_l the pair weights on the
//! magnitudes of the moments and of l's column. The kinematic quantities are rounded relative
//! to their lengths, not component by component (an axis rotated into the world has
//! components of 1e-17 that err by 1e-16), so their magnitudes are isotropic: a vector v
//! enters as ‖v‖ in every component, a matrix as its Frobenius norm in every entry. Positions
//! enter with the reach of their root path (the lengths of the joint offsets along it), since
//! their rounding grows with that length, not with their distance from the origin: a chain
//! that folds back to the origin is charged for its whole length. γ = 64·n·u, as for the other
//! contributions, covers the sums over subtrees and the depth of the kinematic recursion.
//!
//! The origin-referred formulas cancel: a joint far from the origin has entries of the size
//! of its subtree's lever arms, formed from moments of the size of their distance to the
//! origin. The magnitudes charge that cancellation; a norm of the computed entries would not.
//!
//! E = γĒ is non-negative and symmetric and lives on the pairs of coordinates on one root
//! path; it is never formed. Its product with a non-negative vector costs O(n): the sums over
//! a coordinate's carriers grow from the root along the path, and the sums over the
//! coordinates it carries grow back from the leaves. From it:
//! - a mode x moves by |xᵀδBx| ≤ |x|ᵀE|x|;
//! - with D = diag(B), ‖D^{-1/2} δB D^{-1/2}‖₂ ≤ ρ(D^{-1/2} E D^{-1/2}), at most the largest row
//!   sum of that non-negative matrix.

use crate::arithmetic::Magnitudes;
use crate::configuration::{Column, Moments};
use crate::potentials::UniformField;
use crate::{Configuration, MechanismError};
use faer::{Mat, MatRef};
use mechanica_kinematics::tree::Workspace;
use mechanica_mass::MassProperties;
use nalgebra::{Matrix3, Vector3};

/// The componentwise rounding bound E of the field's Hessian over all coordinates.
#[derive(Debug, Clone)]
pub(crate) struct FieldRounding {
    gamma: f64,
    /// Per coordinate: the magnitude of its column (|w_k|, ā_k).
    columns: Vec<Column>,
    /// Per coordinate l: the magnitudes (p̄_l, r̄_l) of its pair weights.
    weights: Vec<(Vector3<f64>, Vector3<f64>)>,
    /// Per coordinate: the coordinate before it on its root path.
    previous: Vec<Option<usize>>,
    /// Per coordinate: its nearest carrier outside its own rotation vector.
    outside: Vec<Option<usize>>,
    /// The coordinates, each after its carriers.
    order: Vec<usize>,
    /// Ē_el for the pairs e ≤ l inside one rotation vector (their diagonals included).
    block: Vec<(usize, usize, f64)>,
    in_block: Vec<bool>,
    /// Per coordinate: its index among the free coordinates.
    free_index: Vec<Option<usize>>,
}

impl FieldRounding {
    /// The bound for `field` at the evaluated `config` (positions in `ws`), over the free
    /// coordinates `free`.
    pub(crate) fn of(
        field: &UniformField,
        config: &Configuration<'_>,
        ws: &Workspace,
        bodies: &[MassProperties],
        free: &[usize],
        gamma: f64,
    ) -> Result<Self, MechanismError> {
        let tree = config.tree;
        let n = config.dof();
        let (origins, subtree) = magnitude_moments(config, ws, bodies)?;
        let body_of = |k: usize| tree.dof_body(k).unwrap_or(0);
        let mut columns = Vec::with_capacity(n);
        for k in 0..n {
            let (w, v) = ws.motion_column(k)?;
            // a = v − w × o, formed from the origin's position.
            let a = v.norm() + w.norm() * origins[body_of(k)];
            let w = isotropic(w.norm());
            let a = isotropic(a);
            columns.push(Column { w, a });
        }
        let magnitudes = field.magnitudes();
        let weights = (0..n)
            .map(|l| magnitudes.pair_weights::<Magnitudes>(&subtree[body_of(l)], &columns[l]))
            .collect();
        let mut block = Vec::new();
        let mut in_block = vec![false; n];
        let mut outside = vec![None; n];
        for l in 0..n {
            for e in config.carriers(l) {
                if config.same_rotation_block(e, l) {
                    config.require_rebased(l)?;
                    let m = &subtree[body_of(l)];
                    block.push((
                        e,
                        l,
                        magnitudes.rotation_block_entry::<Magnitudes>(m, &columns[e], &columns[l]),
                    ));
                    in_block[l] = true;
                } else if e != l {
                    outside[l] = Some(e);
                    break;
                }
            }
        }
        let order = tree
            .topological_order()
            .iter()
            .flat_map(|&b| tree.dof_range(b))
            .collect();
        Ok(Self {
            gamma,
            columns,
            weights,
            previous: (0..n).map(|k| tree.previous_dof(k)).collect(),
            outside,
            order,
            block,
            in_block,
            free_index: super::free_positions(n, free),
        })
    }

    /// E over all coordinates, entry by entry (O(n²) storage: for reports and checks).
    pub(crate) fn dense(&self) -> Mat<f64> {
        let n = self.columns.len();
        let mut e = Mat::zeros(n, n);
        for l in 0..n {
            let (p, r) = &self.weights[l];
            let mut carrier = if self.in_block[l] { self.outside[l] } else { Some(l) };
            while let Some(k) = carrier {
                let entry = self.gamma * (self.columns[k].w.dot(p) + self.columns[k].a.dot(r));
                e[(k, l)] = entry;
                e[(l, k)] = entry;
                carrier = self.previous[k];
            }
        }
        for &(k, l, entry) in &self.block {
            e[(k, l)] = self.gamma * entry;
            e[(l, k)] = self.gamma * entry;
        }
        e
    }

    /// Ē v for a non-negative v over all coordinates, in O(n).
    fn product(&self, v: &[f64]) -> Vec<f64> {
        let n = v.len();
        // Σ v_e (|w_e|, ā_e) over e = k and k's carriers.
        let mut along = vec![(Vector3::zeros(), Vector3::zeros()); n];
        // Σ v_l (p̄_l, r̄_l) over the l whose outside carrier is k or is carried by k.
        let mut behind = vec![(Vector3::zeros(), Vector3::zeros()); n];
        for &k in &self.order {
            let above = self.previous[k].map_or((Vector3::zeros(), Vector3::zeros()), |p| along[p]);
            along[k] = (above.0 + self.columns[k].w * v[k], above.1 + self.columns[k].a * v[k]);
            if let Some(o) = self.outside[k] {
                behind[o].0 += self.weights[k].0 * v[k];
                behind[o].1 += self.weights[k].1 * v[k];
            }
        }
        for &k in self.order.iter().rev() {
            if let Some(p) = self.previous[k] {
                let below = behind[k];
                behind[p].0 += below.0;
                behind[p].1 += below.1;
            }
        }
        let mut out = vec![0.0; n];
        for k in 0..n {
            let (p, r) = &self.weights[k];
            let column = &self.columns[k];
            let carriers = self.outside[k].map_or(0.0, |o| along[o].0.dot(p) + along[o].1.dot(r));
            let carried = column.w.dot(&behind[k].0) + column.a.dot(&behind[k].1);
            let own = if self.in_block[k] {
                0.0
            } else {
                v[k] * (column.w.dot(p) + column.a.dot(r))
            };
            out[k] = carriers + carried + own;
        }
        for &(e, l, entry) in &self.block {
            out[e] += entry * v[l];
            if e != l {
                out[l] += entry * v[e];
            }
        }
        out
    }

    /// 1 + 8nu: the rounding of the non-negative sums of [`Self::product`] and of the final sum.
    fn summation(&self) -> f64 {
        1.0 + 8.0 * self.columns.len() as f64 * f64::EPSILON
    }

    /// |x|ᵀE|x| for the mode shape `x` over the free coordinates, scaled by its largest
    /// entry so that shapes of light bodies do not overflow the squares.
    pub(crate) fn share(&self, x: impl Fn(usize) -> f64) -> f64 {
        let mut v: Vec<f64> = self.free_index.iter().map(|i| i.map_or(0.0, |i| x(i).abs())).collect();
        let top = v.iter().copied().fold(0.0, f64::max);
        if top == 0.0 {
            return 0.0;
        }
        v.iter_mut().for_each(|e| *e /= top);
        let product = self.product(&v);
        let quadratic: f64 = v.iter().zip(&product).map(|(a, b)| a * b).sum();
        if quadratic == 0.0 {
            // Nothing the mode moves carries a bound, even when top² overflows.
            return 0.0;
        }
        if quadratic.is_nan() {
            // A magnitude overflowed where the mode does not move (∞·0): the bound is unknown.
            return f64::INFINITY;
        }
        (self.gamma * top) * top * quadratic * self.summation()
    }

    /// A bound on ‖D^{-1/2} E D^{-1/2}‖₂, D the diagonal of the stored free-coordinate Hessian
    /// `b`: the largest row sum. None when a free coordinate with a row in E (or a row that is
    /// not a number, a magnitude having overflowed) has a diagonal entry that is not positive,
    /// or the bound is not finite.
    pub(crate) fn margin(&self, b: MatRef<'_, f64>) -> Option<f64> {
        let n = self.columns.len();
        let mut scale = vec![0.0; n];
        let mut unscaled = vec![0.0; n];
        for (k, index) in self.free_index.iter().enumerate() {
            if let Some(i) = *index {
                let diagonal = b[(i, i)];
                if diagonal > 0.0 {
                    scale[k] = diagonal.sqrt().recip();
                } else {
                    unscaled[k] = 1.0;
                }
            }
        }
        let free: Vec<f64> = self
            .free_index
            .iter()
            .map(|i| if i.is_some() { 1.0 } else { 0.0 })
            .collect();
        if self
            .product(&free)
            .iter()
            .zip(&unscaled)
            .any(|(&row, &u)| u > 0.0 && row != 0.0)
        {
            return None;
        }
        let rows = self.product(&scale);
        let scaled: Vec<f64> = rows.iter().zip(&scale).map(|(row, s)| row * s).collect();
        if scaled.iter().any(|r| r.is_nan()) {
            return None;
        }
        let largest = scaled.iter().copied().fold(0.0, f64::max);
        let margin = self.gamma * largest * self.summation();
        margin.is_finite().then_some(margin)
    }
}

/// Per body: the magnitude of its origin (the reach of its root path), and the magnitudes of
/// its subtree's moments: mass, first moment Σ m ρ_c 1, second moment Σ (m ρ_c² + ‖spread‖_F) J,
/// with ρ_c the reach of the body's centre, 1 the vector and J the matrix of ones.
fn magnitude_moments(
    config: &Configuration<'_>,
    ws: &Workspace,
    bodies: &[MassProperties],
) -> Result<(Vec<f64>, Vec<Moments>), MechanismError> {
    let tree = config.tree;
    let count = bodies.len();
    let mut reach = vec![0.0; count];
    let mut subtree = vec![Moments::zero(); count];
    for &i in tree.topological_order() {
        let o = ws.position(i)?;
        let base = tree.parent(i).map_or(Ok(Vector3::zeros()), |p| ws.position(p))?;
        let above = tree.parent(i).map_or(0.0, |p| reach[p]);
        reach[i] = (above + (o - base).norm()).max(o.norm());
        let body = &bodies[i];
        let centre = ws.point_position(i, &body.p_oc)?;
        let c = (reach[i] + (centre - o).norm()).max(centre.norm());
        let r = ws.rotation(i)?;
        let inertia = r.matrix() * body.inertia_c * r.matrix().transpose();
        let spread = (Matrix3::identity() * (0.5 * inertia.trace()) - inertia).norm();
        let mass = body.mass.abs();
        subtree[i] = Moments {
            mass,
            first: isotropic(mass * c),
            second: Matrix3::repeat(mass * c * c + spread),
        };
    }
    for &i in tree.topological_order().iter().rev() {
        if let Some(p) = tree.parent(i) {
            let child = subtree[i];
            subtree[p].add(&child);
        }
    }
    Ok((reach, subtree))
}

/// The vector with every component `size`: the magnitude of a computed vector whose rounding
/// is relative to its length, not to its components (a unit axis rotated into the world has
/// components of 1e-17 that err by 1e-16).
fn isotropic(size: f64) -> Vector3<f64> {
    Vector3::repeat(size)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Mechanism;
    use mechanica_kinematics::tree::{Joint, TreeBuilder};
    use nalgebra::{Isometry3, Translation3, UnitQuaternion};
    use proptest::prelude::*;

    /// A tree of one body per entry of `shape` (parent as a fraction of the bodies before, joint
    /// kind, placement offsets), unit masses, box inertias, tilted gravity.
    fn mechanism(shape: &[(f64, usize, [f64; 3])]) -> Mechanism {
        let mut builder = TreeBuilder::new();
        for (i, &(parent, kind, offset)) in shape.iter().enumerate() {
            let parent = (i > 0).then_some((parent * i as f64) as usize);
            let axis = Vector3::new(offset[1], offset[2], 1.0).normalize();
            let joint = match kind {
                0 => Joint::Revolute { axis },
                1 => Joint::Prismatic { axis },
                2 => Joint::Planar,
                3 => Joint::Spherical,
                4 => Joint::Free,
                _ => Joint::Fixed,
            };
            let rotation = UnitQuaternion::from_scaled_axis(Vector3::new(offset[2], offset[0], offset[1]));
            let placement = Isometry3::from_parts(Translation3::new(offset[0], offset[1], offset[2]), rotation);
            builder.add_body(parent, joint, placement);
        }
        let inertia = Matrix3::from_diagonal(&Vector3::new(0.2, 0.3, 0.4));
        let body = MassProperties::new(1.0, Vector3::new(0.1, -0.2, 0.3), inertia).expect("body");
        let tree = builder.build().expect("tree");
        let mut mechanism = Mechanism::new(tree, vec![body; shape.len()]).expect("mechanism");
        mechanism.set_gravity(Vector3::new(0.3, -0.4, -9.8)).expect("gravity");
        mechanism
    }

    proptest! {
        /// The O(n) product with E agrees with the product by the explicit E, on random trees of
        /// every joint kind (rotation vectors and fixed joints included), with random
        /// coordinates locked.
        #[test]
        fn the_path_sums_multiply_by_the_explicit_bound(
            shape in proptest::collection::vec((0.0..1.0_f64, 0usize..6, [-1.0..1.0_f64, -1.0..1.0, -1.0..1.0]), 1..12),
            weights in proptest::collection::vec(0.0..1.0_f64, 72),
            locked in proptest::collection::vec(any::<bool>(), 72),
        ) {
            let m = mechanism(&shape);
            let n = m.dof();
            let q = vec![0.0; n];
            let free: Vec<usize> = (0..n).filter(|&k| !locked[k] || k == 0).collect();
            let ws = m.positions(&q).expect("positions");
            let config = Configuration::new(m.tree(), &ws, &q, m.bodies()).expect("configuration");
            let bound = FieldRounding::of(&m.field(), &config, &ws, m.bodies(), &free, 1.0).expect("bound");
            let dense = bound.dense();
            let v: Vec<f64> = (0..n).map(|k| if free.contains(&k) { weights[k] } else { 0.0 }).collect();
            let fast = bound.product(&v);
            for (i, value) in fast.iter().enumerate() {
                let explicit: f64 = (0..n).map(|j| dense[(i, j)] * v[j]).sum();
                prop_assert!((value - explicit).abs() <= 1e-12 * explicit.abs(), "{value} vs {explicit}");
            }
            // The share is |x|ᵀE|x| over the free coordinates.
            let x = |i: usize| weights[free[i]] * if i.is_multiple_of(2) { 1.0 } else { -1.0 };
            let quadratic: f64 = (0..n).map(|i| v[i] * fast[i]).sum();
            let share = bound.share(x);
            prop_assert!(share >= quadratic * (1.0 - 1e-12) && share <= quadratic * (1.0 + 1e-12), "{share} vs {quadratic}");
        }
    }

    #[test]
    fn a_coordinate_without_stiffness_under_the_field_leaves_no_margin() {
        let shape = [(0.0, 0, [0.1, 0.2, 0.3]), (0.0, 1, [0.3, -0.2, 0.5])];
        let m = mechanism(&shape);
        let q = vec![0.0; m.dof()];
        let ws = m.positions(&q).expect("positions");
        let config = Configuration::new(m.tree(), &ws, &q, m.bodies()).expect("configuration");
        let all: Vec<usize> = (0..m.dof()).collect();
        let bound = FieldRounding::of(&m.field(), &config, &ws, m.bodies(), &all, 1e-12).expect("bound");
        let definite = Mat::from_fn(2, 2, |i, j| if i == j { 1.0 } else { 0.0 });
        assert!(bound.margin(definite.as_ref()).is_some_and(|t| t > 0.0 && t < 1e-9));
        let singular = Mat::from_fn(2, 2, |i, j| if i == j && i == 0 { 1.0 } else { 0.0 });
        assert_eq!(bound.margin(singular.as_ref()), None);
    }
}
