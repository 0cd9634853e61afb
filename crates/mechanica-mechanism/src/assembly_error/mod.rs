//! How far the rounding of its assembly can move each ω² of a mechanism (docs/theory.md,
//! "Assembly error of A and B").
//!
//! B = ∂²U*/∂q∂q is a sum of contributions B_c: the field (gravity and the rotating frame's
//! −T₀), and each added potential. The field's rounding is bounded entry by entry, |δB_f| ≤ E
//! ([`field`]). Each added potential's B_c is formed from rounded kinematic quantities along
//! root paths of at most n joints; its rounding is bounded by ‖δB_c‖ ≤ γ‖B_c‖_F with
//! γ = 64·n·u (generous: each entry is a sum of O(n) products), and it lives on the rows and
//! columns S_c where B_c is non-zero. To first order a perturbation δB moves ω²_k by
//! x_kᵀ δB x_k (x_k A-normalised), so
//!
//! |δω²_k| ≤ |x_k|ᵀE|x_k| + Σ_c γ ‖B_c‖_F ‖x_k|S_c‖².
//!
//! A is the sum of the bodies' A_b = m J_vᵀJ_v + J_ωᵀ I_C J_ω (J_v the Jacobian of the centre
//! of mass, J_ω the angular one), each on the coordinates of the body's root path, with
//! ‖A_b‖_F ≤ m‖J_v‖_F² + tr(I_C)‖J_ω‖_F². As ω²_k = x_kᵀBx_k / x_kᵀAx_k, a perturbation δA
//! moves ω²_k by −ω²_k x_kᵀ δA x_k, so A's share is |ω²_k| Σ_b γ‖A_b‖_F ‖x_k|S_b‖².
//!
//! A single norm ‖B‖ for the whole matrix would charge a soft mode with the rounding of a
//! stiff spring it hardly moves; per contribution, the stiff spring's share is weighted by the
//! soft mode's tiny component on the stiff coordinate.

mod field;

use crate::configuration::Configuration;
use crate::{Mechanism, MechanismError, PotentialSum};
use faer::{Mat, MatRef};
use field::FieldRounding;
use mechanica_kinematics::scaling;
use mechanica_kinematics::tree::Workspace;
use mechanica_mass::MassProperties;

/// One contribution's share: γ‖B_c‖_F and the free coordinates it touches.
#[derive(Debug, Clone)]
struct Contribution {
    scale: f64,
    support: Vec<usize>,
}

/// A's contributions, one per body: γ‖A_b‖_F on the free coordinates of the body's root path.
/// The paths nest, so Σ_b scale_b ‖x|S_b‖² is summed from the root outwards in O(n) per mode.
#[derive(Debug, Clone, Default)]
struct BodyContributions {
    /// γ‖A_b‖_F per body.
    scale: Vec<f64>,
    /// The bodies, parents before children.
    order: Vec<usize>,
    parent: Vec<Option<usize>>,
    /// Per body: the indices into the free coordinates of its own joint's coordinates.
    own: Vec<Vec<usize>>,
}

/// The assembly errors of B and A over the free coordinates, contribution by contribution.
#[derive(Debug, Clone, Default)]
pub(crate) struct AssemblyError {
    field: Option<FieldRounding>,
    stiffness: Vec<Contribution>,
    inertia: BodyContributions,
}

impl AssemblyError {
    /// The contributions of `mechanism` at q (already re-centred), restricted to `free`
    /// (indices into q).
    pub(crate) fn of(mechanism: &Mechanism, q: &[f64], free: &[usize]) -> Result<Self, MechanismError> {
        let gamma = rounding_factor(mechanism.dof());
        let ws = mechanism.positions(q)?;
        let bodies = mechanism.bodies();
        let config = Configuration::new(mechanism.tree(), &ws, q, bodies)?;
        let mut error = AssemblyError::default();
        if mechanism.field_is_active() {
            error.field = Some(FieldRounding::of(
                &mechanism.field(),
                &config,
                &ws,
                bodies,
                free,
                gamma,
            )?);
        }
        for potential in mechanism.potentials() {
            let sum = evaluate(&config, |c, s| potential.accumulate(c, s))?;
            if let Some(h) = sum.hessian {
                error.stiffness.push(Contribution::of(&h, free, gamma));
            }
        }
        error.inertia = BodyContributions::of(&config, &ws, bodies, free, gamma)?;
        Ok(error)
    }

