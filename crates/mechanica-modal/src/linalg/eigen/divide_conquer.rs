//! All eigenpairs of a symmetric tridiagonal matrix, T = Z Λ Zᵀ, by divide and conquer: the
//! eigenvector stage of the dense solve (C = Q T Qᵀ, Y = Q Z; [`crate::linalg::eigen`]).
//!
//! Method (Cuppen, "A divide and conquer method for the symmetric tridiagonal eigenproblem",
//! Numer. Math. 36, 1981; Gu & Eisenstat, SIMAX 16, 1995; organised as LAPACK `dstedc`):
//! - T, scaled to unit max-norm, is torn at its middle off-diagonal β into
//!   T = diag(T₁, T₂) + |β| v vᵀ, v = e_{n₁} + sign(β) e_{n₁+1}, with |β| taken off the two
//!   diagonal entries beside the tear;
//! - with T_i = Q_i D_i Q_iᵀ solved recursively (leaves of at most [`crate::Tuning::leaf`] rows by
//!   the implicit QL iteration), T = Q (D + ρ z zᵀ) Qᵀ with z = Qᵀv/√2 and ρ = 2|β|;
//! - deflation: a pair whose ρ|z_i| is below 8u·max(‖D‖, ‖z‖) keeps (d_i, q_i); two close poles
//!   are rotated so that one of them deflates (`dlaed2`'s tests);
//! - the k remaining eigenvalues are the roots of the secular equation
//!   f(λ) = 1/ρ + Σ z_i²/(d_i − λ) = 0, each found from the nearer pole (so that every d_i − λ
//!   is accurate) by Li's "middle way" rational iteration inside a bisection bracket;
//! - the eigenvectors of D + ρ ẑ ẑᵀ come from Löwner's formula
//!   ẑ_i² = Π_j (λ_j − d_i) / (ρ Π_{j≠i} (d_j − d_i)), which makes them orthogonal to working
//!   accuracy without extra precision (Gu & Eisenstat), and are multiplied into Q.
//!
//! The product is arranged as in LAPACK `dlaed3`: the columns of Q that live only in its upper
//! block, in both blocks (after a deflating rotation across the tear) and only in its lower
//! block are gathered in that order, so that two matrix products skip the zero blocks. Values
//! are not sorted physically between levels: each node hands its parent a permutation.
//!
//! faer's `tridiagonal_self_adjoint_evd` multiplies deflated columns and zero blocks, and its
//! root finder is scalar, so that most of its time goes outside the matrix products (measured
//! in docs/benchmarks.md).

use crate::linalg::norms::fast_hypot;
use crate::runtime::fork_join::join;
use crate::tuning::Tuning;
use faer::linalg::matmul::matmul;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::{Accum, Mat, MatMut, MatRef, Par};

/// Unit roundoff 2⁻⁵³.
const EPS: f64 = f64::EPSILON / 2.0;
/// Iterations of the secular-equation solver before it bisects only.
const RATIONAL_STEPS: usize = 30;
/// Iterations of the secular-equation solver in all (bisection halves the bracket each time).
const MAX_SECULAR_STEPS: usize = 200;
/// QL sweeps allowed per eigenvalue of a leaf.
const MAX_QL_SWEEPS: usize = 60;

/// Eigenvalues (ascending) and orthonormal eigenvectors of the symmetric tridiagonal matrix with
/// diagonal `diag` and off-diagonal `offdiag`; None when a leaf's QL iteration or a secular root
/// does not converge, or an entry or eigenvalue is not finite (the caller falls back to another
/// solver).
pub(crate) fn tridiagonal_divide_and_conquer(diag: &[f64], offdiag: &[f64], par: Par) -> Option<(Vec<f64>, Mat<f64>)> {
    let n = diag.len();
    if offdiag.len() + 1 != n.max(1) {
        return None;
    }
    let scale = diag.iter().chain(offdiag).fold(0.0_f64, |m, x| m.max(x.abs()));
    if !scale.is_finite() {
        return None;
    }
    if scale == 0.0 {
        return Some((vec![0.0; n], Mat::identity(n, n)));
    }
    let mut d: Vec<f64> = diag.iter().map(|x| x / scale).collect();
    let mut e: Vec<f64> = offdiag.iter().map(|x| x / scale).collect();
    // Three n×n buffers in kept storage (`crate::runtime::scratch`); fresh ones are zeroed, two
    // on one thread and one on the other: fresh memory faults every 4 KiB page on its first
    // write, and faults on two cores proceed in parallel. New storage is allocated here, on the
    // calling thread: memory allocated on a pool thread comes from that thread's allocator
    // arena, which returns it to the system when freed. Kept storage is used with the values it
    // holds: no entry is read before it is written (each merge reads only the rows where a
    // column can be nonzero, see `merge`), which spares zeroing three n×n matrices.
    let (mut u, mut work, mut secular) = (
        crate::runtime::scratch::stale(n, n),
        crate::runtime::scratch::stale(n, n),
        crate::runtime::scratch::stale(n, n),
    );
    let fill_fresh = |m: &mut Mat<f64>| {
        if m.nrows() != n {
            m.resize_with(n, n, |_, _| 0.0);
        }
    };
    join(
        || {
            fill_fresh(&mut u);
            fill_fresh(&mut work);
        },
        || fill_fresh(&mut secular),
        par,
    );
    let mut order = vec![0; n];
    let nodes = Node {
        u: u.as_mut(),
        work: work.as_mut(),
        secular: secular.as_mut(),
    };
    if !solve_node(&mut d, &mut e, nodes, &mut order, par) {
        return None;
    }
    let values: Vec<f64> = order.iter().map(|&c| d[c] * scale).collect();
    if values.iter().any(|v| !v.is_finite()) {
        return None;
    }
    crate::runtime::scratch::give_back(secular);
    // Without deflation at the top merge its columns are already ascending.
    if order.iter().enumerate().all(|(j, &c)| j == c) {
        crate::runtime::scratch::give_back(work);
        return Some((values, u));
    }
    for (j, &c) in order.iter().enumerate() {
        work.col_mut(j).copy_from(u.col(c));
    }
    crate::runtime::scratch::give_back(u);
    Some((values, work))
}

/// The storage of one node of the recursion: its diagonal blocks of the eigenvector matrix and
/// of two workspaces of the same size (children get disjoint diagonal blocks, so that they can
/// run on two threads). Entries hold stale values until written.
struct Node<'a> {
    /// On return: the node's eigenvectors as columns (in the order of the node's values), every
    /// entry written.
    u: MatMut<'a, f64>,
    /// Gathered columns of the children's eigenvectors.
    work: MatMut<'a, f64>,
    /// Differences d_i − λ_j, then the eigenvectors of D + ρ ẑ ẑᵀ.
    secular: MatMut<'a, f64>,
}

