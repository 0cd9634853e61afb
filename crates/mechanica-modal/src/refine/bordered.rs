//! Newton steps on the bordered system [[B − ω₀²A, −Ax₀], [−(Ax₀)ᵀ, 0]] with the Jacobian frozen
//! at the starting pair: factored densely (Bunch–Kaufman LBLᵀ), or, when A and B both have few
//! nonzeros, by a sparse factorization of B − ω₀²A (without fill on a forest pattern, else an
//! LU with partial pivoting) with the border eliminated by blocks.

use crate::dd::{Dd, Operand, SplitVector, dot, pair_residual};
use crate::refine::forest_factor::{ForestFactor, ForestPattern};
use crate::refine::metric::Metric;
use crate::refine::pair::{RefinedPair, finish_pair};
use crate::tuning::Tuning;
use faer::linalg::solvers::Solve;
use faer::{Mat, Side};

/// Refines (ω₀², x₀) by Newton steps on the bordered matrix [B − ω₀²A, −Ax₀; −(Ax₀)ᵀ, 0]
/// (nonsingular for a simple finite eigenvalue, also when A is singular), factored densely,
/// with the final residual measured in `metric`; None if the bordered matrix is singular to
/// working precision (the eigenvalue is not simple) or xᵀAx is not positive.
pub(crate) fn refine_pair(
    a: &Operand<'_>,
    b: &Operand<'_>,
    metric: Metric<'_>,
    x0: &[f64],
    omega0: f64,
) -> Option<RefinedPair> {
    let ax0: Vec<f64> = a.product(x0).iter().map(|v| v.to_f64()).collect();
    let jacobian = BorderedJacobian::dense(a, b, &ax0, omega0);
    let (x, steps, _) = newton_steps(a, b, metric, &jacobian, x0, omega0)?;
    finish_pair(a, b, metric, x, steps)
}

/// [`refine_pair`] for A and B with few nonzeros, the Jacobian factored sparsely
/// ([`BorderedJacobian::sparse`]): O(n) per mode on a forest pattern and O(n·w²) for a
/// bandwidth w otherwise, where the spectral correction of [`refine_cluster_projected`] costs
/// 4n² per step. The forest's factor without pivoting is tried first, rooted where x₀ is
/// largest, then the LU with partial pivoting. None if neither factorization gives converging
/// steps (then the other methods are tried).
pub(crate) fn refine_pair_sparse(
    a: &Operand<'_>,
    b: &Operand<'_>,
    shifts: &SparseShifts,
    metric: Metric<'_>,
    x0: &[f64],
    omega0: f64,
) -> Option<RefinedPair> {
    let ax0: Vec<f64> = a.product(x0).iter().map(|v| v.to_f64()).collect();
    let converged = |factor: ShiftedFactor| {
        let jacobian = BorderedJacobian::sparse(factor, &ax0)?;
        match newton_steps(a, b, metric, &jacobian, x0, omega0)? {
            (x, steps, true) => Some((x, steps)),
            _ => None,
        }
    };
    let largest = (0..x0.len())
        .max_by(|&i, &j| x0[i].abs().total_cmp(&x0[j].abs()))
        .unwrap_or(0);
    let (x, steps) = shifts
        .forest_factor(omega0, largest)
        .and_then(&converged)
        .or_else(|| shifts.lu(omega0).and_then(&converged))?;
    finish_pair(a, b, metric, x, steps)
}

/// K = B − sA for a pencil whose A and B both have few nonzeros: the union of their patterns
/// with both values on it, its LU symbolic analysis (column ordering, structure; formed at the
/// first LU, which a forest whose factors all succeed never needs) and, when the pattern is a
/// forest, its tree structure, found once for every shift of a refinement stage.
pub(crate) struct SparseShifts {
    pattern: faer::sparse::SymbolicSparseColMat<usize>,
    b_values: Vec<f64>,
    a_values: Vec<f64>,
    symbolic: std::sync::OnceLock<Option<faer::sparse::linalg::solvers::SymbolicLu<usize>>>,
    forest: Option<ForestPattern>,
}

impl SparseShifts {
    /// None when A or B is dense.
    pub(crate) fn new(a: &Operand<'_>, b: &Operand<'_>) -> Option<Self> {
        let n = a.matrix().nrows();
        let mut column_starts = Vec::with_capacity(n + 1);
        let (mut rows, mut b_values, mut a_values) = (Vec::new(), Vec::new(), Vec::new());
        column_starts.push(0);
        for j in 0..n {
            let (bj, aj) = (b.column_nonzeros(j)?, a.column_nonzeros(j)?);
            // The rows of B's and A's column j merged (both ascending).
            let (mut p, mut q) = (0, 0);
            while p < bj.len() || q < aj.len() {
                let row_b = bj.get(p).map_or(usize::MAX, |e| e.0);
                let row_a = aj.get(q).map_or(usize::MAX, |e| e.0);
                let row = row_b.min(row_a);
                rows.push(row);
                b_values.push(if row_b == row { bj[p].1 } else { 0.0 });
                a_values.push(if row_a == row { aj[q].1 } else { 0.0 });
                p += usize::from(row_b == row);
                q += usize::from(row_a == row);
            }
            column_starts.push(rows.len());
        }
        let pattern = faer::sparse::SymbolicSparseColMat::new_checked(n, n, column_starts, None, rows);
        let forest = ForestPattern::of(pattern.as_ref());
        Some(Self {
            pattern,
            b_values,
            a_values,
            symbolic: std::sync::OnceLock::new(),
            forest,
        })
    }