    /// The field's componentwise rounding bound E over all coordinates of `mechanism` at q
    /// (zero without a field).
    pub(crate) fn field_rounding(mechanism: &Mechanism, q: &[f64]) -> Result<Mat<f64>, MechanismError> {
        let n = mechanism.dof();
        if !mechanism.field_is_active() {
            return Ok(Mat::zeros(n, n));
        }
        let all: Vec<usize> = (0..n).collect();
        let ws = mechanism.positions(q)?;
        let config = Configuration::new(mechanism.tree(), &ws, q, mechanism.bodies())?;
        let gamma = rounding_factor(n);
        Ok(FieldRounding::of(&mechanism.field(), &config, &ws, mechanism.bodies(), &all, gamma)?.dense())
    }

    /// B's share of the bound on |δω²| for the mode shape `x` (A-normalised, free
    /// coordinates): |x|ᵀE|x| + Σ_c γ‖B_c‖_F ‖x|S_c‖². It decides the sign of ω²: A is
    /// positive definite, so only B's rounding can move ω² across zero.
    pub(crate) fn stiffness_share(&self, x: impl Fn(usize) -> f64) -> f64 {
        let field = self.field.as_ref().map_or(0.0, |f| f.share(&x));
        field + share(&self.stiffness, x)
    }

    /// A bound τ on ‖diag(B)^{-1/2} δB diag(B)^{-1/2}‖₂ for the assembly's rounding δB of the
    /// stored (free-coordinate) Hessian `b`: the field's [`FieldRounding::margin`] plus
    /// Σ_c γ‖B_c‖_F / min_{i∈S_c} b_ii over the other contributions, since each δB_c lives on
    /// S_c. None when a contribution with a non-zero scale touches a diagonal entry that is not
    /// positive, or the sum is not finite.
    pub(crate) fn stiffness_margin(&self, b: MatRef<'_, f64>) -> Option<f64> {
        let mut margin = match &self.field {
            Some(field) => field.margin(b)?,
            None => 0.0,
        };
        for c in self.stiffness.iter().filter(|c| c.scale != 0.0) {
            let smallest = c.support.iter().map(|&i| b[(i, i)]).fold(f64::INFINITY, f64::min);
            if smallest.is_nan() || smallest <= 0.0 {
                return None;
            }
            margin += c.scale / smallest;
        }
        margin.is_finite().then_some(margin)
    }

    /// A's share, |ω²| Σ_b γ‖A_b‖_F ‖x|S_b‖²: relative to ω², it never changes its sign.
    pub(crate) fn inertia_share(&self, omega_sq: f64, x: impl Fn(usize) -> f64) -> f64 {
        if omega_sq == 0.0 {
            return 0.0;
        }
        omega_sq.abs() * self.inertia.share(x)
    }
}

/// Σ_c scale_c ‖x|S_c‖², each term formed as (scale_c·t)·t·Σ(x_i/t)² with t = max |x_i| on
/// S_c, so that shapes of light bodies (entries near 1e158 for a mass of 1e-316) neither
/// overflow the squares nor turn a zero scale into 0·∞ = NaN.
fn share(terms: &[Contribution], x: impl Fn(usize) -> f64) -> f64 {
    terms
        .iter()
        .map(|c| {
            let top = c.support.iter().fold(0.0_f64, |m, &i| m.max(x(i).abs()));
            // A term the mode does not touch, or whose entries are all zero, adds nothing,
            // even when the other factor overflowed.
            if top == 0.0 || c.scale == 0.0 {
                return 0.0;
            }
            let relative: f64 = c.support.iter().map(|&i| (x(i) / top).powi(2)).sum();
            c.scale * top * top * relative
        })
        .sum()
}

