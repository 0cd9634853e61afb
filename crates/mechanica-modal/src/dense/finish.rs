//! The common tail of every dense solve: the accuracy report, refinement of weakly bounded
//! modes ([`crate::dense::refinement`]), the Sturm check, classification and grouping.

use crate::certify::a_priori::APrioriModel;
use crate::certify::forest::ForestPencil;
use crate::certify::inertia::stiffness_is_definite;
use crate::certify::products::PairProducts;
use crate::certify::report::{AccuracyReport, BoundKind};
use crate::certify::resolution::{data_resolutions, normwise_resolution};
use crate::certify::sketch::SketchRows;
use crate::certify::sturm::inertia_check;
use crate::dense::definite::Definite;
use crate::dense::idle_inputs::IdleResults;
use crate::dense::options::{Refinement, Selection, SolveOptions, weakly_bounded};
use crate::dense::refinement::Stage;
use crate::dense::solution::{Method, ModalSolution};
use crate::dense::values_only;
use crate::error::ModalError;
use crate::linalg::eigen::TridiagonalForm;
use crate::linalg::reduce::LowerFactor;
use crate::problem::PencilProblem;
use crate::refine::{Condensation, Metric};
use crate::runtime::scratch;
use crate::spectrum::{Mode, ModeKind, classify, group_modes};
use faer::{Mat, MatRef, Par};
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
        let Definite {
            omega_sq: omega_all,
            first,
            end,
            vectors,
            reduced,
            mut form,
            a_priori,
            mut timings,
            estimates,
        } = def;
        let mut omega: Vec<f64> = omega_all[first..end].to_vec();
        let mut x = match (vectors, lift) {
            (Some(v), Some(f)) => Some(f(v.as_ref())),
            (v, _) => v,
        };
        let clock = Instant::now();
        let (mut products, mut report, a_priori) = self.first_report(x.as_ref(), &omega, a_priori, idle.sketch_rows);
        timings.accuracy += clock.elapsed();
        let clock = Instant::now();
        // Values only: the data resolution of the modes whose vectors were formed.
        let mut measured_resolution: Vec<(usize, f64)> = Vec::new();
        if let (Some(form), Some(model)) = (form.as_mut(), a_priori)
            && lift.is_none()
            && self.options.refinement == Refinement::Auto
        {
            measured_resolution = self.sharpen(model, form, &mut report, &mut omega, &omega_all, first);
        }
        if let (Some(xm), Some(products), Some(metric)) = (x.as_mut(), products.as_mut(), self.metric(lift.is_none()))
            && self.options.refinement != Refinement::Off
        {
            let mut stage = self.refinement_stage(metric, &omega_all, first, reduced.as_ref());
            stage.estimates = estimates.as_deref().map(|e| &e[first..end]);
            stage.run(xm, products, &mut report, &mut omega);
        }
        timings.refine = clock.elapsed();
        let clock = Instant::now();
        if self.options.refinement != Refinement::Always && x.is_some() {
            self.widen_unrefined_bounds(&mut report, &omega, a_priori);
        }
        if let (Some(x), Some(p)) = (&x, products.as_mut()) {
            report.finish(p, self.problem.a(), x.as_ref(), &omega, self.par);
        }
        timings.accuracy += clock.elapsed();
        let clock = Instant::now();
        // The reduced eigenvectors are no longer needed: their storage takes the certificate's
        // matrix (a fresh n×n allocation costs its page faults).
        if let Some(storage) = reduced.or_else(|| form.map(TridiagonalForm::into_storage)) {
            scratch::give_back(storage);
        }
        report.inertia_check = inertia_check(
            self.problem,
            &omega_all,
            (first, end),
            &report.error_bounds,
            self.condensed_stiffness_negatives,
            idle.certificate,
            self.par,
        )?;
        if self.options.refinement != Refinement::Off {
            enclose_weak_modes_by_forest_counts(self.problem, &mut report, &omega, first);
        }
        timings.inertia = clock.elapsed();
        let mut measured = vec![None; omega.len()];
        for (i, value) in measured_resolution {
            measured[i] = Some(value);
        }
        let mut modes = finite_modes(&omega, &report);
        sort_ascending(&mut modes, &mut report, &mut measured, x.as_mut());
        widen_overlapping_estimates(&mut modes, &mut report);
        let resolution = self.resolution(x.as_ref(), &modes, &measured);
        for (mode, &r) in modes.iter_mut().zip(&resolution) {
            mode.kind = classify(mode.omega_sq, mode.error_bound, r);
        }
        let whole = matches!(self.options.selection, Selection::All | Selection::Lowest(_));
        zero_on_null_columns(
            self.problem.b(),
            x.as_ref().map(|x| x.as_ref()),
            &mut modes,
            first == 0 && whole,
        );
        if !self.options.vectors {
            x = None;
            report.backward_errors.iter_mut().for_each(|e| *e = None);
            report.orthogonality_error = None;
            modes.iter_mut().for_each(|m| m.backward_error = None);
        }
        order_above_positive_modes(&mut modes);
        certify_positive_stiffness(self.problem, &mut modes, self.par);
        sign_undecided_by_forest_counts(self.problem, &mut modes, first);
        if matches!(self.options.selection, Selection::All) && !infinite.is_empty() {
            x = append_infinite(&mut modes, x, &infinite);
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

    /// The report before refinement: with vectors, the pair products and the first-order bounds
    /// they give; values only, the a-priori bounds of the error model (`a_priori`, when the
    /// solve computed it already, else computed here), which is returned for later use.
    fn first_report(
        &self,
        x: Option<&Mat<f64>>,
        omega: &[f64],
        a_priori: Option<APrioriModel>,
        sketch_rows: Option<SketchRows>,
    ) -> (Option<PairProducts>, AccuracyReport, Option<APrioriModel>) {
        let (a, b) = (self.problem.a(), self.problem.b());
        let products = x.map(|x| PairProducts::new(a, b, x.as_ref(), self.options.residuals, sketch_rows, self.par));
        let mut model_used = None;
        let report = match (x, &products) {
            (Some(x), Some(p)) => AccuracyReport::from_products(p, x.as_ref(), omega, self.norm_a, self.norm_b),
            _ => {
                let model = a_priori.unwrap_or_else(|| APrioriModel::new(self.l, self.norm_a, self.norm_b, self.par));
                model_used = Some(model);
                AccuracyReport::a_priori(self.norm_a, self.norm_b, model.bounds(omega))
            }
        };
        (products, report, model_used)
    }

    /// A mode left unrefined (`Refinement::Off`, or beyond the budget of `Refinement::Auto`)
    /// whose first-order bound guarantees fewer than 8 digits belongs to a
    /// mode near the reduction's error level, where the first-order theory (a simple eigenvalue
    /// whose perturbation stays below its gaps) need not hold: such a bound is raised to the
    /// a-priori bound of the reduction ([`APrioriModel`]), a Weyl bound that needs no gap.
    fn widen_unrefined_bounds(&self, report: &mut AccuracyReport, omega: &[f64], a_priori: Option<APrioriModel>) {
        let n = self.problem.dim();
        let weak: Vec<usize> = (0..omega.len())
            .filter(|&i| {
                report.bound_kinds[i] == BoundKind::FirstOrder
                    && weakly_bounded(report.bound_with_rounding(i, n), omega[i])
            })
            .collect();
        if weak.is_empty() {
            return;
        }
        let model = a_priori.unwrap_or_else(|| APrioriModel::new(self.l, self.norm_a, self.norm_b, self.par));
        for i in weak {
            let weyl = model.bound(omega[i]);
            if weyl > report.bound_with_rounding(i, n) {
                report.error_bounds[i] = weyl;
                report.bound_kinds[i] = BoundKind::APriori;
            }
        }
    }

    /// Values only: [`values_only::sharpen`] of the report from the error model `model`;
    /// returns the data resolution of the modes whose vectors were formed.
    fn sharpen(
        &self,
        model: APrioriModel,
        form: &mut TridiagonalForm,
        report: &mut AccuracyReport,
        omega: &mut [f64],
        omega_all: &[f64],
        first: usize,
    ) -> Vec<(usize, f64)> {
        let pencil = values_only::Pencil {
            a: self.problem.a(),
            b: self.problem.b(),
            l: self.l,
            residuals: self.options.residuals,
            par: self.par,
        };
        values_only::sharpen(&pencil, model, form, report, omega, omega_all, first)
    }

    /// The refinement stage of this solve, refining in `metric`.
    fn refinement_stage<'s>(
        &'s self,
        metric: Metric<'s>,
        omega_all: &'s [f64],
        first: usize,
        reduced: Option<&'s Mat<f64>>,
    ) -> Stage<'s> {
        Stage {
            a: self.problem.a(),
            b: self.problem.b(),
            l: self.l,
            condensation: self.condensation,
            policy: self.options.refinement,
            metric,
            omega_all,
            first,
            reduced,
            estimates: None,
            par: self.par,
        }
    }

    /// The pencil in which modes are refined: (B, A) through L when no lift is needed, the
    /// condensed pencil when its condensation is exact (diagonal A), else none.
    fn metric(&self, unlifted: bool) -> Option<Metric<'_>> {
        match (unlifted, self.condensation) {
            (true, _) => Some(Metric::Cholesky(LowerFactor::new(self.l))),
            (false, Some(c)) => Some(Metric::Condensed(c)),
            (false, None) => None,
        }
    }

    /// What the data resolve of each (sorted, widened) mode, for the zero classification: the
    /// `measured` value (values only: modes whose vectors were formed); else, with shapes, the
    /// componentwise [`data_resolutions`] wherever the class depends on it (|ω²| within the
    /// cheap normwise value, or within its final bound) and the normwise value elsewhere; else
    /// zero. Without a shape only the normwise value is known, an overestimate by up to the
    /// grading of the data that could call zero what the data resolve, so a mode that was not
    /// measured is never called zero.
    fn resolution(&self, x: Option<&Mat<f64>>, modes: &[Mode], measured: &[Option<f64>]) -> Vec<f64> {
        let mut resolution: Vec<f64> = modes
            .iter()
            .enumerate()
            .map(|(i, mode)| match (measured[i], x) {
                (Some(value), _) => value,
                (None, Some(x)) if i < x.ncols() => {
                    let shape_norm_sq = x.col(i).iter().map(|v| v * v).sum::<f64>();
                    normwise_resolution(mode.omega_sq, self.norm_a, self.norm_b, shape_norm_sq)
                }
                (None, _) => 0.0,
            })
            .collect();
        let Some(x) = x else { return resolution };
        let depends = |i: usize| {
            measured[i].is_none() && i < x.ncols() && modes[i].omega_sq.abs() <= resolution[i].max(modes[i].error_bound)
        };
        let columns: Vec<usize> = (0..modes.len()).filter(|&i| depends(i)).collect();
        let values: Vec<f64> = columns.iter().map(|&i| modes[i].omega_sq).collect();
        let (a, b) = (self.problem.a(), self.problem.b());
        for (&i, r) in columns
            .iter()
            .zip(data_resolutions(a, b, x.as_ref(), &columns, &values, self.par))
        {
            resolution[i] = r;
        }
        resolution
    }
}