/// Solves the node T (diagonal `d`, off-diagonal `e`): on return `d` holds its eigenvalues in
/// the order of `nodes.u`'s columns and `order` lists the columns by ascending eigenvalue.
fn solve_node(d: &mut [f64], e: &mut [f64], nodes: Node<'_>, order: &mut [usize], par: Par) -> bool {
    let n = d.len();
    if n <= Tuning::DEFAULT.leaf {
        return solve_leaf(d, e, nodes.u, order);
    }
    let n1 = n / 2;
    let beta = e[n1 - 1];
    d[n1 - 1] -= beta.abs();
    d[n1] -= beta.abs();
    let Node {
        mut u,
        mut work,
        mut secular,
    } = nodes;
    {
        let (d1, d2) = d.split_at_mut(n1);
        let (e1, rest) = e.split_at_mut(n1 - 1);
        let e2 = &mut rest[1..];
        let (order1, order2) = order.split_at_mut(n1);
        let (u1, _, _, u2) = u.rb_mut().split_at_mut(n1, n1);
        let (w1, _, _, w2) = work.rb_mut().split_at_mut(n1, n1);
        let (s1, _, _, s2) = secular.rb_mut().split_at_mut(n1, n1);
        let top = Node {
            u: u1,
            work: w1,
            secular: s1,
        };
        let bottom = Node {
            u: u2,
            work: w2,
            secular: s2,
        };
        let (ok1, ok2) = join(
            || solve_node(d1, e1, top, order1, par),
            || solve_node(d2, e2, bottom, order2, par),
            par,
        );
        if !(ok1 && ok2) {
            return false;
        }
    }
    merge(d, beta, n1, Node { u, work, secular }, order, par)
}

/// Where a column of the children's eigenvector matrix is nonzero. Only those rows of it are
/// written (a child writes its own block of rows); the others are zero by definition and hold
/// stale values.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Rows {
    Top,
    Bottom,
    Both,
}

impl Rows {
    /// The rows of a node of order n, torn after row n1, that this column may have nonzero.
    fn range(self, n1: usize, n: usize) -> std::ops::Range<usize> {
        match self {
            Rows::Top => 0..n1,
            Rows::Bottom => n1..n,
            Rows::Both => 0..n,
        }
    }
}

/// Writes column `col`'s zero rows (those outside `rows`) of a node of order n torn after row n1.
fn write_zero_rows(mut u: MatMut<'_, f64>, col: usize, rows: Rows, n1: usize) {
    let n = u.nrows();
    let column = u.rb_mut().col_mut(col);
    match rows {
        Rows::Top => column.subrows_mut(n1, n - n1).fill(0.0),
        Rows::Bottom => column.subrows_mut(0, n1).fill(0.0),
        Rows::Both => {}
    }
}

/// Copies the rows of column `from` of `u` that may be nonzero (`rows`, in a node torn after row
/// n1) into column `to` of `work`.
fn copy_nonzero_rows(work: MatMut<'_, f64>, to: usize, u: MatRef<'_, f64>, from: usize, rows: Rows, n1: usize) {
    let range = rows.range(n1, u.nrows());
    let (start, len) = (range.start, range.len());
    work.col_mut(to)
        .subrows_mut(start, len)
        .copy_from(u.col(from).subrows(start, len));
}

/// Combines the solved halves (values `d` in column order, ascending orders `order[..n1]` and
/// `order[n1..]` local to each half) across the tear `beta` after row `n1`; false if a root of the
/// secular equation did not converge.
fn merge(d: &mut [f64], beta: f64, n1: usize, nodes: Node<'_>, order: &mut [usize], par: Par) -> bool {
    let n = d.len();
    let Node {
        mut u,
        mut work,
        secular: mut secular_storage,
    } = nodes;
    let rho = 2.0 * beta.abs();
    let sign = if beta < 0.0 { -1.0 } else { 1.0 };
    let mut z: Vec<f64> = (0..n)
        .map(|c| {
            if c < n1 {
                u[(n1 - 1, c)] * std::f64::consts::FRAC_1_SQRT_2
            } else {
                sign * u[(n1, c)] * std::f64::consts::FRAC_1_SQRT_2
            }
        })
        .collect();
    let ascending = merge_orders(d, &order[..n1], &order[n1..], n1);
    let mut rows: Vec<Rows> = (0..n).map(|c| if c < n1 { Rows::Top } else { Rows::Bottom }).collect();
    let mut columns = Deflation {
        d,
        z: &mut z,
        u: u.rb_mut(),
        rows: &mut rows,
        n1,
    };
    let (kept, deflated) = columns.deflate(&ascending, rho);
    let k = kept.len();
    let typed = TypedColumns::of(&kept, &rows, n);
    let poles: Vec<f64> = typed.order.iter().map(|&c| d[c]).collect();
    let z_kept: Vec<f64> = typed.order.iter().map(|&c| z[c]).collect();

    let mut deltas = secular_storage.rb_mut().submatrix_mut(0, 0, k, k);
    let Some(roots) = secular_roots(&poles, &z_kept, &typed.position, rho, deltas.rb_mut(), par) else {
        return false;
    };
    secular_vectors(&poles, &z_kept, &typed.position, rho, deltas.rb_mut(), par);
    let product = Product {
        typed: &typed,
        deflated: &deflated,
        rows: &rows,
        n1,
    };
    product.multiply(u.rb_mut(), work.rb_mut(), deltas.rb(), par);
    reorder(d, &roots, &deflated, order);
    true
}

/// The columns of a merge being deflated: values `d`, the coupling vector `z`, the eigenvector
/// columns `u` of the two halves, and which rows of each column may be nonzero.
struct Deflation<'a, 'u> {
    d: &'a mut [f64],
    z: &'a mut [f64],
    u: MatMut<'u, f64>,
    rows: &'a mut [Rows],
    n1: usize,
}

impl Deflation<'_, '_> {
    /// Deflation (`dlaed2`): small components of z, then close poles by a Givens rotation,
    /// visiting the columns by `ascending` value. Returns the kept and the deflated columns.
    fn deflate(&mut self, ascending: &[usize], rho: f64) -> (Vec<usize>, Vec<usize>) {
        let (d, z, n1) = (&mut *self.d, &mut *self.z, self.n1);
        let n = d.len();
        let d_max = d.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let z_max = z.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let tol = 8.0 * EPS * d_max.max(z_max);
        let mut kept: Vec<usize> = Vec::with_capacity(n);
        let mut deflated: Vec<usize> = Vec::with_capacity(n);
        for &c in ascending {
            if rho * z[c].abs() <= tol {
                deflated.push(c);
                continue;
            }
            if let Some(&j) = kept.last() {
                let tau = fast_hypot(z[j], z[c]);
                let (cos, sin) = (z[c] / tau, -z[j] / tau);
                if ((d[c] - d[j]) * cos * sin).abs() <= tol {
                    // Rotate columns j and c so that z_j = 0: G = [cos sin; −sin cos] on (j, c).
                    let rows = &mut *self.rows;
                    let span = if rows[j] == rows[c] { rows[c] } else { Rows::Both };
                    if span == Rows::Both {
                        write_zero_rows(self.u.rb_mut(), j, rows[j], n1);
                        write_zero_rows(self.u.rb_mut(), c, rows[c], n1);
                    }
                    for r in span.range(n1, n) {
                        let (uj, uc) = (self.u[(r, j)], self.u[(r, c)]);
                        self.u[(r, j)] = cos * uj + sin * uc;
                        self.u[(r, c)] = cos * uc - sin * uj;
                    }
                    rows[j] = span;
                    rows[c] = span;
                    let (dj, dc) = (d[j], d[c]);
                    d[j] = cos * cos * dj + sin * sin * dc;
                    d[c] = sin * sin * dj + cos * cos * dc;
                    z[c] = tau;
                    z[j] = 0.0;
                    kept.pop();
                    deflated.push(j);
                }
            }
            kept.push(c);
        }
        (kept, deflated)
    }
}

