//! Values-only solves that still certify every mode: the modes whose a-priori bound is too weak
//! get their eigenvectors formed (and no others), so their bounds can be measured and, where
//! still too weak, refined.
//!
//! Without vectors a dense solve can only bound an eigenvalue a priori, by an assumed backward
//! error of n·u: n·u·(‖B‖ + |ω²|‖A‖)·‖A⁻¹‖ (`crate::certify::a_priori::APrioriModel`), which
//! relative to a small |ω²| is weak (the lowest modes of a long chain, stiff problems). For each
//! mode above [`crate::dense::AUTO_REFINE_RELATIVE_BOUND`]·|ω²|:
//!
//! 1. its eigenvector z of the tridiagonal form T of C = L⁻¹BL⁻ᵀ is computed by inverse iteration
//!    ([`crate::linalg::eigen::inverse_iteration`], O(n) per mode), and x = L⁻ᵀQz (O(n²));
//! 2. its backward error is measured and the bound becomes the first-order η·κ
//!    ([`crate::BoundKind::FirstOrder`]); the measured η is usually far below n·u;
//! 3. a mode still above the threshold (stiff and graded problems) is refined as in an
//!    all-pairs solve ([`crate::refine`]; a cluster of nearly equal values as one block), with
//!    the correction applied through Q and T instead of the eigenvectors Y, which a
//!    values-only solve does not have, and gets a residual bound
//!    ([`crate::BoundKind::Residual`]).
//!
//! The cost is O(n²) per flagged mode, against the n³ of the vectors that a full solve forms;
//! beyond [`crate::Tuning::flagged_vectors_up_to`] (or n/4) flagged modes the solve forms all
//! vectors instead.

use crate::certify::a_priori::APrioriModel;
use crate::certify::products::{PairProducts, Residuals};
use crate::certify::report::{AccuracyReport, BoundKind};
use crate::certify::residual_bounds::{ModeBasis, RefinedResidual, residual_bounds};
use crate::certify::resolution::{extended_roundings, zero_resolution};
use crate::dd::Operand;
use crate::dense::options::weakly_bounded;
use crate::linalg::eigen::TridiagonalForm;
use crate::linalg::reduce::{LowerFactor, back_transform};
use crate::refine::{Metric, SparseShifts, TridiagonalCorrection, refine_cluster};
use crate::spectrum::{clusters, refinable};
use faer::{Mat, MatRef, Par};

/// The pencil and its factor, as the refinement needs them.
pub(crate) struct Pencil<'a> {
    pub a: MatRef<'a, f64>,
    pub b: MatRef<'a, f64>,
    /// Cholesky factor of A.
    pub l: MatRef<'a, f64>,
    /// How the flagged modes' residuals are measured (the solve's [`Residuals`] option).
    pub residuals: Residuals,
    pub par: Par,
}

/// Sharpens the a-priori `report` (from the model `a_priori`) of the selected values `omega`
/// (entries `first..` of the ascending spectrum `omega_all`, the eigenvalues of `form`'s T):
/// measured first-order bounds for the flagged modes, refinement and residual bounds for those
/// still flagged. `omega` is updated where refinement moved a value. When inverse iteration fails,
/// the report keeps its a-priori bounds. Returns the data resolution
/// ([`crate::certify::resolution::zero_resolution`]) of every mode whose vector was formed, for the
/// zero classification.
pub(crate) fn sharpen(
    pencil: &Pencil<'_>,
    a_priori: APrioriModel,
    form: &mut TridiagonalForm,
    report: &mut AccuracyReport,
    omega: &mut [f64],
    omega_all: &[f64],
    first: usize,
) -> Vec<(usize, f64)> {
    let flagged: Vec<usize> = (0..omega.len())
        .filter(|&i| weakly_bounded(report.error_bounds[i], omega[i]))
        .collect();
    if flagged.is_empty() {
        return Vec::new();
    }
    let prior: Vec<(f64, f64)> = (0..omega.len()).map(|i| (omega[i], report.error_bounds[i])).collect();
    let values: Vec<f64> = flagged.iter().map(|&i| omega_all[first + i]).collect();
    let Ok((mut x, z)) = form.eigenvectors(&values) else {
        return Vec::new();
    };
    back_transform(pencil.l, x.as_mut(), pencil.par);
    let (a, b) = (pencil.a, pencil.b);
    let mut products = PairProducts::new(a, b, x.as_ref(), pencil.residuals, None, pencil.par);
    for (col, &i) in flagged.iter().enumerate() {
        let (eta, bound) = products.pair_error(x.as_ref(), col, omega[i], report.norm_a, report.norm_b);
        report.error_bounds[i] = bound;
        report.bound_kinds[i] = BoundKind::FirstOrder;
        report.backward_errors[i] = Some(eta);
        // The same rounding allowance as the pairs of a solve with vectors.
        report.error_bounds[i] = report.bound_with_rounding(i, x.nrows());
    }
    if let PairProducts::Sketched { .. } = products {
        report.residuals = Residuals::Sketched;
    }
    // Clusters for the correction: T's eigenvalues and inverse-iteration vectors are only as
    // accurate as the a-priori model, so modes closer than that cannot be told apart by the
    // correction through T, however tight their measured bounds.
    let separable: Vec<f64> = (0..omega.len())
        .map(|i| report.error_bounds[i].max(a_priori.bound(omega[i])))
        .collect();
    let formed = Formed {
        flagged: &flagged,
        z: &z,
        separable: &separable,
        omega_all,
        first,
    };
    let residuals = formed.refine(pencil, form, &mut x, &mut products, report, omega);
    // Unselected values were never measured: the gaps to them allow for their a-priori error.
    let basis = ModeBasis {
        a,
        l: pencil.l,
        x: x.as_ref(),
        modes: &flagged,
        unselected: Some(a_priori),
    };
    residual_bounds(report, omega, omega_all, first, &residuals, &basis, &prior, pencil.par);
    let columns: Vec<usize> = residuals
        .iter()
        .filter_map(|r| flagged.iter().position(|&i| i == r.mode))
        .collect();
    let values: Vec<f64> = columns.iter().map(|&col| omega[flagged[col]]).collect();
    let rounding = extended_roundings(a, b, x.as_ref(), &columns, &values, pencil.par);
    for (&col, r) in columns.iter().zip(rounding) {
        report.error_bounds[flagged[col]] += r;
    }
    let norms = (report.norm_a, report.norm_b);
    flagged
        .iter()
        .enumerate()
        .map(|(col, &i)| (i, zero_resolution(a, b, x.col_as_slice(col), omega[i], norms)))
        .collect()
}