/// The finite modes from their values, bounds and backward errors, not yet classified
/// (undecided until their bounds are final).
fn finite_modes(omega: &[f64], report: &AccuracyReport) -> Vec<Mode> {
    (0..omega.len())
        .map(|i| {
            let bound = report.error_bounds[i];
            Mode {
                lambda: -omega[i],
                omega_sq: omega[i],
                kind: ModeKind::Undecided,
                error_bound: bound,
                backward_error: report.backward_errors.get(i).copied().flatten(),
                group: 0,
            }
        })
        .collect()
}

/// Puts the finite modes in ascending order of ω², with their report entries, measured
/// resolutions and vector columns: refinement moves values by up to their first-order bounds,
/// which can exceed the distance between neighbours (wide-range pencils), and every later step
/// relies on the order.
fn sort_ascending(
    modes: &mut Vec<Mode>,
    report: &mut AccuracyReport,
    measured: &mut Vec<Option<f64>>,
    x: Option<&mut Mat<f64>>,
) {
    if modes.is_sorted_by(|p, q| p.omega_sq <= q.omega_sq) {
        return;
    }
    let mut order: Vec<usize> = (0..modes.len()).collect();
    order.sort_by(|&p, &q| modes[p].omega_sq.total_cmp(&modes[q].omega_sq));
    *modes = order.iter().map(|&k| modes[k]).collect();
    *measured = order.iter().map(|&k| measured[k]).collect();
    report.permute(&order);
    if let Some(x) = x {
        let old = x.clone();
        for (k, &from) in order.iter().enumerate().filter(|&(k, &from)| k.max(from) < old.ncols()) {
            x.col_mut(k).copy_from(old.col(from));
        }
    }
}

