//! Simultaneous impacts of a mechanism at several contacts, frictionless or with isotropic
//! Coulomb friction cones, in the contact space of [`crate::mechanism_contact`]:
//! u⁺ = u⁻ + W P with the Delassus matrix W = J A⁻¹ Jᵀ (7.115–7.117).
//!
//! # The model (two-phase, Poisson-type, energy-guarded)
//! Simultaneous impacts are not unique in general (the outcome depends on the unknown
//! relative timing of the contacts). This module resolves them with a two-phase model:
//!
//! 1. **Compression** (the perfectly inelastic impact): impulses P_c in the friction cones
//!    with Signorini–Coulomb complementarity at the post-compression velocity v = u⁻ + W P_c:
//!    0 ≤ p_n ⊥ v_n ≥ 0 at every contact, and |P_t| ≤ f p_n with P_t = −f p_n v_t/|v_t| when
//!    v_t ≠ 0. Every solution of these conditions dissipates energy:
//!    ΔT = P·v − ½ PᵀWP = −Σ f p_n |v_t| − ½ PᵀWP ≤ 0.
//!    Without friction this is the linear complementarity problem 0 ≤ P ⊥ W P + u⁻ ≥ 0, i.e.
//!    the minimum of the convex quadratic ½ PᵀWP + P·u⁻ over P ≥ 0; when every normal impulse
//!    comes out positive it is the bilateral KKT system of Pinocchio's `impulseDynamics`
//!    (the tests compare with it, with f = ∞ and restitution 0).
//! 2. **Restitution** (Poisson per contact): each contact receives the normal impulse
//!    e_i p_c,i on top, while friction, again complementary with the tangential velocity and
//!    bounded by f_i e_i p_c,i, acts during this phase. For frictionless contacts with one
//!    common e this gives ΔT = (1 − e²) ΔT_c ≤ 0, and for e = 1 conserves energy.
//! 3. **Energy guard**: with different coefficients at coupled contacts (or friction) Poisson's
//!    rule can gain energy. If the total ΔT would be positive, the restitution impulses are
//!    scaled by the largest s ∈ [0, 1] with ΔT(s) ≤ 0 (ΔT is quadratic in s and ΔT(0) ≤ 0);
//!    s is reported as `restitution_scale`. Energy is therefore never gained.
//!
//! The restitution *law* of each contact (Newton, Poisson, Stronge) is used only when a
//! single contact is given, which is resolved by the exact impulse process of
//! [`crate::contact_space`]. For several contacts every law is treated as Poisson's (all
//! three coincide for frictionless contacts).
//!
//! # The solver and which solution it picks
//! Both phases are solved by projected block Gauss–Seidel over the contacts in input order,
//! starting from zero impulses. The block update of contact i is exact: first the normal
//! impulse minimises ½ PᵀWP + P·u⁻ over p_n ≥ 0, then the tangential impulse minimises it
//! over the disk |P_t| ≤ f p_n (a 2-D trust-region problem solved through the eigenvalues of
//! W_tt,i); its optimality condition is exactly Coulomb's law at that contact. Sweeps stop
//! when the complementarity residual (below) is ≤ `tolerance`·max|u⁻|. Frictionless, the
//! sweep is coordinate descent on a convex quadratic and converges; with friction the
//! Coulomb problem is not convex and convergence is not guaranteed: when the sweep budget
//! runs out the result is returned with `converged = false` and its residual, and an
//! unconverged compression phase that would gain energy is scaled back like the restitution.
//! With f = +∞ a contact's tangential impulse is unbounded (it sticks whenever p_n > 0).
//!
//! When W is rank deficient (redundant contacts: duplicated points, four coplanar contacts
//! of a body, planar mechanisms) the velocities u⁺ and Δq̇ of the frictionless problem are
//! still unique, but the split of the impulse among redundant contacts is not: the model
//! returns the split the Gauss–Seidel sweep reaches from zero in input order (for two
//! identical contacts, the first takes the whole impulse). No regularisation is needed,
//! because each block update needs only W_nn,i > 0; the numerical rank of W is reported.
//!
//! # The complementarity residual
//! Per contact, in m/s, the natural-map residual of the Signorini–Coulomb conditions:
//! r_n = |min(v_n, W_nn p_n)| and r_t = L |P_t − Π(P_t − v_t/L)| with Π the projection on
//! the friction disk and L the largest eigenvalue of W_tt; both vanish exactly at a solution.
//! The report gives the largest over contacts and phases.

