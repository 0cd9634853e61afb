//! The common tail of every dense solve: the accuracy report, refinement of weakly bounded
//! modes, the Sturm check, classification and grouping.

use crate::certify::a_priori::APrioriModel;
use crate::certify::products::PairProducts;
use crate::certify::report::AccuracyReport;
use crate::certify::residual_bounds::{ModeBasis, RefinedResidual, residual_bounds, split_refined_clusters};
use crate::certify::resolution::zero_resolution;
use crate::certify::sturm::inertia_check;
use crate::dd::Operand;
use crate::dense::definite::Definite;
use crate::dense::idle_inputs::IdleResults;
use crate::dense::options::{Refinement, Selection, SolveOptions, weakly_bounded};
use crate::dense::solution::{Method, ModalSolution};
use crate::dense::values_only;
use crate::error::ModalError;
use crate::linalg::eigen::TridiagonalForm;
use crate::problem::PencilProblem;
use crate::refine::{
    Condensation, Metric, ReducedCorrection, ReducedSpectrum, RefinedCluster, RefinedPair, SparseShifts,
    polish_simple_mode, refine_cluster, refine_simple_modes,
};
use crate::runtime::fork_join::map_items;
use crate::runtime::scratch;
use crate::spectrum::{Mode, ModeKind, classify, clusters, group_modes, refinable};
use faer::{Mat, MatRef, Par};
use std::ops::Range;
use std::time::Instant;

/// Maps mode shapes of a condensed pencil back to the original coordinates.
pub(crate) type Lift<'a> = &'a dyn Fn(MatRef<'_, f64>) -> Mat<f64>;

/// The common tail of every solve: refinement, accuracy report, classification, groups.
pub(crate) struct Finish<'a> {
    pub problem: &'a PencilProblem,
    /// Cholesky factor of the (condensed) mass matrix used for A⁻¹-norms.
    pub l: MatRef<'a, f64>,
    pub norm_a: f64,
    pub norm_b: f64,
    pub options: &'a SolveOptions,
    pub par: Par,
    /// For a condensed pencil: the number of negative eigenvalues of the stiffness block B₀₀ of
    /// the massless directions, by which the inertia of B − sA exceeds the count of modes
    /// below s (Haynsworth: In(B − sA) = In(B₀₀) + In(S − sA₁), S the condensed stiffness).
    pub condensed_stiffness_negatives: Option<usize>,
    /// For a condensed pencil whose condensation is exact (diagonal A): what refinement needs
    /// to correct its modes and bound them in the condensed pencil.
    pub condensation: Option<&'a Condensation>,
}