/// Makes the unrefined bounds (first-order and a-priori) hold for the mode of the same rank: a
/// run of modes whose intervals ω² ± bound overlap is one cluster, and its exact values can only
/// be matched to its members as a set, so each unrefined member's bound is widened to reach both
/// ends of the cluster (a mode with a tight interval inside a wide neighbour's may otherwise
/// stand for an eigenvalue of another rank). The modes are classified afterwards, with these
/// bounds.
fn widen_overlapping_estimates(modes: &mut [Mode], report: &mut AccuracyReport) {
    let mut start = 0;
    while start < modes.len() {
        let mut end = start + 1;
        let mut reach = modes[start].omega_sq + modes[start].error_bound;
        while end < modes.len() && modes[end].omega_sq - modes[end].error_bound <= reach {
            reach = reach.max(modes[end].omega_sq + modes[end].error_bound);
            end += 1;
        }
        let low = modes[start..end]
            .iter()
            .map(|m| m.omega_sq - m.error_bound)
            .fold(f64::INFINITY, f64::min);
        let rank_proven = |k: usize| matches!(report.bound_kinds[k], BoundKind::Residual | BoundKind::Inertia);
        for k in (start..end).filter(|&k| end - start > 1 && !rank_proven(k)) {
            let mode = &mut modes[k];
            let widened = (mode.omega_sq - low).max(reach - mode.omega_sq).max(mode.error_bound);
            if widened > mode.error_bound {
                mode.error_bound = widened;
                report.error_bounds[k] = widened;
            }
        }
        start = end;
    }
}

