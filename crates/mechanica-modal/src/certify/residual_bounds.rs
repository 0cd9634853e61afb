//! The bounds of refined modes: gap-weighted residual (Kato–Temple) bounds from their
//! extended-precision residuals, per mode or per cluster refined as one block.

use crate::certify::a_priori::APrioriModel;
use crate::certify::report::{AccuracyReport, BoundKind};
use crate::linalg::norms::{euclidean_norm, square_over, vector_norm};
use crate::spectrum::clusters;
use crate::tuning::Tuning;
use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
use faer::{Mat, MatRef, Par};
use std::cmp::Ordering;
use std::ops::Range;

/// The computed modes used to split a residual into its modal components.
pub(crate) struct ModeBasis<'a> {
    pub a: MatRef<'a, f64>,
    /// Cholesky factor of A.
    pub l: MatRef<'a, f64>,
    /// Computed modes, A-orthonormal to working precision: all selected modes, or (values
    /// only) those formed for refinement.
    pub x: MatRef<'a, f64>,
    /// The index within the selection of each column of `x`.
    pub modes: &'a [usize],
    /// Values only: the error model of the unselected modes' values (never measured), for the
    /// gaps to them; None when they are as accurate as the selected ones.
    pub unselected: Option<APrioriModel>,
}

/// The residual of a refined mode, with the cluster of modes refined together as one block
/// ([`crate::refine::refine_cluster_projected`]; a simple mode is a cluster of one).
pub(crate) struct RefinedResidual {
    /// The mode's index within the selection.
    pub mode: usize,
    /// The selection indices of the modes refined together with it (contains `mode`).
    pub cluster: Range<usize>,
    /// max |x_kᵀAx_l| over distinct refined vectors of the cluster (0 for a single mode).
    pub orthogonality: f64,
    /// (B − ω²A)x from double-double, rounded.
    pub residual: Vec<f64>,
}

/// Replaces the bounds of refined modes by a gap-weighted Kato–Temple bound.
///
/// The residual r = (B − ρA)x of a refined, A-normalised x is split along the computed modes,
/// r = Σ_j c_j A x_j + r_⊥ with c_j = x_jᵀ r; since the eigenvalue error is
/// Σ_{j≠i} |γ_j|²(ω²_j − ω²_i) with r's components γ_j(ω²_j − ρ), it is at most
/// Σ_{j≠i} c_j² / δ_j + ‖r_⊥‖²_{A⁻¹}/δ, with δ_j = |ω²_j − ρ| − bound_j and δ the smallest gap
/// (first order in the error of the computed basis). It is never taken larger than the linear
/// residual bound ε = ‖r‖_{A⁻¹}, and u|ρ| is added for rounding ρ to double. Selected modes
/// missing from the basis only enter through δ (their components stay in r_⊥), and so do
/// unselected modes (outside `first..first + m` of `omega_all`), with the largest bound of the
/// selection before refinement as their uncertainty, or (values only) their a-priori error if
/// that is larger.
///
/// A cluster G of p modes refined as one block gets one bound for all its members, the same
/// sums taken over the block: ε² = Σ_{k∈G} ‖r_k‖²_{A⁻¹} (the Frobenius norm of the block
/// residual, which bounds its 2-norm: p eigenvalues lie within it of the Ritz values, Kahan's
/// theorem; Parlett, "The Symmetric Eigenvalue Problem", Thm 11.5.1), Σ_{j∉G} Σ_{k∈G} c_{jk}²/δ_j
/// with δ_j the gap from mode j to the nearest member, and ‖R_⊥‖²_F/δ: the quadratic residual
/// bound of a Ritz block separated by δ from the rest of the spectrum (Mathias, SIMAX 19, 1998).
/// p·γ·s and u·s are added for the block's A-orthogonality defect γ and the rounding, with s
/// the largest |ω²| of the block.
///
/// A residual alone places *some* eigenvalue within ε of ρ, not the mode's own (the i-th in
/// ascending order): it is the i-th only where the interval ρ ± ε is apart from every other
/// mode's, the gap δ > ε. Where it is not, the mode keeps the interval it was refined from,
/// `prior[i]` = (ω², bound) before refinement, which holds for the i-th eigenvalue: the bound
/// becomes |ρ − ω²_prior| + bound_prior. The one exception is a chain of overlapping intervals
/// whose members were all refined and whose vectors are A-orthogonal: it is bounded as one block
/// and every member gets the chain's bound (see `chained_bound`).
#[allow(clippy::too_many_arguments)]
pub(crate) fn residual_bounds(
    report: &mut AccuracyReport,
    omega_sq: &[f64],
    omega_all: &[f64],
    first: usize,
    residuals: &[RefinedResidual],
    basis: &ModeBasis<'_>,
    prior: &[(f64, f64)],
    par: Par,
) {
    let m = omega_sq.len();
    if residuals.is_empty() {
        return;
    }
    // The unselected modes were never refined: their uncertainty is that of the reduction, which
    // the selection's bounds before refinement measure (after it, the refined ones are far
    // smaller than any unselected mode's error).
    let others_bound = report
        .error_bounds
        .iter()
        .chain(prior.iter().map(|(_, bound)| bound))
        .copied()
        .fold(0.0, f64::max);
    let linear: Vec<f64> = (0..m)
        .map(|i| {
            report.residual_norms_a_inv[i].map_or(report.error_bounds[i], |e| e + f64::EPSILON * omega_sq[i].abs())
        })
        .collect();
    let split = SplitResiduals::of(basis, residuals, m, par);
    let spectrum = Spectrum {
        omega_sq,
        omega_all,
        first,
        linear: &linear,
        others_bound,
        unselected: basis.unselected,
    };
    for refined in residuals {
        let i = refined.mode;
        let group = refined.cluster.clone();
        // The block's residual columns; a member without one leaves the linear bound.
        let Some(columns) = group
            .clone()
            .map(|g| split.residual_of[g].zip(report.residual_norms_a_inv[g]))
            .collect::<Option<Vec<(usize, f64)>>>()
        else {
            continue;
        };
        let Some(bound) = split.block_bound(&spectrum, &group, &columns) else {
            let norms = &report.residual_norms_a_inv;
            match split.chained_bound(&spectrum, basis, norms, &group) {
                Some(bound) => {
                    report.error_bounds[i] = bound;
                    report.bound_kinds[i] = BoundKind::Residual;
                }
                None => report.error_bounds[i] = (omega_sq[i] - prior[i].0).abs() + prior[i].1,
            }
            continue;
        };
        // Rounding and the block's A-orthogonality defect at the cluster's largest |ω²|: the
        // Rayleigh–Ritz step in double leaves a mixing of order u between members, which moves a
        // member's Rayleigh quotient by up to u² times the cluster's spread (a zero mode chained
        // to soft ones would otherwise get a bound far below its computed ω²).
        let scale = group.clone().map(|g| omega_sq[g].abs()).fold(0.0, f64::max);
        let defect = group.len() as f64 * refined.orthogonality * scale;
        report.error_bounds[i] = bound + defect + f64::EPSILON * scale;
        report.bound_kinds[i] = BoundKind::Residual;
    }
}