impl Contribution {
    /// γ‖B_c‖_F and the support of `h` restricted to `free`.
    fn of(h: &Mat<f64>, free: &[usize], gamma: f64) -> Self {
        let mut entries = Vec::new();
        let mut support = Vec::new();
        for (i, &r) in free.iter().enumerate() {
            let row = free.iter().map(|&c| h[(r, c)]);
            if row.clone().any(|v| v != 0.0) {
                support.push(i);
                entries.extend(row);
            }
        }
        // The Frobenius norm on scaled entries: their squares would overflow from 1e154.
        Contribution {
            scale: gamma * scaling::norm_of(&entries),
            support,
        }
    }
}

impl BodyContributions {
    /// Per body b, γ times the bound m‖J_v‖_F² + tr(I_C)‖J_ω‖_F² on ‖A_b‖_F, J the Jacobian of
    /// its centre of mass (world) over the free coordinates of its root path: O(depth) each.
    fn of(
        config: &Configuration<'_>,
        ws: &Workspace,
        bodies: &[MassProperties],
        free: &[usize],
        gamma: f64,
    ) -> Result<Self, MechanismError> {
        let tree = config.tree;
        let free_index = free_positions(tree.dof(), free);
        let mut scale = Vec::with_capacity(bodies.len());
        for (b, body) in bodies.iter().enumerate() {
            let centre = ws.point_position(b, &body.p_oc)?;
            let (mut linear, mut angular) = (0.0, 0.0);
            let path = std::iter::successors(Some(b), |&i| tree.parent(i));
            for k in path
                .flat_map(|i| tree.dof_range(i))
                .filter(|&k| free_index[k].is_some())
            {
                let column = config.column(k);
                linear += (column.a + column.w.cross(&centre)).norm_squared();
                angular += column.w.norm_squared();
            }
            scale.push(gamma * (body.mass * linear + body.inertia_c.trace() * angular));
        }
        let own = (0..bodies.len())
            .map(|b| tree.dof_range(b).filter_map(|k| free_index[k]).collect())
            .collect();
        Ok(BodyContributions {
            scale,
            order: tree.topological_order().to_vec(),
            parent: (0..bodies.len()).map(|b| tree.parent(b)).collect(),
            own,
        })
    }

    /// Σ_b scale_b ‖x|S_b‖², S_b the free coordinates on b's root path. Each ‖x|S_b‖² is kept
    /// as t_b²·s_b with t_b = max |x_i| on S_b and s_b = Σ(x_i/t_b)², grown from the parent's
    /// pair by rescaling where the maximum rises, so that shapes of light bodies (entries near
    /// 1e158 for a mass of 1e-316) neither overflow the squares nor swamp the heavy bodies'
    /// small terms. A square or rescaled sum that underflows errs by less than 2⁻¹⁰²⁰ t_b²,
    /// added per entry, and the sums' rounding is covered by a factor 1 + 4·len·u. A body whose
    /// path the mode does not touch, or whose scale is zero, adds nothing, even when the other
    /// factor overflowed.
    fn share(&self, x: impl Fn(usize) -> f64) -> f64 {
        let entries: usize = self.own.iter().map(Vec::len).sum();
        let underflow = (-1020.0_f64).exp2();
        let rounding = 1.0 + 4.0 * entries as f64 * f64::EPSILON;
        let mut path = vec![ScaledSquares::default(); self.scale.len()];
        let mut total = 0.0;
        for &b in &self.order {
            let mut sum = self.parent[b].map_or_else(ScaledSquares::default, |p| path[p]);
            for &i in &self.own[b] {
                sum.add(x(i));
            }
            path[b] = sum;
            if sum.top > 0.0 && self.scale[b] != 0.0 {
                let relative = sum.scaled * rounding + sum.count as f64 * underflow;
                total += (self.scale[b] * sum.top) * (sum.top * relative);
            }
        }
        total
    }
}

/// A sum of squares t²·s with t the largest magnitude added (LAPACK's `dlassq` update), and
/// the number of terms.
#[derive(Debug, Clone, Copy, Default)]
struct ScaledSquares {
    top: f64,
    scaled: f64,
    count: usize,
}

impl ScaledSquares {
    fn add(&mut self, value: f64) {
        let magnitude = value.abs();
        self.count += 1;
        if magnitude == 0.0 {
            return;
        }
        if magnitude > self.top {
            self.scaled = 1.0 + self.scaled * (self.top / magnitude).powi(2);
            self.top = magnitude;
        } else {
            self.scaled += (magnitude / self.top).powi(2);
        }
    }
}

