//! The refinement stage of a dense solve: the clusters of weakly bounded modes are refined
//! ([`crate::refine`]), their columns of X and values replaced, and their bounds replaced by
//! residual bounds in the definite pencil the residuals belong to.

use crate::certify::products::PairProducts;
use crate::certify::report::{AccuracyReport, BoundKind};
use crate::certify::residual_bounds::{ModeBasis, RefinedResidual, residual_bounds, split_refined_clusters};
use crate::certify::resolution::extended_roundings;
use crate::dd::Operand;
use crate::dense::options::{AUTO_REFINE_RELATIVE_BOUND, Refinement, weakly_bounded};
use crate::linalg::norms::euclidean_norm;
use crate::refine::{
    Condensation, Metric, ReducedCorrection, ReducedSpectrum, RefinedCluster, RefinedPair, SparseShifts,
    polish_simple_mode, refine_cluster, refine_simple_modes,
};
use crate::runtime::fork_join::map_items;
use crate::spectrum::{clusters, refinable};
use crate::tuning::Tuning;
use faer::{Mat, MatRef, Par};
use std::ops::Range;

/// What the refinement of a dense solve's selected modes works on.
pub(crate) struct Stage<'a> {
    /// The stored pencil's A and B.
    pub a: MatRef<'a, f64>,
    pub b: MatRef<'a, f64>,
    /// The Cholesky factor of the (condensed) mass matrix.
    pub l: MatRef<'a, f64>,
    /// For a condensed pencil: its exact condensation (diagonal A).
    pub condensation: Option<&'a Condensation>,
    pub policy: Refinement,
    pub metric: Metric<'a>,
    /// All ω² of the (condensed) pencil, ascending; the selection starts at index `first`.
    pub omega_all: &'a [f64],
    pub first: usize,
    /// All n eigenvectors Y of the reduced matrix, when they were computed.
    pub reduced: Option<&'a Mat<f64>>,
    /// The selected modes' error estimates when some came from the reversed pencil: the
    /// clusters are formed from the smaller of each mode's bound and its estimate.
    pub estimates: Option<&'a [f64]>,
    pub par: Par,
}

/// The operands and the sparse shifts that every refined cluster of a stage shares.
struct Operands<'a> {
    mass: Operand<'a>,
    stiffness: Operand<'a>,
    shifts: Option<SparseShifts>,
}

