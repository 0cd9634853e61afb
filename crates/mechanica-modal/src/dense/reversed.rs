//! The low modes of a graded pencil by role reversal ((8.89) read backwards, see
//! docs/theory.md, "Relative accuracy of the low modes").
//!
//! The reduction C = L⁻¹BL⁻ᵀ (A = LLᵀ) gives every ω² to an absolute error of order u‖C‖, the
//! size of the largest ω²: the low modes of a pencil whose ω² span many decades come out with
//! no correct digit, their shapes mixed. The reversed pencil A x = μ (B + sA) x, μ = 1/(ω² + s),
//! reduced by the Cholesky factor R of B + sA to M = R⁻¹AR⁻ᵀ, has the low modes as its
//! *dominant* eigenvalues, each to an absolute error of order u·μ_max: mode j's ω² to about
//! u·(ω²_j + s)²·μ_max, fine where ω²_j is near the bottom. Each mode takes the side with the
//! smaller error estimate; the modes taken from the reversed side are then refined and bounded
//! like every other mode ([`crate::dense::refinement`]), so the estimate decides only where the
//! starting pairs come from, never what is reported as the error.
//!
//! The shift s is 0 when B has a Cholesky factor (B positive definite). Otherwise (rigid-body
//! modes, or an unstable pencil) s grows from the rounding level of B by factors of
//! [`SHIFT_GROWTH`] until B + sA has one, at most [`SHIFT_ATTEMPTS`] times; a pencil that never
//! admits one keeps the reduction's modes.

use crate::dense::definite::Definite;
use crate::linalg::eigen::symmetric_eigen_returning_input;
use crate::linalg::reduce::{Cholesky, back_transform, cholesky_owned, is_diagonal, lower_entry, reduce};
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatRef, Par};

/// Factor by which the shift grows between Cholesky attempts of B + sA.
const SHIFT_GROWTH: f64 = 1e3;
/// Cholesky attempts of B + sA after the unshifted one.
const SHIFT_ATTEMPTS: usize = 6;

/// The lowest modes of a pencil from its reversed form.
pub(crate) struct ReversedBottom {
    /// The ω² of the lowest modes, ascending.
    pub omega_sq: Vec<f64>,
    /// Their error estimates n·u·(ω² + s)²·μ_max (not bounds).
    pub estimates: Vec<f64>,
    /// Their shapes, A-normalised columns (n × omega_sq.len()).
    pub vectors: Mat<f64>,
}

/// The modes of (B, A) whose ω² the reversed pencil gives with a smaller error estimate than the
/// reduction's u·`forward_scale` (the largest |ω²| of the reduction): the lowest modes, up to
/// where u·(ω²_j + s)²·μ_max reaches u·forward_scale. None when B + sA has no Cholesky factor
/// for any shift tried, or when no mode gains.
pub(crate) fn reversed_bottom(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    forward_scale: f64,
    reversal: Reversal,
    par: Par,
) -> Option<ReversedBottom> {
    let attempts = match reversal {
        Reversal::Shifted => SHIFT_ATTEMPTS,
        Reversal::Unshifted => 0,
    };
    let (shift, r) = shifted_factor(a, b, attempts, par)?;
    let m = reduce(r.as_ref(), a, par);
    let (eigen, _) = symmetric_eigen_returning_input(m, true, par, None).ok()?;
    let z = eigen.vectors?;
    let mu_max = eigen.values.last().copied().filter(|&v| v > 0.0)?;
    let mut taken: Vec<usize> = Vec::new();
    for (j, &mu) in eigen.values.iter().enumerate().rev() {
        let reversed_error = mu_max / (mu * mu);
        if !(mu > 0.0 && reversed_error < forward_scale) {
            break;
        }
        taken.push(j);
    }
    if taken.is_empty() {
        return None;
    }
    let omega_sq: Vec<f64> = taken.iter().map(|&j| 1.0 / eigen.values[j] - shift).collect();
    let order = a.nrows() as f64 * f64::EPSILON;
    let estimates: Vec<f64> = taken
        .iter()
        .map(|&j| order * mu_max / (eigen.values[j] * eigen.values[j]))
        .collect();
    let mut vectors = Mat::from_fn(a.nrows(), taken.len(), |i, c| z[(i, taken[c])]);
    back_transform(r.as_ref(), vectors.as_mut(), par);
    normalise_in_a(a, &mut vectors, par);
    omega_sq.iter().all(|w| w.is_finite()).then_some(ReversedBottom {
        omega_sq,
        estimates,
        vectors,
    })
}

/// The smallest shift tried (0, then up to `attempts` growing ones) for which B + sA has a
/// Cholesky factor, with that factor.
fn shifted_factor(a: MatRef<'_, f64>, b: MatRef<'_, f64>, attempts: usize, par: Par) -> Option<(f64, Mat<f64>)> {
    let n = a.nrows();
    let diagonal_ratio = (0..n)
        .map(|i| b[(i, i)].abs() / a[(i, i)])
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    let first_shift = 16.0 * n as f64 * f64::EPSILON * diagonal_ratio;
    let mut shift = 0.0;
    for attempt in 0..=attempts {
        if attempt == 1 {
            shift = first_shift;
        } else if attempt > 1 {
            shift *= SHIFT_GROWTH;
        }
        if attempt > 0 && !(shift > 0.0 && shift.is_finite()) {
            return None;
        }
        let k = Mat::from_fn(n, n, |i, j| lower_entry(b, i, j) + shift * lower_entry(a, i, j));
        if let Cholesky::Factor(r) = cholesky_owned(k, par) {
            return Some((shift, r));
        }
    }
    None
}