/// The kept columns of a merge in the order top-only, both, bottom-only (`order`), so that the
/// two products of [`Product::multiply`] skip the zero blocks; `position[m]` is the place in that
/// order of the m-th smallest pole.
struct TypedColumns {
    order: Vec<usize>,
    top_count: usize,
    bottom_count: usize,
    position: Vec<usize>,
}

impl TypedColumns {
    fn of(kept: &[usize], rows: &[Rows], n: usize) -> Self {
        let order: Vec<usize> = [Rows::Top, Rows::Both, Rows::Bottom]
            .iter()
            .flat_map(|&part| kept.iter().copied().filter(|&c| rows[c] == part).collect::<Vec<_>>())
            .collect();
        let top_count = order.iter().filter(|&&c| rows[c] == Rows::Top).count();
        let bottom_count = order.iter().filter(|&&c| rows[c] == Rows::Bottom).count();
        let mut place = vec![0; n];
        for (r, &c) in order.iter().enumerate() {
            place[c] = r;
        }
        let position: Vec<usize> = kept.iter().map(|&c| place[c]).collect();
        Self {
            order,
            top_count,
            bottom_count,
            position,
        }
    }
}

/// The product of a merge: the node's eigenvectors from the halves' and the secular vectors.
struct Product<'a> {
    typed: &'a TypedColumns,
    deflated: &'a [usize],
    rows: &'a [Rows],
    n1: usize,
}

impl Product<'_> {
    /// Gathers the kept columns of `u` into `work` (typed order; only their nonzero rows, the
    /// only ones the products read), then the deflated ones with their zero rows written (they
    /// become columns of the node as they are); the kept columns of the node are then the two
    /// products of the gathered blocks with the secular `vectors` (k × k).
    fn multiply(&self, mut u: MatMut<'_, f64>, mut work: MatMut<'_, f64>, vectors: MatRef<'_, f64>, par: Par) {
        let (n, n1, k) = (u.nrows(), self.n1, vectors.ncols());
        let (rows, typed) = (self.rows, self.typed);
        for (r, &c) in typed.order.iter().enumerate() {
            copy_nonzero_rows(work.rb_mut(), r, u.rb(), c, rows[c], n1);
        }
        for (r, &c) in self.deflated.iter().enumerate().map(|(i, c)| (k + i, c)) {
            copy_nonzero_rows(work.rb_mut(), r, u.rb(), c, rows[c], n1);
            write_zero_rows(work.rb_mut(), r, rows[c], n1);
        }
        let (top_count, bottom_count) = (typed.top_count, typed.bottom_count);
        let (upper_rows, lower_rows) = (top_count + (k - top_count - bottom_count), k - top_count);
        matmul(
            u.rb_mut().submatrix_mut(0, 0, n1, k),
            Accum::Replace,
            work.rb().submatrix(0, 0, n1, upper_rows),
            vectors.submatrix(0, 0, upper_rows, k),
            1.0,
            par,
        );
        matmul(
            u.rb_mut().submatrix_mut(n1, 0, n - n1, k),
            Accum::Replace,
            work.rb().submatrix(n1, top_count, n - n1, lower_rows),
            vectors.submatrix(top_count, 0, lower_rows, k),
            1.0,
            par,
        );
        u.rb_mut()
            .submatrix_mut(0, k, n, n - k)
            .copy_from(work.rb().submatrix(0, k, n, n - k));
    }
}

/// The node's values in its new column order (the `roots`, then the `deflated` columns'
/// values) and its ascending `order`.
fn reorder(d: &mut [f64], roots: &[f64], deflated: &[usize], order: &mut [usize]) {
    let (n, k) = (d.len(), roots.len());
    let deflated_values: Vec<f64> = deflated.iter().map(|&c| d[c]).collect();
    d[..k].copy_from_slice(roots);
    d[k..].copy_from_slice(&deflated_values);
    let mut deflated_order: Vec<usize> = (k..n).collect();
    deflated_order.sort_by(|&a, &b| d[a].total_cmp(&d[b]));
    let (mut i, mut j) = (0, 0);
    for slot in order.iter_mut() {
        if j == deflated_order.len() || (i < k && d[i] <= d[deflated_order[j]]) {
            *slot = i;
            i += 1;
        } else {
            *slot = deflated_order[j];
            j += 1;
        }
    }
}

/// Column indices of the node by ascending value: the children's orders (the second one local
/// to the lower half, hence + `n1`) merged.
fn merge_orders(d: &[f64], first: &[usize], second: &[usize], n1: usize) -> Vec<usize> {
    let mut merged = Vec::with_capacity(first.len() + second.len());
    let (mut i, mut j) = (0, 0);
    while i < first.len() || j < second.len() {
        let take_first = j == second.len() || (i < first.len() && d[first[i]] <= d[second[j] + n1]);
        if take_first {
            merged.push(first[i]);
            i += 1;
        } else {
            merged.push(second[j] + n1);
            j += 1;
        }
    }
    merged
}

/// The k roots λ_m (ascending) of the secular equation 1/ρ + Σ z_i²/(d_i − λ) = 0 with poles
/// `poles` (any order; `position[m]` is where the m-th smallest is); column m of `deltas`
/// receives d_i − λ_m, computed from the pole nearer to λ_m. None if a root did not converge.
fn secular_roots(
    poles: &[f64],
    z: &[f64],
    position: &[usize],
    rho: f64,
    mut deltas: MatMut<'_, f64>,
    par: Par,
) -> Option<Vec<f64>> {
    let k = poles.len();
    let z_sq: Vec<f64> = z.iter().map(|x| x * x).collect();
    let mut roots = vec![0.0; k];
    let solve_range = |first: usize, roots: &mut [f64], mut deltas: MatMut<'_, f64>| {
        let mut shifted = vec![0.0; k];
        for (offset, root) in roots.iter_mut().enumerate() {
            let m = first + offset;
            let column = deltas.rb_mut().col_mut(offset).try_as_col_major_mut();
            if let Some(column) = column {
                *root = secular_root(m, poles, &z_sq, position, rho, &mut shifted, column.as_slice_mut())
                    .unwrap_or(f64::NAN);
            }
        }
    };
    let split = k / 2;
    if k >= Tuning::DEFAULT.parallel_roots_from && matches!(par, Par::Rayon(t) if t.get() > 1) {
        let (roots1, roots2) = roots.split_at_mut(split);
        let (deltas1, deltas2) = deltas.rb_mut().split_at_col_mut(split);
        join(
            || solve_range(0, roots1, deltas1),
            || solve_range(split, roots2, deltas2),
            par,
        );
    } else {
        solve_range(0, &mut roots, deltas);
    }
    roots.iter().all(|r| r.is_finite()).then_some(roots)
}