/// The flagged modes whose vectors were formed: column c of X (and of Z, their eigenvectors of
/// T) belongs to mode `flagged[c]` of the selection.
struct Formed<'a> {
    flagged: &'a [usize],
    z: &'a Mat<f64>,
    /// Each selected mode's uncertainty for the clusters of the correction through T.
    separable: &'a [f64],
    omega_all: &'a [f64],
    first: usize,
}

impl Formed<'_> {
    /// Refines every cluster of still weakly bounded modes whose members all have their vectors
    /// (consecutive flagged columns), with the correction through Q and T; writes the refined
    /// pairs into `x`, `omega`, `products` and the report, and returns their residual records.
    fn refine(
        &self,
        pencil: &Pencil<'_>,
        form: &mut TridiagonalForm,
        x: &mut Mat<f64>,
        products: &mut PairProducts,
        report: &mut AccuracyReport,
        omega: &mut [f64],
    ) -> Vec<RefinedResidual> {
        let (a, b) = (pencil.a, pencil.b);
        let flagged = self.flagged;
        let mut residuals: Vec<RefinedResidual> = Vec::new();
        let mass = Operand::new(a);
        let stiffness = Operand::new(b);
        let factor = LowerFactor::new(pencil.l);
        let shifts = SparseShifts::new(&mass, &stiffness);
        for g in clusters(omega, self.separable) {
            // A block needs the vectors of all its members: consecutive flagged columns.
            let Some(col) = flagged.iter().position(|&i| i == g.start) else {
                continue;
            };
            let all_flagged = flagged.get(col + g.len() - 1) == Some(&(g.end - 1));
            let weak = g.clone().any(|i| weakly_bounded(report.error_bounds[i], omega[i]));
            if !(all_flagged && weak && refinable(&g, omega, self.separable, self.omega_all, self.first)) {
                continue;
            }
            let x0 = x.as_ref().subcols(col, g.len()).to_owned();
            let mut correction = TridiagonalCorrection {
                form,
                z: self.z.as_ref().subcols(col, g.len()).to_owned(),
                purified: false,
            };
            let refined = refine_cluster(
                &mass,
                &stiffness,
                shifts.as_ref(),
                Metric::Cholesky(factor),
                Some(&mut correction),
                x0.as_ref(),
                omega[g.start],
            );
            let Some(cluster) = refined else { continue };
            for (k, p) in cluster.pairs.into_iter().enumerate() {
                let i = g.start + k;
                x.col_as_slice_mut(col + k).copy_from_slice(&p.x);
                omega[i] = p.omega_sq;
                products.update_column(a, b, x.as_ref(), col + k, pencil.par);
                report.residual_norms_a_inv[i] = Some(p.residual_a_inv);
                report.refinement_steps[i] = p.steps;
                residuals.push(RefinedResidual {
                    mode: i,
                    cluster: g.clone(),
                    orthogonality: cluster.orthogonality,
                    residual: p.residual,
                });
            }
        }
        residuals
    }
}