/// Zero modes proven by the columns of B that are exactly zero (a joint no potential depends
/// on: a robot's vertical first axis under gravity, a wrist turning about a line through its
/// load's centre of mass), where the data's resolution is itself zero and the solve's bound of
/// the order of 1e-60 would leave the mode undecided. With z such columns e_j, B e_j = 0 and the
/// pencil has at least z exact zero eigenvalues, each at a rank whose interval contains zero:
/// - when the selection starts at the bottom of the spectrum (`from_bottom`), its last mode lies
///   above zero or it holds every mode, and no more than z of its modes have intervals that
///   contain zero, every one of those modes is an exact zero;
/// - otherwise, an undecided mode whose shape x vanishes outside those columns is: Bx = 0
///   exactly, so (0, x) is an exact eigenpair, the one the mode stands for.
///
/// Bounds are kept (they contain zero).
fn zero_on_null_columns(b: MatRef<'_, f64>, x: Option<MatRef<'_, f64>>, modes: &mut [Mode], from_bottom: bool) {
    let contains_zero =
        |m: &Mode| matches!(m.kind, ModeKind::Undecided | ModeKind::Zero) && m.omega_sq.abs() <= m.error_bound;
    if !modes.iter().any(|m| m.kind == ModeKind::Undecided) {
        return;
    }
    let n = b.nrows();
    let null_column: Vec<bool> = (0..n).map(|j| (0..n).all(|i| b[(i, j)] == 0.0)).collect();
    let null_dimension = null_column.iter().filter(|&&z| z).count();
    if null_dimension == 0 {
        return;
    }
    let above_zero = |m: &Mode| m.omega_sq - m.error_bound > 0.0;
    let all_zeros_selected = from_bottom && (modes.len() == n || modes.last().is_some_and(above_zero));
    if all_zeros_selected && modes.iter().filter(|m| contains_zero(m)).count() <= null_dimension {
        for mode in modes.iter_mut().filter(|m| contains_zero(m)) {
            mode.kind = ModeKind::Zero;
        }
        return;
    }
    let Some(x) = x else { return };
    for (k, mode) in modes.iter_mut().enumerate().filter(|(k, _)| *k < x.ncols()) {
        let on_null_columns = (0..n).all(|i| x[(i, k)] == 0.0 || null_column[i]);
        let moves = (0..n).any(|i| x[(i, k)] != 0.0);
        if mode.kind == ModeKind::Undecided && contains_zero(mode) && on_null_columns && moves {
            mode.kind = ModeKind::Zero;
        }
    }
}