use crate::ImpulseError;
use crate::contact_space::{ContactMode, ImpactOptions};
use crate::error::check_finite;
use crate::mechanism::MechanismInertia;
use crate::mechanism_contact::{
    ContactSpace, ImpactModel, MechanismContact, MechanismImpact, assemble_impact, resolve_single_in_space,
};
use mechanica_kinematics::tree::{KinematicTree, Workspace};
use nalgebra::{Matrix2, Vector2};

/// Accuracy and budget of a multi-contact impact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MultiContactOptions {
    /// Relative complementarity tolerance: sweeps stop when the residual is
    /// ≤ `tolerance`·max|u⁻| (default 1e-10).
    pub tolerance: f64,
    /// Maximum Gauss–Seidel sweeps per phase (default 10 000). When it is reached the result
    /// is returned with `converged = false` and its residual.
    pub max_iterations: usize,
    /// Options of the single-contact process (used when exactly one contact is given).
    pub process: ImpactOptions,
}

impl Default for MultiContactOptions {
    fn default() -> Self {
        Self {
            tolerance: 1e-10,
            max_iterations: 10_000,
            process: ImpactOptions::default(),
        }
    }
}

/// Resolves a simultaneous impact of the mechanism `tree` at `contacts` (see the module docs
/// for the model): `ws` holds the configuration (positions updated), `inertia` its factored
/// mass matrix, `q_dot` the velocities just before. One contact is resolved by the exact
/// process of [`crate::mechanism_contact::resolve_single_contact`]; none gives a zero impact.
/// The accuracy is reported as [`MechanismImpact::complementarity_residual`] (m/s) with
/// [`MechanismImpact::converged`]; the energy never increases (see the module docs).
///
/// Errors: invalid contacts (named by [`ImpulseError::InContact`]), an approaching contact that
/// cannot move along its normal ([`ImpulseError::ContactImmovable`]), a non-positive tolerance,
/// and [`ImpulseError::Singular`] when the impulses of redundant contacts drift along the null
/// space of W.
pub fn resolve_contacts(
    tree: &KinematicTree,
    ws: &Workspace,
    inertia: &MechanismInertia,
    q_dot: &[f64],
    contacts: &[MechanismContact],
    options: &MultiContactOptions,
) -> Result<MechanismImpact, ImpulseError> {
    check_finite("tolerance", options.tolerance)?;
    if options.tolerance <= 0.0 {
        return Err(ImpulseError::Singular {
            what: "tolerance must be positive",
            value: options.tolerance,
        });
    }
    let space = ContactSpace::new(tree, ws, inertia, q_dot, contacts)?;
    match contacts.len() {
        1 => resolve_single_in_space(&space, inertia, q_dot, &contacts[0], &options.process),
        _ => simultaneous(&space, inertia, q_dot, contacts, options),
    }
}

/// Per-contact constants of the block updates.
struct Block {
    active: bool,
    friction: f64,
    restitution: f64,
    w_nn: f64,
    w_tt: Matrix2<f64>,
    /// Eigenvalues (clamped ≥ 0) and eigenvectors of W_tt, computed once.
    eig_values: Vector2<f64>,
    eig_vectors: Matrix2<f64>,
    /// Largest eigenvalue of W_tt.
    l_t: f64,
}

/// The Gauss–Seidel state: impulses and the velocity v = u⁻ + W P kept in step.
struct Sweeper<'a> {
    rows: usize,
    w: &'a [f64],
    v: Vec<f64>,
}

