//! The certified bounds of the refined sparse pairs: double-double Rayleigh quotients and
//! residuals, the residual solved with K (δ = ‖s‖_{K⁻¹}/‖x‖_K), and the Kato–Temple and cluster
//! bounds made rigorous by the inertia count at τ.

use crate::dd::{self, Dd};
use crate::linalg::norms::{euclidean_norm, sqrt_of_dot, square_over};
use crate::sparse::inertia::SparseInertiaCount;
use crate::sparse::operator::{Mass, Operator, dot, product, solve_with};
use crate::sparse::pencil::{SparsePencil, abs_quadratic};
use crate::sparse::rayleigh_ritz::Refined;
use crate::sparse::solution::{SparseAccuracyReport, SparseModalSolution, SparseSolveTimings};
use crate::spectrum::{Mode, classify, group_modes};
use faer::Mat;
use faer::sparse::linalg::cholesky::SymbolicCholesky;
use std::time::{Duration, Instant};

/// What the bounds of the refined pairs need: each Rayleigh quotient and its rounding, θ, the
/// first-order θ bound δ and the backward error η; and what the classification needs, the
/// data resolution of each ω² ([`crate::certify::resolution::data_resolution`]).
pub(crate) struct PairResiduals {
    omega_sq: Vec<f64>,
    theta: Vec<f64>,
    delta: Vec<f64>,
    eta: Vec<f64>,
    rounding: Vec<f64>,
    resolution: Vec<f64>,
}

/// The residuals of every refined pair: Rayleigh quotients and residuals in double-double, the
/// residual s = Ax − θKx solved with K (δ = ‖s‖_{K⁻¹}/‖x‖_K). With `two_threads` each thread
/// takes half of the pairs.
pub(crate) fn pair_residuals(
    pencil: &SparsePencil,
    op: &mut Operator<'_>,
    refined: &Refined,
    sigma: f64,
    norms: (f64, f64),
    two_threads: bool,
) -> PairResiduals {
    let cols = refined.omega_sq.len();
    let (symbolic, values) = (op.symbolic, op.values.as_slice());
    let max_row = row_lengths(pencil.a()).max(row_lengths(pencil.b())) as f64;
    let shared = ResidualInputs {
        pencil,
        factor: (symbolic, values),
        refined,
        sigma,
        norms,
        max_row,
    };
    let (residuals, solve_time) = if two_threads && cols > 1 {
        let half = cols / 2;
        let work = &mut op.work;
        let (first, second) = std::thread::scope(|scope| {
            let second =
                std::thread::Builder::new().spawn_scoped(scope, || residuals_of(&shared, half..cols, &mut Vec::new()));
            let first = residuals_of(&shared, 0..half, work);
            (first, second.ok().and_then(|s| s.join().ok()))
        });
        // (No thread could be created, or it panicked, a bug: the pairs are then done here.)
        let second = second.unwrap_or_else(|| residuals_of(&shared, half..cols, work));
        let ((mut first, first_time), (second, second_time)) = (first, second);
        first.append(second);
        // The two halves' solves ran at the same time: the stage took the longer one.
        (first, first_time.max(second_time))
    } else {
        residuals_of(&shared, 0..cols, &mut op.work)
    };
    op.applications += cols;
    op.solve_time += solve_time;
    residuals
}

/// What every range of [`residuals_of`] reads.
struct ResidualInputs<'a> {
    pencil: &'a SparsePencil,
    /// The symbolic and numeric Cholesky factor of K.
    factor: (&'a SymbolicCholesky<usize>, &'a [f64]),
    refined: &'a Refined,
    sigma: f64,
    /// (‖A‖_F, ‖B‖_F).
    norms: (f64, f64),
    /// The longest row of A or B (entries), for the rounding term.
    max_row: f64,
}

impl PairResiduals {
    /// Appends the pairs of `other` after those of `self`.
    fn append(&mut self, other: PairResiduals) {
        self.omega_sq.extend(other.omega_sq);
        self.theta.extend(other.theta);
        self.delta.extend(other.delta);
        self.eta.extend(other.eta);
        self.rounding.extend(other.rounding);
        self.resolution.extend(other.resolution);
    }
}

