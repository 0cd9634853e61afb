//! The accuracy report of a modal solve: backward errors, A-orthogonality, per-eigenvalue
//! error bounds and the Sturm (inertia) check.
//!
//! Norms ‖A‖, ‖B‖ are Frobenius norms (upper bounds of the 2-norms, so the bounds stay valid).
//! The residuals Bx − ω²Ax and XᵀAX − I are formed exactly ([`Residuals::Exact`]) or bounded
//! through Gaussian sketches ([`Residuals::Sketched`], see [`crate::certify::sketch`]).
//! For a pair (ω², x) with λ = −ω²:
//! - backward error η = ‖Bx + λAx‖ / ((‖B‖ + |λ|‖A‖)‖x‖) (Higham & Higham, "Structured backward
//!   error and condition of generalized eigenvalue problems", SIMAX 20, 1998);
//! - condition κ = (‖B‖ + |λ|‖A‖)‖x‖² / (xᵀAx) of a simple eigenvalue of a definite pencil, so
//!   that |Δλ| ≤ η κ to first order ([`BoundKind::FirstOrder`]);
//! - after refinement, with ε = ‖Bx + λAx‖_{A⁻¹}/‖x‖_A and a gap δ to the rest of the spectrum,
//!   |Δλ| ≤ min(ε, ε²/δ) (residual and Kato–Temple bounds, Parlett, "The Symmetric Eigenvalue
//!   Problem", §4.5 and §10.5, applied to L⁻¹(B)L⁻ᵀ) ([`BoundKind::Residual`]).

use crate::certify::products::{PairProducts, Residuals};
use crate::certify::sturm::InertiaCheck;
use faer::{MatRef, Par};

/// Where a mode's error bound comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BoundKind {
    /// η·κ from the pair's backward error and the eigenvalue's condition (first order).
    FirstOrder,
    /// n·u·(‖B‖ + |λ|‖A‖)·‖A⁻¹‖ assuming a backward error n·u (values only; no vectors), with
    /// ‖A⁻¹‖₂ bounded with probability ≥ 1 − 1e-12.
    APriori,
    /// Residual / Kato–Temple bound from an extended-precision residual (refined modes).
    Residual,
    /// An enclosure of the eigenvalue of the mode's rank by two inertia counts (Sylvester's
    /// law on B − sA eliminated in double-double), where A is diagonal and B's pattern a forest.
    Inertia,
}

/// Accuracy of every number of a [`crate::ModalSolution`]; per-mode vectors are in mode order.
#[derive(Debug, Clone, PartialEq)]
pub struct AccuracyReport {
    /// ‖A‖_F, or the largest double where the norm exceeds it (a pencil near 1e308).
    pub norm_a: f64,
    /// ‖B‖_F, or the largest double where the norm exceeds it.
    pub norm_b: f64,
    /// Backward error η of each pair (None for values only).
    pub backward_errors: Vec<Option<f64>>,
    /// max η over the pairs (None for values only or no pairs).
    pub max_backward_error: Option<f64>,
    /// max |(XᵀAX − I)_ij| over the finite modes (None for values only).
    pub orthogonality_error: Option<f64>,
    /// Bound on |ω²_computed − ω²_exact| of each mode.
    pub error_bounds: Vec<f64>,
    /// Where each bound comes from.
    pub bound_kinds: Vec<BoundKind>,
    /// ‖Bx + λAx‖_{A⁻¹}/‖x‖_A in extended precision, for refined modes.
    pub residual_norms_a_inv: Vec<Option<f64>>,
    /// Refinement steps taken per mode (0: not refined).
    pub refinement_steps: Vec<usize>,
    /// The Sturm check: LBLᵀ inertia of B − sA against the computed spectrum.
    pub inertia_check: Option<InertiaCheck>,
    /// How the backward errors and the orthogonality error were measured.
    pub residuals: Residuals,
}

impl AccuracyReport {
    /// Reorders the per-mode entries: entry k becomes the old entry `order[k]`.
    pub(crate) fn permute(&mut self, order: &[usize]) {
        fn take<T: Copy>(v: &mut Vec<T>, order: &[usize]) {
            if v.len() == order.len() {
                *v = order.iter().map(|&k| v[k]).collect();
            }
        }
        take(&mut self.backward_errors, order);
        take(&mut self.error_bounds, order);
        take(&mut self.bound_kinds, order);
        take(&mut self.residual_norms_a_inv, order);
        take(&mut self.refinement_steps, order);
    }

    /// Keeps the per-mode entries of the first `k` modes.
    pub(crate) fn truncate(&mut self, k: usize) {
        self.backward_errors.truncate(k);
        self.error_bounds.truncate(k);
        self.bound_kinds.truncate(k);
        self.residual_norms_a_inv.truncate(k);
        self.refinement_steps.truncate(k);
    }