/// A mode called zero or undecided above an oscillatory mode whose interval lies entirely above
/// zero: the
/// modes are in ascending order (the order the Sturm check certifies), so its exact ω² is at
/// least that positive one's, and the mode is oscillatory (an unrefined mode with a wide bound
/// above refined low modes).
fn order_above_positive_modes(modes: &mut [Mode]) {
    let mut positive_below = false;
    for mode in modes.iter_mut() {
        if positive_below && matches!(mode.kind, ModeKind::Zero | ModeKind::Undecided) {
            mode.kind = ModeKind::Oscillatory {
                omega: mode.omega_sq.max(0.0).sqrt(),
            };
        }
        // Only a resolved mode counts: one within the data's resolution is zero whatever its
        // bound says of the stored numbers.
        positive_below |= matches!(mode.kind, ModeKind::Oscillatory { .. }) && mode.omega_sq - mode.error_bound > 0.0;
    }
}

/// A mode the data resolution or its bound would call zero, or unstable, when B itself is
/// positive definite ([`stiffness_is_definite`]): Sylvester's law then puts every finite ω²
/// above zero, so the mode is oscillatory. The Cholesky factorization of B is paid only when
/// such a mode is present.
fn certify_positive_stiffness(problem: &PencilProblem, modes: &mut [Mode], par: Par) {
    let doubtful = |m: &Mode| matches!(m.kind, ModeKind::Zero | ModeKind::Unstable { .. } | ModeKind::Undecided);
    if !modes.iter().any(doubtful) || !stiffness_is_definite(problem, par) {
        return;
    }
    modes
        .iter_mut()
        .filter(|m| doubtful(m))
        .for_each(Mode::set_proven_oscillatory);
}

/// Decides the sign of undecided modes where A is diagonal and positive and B's pattern is a
/// forest: the mode of ascending index k = `first` + its position is oscillatory when the count
/// at s = ω²/2 > 0 proves at most k eigenvalues below s − m > 0, unstable when the count at
/// s = ω²/2 < 0 proves at least k + 1 below s + m < 0 ([`ForestPencil::count_below`],
/// Sylvester's law of inertia; the forest is formed once). Its interval is left as it is.
fn sign_undecided_by_forest_counts(problem: &PencilProblem, modes: &mut [Mode], first: usize) {
    if !modes.iter().any(|m| m.kind == ModeKind::Undecided) {
        return;
    }
    let Some(pencil) = ForestPencil::new(problem.a(), problem.b()) else {
        return;
    };
    for (position, mode) in modes.iter_mut().enumerate() {
        if mode.kind != ModeKind::Undecided {
            continue;
        }
        let (k, shift) = (first + position, 0.5 * mode.omega_sq);
        if shift == 0.0 {
            continue;
        }
        let Some(count) = pencil.count_below(shift) else {
            continue;
        };
        if shift > 0.0 && shift - count.margin > 0.0 && count.below <= k {
            mode.kind = ModeKind::Oscillatory {
                omega: mode.omega_sq.sqrt(),
            };
        } else if shift < 0.0 && shift + count.margin < 0.0 && count.below > k {
            mode.kind = ModeKind::Unstable {
                growth_rate: (-mode.omega_sq).sqrt(),
            };
        }
    }
}