impl Sweeper<'_> {
    /// Adds `delta` to impulse row `r` (and the velocities it moves).
    fn push(&mut self, r: usize, delta: f64) {
        if delta != 0.0 {
            let col = &self.w[self.rows * r..self.rows * r + self.rows];
            for (v, w) in self.v.iter_mut().zip(col) {
                *v += w * delta;
            }
        }
    }

    fn v_t(&self, i: usize) -> Vector2<f64> {
        Vector2::new(self.v[3 * i], self.v[3 * i + 1])
    }
}

/// The outcome of one phase of the Gauss–Seidel solve.
struct PhaseSolution {
    /// The phase's impulses, 3 rows per contact (tangential x, y, then normal).
    impulses: Vec<f64>,
    /// Its complementarity residual, m/s (0 for a restitution phase that did not run).
    residual: f64,
    /// The sweeps it took.
    iterations: usize,
    /// Whether its residual reached the target (true for a restitution phase that did not run).
    converged: bool,
}

/// Two or more contacts: the two-phase, energy-guarded model of the module docs.
fn simultaneous(
    space: &ContactSpace,
    inertia: &MechanismInertia,
    q_dot: &[f64],
    contacts: &[MechanismContact],
    options: &MultiContactOptions,
) -> Result<MechanismImpact, ImpulseError> {
    let m = contacts.len();
    let rows = 3 * m;
    let w = space.delassus();
    let u = space.u_before();
    let blocks = contact_blocks(w, u, contacts)?;
    let speed = u.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
    let target = options.tolerance * speed;
    let mut sweeper = Sweeper { rows, w, v: u.to_vec() };
    let mut compression = compression_phase(&blocks, &mut sweeper, target, options.max_iterations);
    check_no_drift(w, rows, &compression.impulses, speed)?;
    if scale_back_energy_gain(space, u, &mut compression.impulses, &mut sweeper) {
        compression.converged = false;
    }
    let p1 = &compression.impulses;
    let restitution = restitution_phase(&blocks, p1, &mut sweeper, target, options.max_iterations);
    let p2 = &restitution.impulses;
    let scale = restitution_scale(space, u, p1, p2);
    let p: Vec<f64> = p1.iter().zip(p2).map(|(a, b)| a + scale * b).collect();
    check_no_drift(w, rows, &p, speed)?;
    let modes = contact_modes(&blocks, &p);
    let normal_compression: Vec<f64> = (0..m).map(|i| p1[3 * i + 2]).collect();
    let mut impact = assemble_impact(space, inertia, q_dot, &p, &modes, &normal_compression)?;
    impact.complementarity_residual = compression.residual.max(restitution.residual);
    impact.iterations = compression.iterations + restitution.iterations;
    impact.converged = compression.converged && restitution.converged;
    impact.restitution_scale = scale;
    impact.model = ImpactModel::Simultaneous;
    impact.check_finite()?;
    Ok(impact)
}

/// The per-contact constants of the block updates, from the Delassus matrix `w` (column-major,
/// 3 rows per contact) and the approach velocities `u`; a contact whose W_nn is not positive
/// (relative to the largest diagonal entry) is inactive, and an error when it approaches.
fn contact_blocks(w: &[f64], u: &[f64], contacts: &[MechanismContact]) -> Result<Vec<Block>, ImpulseError> {
    let rows = 3 * contacts.len();
    let max_diag = (0..rows).map(|r| w[r + rows * r]).fold(0.0, f64::max);
    let mut blocks = Vec::with_capacity(contacts.len());
    for (i, contact) in contacts.iter().enumerate() {
        let n = 3 * i + 2;
        let w_nn = w[n + rows * n];
        let u_n = u[n];
        let movable = w_nn > 1e-14 * max_diag && w_nn > 0.0;
        if !movable && u_n < 0.0 {
            return Err(ImpulseError::ContactImmovable { contact: i, w_nn, u_n });
        }
        let w_tt = Matrix2::new(
            w[3 * i + rows * 3 * i],
            w[3 * i + rows * (3 * i + 1)],
            w[3 * i + 1 + rows * 3 * i],
            w[3 * i + 1 + rows * (3 * i + 1)],
        );
        let eig = w_tt.symmetric_eigen();
        let eig_values = eig.eigenvalues.map(|l| l.max(0.0));
        blocks.push(Block {
            active: movable,
            friction: contact.law.friction,
            restitution: contact.law.restitution,
            w_nn,
            w_tt,
            eig_values,
            eig_vectors: eig.eigenvectors,
            l_t: eig_values.max(),
        });
    }
    Ok(blocks)
}

