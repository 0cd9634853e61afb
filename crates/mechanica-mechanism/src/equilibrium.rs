//! Equilibria: grad U*(q) = 0 (8.74) by Newton's method with a backtracking line search on
//! ‖grad U*‖, inside the joint limits.
//!
//! Newton's direction d = −B⁻¹ g is a descent direction of ½‖g‖² whenever B is nonsingular, so
//! the search finds any equilibrium (stable or not: an inverted pendulum's upright position is
//! found as readily as the hanging one). B is inverted through its eigen-decomposition with
//! the eigenvalues kept away from zero by δ = 64·n·u·‖B‖, the rounding level of B, so a
//! singular B (a neutral direction) gives a bounded step instead of a blow-up (the step is
//! also capped at `max_step`). A floor far above the rounding level crawls along soft
//! directions: a joint about a nearly vertical axis carrying an offset load (a humanoid's
//! wrist) has a curvature of 1e-9·‖B‖, and each Newton step would cover only λ/floor of the
//! way. Coordinates resting on a limit that pushes them outwards are frozen and the Newton step is taken in the others (projected Newton); trial
//! points are clipped to the limits. Spherical and free joints are re-centred
//! ([`Mechanism::rebase`]) before every Hessian, so the returned q is in the mechanism's final
//! chart.
//!
//! **Convergence criterion.** ‖g‖ ≤ τ with τ = 64·n·u·(‖B(q₀)‖_F·max(1, ‖q₀‖) + ‖g(q₀)‖) by
//! default: the size of the rounding error of g near q₀. The report gives ‖g‖ and the last
//! Newton step, an estimate of the distance to the exact equilibrium.

use crate::{Mechanism, MechanismError, PotentialSum};
use faer::{Mat, Side};

/// Which equilibria a search heads for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Seek {
    /// Any equilibrium (stable or not): Newton on grad U* = 0, line search on ‖grad U*‖.
    Stationary,
    /// A local minimum of U* (a stable equilibrium when B is definite): Newton with the
    /// Hessian's eigenvalues replaced by their absolute values (a descent direction), line
    /// search on U* with the Armijo condition. A stationary point whose Hessian (coordinates
    /// held by limits left out) has an eigenvalue below −64·n·u·‖B‖ is left along that
    /// eigenvector, backtracking until U* falls by a quarter of the quadratic model's decrease,
    /// and the search goes on (an inverted pendulum started upright falls). Where no such
    /// decrease is found above the rounding of U* and of the gradient (a saddle whose negative
    /// curvature is below what the data resolves), or at the last iteration, the stationary
    /// point is returned; its modes then show the instability.
    Minimum,
}

/// Options of [`find_equilibrium`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EquilibriumOptions {
    /// Maximum Newton iterations.
    pub max_iterations: usize,
    /// Gradient-norm tolerance τ; None derives it from rounding (see the module docs).
    pub tolerance: Option<f64>,
    /// Stationary point or minimum.
    pub seek: Seek,
    /// Largest step ‖Δq‖ (trust radius, in the units of q), which keeps a singular or
    /// indefinite Hessian from throwing the search far away.
    pub max_step: f64,
}

impl Default for EquilibriumOptions {
    fn default() -> Self {
        Self {
            max_iterations: 100,
            tolerance: None,
            seek: Seek::Stationary,
            max_step: 1.0,
        }
    }
}