    /// The LU factorization with partial pivoting of B − shift·A; None if it or the symbolic
    /// analysis fails.
    fn lu(&self, shift: f64) -> Option<ShiftedFactor> {
        let values: Vec<f64> = self
            .b_values
            .iter()
            .zip(&self.a_values)
            .map(|(b, a)| b - shift * a)
            .collect();
        let k = faer::sparse::SparseColMatRef::new(self.pattern.as_ref(), &values);
        let symbolic = self
            .symbolic
            .get_or_init(|| faer::sparse::linalg::solvers::SymbolicLu::try_new(self.pattern.as_ref()).ok())
            .clone()?;
        let lu = faer::sparse::linalg::solvers::Lu::try_new_with_symbolic(symbolic, k).ok()?;
        Some(ShiftedFactor::Lu(Box::new(lu)))
    }

    /// The forest's LDLᵀ factorization of B − shift·A eliminated towards `root`; None when the
    /// pattern is not a forest or the factor is declined ([`ForestPattern::factor`]).
    fn forest_factor(&self, shift: f64, root: usize) -> Option<ShiftedFactor> {
        let forest = self.forest.as_ref()?;
        let factor = forest.factor(&self.b_values, &self.a_values, shift, root)?;
        Some(ShiftedFactor::Forest(factor))
    }
}

/// A factorization of K = B − ω₀²A for the sparse bordered Jacobian.
enum ShiftedFactor {
    Lu(Box<faer::sparse::linalg::solvers::Lu<usize, f64>>),
    Forest(ForestFactor),
}

impl ShiftedFactor {
    /// K⁻¹r.
    fn solve(&self, r: &[f64]) -> Vec<f64> {
        match self {
            Self::Lu(lu) => {
                let y = lu.solve(Mat::from_fn(r.len(), 1, |i, _| r[i]));
                y.col(0).iter().copied().collect()
            }
            Self::Forest(factor) => factor.solve(r),
        }
    }
}

/// Relative residual ‖r‖_{A⁻¹} / (|ω²|·‖x‖_A) below which a converged iterate is not improved
/// further: u^{3/4}. The refined bound is quadratic in the residual (Kato–Temple,
/// [`crate::certify::residual_bounds`]), ε²/δ for a gap δ, so at this residual it is below the
/// rounding u|ω²| of the reported value for every relative gap δ/|ω²| above √u.
pub(crate) const ACCURATE_RESIDUAL: f64 = 1.8e-12;

/// Newton steps of [`refine_pair`] with the frozen Jacobian `jacobian`: the iterate, the steps
/// taken and whether a step fell below the rounding of a double iterate; None if a step was not
/// finite. The iterate is kept in double-double. Once a step falls below the rounding of a
/// double iterate, the steps go on (to about u² of the iterate, while they still halve) only
/// while the residual, measured in `metric`, is above [`ACCURATE_RESIDUAL`]: a stiff mode's
/// residual is K·δx with ‖K‖ far above |ω²|, so a vector exact to double can still leave a
/// residual too large for the bound.
fn newton_steps(
    a: &Operand<'_>,
    b: &Operand<'_>,
    metric: Metric<'_>,
    jacobian: &BorderedJacobian,
    x0: &[f64],
    omega0: f64,
) -> Option<(SplitVector, usize, bool)> {
    let mut x = SplitVector::of(x0.to_vec());
    let mut omega = Dd::of(omega0);
    let mut converged = false;
    let mut previous = f64::INFINITY;
    for step in 1..=Tuning::DEFAULT.max_newton_steps {
        let bx = b.product_split(&x);
        let axd = a.product_split(&x);
        let mut residual = pair_residual(&axd, &bx, omega);
        if converged && accurate(metric, &residual, &x, &axd, omega.hi) {
            return Some((x, step - 1, true));
        }
        residual.iter_mut().for_each(|r| *r = -*r);
        // Normalisation residual: (Ax₀)ᵀx − 1, computed as x₀ᵀ(Ax) in double-double.
        let normalisation = dot(x0, &axd).minus(Dd::of(1.0)).to_f64();
        let (dx, d_omega) = jacobian.solve(residual, normalisation)?;
        let xmax = x.hi.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let dmax = dx.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        x.add(&dx);
        omega = omega.plus(Dd::of(d_omega));
        converged |= dmax <= 2.0 * f64::EPSILON * xmax && d_omega.abs() <= 2.0 * f64::EPSILON * omega.hi.abs();
        if converged && (dmax <= 4.0 * f64::EPSILON * f64::EPSILON * xmax || dmax > 0.5 * previous) {
            return Some((x, step, true));
        }
        previous = dmax;
    }
    Some((x, Tuning::DEFAULT.max_newton_steps, converged))
}

