//! Projected Newton steps: the correction through the reduction's computed decomposition
//! ([`crate::refine::correction`]) in place of a factorization, for one mode or, in block form,
//! for a cluster of nearly equal eigenvalues.

use crate::dd::{Dd, Operand, SplitVector, dot, dot_split, pair_residual};
use crate::refine::correction::ReducedCorrection;
use crate::refine::metric::Metric;
use crate::refine::pair::{RefinedCluster, RefinedPair, finish_pair};
use crate::tuning::Tuning;
use faer::linalg::triangular_solve::{solve_lower_triangular_in_place, solve_upper_triangular_in_place};
use faer::{Mat, MatRef, Par, Side};

/// Refines the simple pair (ω²_i, x₀): [`refine_cluster_projected`] for one mode.
#[cfg(test)]
pub(crate) fn refine_pair_projected(
    a: &Operand<'_>,
    b: &Operand<'_>,
    metric: Metric<'_>,
    correction: &mut dyn ReducedCorrection,
    x0: &[f64],
) -> Option<RefinedPair> {
    let x0 = MatRef::from_column_major_slice(x0, x0.len(), 1);
    refine_cluster_projected(a, b, metric, correction, x0).and_then(|c| c.pairs.into_iter().next())
}

/// Refines a cluster G of p modes with nearly equal ω² (p = 1: a simple pair), starting from
/// their computed vectors X₀ (n × p, A-orthonormal to working precision), by block
/// Rayleigh-quotient steps with a projected correction: the p × p Rayleigh-quotient matrix
/// M = (XᵀAX)⁻¹XᵀBX and R = BX − AXM in double-double, ρ = trace M / p, then
/// X ← X − L⁻ᵀ K L⁻¹ R with K the [`ReducedCorrection`], Σ_{j∉G} y_j y_jᵀ/(ω̃²_j − ρ).
///
/// For p = 1 this is the Newton step of [`refine_pair`] with the bordered Jacobian replaced by
/// the reduction's computed decomposition, which has a backward error of the same order as an
/// LBLᵀ factorization of B − ρA when the reduction is accurate. For p > 1 it is the block
/// (subspace) form of that step, which needs no single vector of the cluster to be well
/// defined: X converges to the invariant subspace, and a final Rayleigh–Ritz step on (XᵀBX,
/// XᵀAX) gives the A-orthonormal pairs. It converges linearly with the ratio of the cluster's
/// spread and the decomposition's error to the gap to the other modes. None when a step above
/// rounding level fails to halve the correction (graded problems where the computed spectrum is
/// too far from the exact one, or a cluster that is not separated from the rest): for p = 1 the
/// caller then falls back to [`refine_pair`].
pub(crate) fn refine_cluster_projected(
    a: &Operand<'_>,
    b: &Operand<'_>,
    metric: Metric<'_>,
    correction: &mut dyn ReducedCorrection,
    x0: MatRef<'_, f64>,
) -> Option<RefinedCluster> {
    let (n, p) = (x0.nrows(), x0.ncols());
    if p == 0 {
        return None;
    }
    let mut x = x0.to_owned();
    let mut previous = f64::INFINITY;
    for step in 1..=Tuning::DEFAULT.max_projected_steps {
        let ax: Vec<Vec<Dd>> = (0..p).map(|k| a.product(x.col_as_slice(k))).collect();
        let bx: Vec<Vec<Dd>> = (0..p).map(|k| b.product(x.col_as_slice(k))).collect();
        let m = rayleigh_quotient_matrix(&x, &ax, &bx)?;
        let rho = (0..p).fold(Dd::of(0.0), |t, k| t.plus(m[k][k])).to_f64() / p as f64;
        let w = Mat::from_fn(n, p, |i, k| {
            (0..p).fold(bx[k][i], |r, j| r.minus(m[j][k].times(ax[j][i]))).to_f64()
        });
        let delta = metric.correction(w, rho, correction);
        // f64::max ignores NaN, so a failed correction is caught here, not by dmax.
        if !delta.col_iter().all(|c| c.iter().all(|v| v.is_finite())) {
            return None;
        }
        let xmax = x.col_iter().flat_map(|c| c.iter()).fold(0.0_f64, |m, v| m.max(v.abs()));
        let dmax = delta
            .col_iter()
            .flat_map(|c| c.iter())
            .fold(0.0_f64, |m, v| m.max(v.abs()));
        let at_rounding = dmax <= Tuning::DEFAULT.stagnation_ulps * f64::EPSILON * xmax;
        let contracting = dmax <= 0.5 * previous;
        if !dmax.is_finite() || !(contracting || at_rounding) {
            return None;
        }
        for k in 0..p {
            for (xi, di) in x.col_as_slice_mut(k).iter_mut().zip(delta.col_as_slice(k)) {
                *xi -= di;
            }
        }
        if dmax <= 2.0 * f64::EPSILON * xmax || (at_rounding && !contracting) {
            return finish_cluster(a, b, metric, x, step);
        }
        previous = dmax;
    }
    None
}

