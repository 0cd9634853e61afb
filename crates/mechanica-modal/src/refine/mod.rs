//! Refinement of one simple eigenpair, or of one cluster of nearly equal eigenvalues, of
//! det(λA + B) = 0 with extended-precision residuals, for stiff and graded problems where the
//! Cholesky reduction is accurate only relative to the largest eigenvalue.
//!
//! Method (Dongarra, Moler & Wilkinson, "Improving the accuracy of computed eigenvalues and
//! eigenvectors", SIAM J. Numer. Anal. 20, 1983, adapted to the symmetric pencil): Newton's
//! method on F(x, ω²) = (B − ω²A)x = 0 with the normalisation (Ax₀)ᵀx = 1, the Jacobian frozen
//! at the starting pair and factored once, in double precision, as the symmetric bordered matrix
//! [[B − ω₀²A, −Ax₀], [−(Ax₀)ᵀ, 0]] (Bunch–Kaufman LBLᵀ). The residual (B − ω²A)x and the
//! Rayleigh quotient are computed in double-double, so the iteration converges to the pair of
//! the pencil as stored, to working precision, as long as the double-precision solve has a
//! relative accuracy below 1 (true for stiffness ratios far beyond 1e12). Its cost is one
//! (n+1)³/3 factorization plus a few O(n²) double-double residuals per refined mode. When A and
//! B both have few nonzeros (a banded or assembled pencil stored densely), K = B − ω₀²A is
//! factored by a sparse LU with partial pivoting instead, its pattern analysed once for all
//! modes ([`SparseShifts`]), and the border is eliminated by blocks ([`refine_pair_sparse`]):
//! each simple mode then costs O(nnz(L + U)) per step instead of the batch's 4n² products
//! through the reduced eigenvectors.
//!
//! It is chosen by [`crate::Refinement::Auto`] for every selected simple mode whose first-order
//! bound from the reduction exceeds 1e-8·|ω²| (fewer than 8 guaranteed digits). Modes whose
//! bound intervals overlap (a repeated frequency of a symmetric structure, or eigenvalues too
//! close to tell apart) are refined together as one block by [`refine_cluster_projected`]: the
//! block's invariant subspace is well defined where its single vectors are not.
//!
//! A condensed pencil (massless coordinates of a diagonal A, condensed by the dense solve) is
//! refined the same way in the original coordinates; its residuals are mapped exactly to
//! residuals of the condensed pencil (S, A₁) ([`Condensation`]) and its corrections go through
//! the condensed spectrum ([`Metric`]).
//!
//! Files: what refinement returns (`pair`), the definite pencil it works in (`metric`,
//! `condensed`), the corrections through the reduced spectrum (`correction`), the bordered
//! Newton steps (`bordered`), the projected steps for one mode or a cluster (`projected`) and
//! for many simple modes at once (`batch`); [`refine_cluster`] here chooses among them.

mod batch;
mod bordered;
mod condensed;
mod correction;
mod forest_factor;
mod metric;
mod pair;
mod projected;
#[cfg(test)]
mod tests;

pub(crate) use batch::refine_simple_modes;
pub(crate) use bordered::SparseShifts;
pub(crate) use condensed::{Blocks, Condensation};
pub(crate) use correction::{ReducedCorrection, ReducedSpectrum, TridiagonalCorrection};
pub(crate) use metric::Metric;
pub(crate) use pair::{RefinedCluster, RefinedPair};
pub(crate) use projected::polish_simple_mode;

use crate::dd::{Operand, dot};
use crate::refine::bordered::{refine_pair, refine_pair_sparse};
use crate::refine::projected::refine_cluster_projected;
use faer::MatRef;

/// A sparse pencil's (`shifts`) single mode by [`refine_pair_sparse`] first, and a cluster's
/// members one by one ([`refine_members`]); then
/// [`refine_cluster_projected`] through `correction` when there is one, and for a single mode
/// the dense bordered Newton step of [`refine_pair`] where that declines (the bordered step
/// needs a simple eigenvalue; a dense pencil's cluster whose block refinement fails tries its
/// members one by one on dense factorizations, (n + 1)³/3 each).
pub(crate) fn refine_cluster(
    a: &Operand<'_>,
    b: &Operand<'_>,
    shifts: Option<&SparseShifts>,
    metric: Metric<'_>,
    correction: Option<&mut dyn ReducedCorrection>,
    x0: MatRef<'_, f64>,
    omega0: f64,
) -> Option<RefinedCluster> {
    let single = (x0.ncols() == 1).then(|| x0.col(0).iter().copied().collect::<Vec<f64>>());
    let sparse = match (&single, shifts) {
        (Some(x), Some(shifts)) => refine_pair_sparse(a, b, shifts, metric, x, omega0).map(RefinedCluster::single),
        (None, Some(_)) => refine_members(a, b, shifts, metric, x0),
        (_, None) => None,
    };
    sparse
        .or_else(|| correction.and_then(|c| refine_cluster_projected(a, b, metric, c, x0)))
        .or_else(|| match (single, shifts) {
            (Some(x), _) => refine_pair(a, b, metric, &x, omega0).map(RefinedCluster::single),
            (None, None) => refine_members(a, b, None, metric, x0),
            (None, Some(_)) => None,
        })
}

/// The members of a cluster refined one by one by bordered Newton steps (each from its own
/// start vector and Rayleigh quotient; on a sparse LU with `shifts`, [`refine_pair_sparse`],
/// else the dense LBLᵀ of [`refine_pair`]): modes whose first-order bounds overlap but whose
/// eigenvalues are simple (in a graded chain the unrefined bounds are wide). Accepted only when
/// the refined intervals ω²_k ± (‖r_k‖_{A⁻¹} + u|ω²_k|) are separated (the clusters of
/// `solve::clusters`, ascending, all single) and the vectors A-orthogonal to √u: each member
/// is then a simple eigenvalue of its own. None otherwise (a repeated eigenvalue, or two
/// members that converged to the same pair).
fn refine_members(
    a: &Operand<'_>,
    b: &Operand<'_>,
    shifts: Option<&SparseShifts>,
    metric: Metric<'_>,
    x0: MatRef<'_, f64>,
) -> Option<RefinedCluster> {
    let mut pairs = Vec::with_capacity(x0.ncols());
    for k in 0..x0.ncols() {
        let x: Vec<f64> = x0.col(k).iter().copied().collect();
        let rayleigh = dot(&x, &b.product(&x)).over(dot(&x, &a.product(&x))).to_f64();
        let pair = match shifts {
            Some(shifts) => refine_pair_sparse(a, b, shifts, metric, &x, rayleigh),
            None => refine_pair(a, b, metric, &x, rayleigh),
        };
        pairs.push(pair?);
    }
    let omega: Vec<f64> = pairs.iter().map(|p| p.omega_sq).collect();
    let reach: Vec<f64> = pairs
        .iter()
        .map(|p| p.residual_a_inv + f64::EPSILON * p.omega_sq.abs())
        .collect();
    let ascending = omega.windows(2).all(|w| w[0] < w[1]);
    if !ascending || crate::spectrum::clusters(&omega, &reach).len() != pairs.len() {
        return None;
    }
    let mut orthogonality = 0.0_f64;
    for (k, pk) in pairs.iter().enumerate() {
        let apk = a.product(&pk.x);
        for pl in &pairs[..k] {
            orthogonality = orthogonality.max(dot(&pl.x, &apk).to_f64().abs());
        }
    }
    (orthogonality <= f64::EPSILON.sqrt()).then_some(RefinedCluster { pairs, orthogonality })
}