/// The spectrum the gaps of [`residual_bounds`] are measured in.
struct Spectrum<'a> {
    /// The selected modes' ω².
    omega_sq: &'a [f64],
    /// All ω², ascending; the selection is `first..first + omega_sq.len()`.
    omega_all: &'a [f64],
    first: usize,
    /// Each selected mode's linear bound (its residual norm, or its bound before refinement).
    linear: &'a [f64],
    /// The largest bound of the selection before or after refinement, the uncertainty of the
    /// unselected modes.
    others_bound: f64,
    /// Values only: the error model of the unselected modes' values.
    unselected: Option<APrioriModel>,
}

impl Spectrum<'_> {
    /// The ω² of the modes outside the selection.
    fn unselected_values(&self) -> impl Iterator<Item = f64> + '_ {
        let selection = self.first..self.first + self.omega_sq.len();
        self.omega_all
            .iter()
            .enumerate()
            .filter(move |(k, _)| !selection.contains(k))
            .map(|(_, &w)| w)
    }

    /// The uncertainty of an unselected mode's value `w`: the largest bound of the selection,
    /// or (values only) its a-priori error if that is larger.
    fn unselected_uncertainty(&self, w: f64) -> f64 {
        self.unselected
            .map_or(self.others_bound, |model| model.bound(w).max(self.others_bound))
    }
}

/// The refined residuals R split along the computed modes: C = Xᵀ R, and R_⊥ = L⁻¹(R − A X C),
/// whose column norms are the A⁻¹-norms of the parts outside the basis.
struct SplitResiduals {
    c: Mat<f64>,
    rest: Mat<f64>,
    /// The basis column of each selected mode (None when not in the basis).
    column_of: Vec<Option<usize>>,
    /// The residual column of each selected mode (None when not refined).
    residual_of: Vec<Option<usize>>,
}