/// More projected Newton steps ([`refine_cluster_projected`] for one mode) on a refined simple
/// mode, with the iterate in double-double ([`SplitVector`]): where rounding a double vector
/// limits the residual (k·u·|x| at a stiff spring of a graded pencil), the steps go on while
/// they halve, to about u² of the iterate. A step that does not halve is not taken. `steps` is
/// what the mode took before; None if no step was taken or one was not finite.
pub(crate) fn polish_simple_mode(
    a: &Operand<'_>,
    b: &Operand<'_>,
    metric: Metric<'_>,
    correction: &mut dyn ReducedCorrection,
    x0: &[f64],
    steps: usize,
) -> Option<RefinedPair> {
    let n = x0.len();
    let mut x = SplitVector::of(x0.to_vec());
    let mut previous = f64::INFINITY;
    let mut taken = 0;
    for _ in 0..Tuning::DEFAULT.max_projected_steps {
        let ax = a.product_split(&x);
        let bx = b.product_split(&x);
        let rho = dot_split(&x, &bx).over(dot_split(&x, &ax));
        let r = pair_residual(&ax, &bx, rho);
        let w = Mat::from_fn(n, 1, |i, _| r[i]);
        let delta = metric.correction(w, rho.to_f64(), correction);
        let step: Vec<f64> = delta.col(0).iter().map(|d| -d).collect();
        if !step.iter().all(|v| v.is_finite()) {
            return None;
        }
        let xmax = x.hi.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let dmax = step.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        if dmax > 0.5 * previous {
            break;
        }
        x.add(&step);
        taken += 1;
        if dmax <= 4.0 * f64::EPSILON * f64::EPSILON * xmax {
            break;
        }
        previous = dmax;
    }
    if taken == 0 {
        return None;
    }
    finish_pair(a, b, metric, x, steps + taken)
}

/// M = (XᵀAX)⁻¹ XᵀBX in double-double from the double-double products AX and BX (one vector
/// per column), by Gaussian elimination on the Gram matrix XᵀAX (symmetric positive definite
/// and close to I for an A-orthonormal X, so no pivoting); None if a pivot is not positive.
fn rayleigh_quotient_matrix(x: &Mat<f64>, ax: &[Vec<Dd>], bx: &[Vec<Dd>]) -> Option<Vec<Vec<Dd>>> {
    let p = ax.len();
    let mut gram: Vec<Vec<Dd>> = (0..p)
        .map(|k| (0..p).map(|j| dot(x.col_as_slice(k), &ax[j])).collect())
        .collect();
    let mut m: Vec<Vec<Dd>> = (0..p)
        .map(|k| (0..p).map(|j| dot(x.col_as_slice(k), &bx[j])).collect())
        .collect();
    for k in 0..p {
        let pivot = gram[k][k];
        if pivot.hi.is_nan() || pivot.hi <= 0.0 {
            return None;
        }
        for i in k + 1..p {
            let factor = gram[i][k].over(pivot);
            for j in k..p {
                gram[i][j] = gram[i][j].minus(factor.times(gram[k][j]));
            }
            for j in 0..p {
                m[i][j] = m[i][j].minus(factor.times(m[k][j]));
            }
        }
    }
    for k in (0..p).rev() {
        for j in 0..p {
            let mut v = m[k][j];
            for i in k + 1..p {
                v = v.minus(gram[k][i].times(m[i][j]));
            }
            m[k][j] = v.over(gram[k][k]);
        }
    }
    Some(m)
}

/// Rayleigh–Ritz on the converged cluster (p > 1): the A-orthonormal Ritz vectors of
/// (XᵀBX, XᵀAX) in ascending order, each finished by [`finish_pair`], and their mutual
/// A-orthogonality in double-double.
fn finish_cluster(
    a: &Operand<'_>,
    b: &Operand<'_>,
    metric: Metric<'_>,
    x: Mat<f64>,
    steps: usize,
) -> Option<RefinedCluster> {
    let p = x.ncols();
    if p == 1 {
        return finish_pair(a, b, metric, SplitVector::of(x.col_as_slice(0).to_vec()), steps)
            .map(RefinedCluster::single);
    }
    let ax: Vec<Vec<Dd>> = (0..p).map(|k| a.product(x.col_as_slice(k))).collect();
    let bx: Vec<Vec<Dd>> = (0..p).map(|k| b.product(x.col_as_slice(k))).collect();
    let symmetric = |products: &[Vec<Dd>], i: usize, j: usize| {
        let upper = dot(x.col_as_slice(i), &products[j]).to_f64();
        let lower = dot(x.col_as_slice(j), &products[i]).to_f64();
        0.5 * (upper + lower)
    };
    let gram = Mat::from_fn(p, p, |i, j| symmetric(&ax, i, j));
    let projected = Mat::from_fn(p, p, |i, j| symmetric(&bx, i, j));
    let factor = gram.llt(Side::Lower).ok()?;
    let lg = factor.L();
    let mut c = projected;
    solve_lower_triangular_in_place(lg, c.as_mut(), Par::Seq);
    solve_lower_triangular_in_place(lg, c.as_mut().transpose_mut(), Par::Seq);
    let eigen = c.self_adjoint_eigen(Side::Lower).ok()?;
    let mut v = eigen.U().to_owned();
    solve_upper_triangular_in_place(lg.transpose(), v.as_mut(), Par::Seq);
    let rotated = &x * &v;
    let pairs: Vec<RefinedPair> = (0..p)
        .map(|k| finish_pair(a, b, metric, SplitVector::of(rotated.col_as_slice(k).to_vec()), steps))
        .collect::<Option<_>>()?;
    let mut orthogonality = 0.0_f64;
    for k in 0..p {
        let axk = a.product(&pairs[k].x);
        for j in 0..k {
            orthogonality = orthogonality.max(dot(&pairs[j].x, &axk).to_f64().abs());
        }
    }
    Some(RefinedCluster { pairs, orthogonality })
}
