//! What refinement returns: a refined pair with its double-double residual, or a cluster of
//! pairs refined together, and the final measurement of a refined vector.

use crate::dd::Operand;
use crate::dd::{SplitVector, dot_split, pair_residual};
use crate::refine::metric::Metric;

/// A refined pair.
#[derive(Debug, Clone)]
pub(crate) struct RefinedPair {
    /// A-normalised eigenvector.
    pub x: Vec<f64>,
    /// ω² (the double-double Rayleigh quotient, rounded).
    pub omega_sq: f64,
    /// ‖(B − ω²A)x‖_{A⁻¹} / ‖x‖_A from the double-double residual; for a condensed pencil
    /// ‖s‖_{A₁⁻¹} / ‖x‖_A of its residual s (plus the rounding allowance of s).
    pub residual_a_inv: f64,
    /// The residual (B − ω²A)x from double-double, rounded to double; for a condensed pencil
    /// the residual s of (S, A₁) (`Condensation::condensed_residual`), of order n − r.
    pub residual: Vec<f64>,
    /// Newton steps taken.
    pub steps: usize,
}

/// The modes of one cluster refined together ([`refine_cluster_projected`]).
#[derive(Debug, Clone)]
pub(crate) struct RefinedCluster {
    /// The refined pairs, ascending ω², each A-normalised.
    pub pairs: Vec<RefinedPair>,
    /// max_{k≠l} |x_kᵀAx_l| of the refined vectors, in double-double (0 for a single mode).
    pub orthogonality: f64,
}

impl RefinedCluster {
    /// A cluster of one pair.
    pub(crate) fn single(pair: RefinedPair) -> Self {
        Self {
            pairs: vec![pair],
            orthogonality: 0.0,
        }
    }
}

/// A-normalises x, then its double-double Rayleigh quotient, residual and A⁻¹-norm residual;
/// the vector returned is x rounded to double.
pub(crate) fn finish_pair(
    a: &Operand<'_>,
    b: &Operand<'_>,
    metric: Metric<'_>,
    mut x: SplitVector,
    steps: usize,
) -> Option<RefinedPair> {
    let axd = a.product_split(&x);
    let xax = dot_split(&x, &axd);
    if xax.hi.is_nan() || xax.hi <= 0.0 {
        return None;
    }
    x.scale(1.0 / xax.hi.sqrt());
    let axd = a.product_split(&x);
    let bxd = b.product_split(&x);
    let xax = dot_split(&x, &axd);
    let rq = dot_split(&x, &bxd).over(xax);
    let r = pair_residual(&axd, &bxd, rq);
    let (r, norm) = metric.definite_residual(r);
    let residual_a_inv = norm / xax.to_f64().sqrt();
    let omega_sq = rq.to_f64();
    if !omega_sq.is_finite() || !residual_a_inv.is_finite() {
        return None;
    }
    Some(RefinedPair {
        x: x.hi,
        omega_sq,
        residual_a_inv,
        residual: r,
        steps,
    })
}