/// Sums over the poles at one point λ = origin + τ.
#[derive(Clone, Copy, Default)]
struct SecularSums {
    /// Σ z_i²/(d_i − λ) over the poles at or below the root's interval (ψ, ≤ 0).
    below: f64,
    /// Σ z_i²/(d_i − λ)² over the same poles (ψ′).
    below_slope: f64,
    /// Σ z_i²/(d_i − λ) over the poles above (φ, ≥ 0).
    above: f64,
    /// Σ z_i²/(d_i − λ)² over the poles above (φ′).
    above_slope: f64,
}

/// The m-th root of the secular equation; `delta` receives d_i − λ. `shifted` is scratch.
/// None if the iteration neither converged nor closed its bracket (not seen in tests).
///
/// The root lies in (d_(m), d_(m+1)) (the last one in (d_(k), d_(k) + ρ‖z‖²)); the origin is the
/// nearer of the two poles (decided by the sign of f at the midpoint), τ = λ − origin, and
/// d_i − λ = (d_i − origin) − τ, so that the differences to the nearest poles are exact. The
/// first guess is `dlaed4`'s (the two poles beside the root exact, the other terms frozen at the
/// midpoint). Each step fits c + s/(δ_(m) − η) + S/(δ_(m+1) − η) to f and f′, with the origin
/// pole's own weight exact and the derivative of the other terms on the far pole (`dlaed4`'s
/// middle way; for the last root the two poles below it), and takes its root in the bisection
/// bracket, or bisects. Stops when |f| is below its rounding error (`dlaed4`'s test).
fn secular_root(
    m: usize,
    poles: &[f64],
    z_sq: &[f64],
    position: &[usize],
    rho: f64,
    shifted: &mut [f64],
    delta: &mut [f64],
) -> Option<f64> {
    let last = m + 1 == poles.len();
    let (mut root, mut sums, mut f) = first_guess(m, poles, z_sq, position, rho, shifted, delta);
    let below_limit = shifted[position[m]];
    for step in 0..MAX_SECULAR_STEPS {
        let slope = sums.below_slope + sums.above_slope;
        let rounding = EPS * (8.0 * (sums.above - sums.below) + 2.0 / rho + 3.0 * root.tau.abs() * slope);
        if f.abs() <= rounding {
            return Some(root.origin + root.tau);
        }
        if f < 0.0 {
            root.low = root.low.max(root.tau);
        } else {
            root.high = root.high.min(root.tau);
        }
        if root.high - root.low <= 2.0 * EPS * root.low.abs().max(root.high.abs()) {
            return Some(root.origin + root.tau);
        }
        let model = Model {
            m,
            last,
            position,
            z_sq,
            delta,
            rho,
        };
        let eta = model.step(root.origin_pole, f, slope);
        let mut next = root.tau + eta;
        if step >= RATIONAL_STEPS || !(next > root.low && next < root.high) {
            next = 0.5 * (root.low + root.high);
        }
        if next == root.tau {
            return Some(root.origin + root.tau);
        }
        root.tau = next;
        sums = evaluate(shifted, z_sq, below_limit, root.tau, delta);
        f = 1.0 / rho + sums.below + sums.above;
    }
    None
}

/// A root being found: λ = origin + τ, with the origin at the pole `origin_pole`, inside the
/// bisection bracket low < τ < high.
struct RootIterate {
    origin: f64,
    origin_pole: usize,
    tau: f64,
    low: f64,
    high: f64,
}

/// The first iterate of [`secular_root`] for the m-th root, the sums there and f there:
/// `dlaed4`'s guess (the two poles beside the root exact, the other terms frozen at the
/// midpoint), with the origin at the nearer pole; the last root starts at its interval's
/// midpoint.
fn first_guess(
    m: usize,
    poles: &[f64],
    z_sq: &[f64],
    position: &[usize],
    rho: f64,
    shifted: &mut [f64],
    delta: &mut [f64],
) -> (RootIterate, SecularSums, f64) {
    let k = poles.len();
    let lower = poles[position[m]];
    let last = m + 1 == k;
    // Half the root's interval, for the last root in τ-space (not through d_(k) + ρ‖z‖², which
    // would round it at the scale of ulp(d_(k))).
    let half_gap = if last {
        0.5 * rho * z_sq.iter().sum::<f64>() * (1.0 + 4.0 * EPS)
    } else {
        0.5 * (poles[position[m + 1]] - lower)
    };
    // f at the midpoint, with the origin at the lower pole.
    let mut origin = lower;
    let mut origin_pole = position[m];
    shift_poles(poles, lower, shifted);
    let mut tau = half_gap;
    let mut sums = evaluate(shifted, z_sq, 0.0, tau, delta);
    let mut f = 1.0 / rho + sums.below + sums.above;
    let (mut low, mut high) = (0.0, half_gap);
    if last && f < 0.0 {
        (low, high) = (half_gap, 2.0 * half_gap);
    }
    if !last {
        if f < 0.0 {
            // The root is in the upper half: the origin moves to the upper pole (the sums at
            // the midpoint are the same).
            origin = poles[position[m + 1]];
            origin_pole = position[m + 1];
            shift_poles(poles, origin, shifted);
            tau = -half_gap;
            (low, high) = (-half_gap, 0.0);
        }
        // First guess: the two poles beside the root exact, the other terms frozen.
        let (a, b) = (shifted[position[m]], shifted[position[m + 1]]);
        let (s_low, s_high) = (z_sq[position[m]], z_sq[position[m + 1]]);
        let others = f - s_low / (a - tau) - s_high / (b - tau);
        let guess = two_pole_root(others, a, b, s_low, s_high);
        tau = if guess > low && guess < high {
            guess
        } else {
            0.5 * (low + high)
        };
        sums = evaluate(shifted, z_sq, a, tau, delta);
        f = 1.0 / rho + sums.below + sums.above;
    }
    let iterate = RootIterate {
        origin,
        origin_pole,
        tau,
        low,
        high,
    };
    (iterate, sums, f)
}