/// [`pair_residuals`] of the refined pairs in `range`, their residuals solved in one block with
/// the factor of K; also returns the wall time of that solve.
fn residuals_of(
    inputs: &ResidualInputs<'_>,
    range: std::ops::Range<usize>,
    work: &mut Vec<f64>,
) -> (PairResiduals, Duration) {
    let ResidualInputs {
        pencil,
        factor: (symbolic, values),
        refined,
        sigma,
        norms: (norm_a, norm_b),
        max_row,
    } = *inputs;
    let n = pencil.dim();
    let (a, b) = (pencil.a(), pencil.b());
    let cols = range.len();
    let mut theta = vec![0.0; cols];
    let mut delta = vec![0.0; cols];
    let mut eta = vec![0.0; cols];
    let mut rounding = vec![0.0; cols];
    let mut resolution = vec![0.0; cols];
    let mut omega_sq = refined.omega_sq[range.clone()].to_vec();
    // Residuals s = Ax − θKx of every pair, solved with K in one block.
    let mut residuals = vec![0.0; n * cols];
    let mut xkx = vec![0.0; cols];
    let mut r = vec![0.0; n];
    for (c, pair) in range.enumerate() {
        let x = &refined.vectors[n * pair..n * (pair + 1)];
        // Rayleigh quotient and residuals in double-double: the bounds below then need no
        // first-order rounding term of size u·|x|ᵀ|B||x|.
        let bx_dd = dd::sparse_mat_vec(b, x);
        let ax_dd = dd::sparse_mat_vec(a, x);
        let xbx = dd::dot(x, &bx_dd);
        let xax = dd::dot(x, &ax_dd);
        let w = xbx.over(xax).to_f64();
        omega_sq[c] = w;
        let t = 1.0 / (w - sigma);
        theta[c] = t;
        // s = Ax − θ(Bx − σAx), r = Bx − ω²Ax; ‖x‖²_K = xᵀBx − σxᵀAx.
        dd::pencil_residuals(
            &ax_dd,
            &bx_dd,
            (w, t, sigma),
            &mut r,
            &mut residuals[n * c..n * (c + 1)],
        );
        xkx[c] = xbx.minus(Dd::of(sigma).times(xax)).to_f64();
        let xn = dot(x, x).sqrt();
        eta[c] = euclidean_norm(&r) / ((norm_b + w.abs() * norm_a) * xn).max(f64::MIN_POSITIVE);
        let xax = xax.to_f64().max(f64::MIN_POSITIVE);
        // Rounding of the double-double quotient and its final rounding to double.
        let componentwise = (abs_quadratic(b, x) + w.abs() * abs_quadratic(a, x)) / xax;
        rounding[c] = 2.0 * f64::EPSILON * w.abs() + max_row * f64::EPSILON * f64::EPSILON * componentwise;
        resolution[c] = f64::EPSILON * componentwise;
    }
    let mut solved = residuals.clone();
    let clock = Instant::now();
    solve_with(symbolic, values, &mut solved, cols, work);
    let solve_time = clock.elapsed();
    for c in 0..cols {
        let sc = &residuals[n * c..n * (c + 1)];
        let kc = &solved[n * c..n * (c + 1)];
        // Subnormal residuals of the softest modes of a pencil scaled to the edge of the range
        // would square to zero: the square root is taken on scaled data.
        delta[c] = sqrt_of_dot(sc, kc) / xkx[c].max(f64::MIN_POSITIVE).sqrt();
    }
    let residuals = PairResiduals {
        omega_sq,
        theta,
        delta,
        eta,
        rounding,
        resolution,
    };
    (residuals, solve_time)
}

/// Bounds, classification and the report for the lowest k refined modes, from their residuals
/// and the inertia count at τ (σ the operator's shift).
#[allow(clippy::too_many_arguments)]
pub(crate) fn finish(
    a: Mass<'_>,
    refined: &Refined,
    residuals: PairResiduals,
    k: usize,
    (sigma, tau): (f64, f64),
    inertia: SparseInertiaCount,
    below: usize,
    (norm_a, norm_b): (f64, f64),
) -> SparseModalSolution {
    let n = a.nrows();
    let cols = refined.omega_sq.len();
    let PairResiduals {
        omega_sq,
        theta,
        delta,
        eta,
        rounding,
        resolution,
    } = residuals;
    let theta_tau = 1.0 / (tau - sigma);
    let consistent = inertia.count.below == below && inertia.count.zero == 0;
    // θ(τ) bounds the gap below the pairs only when no eigenvalue with ω² < τ is unaccounted for.
    let theta_tau = consistent.then_some(theta_tau);
    let bounds = omega_bounds(&omega_sq, &theta, &delta, &rounding, (tau, theta_tau));
    let take = k.min(cols);
    let mut modes: Vec<Mode> = (0..cols)
        .map(|c| Mode {
            lambda: -omega_sq[c],
            omega_sq: omega_sq[c],
            kind: classify(omega_sq[c], bounds[c], resolution[c]),
            error_bound: bounds[c],
            backward_error: Some(eta[c]),
            group: 0,
        })
        .collect();
    let kth_group_multiplicity = kth_group_multiplicity(&mut modes, take);
    modes.truncate(take);
    let groups = group_modes(&mut modes);
    let vectors = Mat::from_fn(n, take, |i, c| refined.vectors[i + n * c]);
    let orthogonality_error = orthogonality(a, &vectors);
    SparseModalSolution {
        report: SparseAccuracyReport {
            shift: sigma,
            shift_attempts: 0,
            factor_nnz: 0,
            norm_a,
            norm_b,
            restarts: 0,
            operator_applications: 0,
            lanczos_runs: 0,
            kth_group_multiplicity,
            max_backward_error: eta[..take].iter().copied().fold(0.0, f64::max),
            orthogonality_error,
            inertia: Some(inertia),
            computed_below: below,
            consistent,
            dense_fallback: false,
            timings: SparseSolveTimings::default(),
        },
        modes,
        vectors,
        groups,
    }
}

