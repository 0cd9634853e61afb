//! The projected Newton step of many simple modes at once, for a positive definite A with the
//! reduced spectrum at hand: the corrections of all modes still iterating as block products.

use crate::dd::{Operand, SplitVector, dot, pair_residual};
use crate::linalg::reduce::LowerFactor;
use crate::refine::metric::Metric;
use crate::refine::pair::{RefinedPair, finish_pair};
use crate::runtime::fork_join::map_items;
use crate::tuning::Tuning;
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatRef, Par};

/// [`refine_cluster_projected`] for many simple modes at once, for a positive definite A with
/// the reduced spectrum at hand: the same projected Newton step per mode (ρ_k its Rayleigh
/// quotient, the correction L⁻ᵀ Σ_{j≠k} y_j y_jᵀ/(ω̃²_j − ρ_k) L⁻¹ r_k), but the correction of
/// all modes still iterating is applied as two triangular solves and two products with Y on a
/// block of columns. One mode at a time, each correction reads Y twice and L twice (3n²
/// numbers, memory-bound at 2n² flops per column); a block reads them once per step. The
/// double-double residuals stay per mode, on the pool's threads. Each entry is the mode's
/// refined pair, or None where the step did not contract (the caller falls back as for a
/// cluster of one). `reduced` is Y and all n eigenvalues of C; `modes[c]` is the index in
/// that spectrum of column c of `x0`.
pub(crate) fn refine_simple_modes(
    a: &Operand<'_>,
    b: &Operand<'_>,
    l: LowerFactor<'_>,
    reduced: (MatRef<'_, f64>, &[f64]),
    modes: &[usize],
    x0: MatRef<'_, f64>,
    par: Par,
) -> Vec<Option<RefinedPair>> {
    let k = x0.ncols();
    let mut x = x0.to_owned();
    let mut state = vec![State::Iterating; k];
    let mut previous = vec![f64::INFINITY; k];
    for step in 1..=Tuning::DEFAULT.max_projected_steps {
        let active: Vec<usize> = (0..k).filter(|&c| state[c] == State::Iterating).collect();
        if active.is_empty() {
            break;
        }
        // Residual r = Bx − ρAx in double-double, ρ = xᵀBx / xᵀAx, per active mode.
        let residual_of = |&c: &usize| {
            let xc = x.col_as_slice(c);
            let (ax, bx) = (a.product(xc), b.product(xc));
            let rho = dot(xc, &bx).over(dot(xc, &ax));
            (rho.to_f64(), pair_residual(&ax, &bx, rho))
        };
        let residuals: Vec<(f64, Vec<f64>)> = map_items(&active, par, residual_of);
        let delta = corrections(l, reduced, modes, &active, &residuals, par);
        for (c, &mode) in active.iter().enumerate() {
            state[mode] = take_step(
                x.col_as_slice_mut(mode),
                delta.col_as_slice(c),
                &mut previous[mode],
                step,
            );
        }
    }
    let metric = Metric::Cholesky(l);
    let converged: Vec<(usize, usize)> = (0..k)
        .filter_map(|mode| match state[mode] {
            State::Converged { steps } => Some((mode, steps)),
            State::Iterating | State::Failed => None,
        })
        .collect();
    let finished = map_items(&converged, par, |&(mode, steps)| {
        finish_pair(a, b, metric, SplitVector::of(x.col_as_slice(mode).to_vec()), steps)
    });
    let mut pairs: Vec<Option<RefinedPair>> = vec![None; k];
    for (&(mode, _), pair) in converged.iter().zip(finished) {
        pairs[mode] = pair;
    }
    pairs
}

/// Where a mode of the batch stands.
#[derive(Clone, Copy, PartialEq)]
enum State {
    Iterating,
    Converged { steps: usize },
    Failed,
}

/// The corrections L⁻ᵀ Σ_{j≠k} y_j y_jᵀ/(ω̃²_j − ρ_k) L⁻¹ r_k of the `active` modes (columns of
/// the result), from their Rayleigh quotients and residuals (ρ_k, r_k), as two triangular solves
/// and two products with Y on the block.
fn corrections(
    l: LowerFactor<'_>,
    (y, omega_all): (MatRef<'_, f64>, &[f64]),
    modes: &[usize],
    active: &[usize],
    residuals: &[(f64, Vec<f64>)],
    par: Par,
) -> Mat<f64> {
    let n = y.nrows();
    let mut w = Mat::from_fn(n, active.len(), |i, c| residuals[c].1[i]);
    l.solve(w.as_mut(), par);
    let mut coefficients = Mat::<f64>::zeros(y.ncols(), active.len());
    matmul(
        coefficients.as_mut(),
        Accum::Replace,
        y.transpose(),
        w.as_ref(),
        1.0,
        par,
    );
    for (c, &mode) in active.iter().enumerate() {
        let rho = residuals[c].0;
        let own = modes[mode];
        for j in 0..coefficients.nrows() {
            let gap = omega_all[j] - rho;
            let value = coefficients[(j, c)];
            coefficients[(j, c)] = if j == own || gap == 0.0 { 0.0 } else { value / gap };
        }
    }
    let mut delta = Mat::<f64>::zeros(n, active.len());
    matmul(delta.as_mut(), Accum::Replace, y, coefficients.as_ref(), 1.0, par);
    l.solve_transposed(delta.as_mut(), par);
    delta
}

/// One mode's step x ← x − d (the `step`-th): failed when d is not finite or neither contracts
/// (halves the `previous` step's size) nor is at rounding level; converged when it is below
/// 2u·|x| or stagnates at rounding level.
fn take_step(x: &mut [f64], d: &[f64], previous: &mut f64, step: usize) -> State {
    if !d.iter().all(|v| v.is_finite()) {
        return State::Failed;
    }
    let xmax = x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let dmax = d.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let at_rounding = dmax <= Tuning::DEFAULT.stagnation_ulps * f64::EPSILON * xmax;
    let contracting = dmax <= 0.5 * *previous;
    if !dmax.is_finite() || !(contracting || at_rounding) {
        return State::Failed;
    }
    for (xi, di) in x.iter_mut().zip(d) {
        *xi -= di;
    }
    *previous = dmax;
    if dmax <= 2.0 * f64::EPSILON * xmax || (at_rounding && !contracting) {
        State::Converged { steps: step }
    } else {
        State::Iterating
    }
}