/// Phase 1, the inelastic Signorini–Coulomb problem: Gauss–Seidel sweeps from zero impulses
/// until the residual is ≤ `target` or `max_iterations` sweeps; `sweeper.v` ends at u⁻ + W P_c.
fn compression_phase(blocks: &[Block], sweeper: &mut Sweeper<'_>, target: f64, max_iterations: usize) -> PhaseSolution {
    let mut p1 = vec![0.0; sweeper.rows];
    let mut iterations = 0;
    let mut residual1 = residual(blocks, &p1, &p1, sweeper, Phase::Compression);
    while residual1 > target && iterations < max_iterations {
        iterations += 1;
        for (i, b) in blocks.iter().enumerate() {
            if !b.active {
                continue;
            }
            let n = 3 * i + 2;
            let p_new = (p1[n] - sweeper.v[n] / b.w_nn).max(0.0);
            sweeper.push(n, p_new - p1[n]);
            p1[n] = p_new;
            if b.friction > 0.0 {
                let radius = disk_radius(b.friction, p1[n]);
                tangential_update(b, i, radius, &mut p1, sweeper);
            }
        }
        residual1 = residual(blocks, &p1, &p1, sweeper, Phase::Compression);
    }
    PhaseSolution {
        impulses: p1,
        residual: residual1,
        iterations,
        converged: residual1 <= target,
    }
}

/// Energy safeguard for an unconverged compression phase (a converged one dissipates): when
/// the impulses `p1` would gain energy they are scaled down (to zero if need be) so that they
/// do not, `sweeper.v` is recomputed from u⁻, and the result is true.
fn scale_back_energy_gain(space: &ContactSpace, u: &[f64], p1: &mut [f64], sweeper: &mut Sweeper<'_>) -> bool {
    let e1 = space.energy_change(p1);
    if e1 > 0.0 {
        let a: f64 = p1.iter().zip(u).map(|(p, u)| p * u).sum();
        let c = 2.0 * (e1 - a);
        let s = if a < 0.0 && c > 0.0 {
            (-2.0 * a / c).min(1.0)
        } else {
            0.0
        };
        p1.iter_mut().for_each(|p| *p *= s);
        sweeper.v = u.to_vec();
        for (r, &value) in p1.iter().enumerate() {
            sweeper.push(r, value);
        }
        true
    } else {
        false
    }
}

