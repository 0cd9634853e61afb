//! How far the rounding of its assembly can move each ω² of a mechanism (docs/theory.md,
//! "Assembly error of A and B").
//!
//! B = ∂²U*/∂q∂q is a sum of contributions B_c: the field (gravity and the rotating frame's
//! −T₀) of each body, and each added potential. Each B_c is formed from rounded kinematic
//! quantities along root paths of at most n joints; its rounding is bounded by
//! ‖δB_c‖ ≤ γ‖B_c‖_F with γ = 64·n·u (generous: each entry is a sum of O(n) products), and it
//! lives on the rows and columns S_c where B_c is non-zero. To first order a perturbation δB
//! moves ω²_k by x_kᵀ δB x_k (x_k A-normalised), so
//!
//! |δω²_k| ≤ Σ_c γ ‖B_c‖_F ‖x_k|S_c‖².
//!
//! A is the sum of the bodies' A_b = m J_vᵀJ_v + J_ωᵀ I_C J_ω (J_v the Jacobian of the centre
//! of mass, J_ω the angular one), each on the coordinates of the body's root path, with
//! ‖A_b‖_F ≤ m‖J_v‖_F² + tr(I_C)‖J_ω‖_F². As ω²_k = x_kᵀBx_k / x_kᵀAx_k, a perturbation δA
//! moves ω²_k by −ω²_k x_kᵀ δA x_k, so A's share is |ω²_k| Σ_b γ‖A_b‖_F ‖x_k|S_b‖².
//!
//! A single norm ‖B‖ for the whole matrix would charge a soft mode with the rounding of a
//! stiff spring it hardly moves; per contribution, the stiff spring's share is weighted by the
//! soft mode's tiny component on the stiff coordinate.

use crate::configuration::Configuration;
use crate::{Mechanism, MechanismError, Potential, PotentialSum};
use faer::Mat;
use mechanica_kinematics::scaling;
use mechanica_mass::MassProperties;

/// Beyond this many entries (bodies × n²), the field is taken as one contribution instead of
/// one per body, so the bound never costs more than a dense solve of the same order.
const PER_BODY_BUDGET: f64 = 3e8;

/// One contribution's share: γ‖B_c‖_F and the free coordinates it touches.
#[derive(Debug, Clone)]
struct Contribution {
    scale: f64,
    support: Vec<usize>,
}

/// The assembly errors of B and A over the free coordinates, contribution by contribution.
#[derive(Debug, Clone, Default)]
pub(crate) struct AssemblyError {
    stiffness: Vec<Contribution>,
    inertia: Vec<Contribution>,
}

impl AssemblyError {
    /// The contributions of `mechanism` at q (already re-centred), restricted to `free`
    /// (indices into q).
    pub(crate) fn of(mechanism: &Mechanism, q: &[f64], free: &[usize]) -> Result<Self, MechanismError> {
        let gamma = 64.0 * mechanism.dof() as f64 * f64::EPSILON;
        let mut error = AssemblyError::default();
        let mut add = |sum: PotentialSum| {
            if let Some(h) = sum.hessian {
                error.stiffness.push(Contribution::of(&h, free, gamma));
            }
        };
        let ws = mechanism.positions(q)?;
        let bodies = mechanism.bodies();
        let field = mechanism.field();
        if mechanism.field_is_active() {
            let n = mechanism.dof() as f64;
            if bodies.len() as f64 * n * n <= PER_BODY_BUDGET {
                for b in 0..bodies.len() {
                    let alone = only_body(bodies, b);
                    let config = Configuration::new(mechanism.tree(), &ws, q, &alone)?;
                    add(evaluate(&config, |c, s| field.accumulate(c, s))?);
                }
            } else {
                let config = Configuration::new(mechanism.tree(), &ws, q, bodies)?;
                add(evaluate(&config, |c, s| field.accumulate(c, s))?);
            }
        }
        let config = Configuration::new(mechanism.tree(), &ws, q, bodies)?;
        for potential in mechanism.potentials() {
            add(evaluate(&config, |c, s| potential.accumulate(c, s))?);
        }
        for (b, body) in bodies.iter().enumerate() {
            let centre = ws.point_position(b, &body.p_oc)?;
            error
                .inertia
                .push(Contribution::of_body(&config, b, body, &centre, free, gamma));
        }
        Ok(error)
    }

    /// B's share of the bound on |δω²| for the mode shape `x` (A-normalised, free
    /// coordinates): Σ_c γ‖B_c‖_F ‖x|S_c‖². It decides the sign of ω²: A is positive definite,
    /// so only B's rounding can move ω² across zero.
    pub(crate) fn stiffness_share(&self, x: impl Fn(usize) -> f64) -> f64 {
        share(&self.stiffness, x)
    }

    /// A's share, |ω²| Σ_b γ‖A_b‖_F ‖x|S_b‖²: relative to ω², it never changes its sign.
    pub(crate) fn inertia_share(&self, omega_sq: f64, x: impl Fn(usize) -> f64) -> f64 {
        if omega_sq == 0.0 {
            return 0.0;
        }
        omega_sq.abs() * share(&self.inertia, x)
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

impl Contribution {
    /// γ times the bound m‖J_v‖_F² + tr(I_C)‖J_ω‖_F² on ‖A_b‖_F for body `b` with its centre
    /// of mass at `centre` (world), on the free coordinates of its root path.
    fn of_body(
        config: &Configuration<'_>,
        b: usize,
        body: &MassProperties,
        centre: &nalgebra::Vector3<f64>,
        free: &[usize],
        gamma: f64,
    ) -> Self {
        let tree = config.tree;
        let (mut linear, mut angular) = (0.0, 0.0);
        let mut support = Vec::new();
        for (i, &k) in free.iter().enumerate() {
            let Some(owner) = tree.dof_body(k) else { continue };
            if !tree.is_ancestor_or_self(owner, b) {
                continue;
            }
            let column = config.column(k);
            linear += (column.a + column.w.cross(centre)).norm_squared();
            angular += column.w.norm_squared();
            support.push(i);
        }
        Contribution {
            scale: gamma * (body.mass * linear + body.inertia_c.trace() * angular),
            support,
        }
    }
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

/// The bodies with every mass property but body `b`'s set to zero.
fn only_body(bodies: &[MassProperties], b: usize) -> Vec<MassProperties> {
    let nothing = MassProperties::ZERO;
    (0..bodies.len())
        .map(|i| if i == b { bodies[i] } else { nothing })
        .collect()
}