impl Stage<'_> {
    /// Refines the clusters of weakly bounded modes (every cluster under
    /// [`Refinement::Always`]) of the selected modes `omega` with shapes `x`, and updates `x`,
    /// `omega`, the pair `products` and the `report` (residual norms, steps, backward errors and
    /// residual bounds) for every refined mode.
    pub(crate) fn run(
        &self,
        x: &mut Mat<f64>,
        products: &mut PairProducts,
        report: &mut AccuracyReport,
        omega: &mut [f64],
    ) {
        let n = self.a.nrows();
        let prior: Vec<(f64, f64)> = (0..omega.len())
            .map(|i| (omega[i], report.bound_with_rounding(i, n)))
            .collect();
        let jobs = self.jobs(report, omega);
        let (mass, stiffness) = (Operand::new(self.a), Operand::new(self.b));
        let shifts = if jobs.is_empty() {
            None
        } else {
            SparseShifts::new(&mass, &stiffness)
        };
        let operands = Operands {
            mass,
            stiffness,
            shifts,
        };
        let mut refined = self.refine_jobs(&operands, &jobs, x.as_ref(), omega);
        for (g, cluster) in jobs.iter().zip(refined.iter_mut()) {
            let first_order = g.clone().any(|i| report.bound_kinds[i] == BoundKind::FirstOrder);
            let kept = cluster.as_ref().is_none_or(|c| {
                stays_in_its_interval(c, g, omega, |i| report.bound_with_rounding(i, n))
                    || (first_order && stays_in_its_span(c, g, self.a, x.as_ref()))
            });
            if !kept {
                *cluster = None;
            }
        }
        let (mut residuals, changed) = apply_refined(&jobs, refined, x, report, omega);
        products.update_columns(self.a, self.b, x.as_ref(), &changed, self.par);
        for &i in &changed {
            report.set_pair_error(products, x.as_ref(), i, omega[i]);
        }
        split_refined_clusters(&mut residuals, omega, &report.residual_norms_a_inv);
        let first_order = (report.error_bounds.clone(), report.bound_kinds.clone());
        self.residual_bounds(report, omega, &residuals, x.as_ref(), &prior);
        self.polish(
            &operands,
            &mut residuals,
            first_order,
            &prior,
            x,
            products,
            report,
            omega,
        );
    }

    /// The clusters to refine: those the policy asks for (a weakly bounded member, or all under
    /// [`Refinement::Always`] and on a condensation whose first-order bounds are not to be
    /// trusted, its [`Condensation::relative_rounding`] above [`AUTO_REFINE_RELATIVE_BOUND`])
    /// that refinement can take ([`refinable`]).
    fn jobs(&self, report: &AccuracyReport, omega: &[f64]) -> Vec<Range<usize>> {
        let every_mode = self.policy == Refinement::Always
            || self
                .condensation
                .is_some_and(|c| c.relative_rounding() > AUTO_REFINE_RELATIVE_BOUND);
        let separation: Vec<f64> = match self.estimates {
            Some(estimates) => report
                .error_bounds
                .iter()
                .zip(estimates)
                .map(|(b, e)| b.min(*e))
                .collect(),
            None => report.error_bounds.clone(),
        };
        let jobs: Vec<Range<usize>> = clusters(omega, &separation)
            .into_iter()
            .filter(|g| {
                let wanted = every_mode
                    || g.clone()
                        .any(|i| weakly_bounded(report.bound_with_rounding(i, self.a.nrows()), omega[i]));
                wanted && refinable(g, omega, &separation, self.omega_all, self.first)
            })
            .collect();
        if self.policy == Refinement::Always {
            return jobs;
        }
        // Auto: the lowest weak modes first, within the budget of Tuning::auto_refined_at_least.
        let tuning = Tuning::DEFAULT;
        let budget = tuning
            .auto_refined_at_least
            .max(self.a.nrows() / tuning.auto_refined_fraction.max(1));
        let mut taken = 0;
        jobs.into_iter()
            .take_while(|g| {
                taken += g.len();
                taken <= budget
            })
            .collect()
    }

    /// Each job's refined cluster (None where refinement declined). Simple modes of a definite
    /// pencil are refined as one batch whose corrections are block products
    /// ([`refine_simple_modes`]); a mode whose batch step fails, and every cluster, takes its own
    /// path. A sparse pencil's simple modes take theirs at once: a sparse bordered factorization
    /// per mode costs less than the batch's products through Y. Clusters are independent: each
    /// is refined from its own columns of X, sequentially inside, and the clusters are shared
    /// among the threads.
    fn refine_jobs(
        &self,
        operands: &Operands<'_>,
        jobs: &[Range<usize>],
        start: MatRef<'_, f64>,
        omega: &[f64],
    ) -> Vec<Option<RefinedCluster>> {
        let refine_one = |g: &Range<usize>| {
            let x0 = start.subcols(g.start, g.len()).to_owned();
            let mut spectrum = self.reduced.map(|y| ReducedSpectrum {
                y: y.as_ref(),
                omega_sq: self.omega_all,
                modes: self.first + g.start..self.first + g.end,
            });
            let correction = spectrum.as_mut().map(|s| s as &mut dyn ReducedCorrection);
            refine_cluster(
                &operands.mass,
                &operands.stiffness,
                operands.shifts.as_ref(),
                self.metric,
                correction,
                x0.as_ref(),
                omega[g.start],
            )
        };
        let mut refined: Vec<Option<RefinedCluster>> = vec![None; jobs.len()];
        let mut pending: Vec<usize> = (0..jobs.len()).collect();
        if let (Metric::Cholesky(l), Some(y), None) = (self.metric, self.reduced, &operands.shifts) {
            let singles: Vec<usize> = pending.iter().copied().filter(|&j| jobs[j].len() == 1).collect();
            if !singles.is_empty() {
                let x0 = Mat::from_fn(start.nrows(), singles.len(), |i, c| start[(i, jobs[singles[c]].start)]);
                let modes: Vec<usize> = singles.iter().map(|&j| self.first + jobs[j].start).collect();
                let pairs = refine_simple_modes(
                    &operands.mass,
                    &operands.stiffness,
                    l,
                    (y.as_ref(), self.omega_all),
                    &modes,
                    x0.as_ref(),
                    self.par,
                );
                for (&j, pair) in singles.iter().zip(pairs) {
                    refined[j] = pair.map(RefinedCluster::single);
                }
                pending.retain(|&j| refined[j].is_none());
            }
        }
        let rest: Vec<Option<RefinedCluster>> = map_items(&pending, self.par, |&j| refine_one(&jobs[j]));
        for (&j, cluster) in pending.iter().zip(rest) {
            refined[j] = cluster;
        }
        refined
    }

    /// Simple modes refined in double (the batch, the projected step) whose bound is still
    /// weak: their residual is limited by rounding the vector. More projected steps with a
    /// double-double iterate, kept where they lower the residual; then the bounds again, from
    /// the first-order bounds `first_order` of the changed pairs.
    #[allow(clippy::too_many_arguments)]
    fn polish(
        &self,
        operands: &Operands<'_>,
        residuals: &mut [RefinedResidual],
        first_order: (Vec<f64>, Vec<BoundKind>),
        prior: &[(f64, f64)],
        x: &mut Mat<f64>,
        products: &mut PairProducts,
        report: &mut AccuracyReport,
        omega: &mut [f64],
    ) {
        let (Metric::Cholesky(_), Some(y), None) = (self.metric, self.reduced, &operands.shifts) else {
            return;
        };
        let weak: Vec<usize> = (0..residuals.len())
            .filter(|&k| {
                let i = residuals[k].mode;
                residuals[k].cluster.len() == 1 && weakly_bounded(report.error_bounds[i], omega[i])
            })
            .collect();
        let polish = |&k: &usize| {
            let i = residuals[k].mode;
            let mut spectrum = ReducedSpectrum {
                y: y.as_ref(),
                omega_sq: self.omega_all,
                modes: self.first + i..self.first + i + 1,
            };
            let steps = report.refinement_steps[i];
            polish_simple_mode(
                &operands.mass,
                &operands.stiffness,
                self.metric,
                &mut spectrum,
                x.col_as_slice(i),
                steps,
            )
        };
        let polished: Vec<Option<RefinedPair>> = map_items(&weak, self.par, polish);
        let mut improved: Vec<usize> = Vec::new();
        for (&k, pair) in weak.iter().zip(polished) {
            let i = residuals[k].mode;
            let within_bound = |p: &RefinedPair| (p.omega_sq - omega[i]).abs() <= report.error_bounds[i];
            let lower_residual = |p: &RefinedPair| Some(p.residual_a_inv) < report.residual_norms_a_inv[i];
            let Some(p) = pair.filter(|p| within_bound(p) && lower_residual(p)) else {
                continue;
            };
            x.col_as_slice_mut(i).copy_from_slice(&p.x);
            omega[i] = p.omega_sq;
            report.residual_norms_a_inv[i] = Some(p.residual_a_inv);
            report.refinement_steps[i] = p.steps;
            residuals[k].residual = p.residual;
            improved.push(i);
        }
        if !improved.is_empty() {
            products.update_columns(self.a, self.b, x.as_ref(), &improved, self.par);
            (report.error_bounds, report.bound_kinds) = first_order;
            for &i in &improved {
                report.set_pair_error(products, x.as_ref(), i, omega[i]);
            }
            self.residual_bounds(report, omega, residuals, x.as_ref(), prior);
        }
    }

    /// The refined modes' residual bounds ([`residual_bounds`]), in the definite pencil the
    /// residuals belong to: (B, A) itself, or the condensed (S, A₁) with the modes' rows at the
    /// coordinates with mass.
    fn residual_bounds(
        &self,
        report: &mut AccuracyReport,
        omega: &[f64],
        residuals: &[RefinedResidual],
        x: MatRef<'_, f64>,
        prior: &[(f64, f64)],
    ) {
        let all: Vec<usize> = (0..omega.len()).collect();
        let condensed = self.condensation.map(|c| (c.condensed_mass(), c.massed_rows(x)));
        let (basis_a, basis_x) = match &condensed {
            Some((a1, z)) => (a1.as_ref(), z.as_ref()),
            None => (self.a, x),
        };
        let basis = ModeBasis {
            a: basis_a,
            l: self.l,
            x: basis_x,
            modes: &all,
            unselected: None,
        };
        residual_bounds(
            report,
            omega,
            self.omega_all,
            self.first,
            residuals,
            &basis,
            prior,
            self.par,
        );
        let columns: Vec<usize> = residuals.iter().map(|r| r.mode).collect();
        let values: Vec<f64> = columns.iter().map(|&i| omega[i]).collect();
        let rounding = extended_roundings(self.a, self.b, x, &columns, &values, self.par);
        for (&i, r) in columns.iter().zip(rounding) {
            report.error_bounds[i] += r;
        }
    }
}