/// The rational model of one step of [`secular_root`] for the m-th root, from the current
/// differences `delta` = d_i − λ.
struct Model<'a> {
    m: usize,
    last: bool,
    position: &'a [usize],
    z_sq: &'a [f64],
    delta: &'a [f64],
    rho: f64,
}

impl Model<'_> {
    /// The step η: the root of c + s/(δ_(m) − η) + S/(δ_(m+1) − η) fitted to f and its `slope`,
    /// the origin pole's own weight exact and the other terms' slope on the far pole (for the
    /// last root the two poles below it); a Newton step where the model steps away from the
    /// root.
    fn step(&self, origin_pole: usize, f: f64, slope: f64) -> f64 {
        let (m, position, z_sq, delta) = (self.m, self.position, self.z_sq, self.delta);
        // The origin pole's own slope z_o²/δ_o², and the slope of all the other terms.
        let own = z_sq[origin_pole] / (delta[origin_pole] * delta[origin_pole]);
        let others = (slope - own).max(0.0);
        let model = if self.last && m > 0 {
            // Poles d_(k−1) and d_(k) (the origin): the other terms' slope on d_(k−1).
            let (a, b) = (delta[position[m - 1]], delta[origin_pole]);
            let (s, big_s) = (a * a * others, z_sq[origin_pole]);
            Some((f - s / a - big_s / b, a, b, s, big_s))
        } else if self.last {
            None
        } else {
            let (a, b) = (delta[position[m]], delta[position[m + 1]]);
            let (s, big_s) = if origin_pole == position[m] {
                (z_sq[origin_pole], b * b * others)
            } else {
                (a * a * others, z_sq[origin_pole])
            };
            Some((f - s / a - big_s / b, a, b, s, big_s))
        };
        let mut eta = match model {
            Some((c, a, b, s, big_s)) if self.last => beyond_two_poles_root(c, a, b, s, big_s),
            Some((c, a, b, s, big_s)) => two_pole_root(c, a, b, s, big_s),
            None => {
                // k = 1: f = 1/ρ + z²/(δ − η) exactly.
                let a = delta[origin_pole];
                a + z_sq[origin_pole] * self.rho
            }
        };
        let towards_root = f * eta < 0.0;
        if !towards_root {
            // The model stepped away from the root (or failed): a Newton step instead.
            eta = -f / slope;
        }
        eta
    }
}

/// The root η > b of c + s/(a − η) + S/(b − η) = 0 for two poles a < b below it (the last
/// root's model, `dlaed4`'s case i = n); NaN when c ≤ 0 (no such root).
fn beyond_two_poles_root(c: f64, a: f64, b: f64, s: f64, big_s: f64) -> f64 {
    if c <= 0.0 {
        return f64::NAN;
    }
    let linear = c * (a + b) + s + big_s;
    let constant = c * a * b + s * b + big_s * a;
    let root = (linear * linear - 4.0 * constant * c).abs().sqrt();
    if linear >= 0.0 {
        (linear + root) / (2.0 * c)
    } else {
        2.0 * constant / (linear - root)
    }
}

/// The root η in (a, b) of c + s/(a − η) + S/(b − η) = 0 (s, S ≥ 0, a < 0 < b or a < b),
/// i.e. of c η² − (c(a + b) + s + S) η + c ab + s b + S a = 0, in the cancellation-free form of
/// `dlaed4`.
fn two_pole_root(c: f64, a: f64, b: f64, s: f64, big_s: f64) -> f64 {
    let linear = c * (a + b) + s + big_s;
    let constant = c * a * b + s * b + big_s * a;
    if c == 0.0 {
        return constant / linear;
    }
    let root = (linear * linear - 4.0 * constant * c).abs().sqrt();
    if linear <= 0.0 {
        (linear - root) / (2.0 * c)
    } else {
        2.0 * constant / (linear + root)
    }
}

/// shifted_i = d_i − origin.
fn shift_poles(poles: &[f64], origin: f64, shifted: &mut [f64]) {
    for (s, p) in shifted.iter_mut().zip(poles) {
        *s = p - origin;
    }
}

/// The sums of [`SecularSums`] at τ, with poles `shifted` relative to the origin (those at or
/// below `below_limit` count as below); `delta` receives (d_i − origin) − τ.
fn evaluate(shifted: &[f64], z_sq: &[f64], below_limit: f64, tau: f64, delta: &mut [f64]) -> SecularSums {
    #[cfg(target_arch = "x86_64")]
    if crate::runtime::cpu::fused_available() {
        // SAFETY: the running CPU supports FMA and AVX2, checked just above.
        return unsafe { evaluate_avx2(shifted, z_sq, below_limit, tau, delta) };
    }
    evaluate_lanes(shifted, z_sq, below_limit, tau, delta)
}

/// [`evaluate`] in AVX2 vectors, four terms per division instruction: the compiler leaves
/// [`evaluate_lanes`]'s selects scalar (one `vdivsd` per term; the secular equation took 5 % of
/// a solve's cycles at n = 1000). Each of the eight lanes accumulates the same terms in the same
/// order as there, with the same operations (no fused multiply–add), so the sums are identical
/// bit for bit.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "fma,avx2")]
fn evaluate_avx2(shifted: &[f64], z_sq: &[f64], below_limit: f64, tau: f64, delta: &mut [f64]) -> SecularSums {
    use std::arch::x86_64::{
        _CMP_LE_OQ, _mm256_add_pd, _mm256_and_pd, _mm256_andnot_pd, _mm256_cmp_pd, _mm256_div_pd, _mm256_loadu_pd,
        _mm256_mul_pd, _mm256_set1_pd, _mm256_setzero_pd, _mm256_storeu_pd, _mm256_sub_pd,
    };
    const LANES: usize = 8;
    let (tau_v, limit_v, one) = (_mm256_set1_pd(tau), _mm256_set1_pd(below_limit), _mm256_set1_pd(1.0));
    // acc[q][h]: quantity q (ψ, ψ′, φ, φ′) on lanes 4h..4h+4.
    let mut acc = [[_mm256_setzero_pd(); 2]; 4];
    let (s_chunks, s_rest) = shifted.as_chunks::<LANES>();
    let (w_chunks, w_rest) = z_sq.as_chunks::<LANES>();
    let (d_chunks, d_rest) = delta.as_chunks_mut::<LANES>();
    for ((s, w), d) in s_chunks.iter().zip(w_chunks).zip(d_chunks.iter_mut()) {
        for h in 0..2 {
            // SAFETY: each pointer is 4·h lanes into an [f64; 8] chunk, so every 4-lane load
            // and store stays inside its chunk.
            unsafe {
                let poles = _mm256_loadu_pd(s.as_ptr().add(4 * h));
                let weights = _mm256_loadu_pd(w.as_ptr().add(4 * h));
                let dl = _mm256_sub_pd(poles, tau_v);
                _mm256_storeu_pd(d.as_mut_ptr().add(4 * h), dl);
                let inverse = _mm256_div_pd(one, dl);
                let value = _mm256_mul_pd(weights, inverse);
                let slope = _mm256_mul_pd(value, inverse);
                let below = _mm256_cmp_pd::<_CMP_LE_OQ>(poles, limit_v);
                acc[0][h] = _mm256_add_pd(acc[0][h], _mm256_and_pd(below, value));
                acc[1][h] = _mm256_add_pd(acc[1][h], _mm256_and_pd(below, slope));
                acc[2][h] = _mm256_add_pd(acc[2][h], _mm256_andnot_pd(below, value));
                acc[3][h] = _mm256_add_pd(acc[3][h], _mm256_andnot_pd(below, slope));
            }
        }
    }
    let lanes = |q: usize| {
        let mut out = [0.0; LANES];
        // SAFETY: each store writes 4 lanes into an 8-lane array at offset 0 or 4.
        unsafe {
            _mm256_storeu_pd(out.as_mut_ptr(), acc[q][0]);
            _mm256_storeu_pd(out.as_mut_ptr().add(4), acc[q][1]);
        }
        out
    };
    let mut sums = evaluate_lanes(s_rest, w_rest, below_limit, tau, d_rest);
    sums.below += lanes(0).iter().sum::<f64>();
    sums.below_slope += lanes(1).iter().sum::<f64>();
    sums.above += lanes(2).iter().sum::<f64>();
    sums.above_slope += lanes(3).iter().sum::<f64>();
    sums
}