/// Scales every column x to xᵀAx = 1: for a lumped (diagonal) A from its diagonal, otherwise
/// from AX formed as one matrix product (a product per column reads A from memory once per
/// column).
fn normalise_in_a(a: MatRef<'_, f64>, x: &mut Mat<f64>, par: Par) {
    let norms_sq: Vec<f64> = if is_diagonal(a) {
        (0..x.ncols())
            .map(|c| x.col(c).iter().enumerate().map(|(i, v)| a[(i, i)] * v * v).sum())
            .collect()
    } else {
        let mut ax = Mat::<f64>::zeros(a.nrows(), x.ncols());
        matmul(ax.as_mut(), Accum::Replace, a, x.as_ref(), 1.0, par);
        (0..x.ncols())
            .map(|c| x.col(c).iter().zip(ax.col(c).iter()).map(|(u, v)| u * v).sum())
            .collect()
    };
    for (c, norm_sq) in norms_sq.into_iter().enumerate() {
        if norm_sq > 0.0 && norm_sq.is_finite() {
            let s = norm_sq.sqrt().recip();
            x.col_mut(c).iter_mut().for_each(|v| *v *= s);
        }
    }
}

/// The relative error estimate u·n·max|ω²| / min|ω²| of the reduction's lowest mode from which
/// the reversed solve is used: below it, the reduction's pairs are close enough for Newton
/// refinement to start from (graded chains to ratios of 1e12 and beyond); above it, they can be
/// mixed beyond repair (random gradings).
pub(crate) const REVERSAL_FROM: f64 = 1e-4;

/// How the bottom of the reduction's spectrum calls for the reversed solve.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Reversal {
    /// The pencil is graded: a mode whose relative error estimate u·n·max|ω²| / |ω²| exceeds
    /// [`REVERSAL_FROM`] while |ω²| is above the estimate itself (visibly not zero but poorly
    /// resolved), or more modes within the estimate of zero than a free body has rigid-body
    /// modes ([`RIGID_BODY_MODES`]). Reversed with shifts as needed.
    Shifted,
    /// A few modes within the estimate of zero: the rigid-body modes of a free structure, or
    /// soft modes buried under the stiff ones' rounding. Reversed only when B itself has a
    /// Cholesky factor, which rules rigid-body modes out.
    Unshifted,
}

/// Whether (and how) the reduction's spectrum `omega_sq` calls for the reversed solve.
pub(crate) fn bottom_reversal(omega_sq: &[f64]) -> Option<Reversal> {
    let scale = omega_sq.iter().fold(0.0_f64, |m, w| m.max(w.abs()));
    let estimate = f64::EPSILON * omega_sq.len() as f64 * scale;
    let within_estimate = omega_sq.iter().filter(|w| w.abs() <= estimate).count();
    let poorly_resolved = omega_sq
        .iter()
        .any(|w| w.abs() > estimate && estimate > REVERSAL_FROM * w.abs());
    if poorly_resolved || within_estimate > RIGID_BODY_MODES {
        Some(Reversal::Shifted)
    } else if within_estimate > 0 {
        Some(Reversal::Unshifted)
    } else {
        None
    }
}

/// The rigid-body modes of one free body in space.
const RIGID_BODY_MODES: usize = 6;

/// The reversed bottom of the reduction's spectrum `omega_sq`, when it calls for one
/// ([`bottom_reversal`]) and the reversed solve succeeds.
pub(crate) fn reversed_bottom_of(
    omega_sq: &[f64],
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    par: Par,
) -> Option<ReversedBottom> {
    let reversal = bottom_reversal(omega_sq)?;
    let scale = omega_sq.iter().fold(0.0_f64, |m, w| m.max(w.abs()));
    reversed_bottom(a, b, scale, reversal, par)
}

/// Replaces the lowest modes of the reduction's spectrum `def` (values, selected shapes, and
/// the reduced eigenvectors Y = LᵀX that refinement corrects through, formed as one product) by
/// those of `bottom` ([`reversed_bottom_of`]), where that gains. Returns whether anything was
/// replaced.
pub(crate) fn adopt_reversed_bottom(def: &mut Definite, bottom: &ReversedBottom, l: MatRef<'_, f64>, par: Par) -> bool {
    let scale = def.omega_sq.iter().fold(0.0_f64, |m, w| m.max(w.abs()));
    let n = def.omega_sq.len();
    // Keep the spectrum ascending across the seam between the two sides.
    let mut m = bottom.omega_sq.len().min(n);
    while m > 0 && m < n && bottom.omega_sq[m - 1] > def.omega_sq[m] {
        m -= 1;
    }
    if m == 0 {
        return false;
    }
    let forward_estimate = f64::EPSILON * n as f64 * scale;
    let mut estimates = vec![forward_estimate; n];
    estimates[..m].copy_from_slice(&bottom.estimates[..m]);
    def.estimates = Some(estimates);
    def.omega_sq[..m].copy_from_slice(&bottom.omega_sq[..m]);
    if let Some(x) = def.vectors.as_mut() {
        for j in def.first..def.end.min(m) {
            x.col_mut(j - def.first).copy_from(bottom.vectors.col(j));
        }
    }
    if let Some(y) = def.reduced.as_mut() {
        let x = bottom.vectors.as_ref().subcols(0, m);
        let mut y = y.as_mut().subcols_mut(0, m);
        if is_diagonal(l) {
            y.copy_from(x);
            for i in 0..x.nrows() {
                y.as_mut().row_mut(i).iter_mut().for_each(|v| *v *= l[(i, i)]);
            }
        } else {
            matmul(y, Accum::Replace, l.transpose(), x, 1.0, par);
        }
    }
    true
}