/// Whether every refined value of cluster `g` lies in the union of the cluster's intervals
/// ω²_i ± bound(i) before refinement. Those bounds hold, so a value outside them belongs to an
/// eigenpair of another mode: the iteration has left the cluster (a start vector mixing modes
/// that the reduction could not separate) and its result is not taken.
fn stays_in_its_interval(
    cluster: &RefinedCluster,
    g: &Range<usize>,
    omega: &[f64],
    bound: impl Fn(usize) -> f64,
) -> bool {
    let lowest = g.clone().map(|i| omega[i] - bound(i)).fold(f64::INFINITY, f64::min);
    let highest = g.clone().map(|i| omega[i] + bound(i)).fold(f64::NEG_INFINITY, f64::max);
    cluster.pairs.iter().all(|p| (lowest..=highest).contains(&p.omega_sq))
}

/// Whether every refined vector of cluster `g` lies mostly in the span of the cluster's
/// starting vectors `x`: its A-orthogonal projection onto them keeps at least half its squared
/// A-norm. A first-order bound is not a proof (the perturbation theory behind it fails where the
/// pencil is near a singular one, e.g. a condensation through a nearly singular B₀₀), so a value
/// outside it may still be the mode's own; a refined vector that kept its direction is, where
/// one that converged to another mode's eigenvector is nearly A-orthogonal to its start.
fn stays_in_its_span(cluster: &RefinedCluster, g: &Range<usize>, a: MatRef<'_, f64>, x: MatRef<'_, f64>) -> bool {
    let start = x.subcols(g.start, g.len());
    let a_start = a * start;
    let gram = start.transpose() * &a_start;
    // ‖G − I‖₂ ≤ p·max|G − I| =: δ, and the squared A-norm of the projection of y onto the
    // span is cᵀG⁻¹c ≥ ‖c‖²/(1 + δ) with c = XᵀAy.
    let p = g.len();
    let defect = (0..p)
        .flat_map(|k| (0..p).map(move |l| (k, l)))
        .map(|(k, l)| (gram[(k, l)] - if k == l { 1.0 } else { 0.0 }).abs())
        .fold(0.0, f64::max);
    let gram_norm = p as f64 * defect;
    if gram_norm.partial_cmp(&0.5) != Some(std::cmp::Ordering::Less) {
        return false;
    }
    cluster.pairs.iter().all(|pair| {
        let components: Vec<f64> = (0..p)
            .map(|k| a_start.col(k).iter().zip(&pair.x).map(|(u, v)| u * v).sum())
            .collect();
        let projected = euclidean_norm(&components);
        projected * projected >= 0.5 * (1.0 + gram_norm)
    })
}

/// Writes the refined clusters into `x`, `omega` and the report's residual norms and steps;
/// returns each refined mode's residual record and the changed columns.
fn apply_refined(
    jobs: &[Range<usize>],
    refined: Vec<Option<RefinedCluster>>,
    x: &mut Mat<f64>,
    report: &mut AccuracyReport,
    omega: &mut [f64],
) -> (Vec<RefinedResidual>, Vec<usize>) {
    let mut residuals: Vec<RefinedResidual> = Vec::new();
    let mut changed: Vec<usize> = Vec::new();
    for (g, cluster) in jobs.iter().zip(refined) {
        let Some(cluster) = cluster else { continue };
        for (i, p) in g.clone().zip(cluster.pairs) {
            x.col_as_slice_mut(i).copy_from_slice(&p.x);
            omega[i] = p.omega_sq;
            report.residual_norms_a_inv[i] = Some(p.residual_a_inv);
            report.refinement_steps[i] = p.steps;
            changed.push(i);
            residuals.push(RefinedResidual {
                mode: i,
                cluster: g.clone(),
                orthogonality: cluster.orthogonality,
                residual: p.residual,
            });
        }
    }
    (residuals, changed)
}