impl SplitResiduals {
    /// All refined residuals at once, for a selection of `m` modes.
    fn of(basis: &ModeBasis<'_>, residuals: &[RefinedResidual], m: usize, par: Par) -> Self {
        let n = basis.x.nrows();
        let k = residuals.len();
        let r = Mat::from_fn(n, k, |row, col| residuals[col].residual[row]);
        let mut c = Mat::<f64>::zeros(basis.x.ncols(), k);
        faer::linalg::matmul::matmul(
            c.as_mut(),
            faer::Accum::Replace,
            basis.x.transpose(),
            r.as_ref(),
            1.0,
            par,
        );
        let mut xc = Mat::<f64>::zeros(n, k);
        let mut column_of = vec![None; m];
        for (col, &mode) in basis.modes.iter().enumerate() {
            column_of[mode] = Some(col);
        }
        let mut residual_of = vec![None; m];
        for (col, refined) in residuals.iter().enumerate() {
            residual_of[refined.mode] = Some(col);
        }
        faer::linalg::matmul::matmul(xc.as_mut(), faer::Accum::Replace, basis.x, c.as_ref(), 1.0, par);
        let mut rest = r;
        faer::linalg::matmul::matmul(rest.as_mut(), faer::Accum::Add, basis.a, xc.as_ref(), -1.0, par);
        solve_lower_triangular_in_place(basis.l, rest.as_mut(), par);
        Self {
            c,
            rest,
            column_of,
            residual_of,
        }
    }

    /// The bound of the block `group` (its members' residual columns and residual norms
    /// `columns`) before its orthogonality defect and rounding: min(ε, ε²/δ, Σ c²/δ_j +
    /// ‖R_⊥‖²/δ) where the gap δ exceeds ε; None where it does not (ε then bounds the distance
    /// to some eigenvalue, not necessarily the members' own).
    fn block_bound(&self, spectrum: &Spectrum<'_>, group: &Range<usize>, columns: &[(usize, f64)]) -> Option<f64> {
        let (omega_sq, linear) = (spectrum.omega_sq, spectrum.linear);
        let m = omega_sq.len();
        // Norms and quadratic terms are formed without squaring small numbers: after the exact
        // scaling of a pencil whose entries span most of the double range, residuals of its
        // softest modes are subnormal, and their squares would vanish.
        let norms: Vec<f64> = columns.iter().map(|&(_, e)| e).collect();
        let eps = euclidean_norm(&norms);
        let distance = |w: f64| {
            group
                .clone()
                .map(|g| (omega_sq[g] - w).abs())
                .fold(f64::INFINITY, f64::min)
        };
        let mut gap = f64::INFINITY;
        let mut weighted = 0.0;
        let mut usable = true;
        for j in (0..m).filter(|j| !group.contains(j)) {
            let d = distance(omega_sq[j]) - linear[j];
            gap = gap.min(d);
            if let Some(basis_col) = self.column_of[j] {
                if d > 0.0 {
                    let components: Vec<f64> = columns.iter().map(|&(col, _)| self.c[(basis_col, col)]).collect();
                    weighted += square_over(euclidean_norm(&components), d);
                } else {
                    usable = false;
                }
            }
        }
        for w in spectrum.unselected_values() {
            gap = gap.min(distance(w) - spectrum.unselected_uncertainty(w));
        }
        let rest_norms: Vec<f64> = columns
            .iter()
            .map(|&(col, _)| vector_norm(self.rest.col(col)))
            .collect();
        let eps_rest = euclidean_norm(&rest_norms);
        // The gap-weighted bounds hold for the eigenvalues of H = XᵀBX, not for its diagonal
        // (the members' values): Weyl's theorem puts them within ‖H − diag(ω²)‖_F of it.
        if gap.partial_cmp(&eps) != Some(Ordering::Greater) {
            return None;
        }
        let Some(coupling) = self.in_block_coupling(group, columns) else {
            return Some(eps);
        };
        let gap = gap - coupling;
        let mut bound = eps;
        if gap > eps {
            bound = bound.min(coupling + square_over(eps, gap));
            if usable && gap > eps_rest {
                bound = bound.min(coupling + weighted + square_over(eps_rest, gap));
            }
        }
        Some(bound)
    }