/// [`evaluate`] with eight independent partial sums per quantity, so that the compiler can
/// keep them in vector registers.
#[inline(always)]
fn evaluate_lanes(shifted: &[f64], z_sq: &[f64], below_limit: f64, tau: f64, delta: &mut [f64]) -> SecularSums {
    const LANES: usize = 8;
    let mut acc = [[0.0; LANES]; 4];
    let term = |s: f64, w: f64| {
        let dl = s - tau;
        let inverse = 1.0 / dl;
        let value = w * inverse;
        (dl, value, value * inverse, s <= below_limit)
    };
    let (s_chunks, s_rest) = shifted.as_chunks::<LANES>();
    let (w_chunks, w_rest) = z_sq.as_chunks::<LANES>();
    let (d_chunks, d_rest) = delta.as_chunks_mut::<LANES>();
    for ((s, w), d) in s_chunks.iter().zip(w_chunks).zip(d_chunks.iter_mut()) {
        for l in 0..LANES {
            let (dl, value, slope, below) = term(s[l], w[l]);
            d[l] = dl;
            acc[0][l] += if below { value } else { 0.0 };
            acc[1][l] += if below { slope } else { 0.0 };
            acc[2][l] += if below { 0.0 } else { value };
            acc[3][l] += if below { 0.0 } else { slope };
        }
    }
    let mut sums = SecularSums::default();
    for ((s, w), d) in s_rest.iter().zip(w_rest).zip(d_rest.iter_mut()) {
        let (dl, value, slope, below) = term(*s, *w);
        *d = dl;
        if below {
            sums.below += value;
            sums.below_slope += slope;
        } else {
            sums.above += value;
            sums.above_slope += slope;
        }
    }
    sums.below += acc[0].iter().sum::<f64>();
    sums.below_slope += acc[1].iter().sum::<f64>();
    sums.above += acc[2].iter().sum::<f64>();
    sums.above_slope += acc[3].iter().sum::<f64>();
    sums
}

/// Overwrites `deltas` (column m: d_i − λ_m) by the unit eigenvectors of D + ρ ẑ ẑᵀ, with ẑ
/// from Löwner's formula (Gu & Eisenstat 1995, eq. 3.6) so that they are orthogonal.
fn secular_vectors(poles: &[f64], z: &[f64], position: &[usize], rho: f64, mut deltas: MatMut<'_, f64>, par: Par) {
    let k = poles.len();
    // ẑ_i² = (λ_(rank i) − d_i)/ρ · Π_{m ≠ rank i} (λ_m − d_i)/(d_(m) − d_i), each factor > 0.
    let mut rank = vec![0; k];
    for (m, &r) in position.iter().enumerate() {
        rank[r] = m;
    }
    let mut z_hat: Vec<f64> = (0..k).map(|i| -deltas[(i, rank[i])] / rho).collect();
    let view = deltas.rb();
    let products = |rows: std::ops::Range<usize>, z_hat: &mut [f64]| {
        for (m, &r) in position.iter().enumerate() {
            let pole = poles[r];
            let Some(column) = view.col(m).try_as_col_major().map(|c| c.as_slice()) else {
                continue;
            };
            let multiply = |range: std::ops::Range<usize>, z_hat: &mut [f64]| {
                let factors = column[range.clone()].iter().zip(&poles[range]);
                for (value, (delta, p)) in z_hat.iter_mut().zip(factors) {
                    *value *= delta / (p - pole);
                }
            };
            if rows.contains(&r) {
                let (before, after) = z_hat.split_at_mut(r - rows.start);
                multiply(rows.start..r, before);
                multiply(r + 1..rows.end, &mut after[1..]);
            } else {
                multiply(rows.clone(), z_hat);
            }
        }
    };
    if k >= Tuning::DEFAULT.parallel_roots_from && matches!(par, Par::Rayon(t) if t.get() > 1) {
        let split = k / 2;
        let (first, second) = z_hat.split_at_mut(split);
        join(|| products(0..split, first), || products(split..k, second), par);
    } else {
        products(0..k, &mut z_hat);
    }
    for (value, &original) in z_hat.iter_mut().zip(z) {
        *value = value.abs().sqrt().copysign(original);
    }
    for m in 0..k {
        let Some(column) = deltas.rb_mut().col_mut(m).try_as_col_major_mut() else {
            continue;
        };
        let column = column.as_slice_mut();
        let mut norm_sq = 0.0_f64;
        for (entry, &zi) in column.iter_mut().zip(&z_hat) {
            *entry = zi / *entry;
            norm_sq += *entry * *entry;
        }
        let inverse_norm = 1.0 / norm_sq.sqrt();
        column.iter_mut().for_each(|x| *x *= inverse_norm);
    }
}