/// A converged equilibrium.
#[derive(Debug, Clone, PartialEq)]
pub struct Equilibrium {
    /// The coordinates (in the mechanism's chart after re-centring).
    pub q: Vec<f64>,
    /// U* at q.
    pub potential: f64,
    /// ‖grad U*(q)‖.
    pub gradient_norm: f64,
    /// The tolerance τ used.
    pub tolerance: f64,
    /// Newton iterations.
    pub iterations: usize,
    /// ‖Δq‖ of the last step taken (Newton, or off a saddle): an estimate of the distance to the
    /// exact equilibrium.
    pub last_step: f64,
    /// Coordinates resting on a joint limit (there the gradient component is a reaction, not zero).
    pub at_limit: Vec<usize>,
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The gradient with the components pushing against an active limit removed (those are
/// carried by the limit).
fn free_gradient(g: &[f64], q: &[f64], limits: &[(f64, f64)]) -> (Vec<f64>, Vec<usize>) {
    let mut free = g.to_vec();
    let mut at_limit = Vec::new();
    for k in 0..g.len() {
        let (lo, hi) = limits[k];
        if (q[k] <= lo && g[k] > 0.0) || (q[k] >= hi && g[k] < 0.0) {
            free[k] = 0.0;
            at_limit.push(k);
        }
    }
    (free, at_limit)
}

fn clamp(q: &mut [f64], limits: &[(f64, f64)]) {
    for (x, (lo, hi)) in q.iter_mut().zip(limits) {
        *x = x.clamp(*lo, *hi);
    }
}

/// The coordinates not held by a limit (`at_limit`) among the `n` and the Hessian restricted
/// to them.
fn reduced_hessian(hessian: &Mat<f64>, n: usize, at_limit: &[usize]) -> (Vec<usize>, Mat<f64>) {
    let moving: Vec<usize> = (0..n).filter(|k| !at_limit.contains(k)).collect();
    let reduced = Mat::from_fn(moving.len(), moving.len(), |i, j| hessian[(moving[i], moving[j])]);
    (moving, reduced)
}

/// The eigen-decomposition of the symmetric `b` (at least 1 × 1), and its spectral scale
/// max |λ|.
fn spectrum(b: &Mat<f64>) -> Result<(faer::linalg::solvers::SelfAdjointEigen<f64>, f64), MechanismError> {
    let eig = b
        .self_adjoint_eigen(Side::Lower)
        .map_err(|_| MechanismError::Numerical("eigen-decomposition of the Hessian did not converge"))?;
    let scale = (0..b.nrows()).map(|i| eig.S()[i].abs()).fold(0.0, f64::max);
    Ok((eig, scale))
}

/// The regularised Newton step d = −B̃⁻¹ g (see the module docs), with |B| instead of B when
/// seeking a minimum, shortened to at most `max_step`.
fn newton_step(b: &Mat<f64>, g: &[f64], seek: Seek, max_step: f64) -> Result<Vec<f64>, MechanismError> {
    let n = g.len();
    if n == 0 {
        return Ok(Vec::new());
    }
    let (eig, scale) = spectrum(b)?;
    let (s, u) = (eig.S(), eig.U());
    let floor = rounding_level(n, scale).max(f64::MIN_POSITIVE);
    let mut d = vec![0.0; n];
    for i in 0..n {
        let coefficient: f64 = (0..n).map(|r| u[(r, i)] * g[r]).sum();
        let lambda = match seek {
            Seek::Stationary if s[i].abs() >= floor => s[i],
            Seek::Stationary => floor.copysign(s[i]),
            Seek::Minimum => s[i].abs().max(floor),
        };
        let c = -coefficient / lambda;
        for (r, x) in d.iter_mut().enumerate() {
            *x += c * u[(r, i)];
        }
    }
    let length = norm(&d);
    if length > max_step {
        for x in &mut d {
            *x *= max_step / length;
        }
    }
    Ok(d)
}

/// Finds an equilibrium of `mechanism` from `q0` (see the module docs). On failure the error
/// carries the best point found and its ‖grad U*‖.
pub fn find_equilibrium(
    mechanism: &mut Mechanism,
    q0: &[f64],
    options: &EquilibriumOptions,
) -> Result<Equilibrium, MechanismError> {
    let limits = mechanism.limits().to_vec();
    let mut q = q0.to_vec();
    check_start(mechanism.dof(), &q, options)?;
    clamp(&mut q, &limits);
    let rebase = mechanism.has_rotation_vectors();
    if rebase {
        mechanism.rebase(&mut q)?;
    }
    let start = mechanism.potential(&q, true)?;
    let tolerance = gradient_tolerance(options.tolerance, &q, &start)?;
    let mut current = start;
    let mut last_step = f64::INFINITY;
    for iteration in 0..=options.max_iterations {
        let (free, at_limit) = free_gradient(&current.gradient, &q, &limits);
        let gradient_norm = norm(&free);
        let hessian = current
            .hessian
            .as_ref()
            .ok_or(MechanismError::Numerical("Hessian missing"))?;
        let stationary = gradient_norm <= tolerance;
        // A stationary point that is not a minimum, when one is sought: leave it along the
        // Hessian's most negative curvature.
        let escape = match (stationary, options.seek) {
            (true, Seek::Minimum) if iteration < options.max_iterations => {
                negative_curvature_step(hessian, &free, &at_limit, options.max_step)?
            }
            _ => None,
        };
        let next = match &escape {
            Some(escape) => {
                let from = Stationary {
                    q: &q,
                    value: current.value,
                    tolerance,
                };
                descend_along(mechanism, &limits, &from, escape)?
            }
            None if stationary || iteration == options.max_iterations => None,
            None => {
                let direction = projected_newton_direction(hessian, &free, &at_limit, options)?;
                let from = Iterate {
                    q: &q,
                    value: current.value,
                    free: &free,
                    gradient_norm,
                };
                line_search(mechanism, &limits, options.seek, &from, &direction)?
            }
        };
        let Some(mut next) = next else {
            if stationary {
                return Ok(Equilibrium {
                    q,
                    potential: current.value,
                    gradient_norm,
                    tolerance,
                    iterations: iteration,
                    last_step: if last_step.is_finite() { last_step } else { 0.0 },
                    at_limit,
                });
            }
            break;
        };
        last_step = distance(&q, &next);
        if rebase {
            mechanism.rebase(&mut next)?;
        }
        q = next;
        current = mechanism.potential(&q, true)?;
    }
    let (free, _) = free_gradient(&current.gradient, &q, &limits);
    Err(MechanismError::NoEquilibrium {
        iterations: options.max_iterations,
        gradient_norm: norm(&free),
        tolerance,
        best_q: q,
    })
}

/// Ok when `q0` has `dof` finite entries and the maximum step is positive.
fn check_start(dof: usize, q0: &[f64], options: &EquilibriumOptions) -> Result<(), MechanismError> {
    if q0.len() != dof {
        return Err(MechanismError::WrongLength {
            what: "q0",
            expected: dof,
            got: q0.len(),
        });
    }
    crate::error::check_all_finite(q0, "q0")?;
    if options.max_step.is_nan() || options.max_step <= 0.0 {
        return Err(MechanismError::OutOfRange {
            what: "maximum equilibrium step",
            requirement: "> 0",
            value: options.max_step,
        });
    }
    Ok(())
}

/// The gradient-norm tolerance τ: the `given` one (checked finite), else the rounding-level
/// default of the module docs from the start point `q` and its potential `start`.
fn gradient_tolerance(given: Option<f64>, q: &[f64], start: &PotentialSum) -> Result<f64, MechanismError> {
    let start_hessian_norm = start.hessian.as_ref().map_or(0.0, |h| h.norm_l2());
    let n = q.len().max(1) as f64;
    Ok(match given {
        Some(t) => crate::error::check_finite(t, "equilibrium tolerance")?,
        None => {
            64.0 * n * f64::EPSILON * (start_hessian_norm * norm(q).max(1.0) + norm(&start.gradient))
                + f64::MIN_POSITIVE
        }
    })
}

/// The projected Newton direction: coordinates held by a limit (`at_limit`) are frozen, the
/// rest take the Newton step of the reduced problem on the `free` gradient.
fn projected_newton_direction(
    hessian: &Mat<f64>,
    free: &[f64],
    at_limit: &[usize],
    options: &EquilibriumOptions,
) -> Result<Vec<f64>, MechanismError> {
    let (moving, reduced) = reduced_hessian(hessian, free.len(), at_limit);
    let reduced_gradient: Vec<f64> = moving.iter().map(|&k| free[k]).collect();
    let reduced_step = newton_step(&reduced, &reduced_gradient, options.seek, options.max_step)?;
    let mut direction = vec![0.0; free.len()];
    for (&k, d) in moving.iter().zip(&reduced_step) {
        direction[k] = *d;
    }
    Ok(direction)
}

/// At a stationary point, the step of length `max_step` along the eigenvector of the reduced
/// Hessian (coordinates held by a limit frozen) with the most negative eigenvalue λ, when
/// λ < −64·n·u·‖B‖ (negative beyond the Hessian's rounding), oriented against the remaining
/// gradient `free`, and λ itself. None at a minimum (no such eigenvalue).
fn negative_curvature_step(
    hessian: &Mat<f64>,
    free: &[f64],
    at_limit: &[usize],
    max_step: f64,
) -> Result<Option<CurvatureStep>, MechanismError> {
    let (moving, reduced) = reduced_hessian(hessian, free.len(), at_limit);
    let n = moving.len();
    if n == 0 {
        return Ok(None);
    }
    let (eig, scale) = spectrum(&reduced)?;
    let (s, u) = (eig.S(), eig.U());
    let Some(lowest) = (0..n).min_by(|&i, &j| s[i].total_cmp(&s[j])) else {
        return Ok(None);
    };
    let curvature = s[lowest];
    if curvature.is_nan() || curvature >= -rounding_level(n, scale) {
        return Ok(None);
    }
    let slope: f64 = moving.iter().enumerate().map(|(i, &k)| u[(i, lowest)] * free[k]).sum();
    let sign = if slope > 0.0 { -1.0 } else { 1.0 };
    let mut direction = vec![0.0; free.len()];
    for (i, &k) in moving.iter().enumerate() {
        direction[k] = sign * max_step * u[(i, lowest)];
    }
    Ok(Some(CurvatureStep { direction, curvature }))
}

/// A step along negative curvature: its direction (length `max_step`) and the curvature λ < 0.
struct CurvatureStep {
    direction: Vec<f64>,
    curvature: f64,
}

/// The rounding level 64·n·u·s of a symmetric matrix of order n and spectral scale s.
fn rounding_level(n: usize, scale: f64) -> f64 {
    64.0 * n as f64 * f64::EPSILON * scale
}

/// A stationary point the search leaves along negative curvature.
struct Stationary<'a> {
    /// The coordinates.
    q: &'a [f64],
    /// U* at `q`.
    value: f64,
    /// The gradient tolerance τ (the rounding of grad U*).
    tolerance: f64,
}

/// Backtracking along ±`step.direction` from the stationary point `from` (at most 40 halvings
/// per sign, trial points clipped to the limits): the first trial point where U* has fallen
/// by at least a quarter of the quadratic model's ½|λ|‖Δq‖², or None when neither sign
/// achieves it before that decrease falls below what rounding explains (64u|U*| + τ‖Δq‖).
fn descend_along(
    mechanism: &Mechanism,
    limits: &[(f64, f64)],
    from: &Stationary<'_>,
    step: &CurvatureStep,
) -> Result<Option<Vec<f64>>, MechanismError> {
    for sign in [1.0, -1.0] {
        let mut alpha = 1.0;
        for _ in 0..40 {
            let mut trial: Vec<f64> = from
                .q
                .iter()
                .zip(&step.direction)
                .map(|(x, d)| x + sign * alpha * d)
                .collect();
            clamp(&mut trial, limits);
            let moved = distance(from.q, &trial);
            let predicted = 0.5 * step.curvature.abs() * moved * moved;
            if predicted <= 64.0 * f64::EPSILON * from.value.abs() + from.tolerance * moved {
                break;
            }
            if mechanism.potential(&trial, false)?.value <= from.value - 0.25 * predicted {
                return Ok(Some(trial));
            }
            alpha *= 0.5;
        }
    }
    Ok(None)
}

/// The Euclidean distance between two coordinate vectors.
fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt()
}