    /// The bound of block `group` (its residual columns and norms `columns`) where its interval
    /// meets other modes': its residual then bounds the distance to *some* eigenvalue, not
    /// necessarily its own. The modes whose intervals chain with the block's form a chain K; when
    /// every one of them was refined, the chain is a contiguous run of the selection, its vectors
    /// are A-orthogonal to 1/(2|K|), and no unselected mode meets it, the |K| eigenvalues of
    /// H = X_KᵀBX_K lie within ‖R_K‖_F of |K| eigenvalues of the pencil (Kahan's theorem, as for a
    /// refined block), and the values within ‖H − diag(ω²)‖_F of H's (Weyl). Sorted values and
    /// sorted eigenvalues then pair within the same bound E = ‖R_K‖_F + ‖H − diag‖_F + |K|·γ·s +
    /// u·s (γ = max |x_kᵀAx_l| over K, s the largest |ω²| of K): a matching within E exists, and
    /// the sorted pairing is the best one. Those |K| eigenvalues are the chain's own (its modes'
    /// indices) when no other mode's interval meets the chain's values widened by E. None
    /// otherwise, or past [`Tuning::max_refined_cluster`] members: the mode then keeps its prior
    /// interval.
    fn chained_bound(
        &self,
        spectrum: &Spectrum<'_>,
        basis: &ModeBasis<'_>,
        norms: &[Option<f64>],
        group: &Range<usize>,
    ) -> Option<f64> {
        let chain = chain_of(spectrum, norms, group)?;
        let (omega_sq, linear) = (spectrum.omega_sq, spectrum.linear);
        let columns = chain
            .clone()
            .map(|j| self.residual_of[j].zip(norms[j]))
            .collect::<Option<Vec<(usize, f64)>>>()?;
        let basis_columns = chain
            .clone()
            .map(|j| self.column_of[j])
            .collect::<Option<Vec<usize>>>()?;
        let p = chain.len() as f64;
        let gamma = a_orthogonality(basis, &basis_columns);
        if (p * gamma).partial_cmp(&0.5) != Some(Ordering::Less) {
            return None;
        }
        let chain_norms: Vec<f64> = columns.iter().map(|&(_, e)| e).collect();
        let coupling = self.in_block_coupling(&chain, &columns)?;
        let scale = chain.clone().map(|j| omega_sq[j].abs()).fold(0.0, f64::max);
        let bound = euclidean_norm(&chain_norms) + coupling + p * gamma * scale + f64::EPSILON * scale;
        let lo = chain.clone().map(|j| omega_sq[j]).fold(f64::INFINITY, f64::min) - bound;
        let hi = chain.clone().map(|j| omega_sq[j]).fold(f64::NEG_INFINITY, f64::max) + bound;
        let meets = |w: f64, e: f64| w + e >= lo && w - e <= hi;
        let other_meets = (0..omega_sq.len())
            .filter(|j| !chain.contains(j))
            .any(|j| meets(omega_sq[j], linear[j]))
            || spectrum
                .unselected_values()
                .any(|w| meets(w, spectrum.unselected_uncertainty(w)));
        (!other_meets && bound.is_finite()).then_some(bound)
    }

    /// ‖H − diag(ω²)‖_F for the block's members, with H = X_GᵀBX_G: for A-orthonormal X, the
    /// in-block components C_GG = X_Gᵀ R_G of the residuals (8n·u·‖R_G‖_F allows for forming
    /// them in double). None when a member is not in the basis.
    fn in_block_coupling(&self, group: &Range<usize>, columns: &[(usize, f64)]) -> Option<f64> {
        let rows = group
            .clone()
            .map(|g| self.column_of[g])
            .collect::<Option<Vec<usize>>>()?;
        let mut components = Vec::with_capacity(columns.len() * rows.len());
        let mut rest_norms = Vec::with_capacity(columns.len());
        for &(col, _) in columns {
            rest_norms.push(vector_norm(self.rest.col(col)));
            components.extend(rows.iter().map(|&row| self.c[(row, col)]));
        }
        let sum = euclidean_norm(&components);
        let rounding =
            8.0 * self.rest.nrows() as f64 * f64::EPSILON * euclidean_norm(&[sum, euclidean_norm(&rest_norms)]);
        Some(sum + rounding)
    }
}

/// The modes whose intervals chain with the refined block `group`'s: each refined member reaches
/// its residual norm (`norms`), each other mode its linear bound. None when the chain takes in a
/// mode that was not refined or more than [`Tuning::max_refined_cluster`] modes, or is not a
/// contiguous run of the selection.
fn chain_of(spectrum: &Spectrum<'_>, norms: &[Option<f64>], group: &Range<usize>) -> Option<Range<usize>> {
    let (omega_sq, linear) = (spectrum.omega_sq, spectrum.linear);
    let mut members: Vec<usize> = group.clone().collect();
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    loop {
        for &j in &members {
            let reach = norms[j]?;
            lo = lo.min(omega_sq[j] - reach);
            hi = hi.max(omega_sq[j] + reach);
        }
        let meeting: Vec<usize> = (0..omega_sq.len())
            .filter(|j| !members.contains(j))
            .filter(|&j| omega_sq[j] + linear[j] >= lo && omega_sq[j] - linear[j] <= hi)
            .collect();
        if meeting.is_empty() {
            break;
        }
        members.extend(meeting);
        if members.len() > Tuning::DEFAULT.max_refined_cluster {
            return None;
        }
    }
    let first = members.iter().copied().min()?;
    let end = members.iter().copied().max()? + 1;
    (end - first == members.len()).then_some(first..end)
}