/// The ω² bound of every refined pair from its θ = 1/(ω² − σ) and θ bound δ: clusters of θ whose
/// δ-intervals overlap, Kato–Temple with the gap to other clusters and, when the inertia check
/// passed (`theta_tau` given), to θ(τ); mapped to ω² as e/(θ(θ − e)), plus the `rounding` of
/// each Rayleigh quotient.
fn omega_bounds(
    omega_sq: &[f64],
    theta: &[f64],
    delta: &[f64],
    rounding: &[f64],
    (tau, theta_tau): (f64, Option<f64>),
) -> Vec<f64> {
    let cols = theta.len();
    let mut bounds = vec![0.0; cols];
    for c in 0..cols {
        let in_cluster = |d: usize| (theta[c] - theta[d]).abs() <= delta[c] + delta[d];
        let mut g = match theta_tau {
            Some(theta_tau) if omega_sq[c] < tau => theta[c] - theta_tau,
            _ => 0.0,
        };
        // Quadratic residual bound for a Rayleigh–Ritz cluster (Mathias, SIMAX 19, 1998):
        // |Δθ| ≤ ‖R‖²/gap with ‖R‖² ≤ Σ δ_d² over the cluster.
        let mut cluster = Vec::new();
        for d in 0..cols {
            if in_cluster(d) {
                cluster.push(delta[d]);
            } else {
                g = g.min((theta[c] - theta[d]).abs() - delta[d]);
            }
        }
        let e = if g > 0.0 {
            delta[c].min(square_over(euclidean_norm(&cluster), g))
        } else {
            delta[c]
        };
        let t = theta[c];
        let omega_bound = if t > e { e / (t * (t - e)) } else { f64::INFINITY };
        bounds[c] = omega_bound + rounding[c];
    }
    bounds
}

/// The multiplicity, among all of `modes` (ascending), of the group of mode `k` − 1 (0 when
/// k = 0), grouped as the returned modes are (ω² within the sum of their bounds).
fn kth_group_multiplicity(modes: &mut [Mode], k: usize) -> usize {
    if k == 0 || k > modes.len() {
        return 0;
    }
    let groups = group_modes(modes);
    groups.get(modes[k - 1].group).map_or(0, |g| g.multiplicity)
}

/// Largest number of stored entries in a column (= row, symmetric).
fn row_lengths(m: faer::sparse::SparseColMatRef<'_, usize, f64>) -> usize {
    (0..m.ncols())
        .map(|j| m.symbolic().col_range(j).len())
        .max()
        .unwrap_or(0)
}

/// max |(XᵀAX − I)_ij|.
fn orthogonality(a: Mass<'_>, x: &Mat<f64>) -> f64 {
    let (n, c) = (x.nrows(), x.ncols());
    let mut ax = Mat::<f64>::zeros(n, c);
    for j in 0..c {
        let (Some(xj), Some(axj)) = (
            x.col(j).try_as_col_major().map(|col| col.as_slice()),
            ax.col_mut(j).try_as_col_major_mut().map(|col| col.as_slice_mut()),
        ) else {
            continue;
        };
        a.apply(xj, axj);
    }
    let g = product(x.transpose(), ax.as_ref());
    let mut worst = 0.0_f64;
    for j in 0..c {
        for i in 0..c {
            let target = if i == j { 1.0 } else { 0.0 };
            worst = worst.max((g[(i, j)] - target).abs());
        }
    }
    worst
}