/// The current point of the Newton iteration, as the line search needs it.
struct Iterate<'a> {
    /// The coordinates.
    q: &'a [f64],
    /// U* at `q`.
    value: f64,
    /// The gradient at `q` without the components carried by a limit.
    free: &'a [f64],
    /// ‖`free`‖.
    gradient_norm: f64,
}

/// Backtracking along `direction` from `from` (steps 1, ½, ¼, … at most 40 halvings, trial
/// points clipped to the limits): the first trial point with a sufficient decrease of ‖grad U*‖
/// (stationary) or of U* (Armijo, minimum), or None when none is found.
fn line_search(
    mechanism: &Mechanism,
    limits: &[(f64, f64)],
    seek: Seek,
    from: &Iterate<'_>,
    direction: &[f64],
) -> Result<Option<Vec<f64>>, MechanismError> {
    let slope: f64 = from.free.iter().zip(direction).map(|(g, d)| g * d).sum();
    let mut alpha = 1.0;
    for _ in 0..40 {
        let mut trial: Vec<f64> = from.q.iter().zip(direction).map(|(x, d)| x + alpha * d).collect();
        clamp(&mut trial, limits);
        let evaluation = mechanism.potential(&trial, false)?;
        let (trial_free, _) = free_gradient(&evaluation.gradient, &trial, limits);
        let sufficient = match seek {
            Seek::Stationary => norm(&trial_free) < (1.0 - 1e-4 * alpha) * from.gradient_norm,
            Seek::Minimum => {
                evaluation.value <= from.value + 1e-4 * alpha * slope || norm(&trial_free) < 1e-3 * from.gradient_norm
            }
        };
        if sufficient {
            return Ok(Some(trial));
        }
        alpha *= 0.5;
    }
    Ok(None)
}