/// Phase 2, Poisson restitution: normal impulses e p_c on top of the compression impulses
/// `p1`, with friction sweeps until the residual is ≤ `target` or `max_iterations` sweeps.
/// Skipped (zero impulses) when no contact has both e > 0 and a compression impulse.
fn restitution_phase(
    blocks: &[Block],
    p1: &[f64],
    sweeper: &mut Sweeper<'_>,
    target: f64,
    max_iterations: usize,
) -> PhaseSolution {
    let mut p2 = vec![0.0; sweeper.rows];
    let mut residual2 = 0.0;
    let mut iterations2 = 0;
    let mut converged = true;
    if blocks
        .iter()
        .enumerate()
        .any(|(i, b)| b.restitution > 0.0 && p1[3 * i + 2] > 0.0)
    {
        for (i, b) in blocks.iter().enumerate() {
            let n = 3 * i + 2;
            p2[n] = b.restitution * p1[n];
            sweeper.push(n, p2[n]);
        }
        residual2 = residual(blocks, p1, &p2, sweeper, Phase::Restitution);
        while residual2 > target && iterations2 < max_iterations {
            iterations2 += 1;
            for (i, b) in blocks.iter().enumerate() {
                if b.active && b.friction > 0.0 && p2[3 * i + 2] > 0.0 {
                    let radius = disk_radius(b.friction, p2[3 * i + 2]);
                    tangential_update(b, i, radius, &mut p2, sweeper);
                }
            }
            residual2 = residual(blocks, p1, &p2, sweeper, Phase::Restitution);
        }
        converged = residual2 <= target;
    }
    PhaseSolution {
        impulses: p2,
        residual: residual2,
        iterations: iterations2,
        converged,
    }
}

/// The energy guard: the largest s ∈ [0, 1] with ΔT(P₁ + s P₂) ≤ 0, 1 when the full
/// restitution impulses `p2` gain no energy.
fn restitution_scale(space: &ContactSpace, u: &[f64], p1: &[f64], p2: &[f64]) -> f64 {
    // ΔT(s) = ΔT(P₁ + s P₂) = c₀ + c₁ s + c₂ s², c₀ ≤ 0.
    let c0 = space.energy_change(p1);
    let total: Vec<f64> = p1.iter().zip(p2).map(|(a, b)| a + b).collect();
    let e_total = space.energy_change(&total);
    let mut scale = 1.0;
    if e_total > 0.0 {
        let e_p2 = space.energy_change(p2);
        // P₂·u⁻ + ½P₂ᵀWP₂ = e_p2; P₂ᵀWP₂ = 2 c₂; the cross term gives c₁.
        let p2u: f64 = p2.iter().zip(u).map(|(p, u)| p * u).sum();
        let c2 = e_p2 - p2u;
        let c1 = e_total - c0 - c2;
        scale = if c2 > 0.0 {
            let disc = (c1 * c1 - 4.0 * c2 * c0).max(0.0);
            ((-c1 + disc.sqrt()) / (2.0 * c2)).clamp(0.0, 1.0)
        } else if c1 > 0.0 {
            (-c0 / c1).clamp(0.0, 1.0)
        } else {
            1.0
        };
        // Round-off in the root can leave ΔT a few ulps above 0: step down until it is not.
        let mut trial: Vec<f64> = p1.iter().zip(p2).map(|(a, b)| a + scale * b).collect();
        let mut guard = 0;
        while space.energy_change(&trial) > 0.0 && guard < 60 {
            scale *= 1.0 - 1e-12 * 2f64.powi(guard);
            trial = p1.iter().zip(p2).map(|(a, b)| a + scale * b).collect();
            guard += 1;
        }
    }
    scale
}

/// The mode of each contact under the total impulses `p`: no impact, frictionless, stick
/// (tangential impulse inside the friction disk by a relative 1e-9) or slip.
fn contact_modes(blocks: &[Block], p: &[f64]) -> Vec<ContactMode> {
    blocks
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let pn = p[3 * i + 2];
            let pt = Vector2::new(p[3 * i], p[3 * i + 1]).norm();
            if pn <= 0.0 {
                ContactMode::NoImpact
            } else if b.friction == 0.0 {
                ContactMode::Frictionless
            } else if b.friction.is_infinite() || pt < b.friction * pn * (1.0 - 1e-9) {
                ContactMode::Stick
            } else {
                ContactMode::Slip
            }
        })
        .collect()
}