    pub(crate) fn empty() -> Self {
        Self {
            norm_a: 0.0,
            norm_b: 0.0,
            backward_errors: Vec::new(),
            max_backward_error: None,
            orthogonality_error: None,
            error_bounds: Vec::new(),
            bound_kinds: Vec::new(),
            residual_norms_a_inv: Vec::new(),
            refinement_steps: Vec::new(),
            inertia_check: None,
            residuals: Residuals::Exact,
        }
    }

    pub(crate) fn a_priori(norm_a: f64, norm_b: f64, bounds: Vec<f64>) -> Self {
        let m = bounds.len();
        Self {
            norm_a,
            norm_b,
            backward_errors: vec![None; m],
            max_backward_error: None,
            orthogonality_error: None,
            error_bounds: bounds,
            bound_kinds: vec![BoundKind::APriori; m],
            residual_norms_a_inv: vec![None; m],
            refinement_steps: vec![0; m],
            inertia_check: None,
            residuals: Residuals::Exact,
        }
    }

    /// Whether every backward error is at most 10·n·u (n the order): the level of a backward
    /// stable solve.
    pub fn meets_backward_error_target(&self, n: usize) -> bool {
        self.max_backward_error
            .is_some_and(|e| e <= 10.0 * n as f64 * f64::EPSILON)
    }
}

impl AccuracyReport {
    /// Backward errors and first-order bounds of every pair from `products` (max η and the
    /// orthogonality are left to [`AccuracyReport::finish`], once the vectors are final).
    pub(crate) fn from_products(
        products: &PairProducts,
        x: MatRef<'_, f64>,
        omega_sq: &[f64],
        norm_a: f64,
        norm_b: f64,
    ) -> Self {
        let m = omega_sq.len();
        let mut report = Self::a_priori(norm_a, norm_b, vec![0.0; m]);
        report.bound_kinds = vec![BoundKind::FirstOrder; m];
        if matches!(products, PairProducts::Sketched { .. }) {
            report.residuals = Residuals::Sketched;
        }
        for i in 0..m {
            report.set_pair_error(products, x, i, omega_sq[i]);
        }
        report
    }

    /// Recomputes η and the first-order bound of pair i.
    pub(crate) fn set_pair_error(&mut self, products: &PairProducts, x: MatRef<'_, f64>, i: usize, omega_sq: f64) {
        let (eta, bound) = products.pair_error(x, i, omega_sq, self.norm_a, self.norm_b);
        self.backward_errors[i] = Some(eta);
        self.error_bounds[i] = bound;
    }

    /// Sets the A-orthogonality error and max η once the vectors are final. Sketched, the
    /// first-order bounds of unrefined modes are recomputed with the final orthogonality bound.
    pub(crate) fn finish(
        &mut self,
        products: &mut PairProducts,
        a: MatRef<'_, f64>,
        x: MatRef<'_, f64>,
        omega_sq: &[f64],
        par: Par,
    ) {
        let m = x.ncols();
        self.orthogonality_error = (m > 0).then(|| products.orthogonality_error(a, x, par));
        if matches!(products, PairProducts::Sketched { .. }) {
            for i in 0..m {
                if self.bound_kinds[i] == BoundKind::FirstOrder {
                    self.set_pair_error(products, x, i, omega_sq[i]);
                }
            }
        }
        self.max_backward_error = (m > 0).then(|| self.backward_errors.iter().flatten().copied().fold(0.0, f64::max));
        self.add_rounding_allowance(x.nrows());
    }

    /// The first-order bounds max(η, u)·κ become (η + 2u)·κ: the residual behind η is formed in
    /// double, so the measured η of an accurate pair is itself mostly rounding and can fall short
    /// of the exact one by about its own size; 2u covers that and the rounding of the reported ω²
    /// (a fixed allowance, not a proof: the proved bounds are the residual ones of refined modes).
    fn add_rounding_allowance(&mut self, n: usize) {
        self.error_bounds = (0..self.error_bounds.len())
            .map(|i| self.bound_with_rounding(i, n))
            .collect();
    }

    /// Mode i's bound as it will be reported, with the rounding allowance of
    /// [`AccuracyReport::finish`] on a first-order bound (n: the order of the pencil).
    pub(crate) fn bound_with_rounding(&self, i: usize, n: usize) -> f64 {
        let bound = self.error_bounds[i];
        match (self.bound_kinds[i], self.backward_errors.get(i)) {
            (BoundKind::FirstOrder, Some(Some(eta))) => {
                let _ = n;
                bound * ((eta + 2.0 * f64::EPSILON) / eta.max(f64::EPSILON))
            }
            _ => bound,
        }
    }
}