/// max_{k≠l} |x_kᵀAx_l| over the basis columns `columns`.
fn a_orthogonality(basis: &ModeBasis<'_>, columns: &[usize]) -> f64 {
    let products: Vec<Vec<f64>> = columns
        .iter()
        .map(|&c| {
            let ax = basis.a * basis.x.col(c);
            ax.iter().copied().collect()
        })
        .collect();
    let mut gamma = 0.0_f64;
    for (k, &c) in columns.iter().enumerate() {
        for ax in products.iter().skip(k + 1) {
            let dot: f64 = basis.x.col(c).iter().zip(ax).map(|(u, v)| u * v).sum();
            gamma = gamma.max(dot.abs());
        }
    }
    gamma
}

/// Narrows the clusters of refined modes to what their refined residuals can tell apart.
/// Clusters are formed from the reduction's bounds, which on stiff problems are wide enough to
/// chain modes that are far apart (the lowest ten of a 1e12 chain); the block's bound then
/// carries its Rayleigh–Ritz defect at the block's largest ω². After refinement each member's
/// residual places an eigenvalue within e_i = ‖r_i‖_{A⁻¹} of ω²_i, so the clusters of the
/// intervals ω²_i ± e_i ([`clusters`]) are separated from one another: each keeps the block's
/// A-orthogonality defect (a maximum over more pairs) and its members' residuals, and a member
/// alone keeps none (its ω² is its own Rayleigh quotient, not a mixture).
pub(crate) fn split_refined_clusters(residuals: &mut [RefinedResidual], omega: &[f64], residual_norms: &[Option<f64>]) {
    let mut start = 0;
    while start < residuals.len() {
        let block = residuals[start].cluster.clone();
        let members = residuals[start..].iter().take_while(|r| r.cluster == block).count();
        let complete = members == block.len();
        let sharp: Option<Vec<f64>> = block
            .clone()
            .map(|i| residual_norms[i].map(|e| e + f64::EPSILON * omega[i].abs()))
            .collect();
        if let (true, Some(sharp)) = (complete && block.len() > 1, sharp) {
            for sub in clusters(&omega[block.clone()], &sharp) {
                let sub = block.start + sub.start..block.start + sub.end;
                for record in residuals[start..start + members]
                    .iter_mut()
                    .filter(|r| sub.contains(&r.mode))
                {
                    record.cluster = sub.clone();
                    if sub.len() == 1 {
                        record.orthogonality = 0.0;
                    }
                }
            }
        }
        start += members;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(mode: usize, cluster: Range<usize>) -> RefinedResidual {
        RefinedResidual {
            mode,
            cluster,
            orthogonality: 1e-15,
            residual: Vec::new(),
        }
    }
    /// A block of four refined together: modes 0 and 1 are a pair within their refined
    /// residuals, 2 and 3 stand apart; a block with a member lacking its residual norm, and a
    /// block cut short (a member not refined), keep their clusters.
    #[test]
    fn refined_blocks_split_where_their_residuals_separate_the_modes() {
        let omega = [1.0, 1.0 + 2e-15, 2.0, 3.0, 5.0, 5.5, 7.0, 7.5];
        let mut norms = vec![Some(1e-15); omega.len()];
        norms[5] = None;
        let mut residuals: Vec<RefinedResidual> = (0..4).map(|i| record(i, 0..4)).collect();
        residuals.extend((4..6).map(|i| record(i, 4..6)));
        residuals.push(record(6, 6..8));
        split_refined_clusters(&mut residuals, &omega, &norms);
        let clusters: Vec<Range<usize>> = residuals.iter().map(|r| r.cluster.clone()).collect();
        assert_eq!(clusters, vec![0..2, 0..2, 2..3, 3..4, 4..6, 4..6, 6..8]);
        let orthogonality: Vec<f64> = residuals.iter().map(|r| r.orthogonality).collect();
        assert_eq!(orthogonality, vec![1e-15, 1e-15, 0.0, 0.0, 1e-15, 1e-15, 1e-15]);
    }
}