/// γ = 64·n·u, the relative rounding the model allows each assembled quantity of a mechanism
/// with n coordinates (generous: each entry sums O(n) products along root paths).
fn rounding_factor(n: usize) -> f64 {
    64.0 * n as f64 * f64::EPSILON
}

/// Per coordinate of n, its index in `free` (None for a locked one).
fn free_positions(n: usize, free: &[usize]) -> Vec<Option<usize>> {
    let mut index = vec![None; n];
    for (i, &k) in free.iter().enumerate() {
        index[k] = Some(i);
    }
    index
}

/// One contribution's U, gradient and Hessian at `config`.
fn evaluate(
    config: &Configuration<'_>,
    accumulate: impl Fn(&Configuration<'_>, &mut PotentialSum) -> Result<(), MechanismError>,
) -> Result<PotentialSum, MechanismError> {
    let mut sum = PotentialSum::new(config.dof(), true);
    accumulate(config, &mut sum)?;
    Ok(sum)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A random tree of `parents.len()` bodies (each parent an earlier body or none), with
    /// `dofs[b]` coordinates per body numbered in body order.
    fn bodies(parents: &[Option<usize>], dofs: &[usize], scale: Vec<f64>) -> BodyContributions {
        let mut own = Vec::new();
        let mut next = 0;
        for &d in dofs {
            own.push((next..next + d).collect());
            next += d;
        }
        BodyContributions {
            scale,
            order: (0..parents.len()).collect(),
            parent: parents.to_vec(),
            own,
        }
    }

    /// The same terms, one explicit support per body (its root path's coordinates).
    fn explicit(tree: &BodyContributions) -> Vec<Contribution> {
        (0..tree.scale.len())
            .map(|b| {
                let path = std::iter::successors(Some(b), |&i| tree.parent[i]);
                Contribution {
                    scale: tree.scale[b],
                    support: path.flat_map(|i| tree.own[i].iter().copied()).collect(),
                }
            })
            .collect()
    }

    proptest! {
        /// The path sums from the root give each body's Σ_{S_b} x² as the direct sum over its
        /// support does, to rounding, over random trees and shapes spread over ±150 decades.
        #[test]
        fn path_sums_match_the_direct_sum_over_each_support(
            seed in proptest::collection::vec((0.0..1.0_f64, 0usize..3, -12.0..12.0_f64), 1..40),
            shape in proptest::collection::vec((-150.0..150.0_f64, any::<bool>()), 120),
        ) {
            let parents: Vec<Option<usize>> = seed
                .iter()
                .enumerate()
                .map(|(b, &(p, _, _))| (b > 0 && p < 0.9).then(|| (p / 0.9 * b as f64) as usize))
                .collect();
            let dofs: Vec<usize> = seed.iter().map(|s| s.1).collect();
            let scale: Vec<f64> = seed.iter().map(|s| 10f64.powf(s.2)).collect();
            let tree = bodies(&parents, &dofs, scale);
            let x = |i: usize| {
                let (e, negative) = shape[i];
                if negative { -(10f64.powf(e)) } else { 10f64.powf(e) }
            };
            let by_paths = tree.share(x);
            let direct = share(&explicit(&tree), x);
            prop_assert!(direct.is_finite() == by_paths.is_finite(), "{by_paths} vs {direct}");
            prop_assert!(by_paths >= direct * (1.0 - 1e-13), "{by_paths} < {direct}");
            prop_assert!(by_paths <= direct * (1.0 + 1e-12) + f64::MIN_POSITIVE, "{by_paths} ≫ {direct}");
        }
    }

    #[test]
    fn a_body_the_mode_does_not_move_adds_nothing_even_with_an_infinite_scale() {
        let tree = bodies(&[None, None], &[1, 1], vec![f64::INFINITY, 2.0]);
        let x = |i: usize| if i == 0 { 0.0 } else { 3.0 };
        let expected = 2.0 * 3.0 * (3.0 * ((1.0 + 8.0 * f64::EPSILON) + (-1020.0_f64).exp2()));
        assert_eq!(tree.share(x), expected);
    }
}