/// Redundant contacts (more impulse rows than the mechanism has freedoms) make W singular, and
/// frictional Gauss–Seidel sweeps can then let the impulses grow along W's null space, where
/// they cancel in their effect. Once an impulse's own velocity effect |P_r|·W_rr exceeds
/// `DRIFT_LIMIT` times the largest approach speed, the rounding of the cancelling terms
/// (u·|P_r|·W_rr) exceeds the complementarity tolerance and the energy bookkeeping is
/// meaningless (the reported ΔT and the actual change of T can then differ by tens of orders
/// of magnitude), so the solve stops with a typed error instead of returning such velocities.
const DRIFT_LIMIT: f64 = 1e6;

fn check_no_drift(w: &[f64], rows: usize, p: &[f64], speed: f64) -> Result<(), ImpulseError> {
    let effect = (0..rows).map(|r| p[r].abs() * w[r + rows * r]).fold(0.0_f64, f64::max);
    if effect.is_nan() || effect > DRIFT_LIMIT * speed {
        return Err(ImpulseError::Singular {
            what: "simultaneous impact: the impulses drift along the null space of the Delassus matrix (redundant contacts); their velocity effect over the approach speed is",
            value: if speed > 0.0 { effect / speed } else { f64::INFINITY },
        });
    }
    Ok(())
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Phase {
    Compression,
    Restitution,
}

/// The friction disk radius f p_n (0 when p_n = 0, also for f = +∞).
fn disk_radius(friction: f64, normal_impulse: f64) -> f64 {
    if normal_impulse > 0.0 {
        friction * normal_impulse
    } else {
        0.0
    }
}

/// Exact block update of the tangential impulse of contact `i` within the disk `radius`
/// (friction f p_n, +∞ for f = ∞): minimises ½ PᵀWP + P·u⁻ over that block.
fn tangential_update(b: &Block, i: usize, radius: f64, p: &mut [f64], sweeper: &mut Sweeper<'_>) {
    if b.l_t <= 0.0 {
        return;
    }
    let pt = Vector2::new(p[3 * i], p[3 * i + 1]);
    let c = sweeper.v_t(i) - b.w_tt * pt;
    let x = disk_minimizer(&b.eig_values, &b.eig_vectors, &c, radius);
    sweeper.push(3 * i, x.x - pt.x);
    sweeper.push(3 * i + 1, x.y - pt.y);
    p[3 * i] = x.x;
    p[3 * i + 1] = x.y;
}

/// The complementarity residual (m/s) of the current phase, see the module docs.
fn residual(blocks: &[Block], p1: &[f64], p: &[f64], sweeper: &Sweeper<'_>, phase: Phase) -> f64 {
    let mut worst = 0.0_f64;
    for (i, b) in blocks.iter().enumerate() {
        if !b.active {
            continue;
        }
        let n = 3 * i + 2;
        let r_n = match phase {
            Phase::Compression => sweeper.v[n].min(b.w_nn * p1[n]).abs(),
            Phase::Restitution => 0.0,
        };
        let r_t = if b.friction > 0.0 && b.l_t > 0.0 {
            let pt = Vector2::new(p[3 * i], p[3 * i + 1]);
            let radius = disk_radius(b.friction, p[n]);
            let y = pt - sweeper.v_t(i) / b.l_t;
            let norm = y.norm();
            let projected = if norm > radius { y * (radius / norm) } else { y };
            (pt - projected).norm() * b.l_t
        } else {
            0.0
        };
        worst = worst.max(r_n.hypot(r_t));
    }
    worst
}

/// Minimises ½ xᵀ W x + cᵀ x over the disk |x| ≤ r (W = V diag(λ) Vᵀ symmetric PSD 2×2 given
/// by its clamped eigenvalues `lam` and eigenvectors `v`; r may be +∞).
/// Inside: x = −W⁺c; on the boundary x = −(W + μI)⁻¹ c with μ > 0 from the secular equation
/// |x(μ)| = r (monotone; safeguarded Newton on 1/|x| − 1/r, as in Moré–Sorensen).
fn disk_minimizer(lam: &Vector2<f64>, v: &Matrix2<f64>, c: &Vector2<f64>, r: f64) -> Vector2<f64> {
    if r <= 0.0 {
        return Vector2::zeros();
    }
    let cp = v.transpose() * c;
    let lam_max = lam.max();
    let zero = 1e-12 * lam_max;
    let mut interior = Vector2::zeros();
    let mut unbounded = false;
    for k in 0..2 {
        if lam[k] > zero {
            interior[k] = -cp[k] / lam[k];
        } else if cp[k] != 0.0 {
            unbounded = true;
        }
    }
    // With f = ∞ the disk is the plane: the min-norm unconstrained minimiser (a slip along a
    // direction the mechanism cannot change is left as it is).
    if (!unbounded && interior.norm() <= r) || r.is_infinite() {
        return v * interior;
    }
    let norm_at = |mu: f64| (cp.x / (lam.x + mu)).hypot(cp.y / (lam.y + mu));
    let (mut lo, mut hi) = (0.0_f64, cp.norm() / r);
    let mut mu = 0.5 * hi;
    for _ in 0..200 {
        let s = norm_at(mu);
        let psi = 1.0 / s - 1.0 / r;
        if psi < 0.0 {
            lo = mu;
        } else {
            hi = mu;
        }
        if psi.abs() * r <= 4.0 * f64::EPSILON || hi - lo <= 4.0 * f64::EPSILON * hi {
            break;
        }
        let d3 = cp.x * cp.x / (lam.x + mu).powi(3) + cp.y * cp.y / (lam.y + mu).powi(3);
        let dpsi = d3 / (s * s * s);
        let next = mu - psi / dpsi;
        mu = if next > lo && next < hi && dpsi.is_finite() {
            next
        } else {
            0.5 * (lo + hi)
        };
    }
    let x = Vector2::new(-cp.x / (lam.x + mu), -cp.y / (lam.y + mu));
    let norm = x.norm();
    // Put the result exactly on the disk (the secular root is accurate to a few ulps).
    let x = if norm > 0.0 { x * (r / norm) } else { x };
    v * x
}

#[cfg(test)]
mod tests {
    use super::*;

    fn minimise(w: &Matrix2<f64>, c: &Vector2<f64>, r: f64) -> Vector2<f64> {
        let eig = w.symmetric_eigen();
        disk_minimizer(&eig.eigenvalues.map(|l| l.max(0.0)), &eig.eigenvectors, c, r)
    }

    #[test]
    fn disk_minimizer_interior_and_boundary() {
        let w = Matrix2::new(2.0, 0.5, 0.5, 1.0);
        let c = Vector2::new(-1.0, 0.3);
        // Interior: the unconstrained minimiser −W⁻¹c.
        let x = minimise(&w, &c, 10.0);
        let exact = -w.try_inverse().expect("invertible") * c;
        assert!((x - exact).norm() <= 1e-14);
        // Boundary: KKT W x + c = −μ x with μ ≥ 0 and |x| = r.
        let r = 0.1;
        let x = minimise(&w, &c, r);
        assert!((x.norm() - r).abs() <= 1e-15);
        let g = w * x + c;
        let cross = g.x * x.y - g.y * x.x;
        assert!(
            cross.abs() <= 1e-14 * g.norm() * r,
            "gradient not parallel to x: {cross}"
        );
        assert!(g.dot(&x) <= 0.0);
    }

    #[test]
    fn disk_minimizer_semidefinite() {
        // W = diag(1, 0) with a linear term along the null direction: the minimum is on the
        // boundary and the whole disk is used.
        let w = Matrix2::new(1.0, 0.0, 0.0, 0.0);
        let x = minimise(&w, &Vector2::new(0.0, 1.0), 0.5);
        assert!((x - Vector2::new(0.0, -0.5)).norm() <= 1e-12, "{x}");
        // No linear term along the null direction: the interior min-norm solution.
        let x = minimise(&w, &Vector2::new(-0.2, 0.0), 0.5);
        assert!((x - Vector2::new(0.2, 0.0)).norm() <= 1e-15, "{x}");
    }
}