/// Whether the `residual` (B − ω²A)x of the iterate x (with A x = `ax`) is below
/// [`ACCURATE_RESIDUAL`] relative to |ω²|, in the norm the refined bound uses.
fn accurate(metric: Metric<'_>, residual: &[f64], x: &SplitVector, ax: &[Dd], omega_sq: f64) -> bool {
    let (_, norm) = metric.definite_residual(residual.to_vec());
    let xax: f64 = x.hi.iter().zip(ax).map(|(xi, axi)| xi * axi.hi).sum();
    xax > 0.0 && norm <= ACCURATE_RESIDUAL * omega_sq.abs() * xax.sqrt()
}

/// The Jacobian [K, −a; −aᵀ, 0] of [`refine_pair`] with K = B − ω₀²A and a = A x₀, factored
/// once in double precision.
enum BorderedJacobian {
    /// Bunch–Kaufman LBLᵀ of the dense matrix of order n + 1 ((n + 1)³/3 flops).
    Dense(faer::linalg::solvers::Lblt<f64>),
    /// A sparse factorization of K alone (the dense border row would fill the factors), the
    /// border by block elimination: K⁻¹a and aᵀK⁻¹a are formed once.
    Sparse {
        factor: ShiftedFactor,
        a: Vec<f64>,
        k_inv_a: Vec<f64>,
        schur: f64,
    },
}

impl BorderedJacobian {
    fn dense(a: &Operand<'_>, b: &Operand<'_>, ax0: &[f64], omega0: f64) -> Self {
        let n = ax0.len();
        let border = Mat::from_fn(n + 1, n + 1, |i, j| match (i < n, j < n) {
            (true, true) => b.matrix()[(i, j)] - omega0 * a.matrix()[(i, j)],
            (true, false) => -ax0[i],
            (false, true) => -ax0[j],
            (false, false) => 0.0,
        });
        Self::Dense(border.lblt(Side::Lower))
    }

    /// The border eliminated by blocks around a sparse `factor` of K = B − ω₀²A (O(n) on a
    /// forest, O(n·w²) for a bandwidth w, instead of (n + 1)³/3); None if it gives a non-finite
    /// K⁻¹a (K singular to working precision). Block elimination loses accuracy along K's
    /// near-null vector, which is x₀ itself; the Newton steps measure their residuals in
    /// double-double, and steps that do not converge are discarded ([`refine_pair_sparse`]).
    fn sparse(factor: ShiftedFactor, ax0: &[f64]) -> Option<Self> {
        let k_inv_a = factor.solve(ax0);
        let schur: f64 = ax0.iter().zip(&k_inv_a).map(|(u, v)| u * v).sum();
        if !(schur.is_finite() && schur != 0.0 && k_inv_a.iter().all(|v| v.is_finite())) {
            return None;
        }
        Some(Self::Sparse {
            factor,
            a: ax0.to_vec(),
            k_inv_a,
            schur,
        })
    }

    /// (δx, δω²) with K δx − a δω² = r and −aᵀδx = s; None if not finite.
    fn solve(&self, r: Vec<f64>, s: f64) -> Option<(Vec<f64>, f64)> {
        let n = r.len();
        let (dx, d_omega) = match self {
            Self::Dense(lblt) => {
                let rhs = Mat::from_fn(n + 1, 1, |i, _| if i < n { r[i] } else { s });
                let delta = lblt.solve(&rhs);
                ((0..n).map(|i| delta[(i, 0)]).collect::<Vec<f64>>(), delta[(n, 0)])
            }
            Self::Sparse {
                factor,
                a,
                k_inv_a,
                schur,
            } => {
                // δx = K⁻¹r + δω² K⁻¹a, and −aᵀδx = s gives δω².
                let y = factor.solve(&r);
                let a_y: f64 = a.iter().zip(&y).map(|(u, v)| u * v).sum();
                let d_omega = -(s + a_y) / schur;
                (
                    y.iter().zip(k_inv_a).map(|(yi, ki)| yi + d_omega * ki).collect(),
                    d_omega,
                )
            }
        };
        (dx.iter().all(|v| v.is_finite()) && d_omega.is_finite()).then_some((dx, d_omega))
    }
}