/// Eigen-decomposition of a leaf by the implicit QL iteration with Wilkinson's shift (Bowdler,
/// Martin, Reinsch & Wilkinson, "The QR and QL algorithms for symmetric matrices", Numer.
/// Math. 11, 1968): `u` becomes the eigenvectors, `d` the eigenvalues in column order and
/// `order` the ascending order. False when an eigenvalue needs more than [`MAX_QL_SWEEPS`].
fn solve_leaf(d: &mut [f64], e: &[f64], mut u: MatMut<'_, f64>, order: &mut [usize]) -> bool {
    let n = d.len();
    for j in 0..n {
        u.rb_mut().col_mut(j).fill(0.0);
        u[(j, j)] = 1.0;
    }
    // off[i] couples rows i and i + 1; off[n − 1] = 0 closes the last block.
    let mut off: Vec<f64> = e.iter().copied().chain(std::iter::once(0.0)).collect();
    for l in 0..n {
        let mut sweeps = 0;
        loop {
            let mut m = l;
            // Relative test, and an absolute floor: T is scaled to unit max-norm, so dropping an
            // entry below u is a normwise backward error of u (without the floor the bulge
            // underflows on leaves graded from huge at the top to tiny, and subnormal rotations
            // lose orthogonality).
            while m + 1 < n && off[m].abs() > EPS * (d[m].abs() + d[m + 1].abs()) && off[m].abs() > EPS {
                m += 1;
            }
            if m == l {
                break;
            }
            sweeps += 1;
            if sweeps > MAX_QL_SWEEPS {
                return false;
            }
            // Wilkinson's shift from the leading 2×2 block, as an implicit QL sweep from m to l.
            let g0 = (d[l + 1] - d[l]) / (2.0 * off[l]);
            let r0 = fast_hypot(g0, 1.0);
            let mut g = d[m] - d[l] + off[l] / (g0 + r0.copysign(g0));
            let (mut sin, mut cos, mut p) = (1.0, 1.0, 0.0);
            let mut deflated_early = false;
            for i in (l..m).rev() {
                let f = sin * off[i];
                let b = cos * off[i];
                let r = fast_hypot(f, g);
                off[i + 1] = r;
                if r == 0.0 {
                    d[i + 1] -= p;
                    off[m] = 0.0;
                    deflated_early = true;
                    break;
                }
                sin = f / r;
                cos = g / r;
                let g1 = d[i + 1] - p;
                let r1 = (d[i] - g1) * sin + 2.0 * cos * b;
                p = sin * r1;
                d[i + 1] = g1 + p;
                g = cos * r1 - b;
                let (mut left, mut right) = u.rb_mut().two_cols_mut(i, i + 1);
                for row in 0..n {
                    let (x, y) = (left[row], right[row]);
                    right[row] = sin * x + cos * y;
                    left[row] = cos * x - sin * y;
                }
            }
            if deflated_early {
                continue;
            }
            d[l] -= p;
            off[l] = g;
            off[m] = 0.0;
        }
    }
    if d.iter().any(|x| !x.is_finite()) {
        return false;
    }
    for (i, slot) in order.iter_mut().enumerate() {
        *slot = i;
    }
    order.sort_by(|&a, &b| d[a].total_cmp(&d[b]));
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::eigen::ql_values::tridiagonal_eigenvalues;

    /// max_j ‖T z_j − λ_j z_j‖ / ‖T‖_max and max |ZᵀZ − I|.
    fn errors(d: &[f64], e: &[f64], values: &[f64], z: &Mat<f64>) -> (f64, f64) {
        let n = d.len();
        let norm = d
            .iter()
            .chain(e)
            .fold(0.0_f64, |m, x| m.max(x.abs()))
            .max(f64::MIN_POSITIVE);
        let mut residual = 0.0_f64;
        for j in 0..n {
            let mut sq = 0.0;
            for i in 0..n {
                let mut t = d[i] * z[(i, j)];
                if i > 0 {
                    t += e[i - 1] * z[(i - 1, j)];
                }
                if i + 1 < n {
                    t += e[i] * z[(i + 1, j)];
                }
                sq += ((t - values[j] * z[(i, j)]) / norm).powi(2);
            }
            residual = residual.max(sq.sqrt());
        }
        let gram = z.transpose() * z;
        let mut orth = 0.0_f64;
        for i in 0..n {
            for j in 0..n {
                orth = orth.max((gram[(i, j)] - if i == j { 1.0 } else { 0.0 }).abs());
            }
        }
        (residual, orth)
    }

    fn check(d: &[f64], e: &[f64], par: Par) {
        let n = d.len();
        let (values, z) = tridiagonal_divide_and_conquer(d, e, par).expect("converges");
        assert!(values.windows(2).all(|w| w[0] <= w[1]), "ascending");
        let (residual, orth) = errors(d, e, &values, &z);
        let limit = 4.0 * n as f64 * EPS;
        assert!(residual <= limit, "n {n}: residual {residual:e}");
        assert!(orth <= limit, "n {n}: orthogonality {orth:e}");
        // The values against the QL/QR iteration's (an independent method).
        let mut reference = tridiagonal_eigenvalues(d, e).expect("converges");
        reference.sort_by(f64::total_cmp);
        let norm = d.iter().chain(e).fold(0.0_f64, |m, x| m.max(x.abs()));
        for (v, r) in values.iter().zip(&reference) {
            assert!((v - r).abs() <= limit * norm, "n {n}: {v} against {r}");
        }
    }

    fn pseudo_random(n: usize, seed: u64) -> Vec<f64> {
        let mut state = seed;
        (0..n)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect()
    }

    #[test]
    fn second_difference_matches_the_closed_form() {
        let n = 300;
        let d = vec![2.0; n];
        let e = vec![-1.0; n - 1];
        let (values, _) = tridiagonal_divide_and_conquer(&d, &e, Par::Seq).expect("converges");
        for (j, v) in values.iter().enumerate() {
            let exact = 2.0 - 2.0 * ((j + 1) as f64 * std::f64::consts::PI / (n + 1) as f64).cos();
            assert!((v - exact).abs() <= 8.0 * EPS * n as f64, "{j}: {v} against {exact}");
        }
        check(&d, &e, Par::Seq);
    }

    #[test]
    fn random_tridiagonals_of_many_orders() {
        for (seed, n) in [1, 2, 3, 31, 32, 33, 64, 65, 100, 257, 600].into_iter().enumerate() {
            let d = pseudo_random(n, seed as u64 + 1);
            let e = pseudo_random(n.saturating_sub(1), seed as u64 + 100);
            check(&d, &e, Par::Seq);
        }
        let d = pseudo_random(700, 7);
        let e = pseudo_random(699, 8);
        check(&d, &e, Par::rayon(2));
    }

    #[test]
    fn heavy_deflation_gives_orthonormal_vectors() {
        // Glued Wilkinson W21+ blocks (pairs equal to 1e-14), the identity with tiny
        // couplings, a constant diagonal (every pole repeated) and a zero matrix.
        let blocks = 20;
        let mut d = Vec::new();
        let mut e = Vec::new();
        for b in 0..blocks {
            d.extend((0..21).map(|i| (10.0 - i as f64).abs()));
            e.extend(std::iter::repeat_n(1.0, 20));
            if b + 1 < blocks {
                e.push(1e-12);
            }
        }
        check(&d, &e, Par::Seq);
        check(&d, &e, Par::rayon(2));
        let n = 200;
        check(&vec![1.0; n], &vec![1e-17; n - 1], Par::Seq);
        check(&vec![3.0; n], &vec![0.0; n - 1], Par::Seq);
        check(&vec![0.0; n], &vec![0.0; n - 1], Par::Seq);
        let e: Vec<f64> = (0..n - 1).map(|i| if i % 3 == 0 { 0.0 } else { 1.0 }).collect();
        check(&vec![1.0; n], &e, Par::Seq);
    }

    /// Working storage full of NaN, as kept storage may hold anything: every entry the recursion
    /// reads was written first (a NaN read would reach a vector), so the pairs are as accurate as
    /// from zeroed storage. Glued Wilkinson matrices rotate columns of both halves together
    /// (close poles across the tear); heavy and no deflation; one and two threads.
    #[test]
    fn stale_working_storage_is_never_read() {
        let mut glued_d = Vec::new();
        let mut glued_e = Vec::new();
        for b in 0..12 {
            glued_d.extend((0..21).map(|i| (10.0 - i as f64).abs() / 10.0));
            glued_e.extend(std::iter::repeat_n(0.1, 20));
            if b + 1 < 12 {
                glued_e.push(1e-13);
            }
        }
        let n = 300;
        let random_d = pseudo_random(n, 3);
        let random_e = pseudo_random(n - 1, 4);
        let tiny_e = vec![1e-17; n - 1];
        let cases: [(&[f64], &[f64]); 3] = [(&glued_d, &glued_e), (&random_d, &random_e), (&vec![1.0; n], &tiny_e)];
        for (d, e) in cases {
            for par in [Par::Seq, Par::rayon(2)] {
                let n = d.len();
                let nan = || Mat::from_fn(n, n, |_, _| f64::NAN);
                let (mut u, mut work, mut secular) = (nan(), nan(), nan());
                let (mut values, mut off) = (d.to_vec(), e.to_vec());
                let mut order = vec![0; n];
                let nodes = Node {
                    u: u.as_mut(),
                    work: work.as_mut(),
                    secular: secular.as_mut(),
                };
                assert!(solve_node(&mut values, &mut off, nodes, &mut order, par));
                let sorted: Vec<f64> = order.iter().map(|&c| values[c]).collect();
                let z = Mat::from_fn(n, n, |i, j| u[(i, order[j])]);
                let (residual, orth) = errors(d, e, &sorted, &z);
                let limit = 4.0 * n as f64 * EPS;
                assert!(residual <= limit, "n {n}: residual {residual:e}");
                assert!(orth <= limit, "n {n}: orthogonality {orth:e}");
            }
        }
    }

    #[test]
    fn graded_and_extreme_scales() {
        let n = 150;
        let d: Vec<f64> = (0..n).map(|i| 10f64.powi(i / 10 - 7)).collect();
        let e: Vec<f64> = (0..n - 1).map(|i| 0.5 * 10f64.powi(i / 10 - 7)).collect();
        check(&d, &e, Par::Seq);
        let reversed: Vec<f64> = d.iter().rev().copied().collect();
        let reversed_e: Vec<f64> = e.iter().rev().copied().collect();
        check(&reversed, &reversed_e, Par::Seq);
        for scale in [1e-300, 1e300] {
            let d: Vec<f64> = pseudo_random(90, 3).iter().map(|x| x * scale).collect();
            let e: Vec<f64> = pseudo_random(89, 4).iter().map(|x| x * scale).collect();
            check(&d, &e, Par::Seq);
        }
    }

    #[test]
    fn graded_from_huge_to_tiny_and_multiscale_couplings() {
        // Graded over 1e±150 with the large end at the top: a leaf's QL iteration must neither
        // stall (an underflowing bulge) nor lose orthogonality through subnormal rotations.
        for n in [100, 150, 200, 1000] {
            let mut d: Vec<f64> = (0..n)
                .map(|i| 10f64.powf(-150.0 + 300.0 * i as f64 / (n - 1) as f64))
                .collect();
            let mut e: Vec<f64> = (0..n - 1).map(|i| 0.5 * (d[i] * d[i + 1]).sqrt()).collect();
            d.reverse();
            e.reverse();
            check(&d, &e, Par::rayon(2));
        }
        // The identity with couplings of 1e0 … 1e-19: one pole survives deflation per merge, and
        // the last root's interval ρ‖z‖² is far below ulp(1).
        let n = 600;
        let r = pseudo_random(n - 1, 11);
        let e: Vec<f64> = r
            .iter()
            .enumerate()
            .map(|(i, x)| x * 10f64.powi(-((i % 20) as i32)))
            .collect();
        check(&vec![1.0; n], &e, Par::Seq);
    }

    #[test]
    #[cfg(target_arch = "x86_64")]
    fn vector_secular_sums_equal_the_scalar_ones_bit_for_bit() {
        if !crate::runtime::cpu::fused_available() {
            return;
        }
        // Orders with and without a tail past the last 8-term chunk; the split between poles
        // below and above the root's interval at several places, NaN poles counted as above.
        for (k, seed) in [(1, 1), (7, 2), (8, 3), (29, 4), (64, 5), (203, 6)] {
            let mut poles: Vec<f64> = pseudo_random(k, seed).iter().map(|x| 4.0 * x).collect();
            if k > 20 {
                poles[11] = f64::NAN;
            }
            let weights: Vec<f64> = pseudo_random(k, seed + 100).iter().map(|x| x * x).collect();
            for (below_limit, tau) in [(-1.0, 0.013), (0.0, -0.2), (0.37, 1e-9), (3.0, 2.5)] {
                let (mut d_scalar, mut d_vector) = (vec![0.0; k], vec![0.0; k]);
                let scalar = evaluate_lanes(&poles, &weights, below_limit, tau, &mut d_scalar);
                // SAFETY: the CPU has AVX2 and FMA (checked above).
                let vector = unsafe { evaluate_avx2(&poles, &weights, below_limit, tau, &mut d_vector) };
                let bits = |s: SecularSums| [s.below, s.below_slope, s.above, s.above_slope].map(f64::to_bits);
                assert_eq!(bits(scalar), bits(vector), "k = {k}, limit {below_limit}, tau {tau}");
                let same = d_scalar.iter().zip(&d_vector).all(|(a, b)| a.to_bits() == b.to_bits());
                assert!(same, "differences d_i - tau, k = {k}");
            }
        }
    }

    #[test]
    fn non_finite_input_is_declined() {
        assert!(tridiagonal_divide_and_conquer(&[1.0, f64::NAN], &[1.0], Par::Seq).is_none());
        assert!(tridiagonal_divide_and_conquer(&[1.0, 2.0], &[f64::INFINITY], Par::Seq).is_none());
        assert!(tridiagonal_divide_and_conquer(&[1.0, 2.0], &[], Par::Seq).is_none());
        let (values, z) = tridiagonal_divide_and_conquer(&[], &[], Par::Seq).expect("empty");
        assert!(values.is_empty() && z.nrows() == 0);
    }
}