/// Replaces the bound of each refined mode still weakly bounded ([`weakly_bounded`]) by an
/// inertia enclosure of the eigenvalue of its rank where that is tighter
/// ([`ForestPencil::enclose`]; A diagonal and positive, B's pattern a forest): the rank of ω²_i
/// is `first` plus its place among the selected values in ascending order. Residual bounds of
/// refined modes near the reduction's error level (low modes of graded chains of a thousand
/// masses) can exceed the value itself, although the value is right, and a refinement whose
/// residual interval could not be accepted keeps the reduction's bound; the counts place those
/// eigenvalues to a few units of 2⁻⁴⁸ relative where the pencil's margins allow. Modes left
/// unrefined (beyond the budget of `Refinement::Auto`) are not offered: their values are not
/// accurate enough for a narrow enclosure, and up to eight O(n) counts each would cost more
/// than their refinement. Classification follows the new bound.
fn enclose_weak_modes_by_forest_counts(
    problem: &PencilProblem,
    report: &mut AccuracyReport,
    omega: &[f64],
    first: usize,
) {
    let mut weak: Vec<usize> = (0..omega.len())
        .filter(|&i| report.refinement_steps[i] > 0 && weakly_bounded(report.error_bounds[i], omega[i]))
        .collect();
    if weak.is_empty() {
        return;
    }
    let Some(pencil) = ForestPencil::new(problem.a(), problem.b()) else {
        return;
    };
    let mut order: Vec<usize> = (0..omega.len()).collect();
    order.sort_by(|&p, &q| omega[p].total_cmp(&omega[q]));
    let mut rank = vec![0; omega.len()];
    for (place, &i) in order.iter().enumerate() {
        rank[i] = first + place;
    }
    // Ascending, so that each shifted margin starts its search where the last one ended.
    weak.sort_by(|&p, &q| omega[p].total_cmp(&omega[q]));
    let mut start = 0.5_f64;
    for i in weak {
        let relative = pencil.relative_margin(omega[i].max(0.0), (1024.0 * start).min(0.5));
        start = relative.map_or(start, |m| m.floor);
        if let Some(bound) = pencil.enclose(rank[i], omega[i], relative)
            && bound < report.error_bounds[i]
        {
            report.error_bounds[i] = bound;
            report.bound_kinds[i] = BoundKind::Inertia;
        }
    }
}

/// Appends the infinite modes (unit null vectors of A, exact) after the finite ones, and their
/// shapes after the finite shapes `x` (when shapes are returned).
fn append_infinite(modes: &mut Vec<Mode>, x: Option<Mat<f64>>, infinite: &[Vec<f64>]) -> Option<Mat<f64>> {
    let m = modes.len();
    for _ in infinite {
        modes.push(Mode {
            lambda: f64::NEG_INFINITY,
            omega_sq: f64::INFINITY,
            kind: ModeKind::Infinite,
            error_bound: 0.0,
            backward_error: None,
            group: 0,
        });
    }
    x.map(|xf| {
        let (n, extra) = (xf.nrows(), infinite.len());
        Mat::from_fn(n, m + extra, |r, c| if c < m { xf[(r, c)] } else { infinite[c - m][r] })
    })
}