/// Equilibria from several starting points, duplicates (within 1e-8·(1 + ‖q‖)) removed.
/// Starts that do not converge are skipped; their count is returned alongside. Each start runs
/// on its own copy of the mechanism, so with spherical or free joints every start and result
/// is in the mechanism's current chart only before re-centring (compare body poses instead).
pub fn find_equilibria(
    mechanism: &mut Mechanism,
    starts: &[Vec<f64>],
    options: &EquilibriumOptions,
) -> Result<(Vec<Equilibrium>, usize), MechanismError> {
    let mut found: Vec<Equilibrium> = Vec::new();
    let mut failed = 0;
    for start in starts {
        let mut copy = mechanism.clone();
        match find_equilibrium(&mut copy, start, options) {
            Ok(eq) => {
                let duplicate = found.iter().any(|other| {
                    let d: f64 = other
                        .q
                        .iter()
                        .zip(&eq.q)
                        .map(|(a, b)| (a - b) * (a - b))
                        .sum::<f64>()
                        .sqrt();
                    d <= 1e-8 * (1.0 + norm(&eq.q))
                });
                if !duplicate {
                    found.push(eq);
                }
            }
            Err(MechanismError::NoEquilibrium { .. }) => failed += 1,
            Err(other) => return Err(other),
        }
    }
    Ok((found, failed))
}