impl Finish<'_> {
    /// The refined modes' residual bounds ([`crate::certify::residual_bounds::residual_bounds`]), in the definite
    /// pencil the residuals belong to: (B, A) itself, or the condensed (S, A₁) with the modes'
    /// rows at the coordinates with mass.
    fn residual_bounds(
        &self,
        report: &mut AccuracyReport,
        omega: &[f64],
        omega_all: &[f64],
        first: usize,
        residuals: &[RefinedResidual],
        x: MatRef<'_, f64>,
    ) {
        let all: Vec<usize> = (0..omega.len()).collect();
        let condensed = self.condensation.map(|c| (c.condensed_mass(), c.massed_rows(x)));
        let (basis_a, basis_x) = match &condensed {
            Some((a1, z)) => (a1.as_ref(), z.as_ref()),
            None => (self.problem.a(), x),
        };
        let basis = ModeBasis {
            a: basis_a,
            l: self.l,
            x: basis_x,
            modes: &all,
            unselected: None,
        };
        residual_bounds(report, omega, omega_all, first, residuals, &basis, self.par);
    }

    /// `def` holds the finite spectrum of the (possibly condensed) pencil; `lift` maps its
    /// vectors to the original coordinates (None: identity); `infinite` are unit null vectors
    /// of A appended as infinite modes.
    pub(crate) fn run(
        &self,
        def: Definite,
        infinite: Vec<Vec<f64>>,
        lift: Option<Lift<'_>>,
        method: Method,
        idle: IdleResults,
    ) -> Result<ModalSolution, ModalError> {
        let (a, b) = (self.problem.a(), self.problem.b());
        let n = self.problem.dim();
        let omega_all = def.omega_sq;
        let mut form = def.form;
        let mut omega: Vec<f64> = omega_all[def.first..def.end].to_vec();
        let mut x = match (def.vectors, lift) {
            (Some(v), Some(f)) => Some(f(v.as_ref())),
            (v, _) => v,
        };
        let m = omega.len();
        let mut timings = def.timings;
        let clock = Instant::now();
        let mut products = x
            .as_ref()
            .map(|x| PairProducts::new(a, b, x.as_ref(), self.options.residuals, idle.sketch_rows, self.par));
        // Values only: the a-priori error model (computed once, here or by `solve`).
        let mut a_priori = None;
        let mut report = match (&x, &products) {
            (Some(x), Some(p)) => AccuracyReport::from_products(p, x.as_ref(), &omega, self.norm_a, self.norm_b),
            _ => {
                let model = def
                    .a_priori
                    .unwrap_or_else(|| APrioriModel::new(self.l, self.norm_a, self.norm_b, self.par));
                a_priori = Some(model);
                AccuracyReport::a_priori(self.norm_a, self.norm_b, model.bounds(&omega))
            }
        };
        timings.accuracy += clock.elapsed();
        let clock = Instant::now();
        // Values only: the data resolution of the modes whose vectors were formed.
        let mut measured_resolution: Vec<(usize, f64)> = Vec::new();
        if let (Some(form), Some(model)) = (form.as_mut(), a_priori)
            && lift.is_none()
            && self.options.refinement == Refinement::Auto
        {
            let pencil = values_only::Pencil {
                a,
                b,
                l: self.l,
                residuals: self.options.residuals,
                par: self.par,
            };
            measured_resolution =
                values_only::sharpen(&pencil, model, form, &mut report, &mut omega, &omega_all, def.first);
        }
        // Refinement of poorly bounded modes (needs vectors in the original coordinates). A
        // condensed pencil is refined when its condensation is exact (diagonal A), in the metric
        // of the condensed pencil.
        let metric = match (lift.is_none(), self.condensation) {
            (true, _) => Some(Metric::Cholesky(crate::linalg::reduce::LowerFactor::new(self.l))),
            (false, Some(c)) => Some(Metric::Condensed(c)),
            (false, None) => None,
        };
        if let (Some(xm), Some(products), Some(metric)) = (x.as_mut(), products.as_mut(), metric)
            && self.options.refinement != Refinement::Off
        {
            let jobs: Vec<Range<usize>> = clusters(&omega, &report.error_bounds)
                .into_iter()
                .filter(|g| {
                    let wanted = self.options.refinement == Refinement::Always
                        || g.clone().any(|i| weakly_bounded(report.error_bounds[i], omega[i]));
                    wanted && refinable(g, &omega, &report.error_bounds, &omega_all, def.first)
                })
                .collect();
            let (mass, stiffness) = (Operand::new(a), Operand::new(b));
            let shifts = if jobs.is_empty() {
                None
            } else {
                SparseShifts::new(&mass, &stiffness)
            };
            // Clusters are independent: each is refined from its own columns of X, sequentially
            // inside, and the clusters are shared among the threads.
            let start = xm.as_ref();
            let refine_one = |g: &Range<usize>| {
                let x0 = start.subcols(g.start, g.len()).to_owned();
                let mut spectrum = def.reduced.as_ref().map(|y| ReducedSpectrum {
                    y: y.as_ref(),
                    omega_sq: &omega_all,
                    modes: def.first + g.start..def.first + g.end,
                });
                let correction = spectrum.as_mut().map(|s| s as &mut dyn ReducedCorrection);
                refine_cluster(
                    &mass,
                    &stiffness,
                    shifts.as_ref(),
                    metric,
                    correction,
                    x0.as_ref(),
                    omega[g.start],
                )
            };
            // Simple modes of a definite pencil are refined as one batch whose corrections are
            // block products ([`refine_simple_modes`]); a mode whose batch step fails, and
            // every cluster, takes its own path. A sparse pencil's simple modes take theirs at
            // once: a sparse bordered factorization per mode costs less than the batch's
            // products through Y (`refine::refine_pair_sparse`).
            let mut refined: Vec<Option<RefinedCluster>> = vec![None; jobs.len()];
            let mut pending: Vec<usize> = (0..jobs.len()).collect();
            if let (Metric::Cholesky(l), Some(y), None) = (metric, def.reduced.as_ref(), &shifts) {
                let singles: Vec<usize> = pending.iter().copied().filter(|&j| jobs[j].len() == 1).collect();
                if !singles.is_empty() {
                    let x0 = Mat::from_fn(n, singles.len(), |i, c| start[(i, jobs[singles[c]].start)]);
                    let modes: Vec<usize> = singles.iter().map(|&j| def.first + jobs[j].start).collect();
                    let pairs = refine_simple_modes(
                        &mass,
                        &stiffness,
                        l,
                        (y.as_ref(), &omega_all),
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
            let mut residuals: Vec<RefinedResidual> = Vec::new();
            let mut changed: Vec<usize> = Vec::new();
            for (g, cluster) in jobs.iter().zip(refined) {
                let Some(cluster) = cluster else { continue };
                for (i, p) in g.clone().zip(cluster.pairs) {
                    xm.col_as_slice_mut(i).copy_from_slice(&p.x);
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
            products.update_columns(a, b, xm.as_ref(), &changed, self.par);
            for &i in &changed {
                report.set_pair_error(products, xm.as_ref(), i, omega[i]);
            }
            split_refined_clusters(&mut residuals, &omega, &report.residual_norms_a_inv);
            let first_order = (report.error_bounds.clone(), report.bound_kinds.clone());
            self.residual_bounds(&mut report, &omega, &omega_all, def.first, &residuals, xm.as_ref());
            // Simple modes refined in double (the batch, the projected step) whose bound is still
            // weak: their residual is limited by rounding the vector; more projected steps with
            // a double-double iterate, kept where they lower the residual, and the bounds again.
            if let (Metric::Cholesky(_), Some(y), None) = (metric, def.reduced.as_ref(), &shifts) {
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
                        omega_sq: &omega_all,
                        modes: def.first + i..def.first + i + 1,
                    };
                    let steps = report.refinement_steps[i];
                    polish_simple_mode(&mass, &stiffness, metric, &mut spectrum, xm.col_as_slice(i), steps)
                };
                let polished: Vec<Option<RefinedPair>> = map_items(&weak, self.par, polish);
                let mut improved: Vec<usize> = Vec::new();
                for (&k, pair) in weak.iter().zip(polished) {
                    let i = residuals[k].mode;
                    let Some(p) = pair.filter(|p| Some(p.residual_a_inv) < report.residual_norms_a_inv[i]) else {
                        continue;
                    };
                    xm.col_as_slice_mut(i).copy_from_slice(&p.x);
                    omega[i] = p.omega_sq;
                    report.residual_norms_a_inv[i] = Some(p.residual_a_inv);
                    report.refinement_steps[i] = p.steps;
                    residuals[k].residual = p.residual;
                    improved.push(i);
                }
                if !improved.is_empty() {
                    products.update_columns(a, b, xm.as_ref(), &improved, self.par);
                    (report.error_bounds, report.bound_kinds) = first_order;
                    for &i in &improved {
                        report.set_pair_error(products, xm.as_ref(), i, omega[i]);
                    }
                    self.residual_bounds(&mut report, &omega, &omega_all, def.first, &residuals, xm.as_ref());
                }
            }
        }
        timings.refine = clock.elapsed();
        let clock = Instant::now();
        if let (Some(x), Some(p)) = (&x, products.as_mut()) {
            report.finish(p, a, x.as_ref(), &omega, self.par);
        }
        timings.accuracy += clock.elapsed();
        let clock = Instant::now();
        // The reduced eigenvectors are no longer needed: their storage takes the certificate's
        // matrix (a fresh n×n allocation costs its page faults).
        if let Some(storage) = def.reduced.or_else(|| form.map(TridiagonalForm::into_storage)) {
            scratch::give_back(storage);
        }
        report.inertia_check = inertia_check(
            self.problem,
            &omega_all,
            (def.first, def.end),
            &report.error_bounds,
            self.condensed_stiffness_negatives,
            idle.certificate,
            self.par,
        )?;
        timings.inertia = clock.elapsed();
        // What the data resolve: the zero classification allows for the rounding of A and B.
        let mut resolution: Vec<f64> = (0..m)
            .map(|i| match (&x, &a_priori) {
                (Some(x), _) => zero_resolution(a, b, x.col_as_slice(i), omega[i], (self.norm_a, self.norm_b)),
                (None, Some(model)) => model.data_resolution(omega[i]),
                (None, None) => 0.0,
            })
            .collect();
        for (i, value) in measured_resolution {
            resolution[i] = value;
        }
        if !self.options.vectors {
            x = None;
            report.backward_errors.iter_mut().for_each(|e| *e = None);
            report.orthogonality_error = None;
        }
        let mut modes: Vec<Mode> = (0..m)
            .map(|i| {
                let bound = report.error_bounds[i];
                Mode {
                    lambda: -omega[i],
                    omega_sq: omega[i],
                    kind: classify(omega[i], bound.max(resolution[i])),
                    error_bound: bound,
                    backward_error: report.backward_errors.get(i).copied().flatten(),
                    group: 0,
                }
            })
            .collect();
        let include_infinite = matches!(self.options.selection, Selection::All) && !infinite.is_empty();
        if include_infinite {
            for _ in &infinite {
                modes.push(Mode {
                    lambda: f64::NEG_INFINITY,
                    omega_sq: f64::INFINITY,
                    kind: ModeKind::Infinite,
                    error_bound: 0.0,
                    backward_error: None,
                    group: 0,
                });
            }
            if let Some(xf) = x.take() {
                let extra = infinite.len();
                x = Some(Mat::from_fn(n, m + extra, |r, c| {
                    if c < m { xf[(r, c)] } else { infinite[c - m][r] }
                }));
            }
        }
        let groups = group_modes(&mut modes);
        Ok(ModalSolution {
            modes,
            vectors: x,
            groups,
            accuracy: report,
            method,
            timings,
        })
    }
}
