//! Double-double arithmetic (about 106 significant bits) for residuals and Rayleigh quotients
//! that must survive cancellation, built on the error-free transformations TwoSum and TwoProd
//! (Ogita, Rump & Oishi, "Accurate sum and dot product", SIAM J. Sci. Comput. 26, 2005).

#[cfg(target_arch = "x86_64")]
use crate::runtime::cpu::fused_available;
use crate::tuning::Tuning;
use faer::MatRef;

/// An unevaluated sum hi + lo with |lo| ≤ ½ ulp(hi).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Dd {
    pub hi: f64,
    pub lo: f64,
}

/// a + b = s + e exactly (Knuth's TwoSum).
#[inline(always)]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// a·b = p + e exactly (TwoProd with a fused multiply-add). Only for code compiled with FMA
/// (see [`two_prod`]).
#[inline(always)]
fn two_prod_fused(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

/// a·b = p + e exactly. Without FMA in the build, `mul_add` is a library call costing about a
/// hundred plain flops (and LLVM may hoist it out of any branch), so Dekker's product of
/// Veltkamp halves is used instead. A factor above 2^995, whose split could overflow, is first
/// scaled by 2^−64 (exact) and the result scaled back.
#[inline(always)]
fn two_prod(a: f64, b: f64) -> (f64, f64) {
    if cfg!(target_feature = "fma") {
        return two_prod_fused(a, b);
    }
    const SPLIT_LIMIT: f64 = 1e299;
    const DOWN: f64 = 1.0 / 18_446_744_073_709_551_616.0; // 2^−64
    const UP: f64 = 18_446_744_073_709_551_616.0; // 2^64
    if a.abs() > SPLIT_LIMIT {
        let (p, e) = two_prod(a * DOWN, b);
        return (p * UP, e * UP);
    }
    if b.abs() > SPLIT_LIMIT {
        let (p, e) = two_prod(a, b * DOWN);
        return (p * UP, e * UP);
    }
    let p = a * b;
    let (ah, al) = split(a);
    let (bh, bl) = split(b);
    (p, ((ah * bh - p) + ah * bl + al * bh) + al * bl)
}

/// [`two_prod_fused`] when FUSED, else [`two_prod`].
#[inline(always)]
fn two_prod_as<const FUSED: bool>(a: f64, b: f64) -> (f64, f64) {
    if FUSED { two_prod_fused(a, b) } else { two_prod(a, b) }
}

/// Veltkamp's split a = hi + lo, each half with at most 26 significant bits.
#[inline(always)]
fn split(a: f64) -> (f64, f64) {
    let c = 134_217_729.0 * a; // 2^27 + 1
    let hi = c - (c - a);
    (hi, a - hi)
}

impl Dd {
    /// The double-double value of a double.
    #[inline]
    pub fn of(x: f64) -> Self {
        Self { hi: x, lo: 0.0 }
    }

    /// Rounded to the nearest double.
    #[inline]
    pub fn to_f64(self) -> f64 {
        self.hi + self.lo
    }

    /// self + other.
    #[inline]
    pub fn plus(self, other: Self) -> Self {
        let (s, e) = two_sum(self.hi, other.hi);
        let e = e + self.lo + other.lo;
        let (hi, lo) = two_sum(s, e);
        Self { hi, lo }
    }

    /// self − other.
    #[inline]
    pub fn minus(self, other: Self) -> Self {
        self.plus(Self {
            hi: -other.hi,
            lo: -other.lo,
        })
    }

    /// self · other.
    #[inline]
    pub fn times(self, other: Self) -> Self {
        self.times_as::<false>(other)
    }

    /// self · other, with the fused product when FUSED (only in code compiled with FMA).
    #[inline(always)]
    fn times_as<const FUSED: bool>(self, other: Self) -> Self {
        let (p, e) = two_prod_as::<FUSED>(self.hi, other.hi);
        let e = e + (self.hi * other.lo + self.lo * other.hi);
        let (hi, lo) = two_sum(p, e);
        Self { hi, lo }
    }

    /// self / other (one Newton correction of the double quotient).
    #[inline]
    pub fn over(self, other: Self) -> Self {
        let q1 = self.hi / other.hi;
        let r = self.minus(other.times(Self::of(q1)));
        let q2 = r.hi / other.hi;
        let (hi, lo) = two_sum(q1, q2);
        Self { hi, lo }
    }
}

/// Σ_j m[i, j]·x[j] in double-double, for every row i (the product M x as if computed in twice the
/// working precision, then kept unrounded). Accumulated column by column into separate high and low
/// parts, which vectorises; on CPUs with FMA and AVX2 the same operations run four rows per
/// instruction (both products are exact, so results are identical). From
/// [`crate::Tuning::parallel_rows_from`] rows, when faer's global parallelism allows two threads,
/// the two halves of the rows are accumulated on two threads (each row's sum is unchanged, so the
/// result is bitwise the same).
pub(crate) fn mat_vec(m: MatRef<'_, f64>, x: &[f64]) -> Vec<Dd> {
    let n = m.nrows();
    let (mut hi, mut lo) = (vec![0.0; n], vec![0.0; n]);
    // Inside a pool thread (refinement runs clusters in parallel) the other threads are busy.
    let nested = rayon::current_thread_index().is_some();
    if n >= Tuning::DEFAULT.parallel_rows_from && !nested && faer::get_global_parallelism().degree() >= 2 {
        let half = n / 2;
        let (hi_top, hi_bottom) = hi.split_at_mut(half);
        let (lo_top, lo_bottom) = lo.split_at_mut(half);
        let bottom = move || accumulate_rows(m.subrows(half, n - half), x, hi_bottom, lo_bottom);
        let spawned = std::thread::scope(|scope| {
            let spawned = std::thread::Builder::new().spawn_scoped(scope, bottom).is_ok();
            accumulate_rows(m.subrows(0, half), x, hi_top, lo_top);
            spawned
        });
        if !spawned {
            // No thread could be created: the bottom half here too.
            accumulate_rows(m.subrows(half, n - half), x, &mut hi[half..], &mut lo[half..]);
        }
    } else {
        accumulate_rows(m, x, &mut hi, &mut lo);
    }
    hi.into_iter().zip(lo).map(|(hi, lo)| Dd { hi, lo }).collect()
}

/// A matrix for double-double products, with its structure found once: a diagonal matrix
/// (lumped masses) costs n exact products (TwoProd) per vector, and a matrix with few nonzeros
/// (a banded or assembled stiffness stored densely) costs one double-double operation per
/// nonzero, instead of n² in every refinement step. The products are those of [`mat_vec`]
/// with its zero terms left out: a zero term adds an exact zero to both parts, so the values
/// are the same.
#[derive(Clone)]
pub(crate) struct Operand<'a> {
    matrix: MatRef<'a, f64>,
    structure: Structure,
}

/// How [`Operand::product`] forms its products.
#[derive(Clone)]
enum Structure {
    Dense,
    Diagonal,
    /// The nonzero entries by columns.
    Sparse(faer::sparse::SparseColMat<usize, f64>),
}

impl<'a> Operand<'a> {
    /// Wraps `matrix`: one scan of its entries, stopping once it holds more nonzeros than a
    /// sparse operand may (a dense matrix costs n²/16 reads).
    pub(crate) fn new(matrix: MatRef<'a, f64>) -> Self {
        let structure =
            if crate::linalg::reduce::is_diagonal(matrix) && crate::linalg::reduce::is_diagonal(matrix.transpose()) {
                Structure::Diagonal
            } else {
                match sparse_columns(matrix) {
                    Some(sparse) => Structure::Sparse(sparse),
                    None => Structure::Dense,
                }
            };
        Self { matrix, structure }
    }

    /// The matrix itself.
    pub(crate) fn matrix(&self) -> MatRef<'a, f64> {
        self.matrix
    }

    /// The nonzeros of column j as (row, value), rows ascending; None for a dense operand.
    pub(crate) fn column_nonzeros(&self, j: usize) -> Option<Vec<(usize, f64)>> {
        match &self.structure {
            Structure::Dense => None,
            Structure::Diagonal => {
                let d = self.matrix[(j, j)];
                Some(if d != 0.0 { vec![(j, d)] } else { Vec::new() })
            }
            Structure::Sparse(m) => {
                let m = m.as_ref();
                Some(m.row_idx_of_col(j).zip(m.val_of_col(j).iter().copied()).collect())
            }
        }
    }

    /// M x in double-double, with the values of [`mat_vec`].
    pub(crate) fn product(&self, x: &[f64]) -> Vec<Dd> {
        match &self.structure {
            Structure::Diagonal => diagonal_product(self.matrix, x),
            Structure::Sparse(m) => sparse_mat_vec(m.as_ref(), x),
            Structure::Dense => mat_vec(self.matrix, x),
        }
    }
}

/// The nonzero entries of `m` by columns when it has at most n²/[`crate::Tuning::sparse_fraction`]
/// of them (one scan, stopping past that many), else None.
pub(crate) fn sparse_columns(m: MatRef<'_, f64>) -> Option<faer::sparse::SparseColMat<usize, f64>> {
    nonzeros_by_columns(m, m.nrows() * m.ncols() / Tuning::DEFAULT.sparse_fraction)
}

/// The nonzero entries of `m` by columns (rows ascending), or None past `limit` nonzeros.
fn nonzeros_by_columns(m: MatRef<'_, f64>, limit: usize) -> Option<faer::sparse::SparseColMat<usize, f64>> {
    let mut column_starts = Vec::with_capacity(m.ncols() + 1);
    let (mut rows, mut values) = (Vec::new(), Vec::new());
    column_starts.push(0);
    for j in 0..m.ncols() {
        for (i, &v) in m.col(j).iter().enumerate() {
            if v != 0.0 {
                if rows.len() == limit {
                    return None;
                }
                rows.push(i);
                values.push(v);
            }
        }
        column_starts.push(rows.len());
    }
    let symbolic = faer::sparse::SymbolicSparseColMat::new_checked(m.nrows(), m.ncols(), column_starts, None, rows);
    Some(faer::sparse::SparseColMat::new(symbolic, values))
}

/// hi + lo += M x with the fastest exact kernel the CPU has.
fn accumulate_rows(m: MatRef<'_, f64>, x: &[f64], hi: &mut [f64], lo: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    {
        if fused_available() {
            // SAFETY: the running CPU supports FMA and AVX2, checked just above; the function
            // has no other requirement.
            unsafe { accumulate_fma(m, x, hi, lo) };
            return;
        }
    }
    accumulate(m, x, hi, lo, two_prod);
}

/// [`accumulate`] compiled for FMA and AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "fma,avx2")]
fn accumulate_fma(m: MatRef<'_, f64>, x: &[f64], hi: &mut [f64], lo: &mut [f64]) {
    accumulate(m, x, hi, lo, two_prod_fused);
}

/// hi + lo += M x, column by column: hi[i] + p = s + e₂ (TwoSum), p = m_ij·x_j − e (TwoProd).
#[inline(always)]
fn accumulate(
    m: MatRef<'_, f64>,
    x: &[f64],
    hi: &mut [f64],
    lo: &mut [f64],
    two_prod: impl Fn(f64, f64) -> (f64, f64),
) {
    // Four contiguous columns per pass over hi and lo: each row takes the four updates in
    // column order with hi and lo held in registers (the same operations in the same order as
    // one column at a time, so the same bits, with a quarter of the loads and stores of hi, lo).
    let mut j = 0;
    while j + 4 <= x.len() {
        let cols = [m.col(j), m.col(j + 1), m.col(j + 2), m.col(j + 3)].map(|c| c.try_as_col_major());
        let [Some(c0), Some(c1), Some(c2), Some(c3)] = cols else {
            break;
        };
        let (c0, c1, c2, c3) = (c0.as_slice(), c1.as_slice(), c2.as_slice(), c3.as_slice());
        let (x0, x1, x2, x3) = (x[j], x[j + 1], x[j + 2], x[j + 3]);
        for (i, (h, l)) in hi.iter_mut().zip(lo.iter_mut()).enumerate() {
            let (mut sh, mut sl) = (*h, *l);
            for (mij, xj) in [(c0[i], x0), (c1[i], x1), (c2[i], x2), (c3[i], x3)] {
                let (p, e) = two_prod(mij, xj);
                let (s, e2) = two_sum(sh, p);
                sh = s;
                sl += e + e2;
            }
            *h = sh;
            *l = sl;
        }
        j += 4;
    }
    for (j, &xj) in x.iter().enumerate().skip(j) {
        let col = m.col(j);
        match col.try_as_col_major() {
            Some(c) => {
                for ((h, l), &mij) in hi.iter_mut().zip(lo.iter_mut()).zip(c.as_slice()) {
                    let (p, e) = two_prod(mij, xj);
                    let (s, e2) = two_sum(*h, p);
                    *h = s;
                    *l += e + e2;
                }
            }
            None => {
                for (i, (h, l)) in hi.iter_mut().zip(lo.iter_mut()).enumerate() {
                    let (p, e) = two_prod(col[i], xj);
                    let (s, e2) = two_sum(*h, p);
                    *h = s;
                    *l += e + e2;
                }
            }
        }
    }
}

/// M x in double-double for a sparse M (compressed columns).
pub(crate) fn sparse_mat_vec(m: faer::sparse::SparseColMatRef<'_, usize, f64>, x: &[f64]) -> Vec<Dd> {
    #[cfg(target_arch = "x86_64")]
    if fused_available() {
        // SAFETY: the running CPU supports FMA and AVX2, checked just above.
        return unsafe { sparse_mat_vec_fma(m, x) };
    }
    sparse_mat_vec_as::<false>(m, x)
}

/// [`sparse_mat_vec`] compiled for FMA and AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "fma,avx2")]
fn sparse_mat_vec_fma(m: faer::sparse::SparseColMatRef<'_, usize, f64>, x: &[f64]) -> Vec<Dd> {
    sparse_mat_vec_as::<true>(m, x)
}

#[inline(always)]
fn sparse_mat_vec_as<const FUSED: bool>(m: faer::sparse::SparseColMatRef<'_, usize, f64>, x: &[f64]) -> Vec<Dd> {
    let (symbolic, val) = m.parts();
    let rows = symbolic.row_idx();
    let mut acc = vec![Dd::default(); m.nrows()];
    for (j, &xj) in x.iter().enumerate() {
        for k in symbolic.col_range(j) {
            let i = rows[k];
            let (p, e) = two_prod_as::<FUSED>(val[k], xj);
            let (s, e2) = two_sum(acc[i].hi, p);
            acc[i].hi = s;
            acc[i].lo += e + e2;
        }
    }
    acc
}

/// A vector held to twice the working precision as hi + lo, entry by entry (|lo_i| at most
/// half an ulp of hi_i): a refined eigenvector whose residual must not be limited by the
/// rounding of its entries (in a stiff chain, k·u·|x| with k = 1e12 at a stiff spring).
#[derive(Debug, Clone)]
pub(crate) struct SplitVector {
    /// The entries rounded to double.
    pub hi: Vec<f64>,
    /// What the rounding left out.
    pub lo: Vec<f64>,
}

impl SplitVector {
    /// A double vector (its low parts zero).
    pub(crate) fn of(hi: Vec<f64>) -> Self {
        let lo = vec![0.0; hi.len()];
        Self { hi, lo }
    }

    /// self += d, in double-double.
    pub(crate) fn add(&mut self, d: &[f64]) {
        for ((hi, lo), &di) in self.hi.iter_mut().zip(self.lo.iter_mut()).zip(d) {
            let sum = Dd { hi: *hi, lo: *lo }.plus(Dd::of(di));
            (*hi, *lo) = (sum.hi, sum.lo);
        }
    }

    /// self ·= s, in double-double.
    pub(crate) fn scale(&mut self, s: f64) {
        for (hi, lo) in self.hi.iter_mut().zip(self.lo.iter_mut()) {
            let product = Dd { hi: *hi, lo: *lo }.times(Dd::of(s));
            (*hi, *lo) = (product.hi, product.lo);
        }
    }
}

impl Operand<'_> {
    /// M (hi + lo) in double-double: M·hi as [`Operand::product`], plus M·lo, whose own
    /// rounding is of order u² relative to M·hi (lo is below the rounding of hi).
    pub(crate) fn product_split(&self, x: &SplitVector) -> Vec<Dd> {
        let mut out = self.product(&x.hi);
        if x.lo.iter().any(|&v| v != 0.0) {
            for (o, l) in out.iter_mut().zip(self.product(&x.lo)) {
                *o = o.plus(l);
            }
        }
        out
    }
}

/// Σ_i x_i·y_i for a split x: hi·y in double-double plus lo·y in double (of order u² relative).
pub(crate) fn dot_split(x: &SplitVector, y: &[Dd]) -> Dd {
    let low: f64 = x.lo.iter().zip(y).map(|(l, v)| l * v.hi).sum();
    dot(&x.hi, y).plus(Dd::of(low))
}

/// Σ_i x[i]·y[i] with y in double-double.
pub(crate) fn dot(x: &[f64], y: &[Dd]) -> Dd {
    #[cfg(target_arch = "x86_64")]
    if fused_available() {
        // SAFETY: the running CPU supports FMA and AVX2, checked just above.
        return unsafe { dot_fma(x, y) };
    }
    dot_as::<false>(x, y)
}

/// [`dot`] compiled for FMA and AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "fma,avx2")]
fn dot_fma(x: &[f64], y: &[Dd]) -> Dd {
    dot_as::<true>(x, y)
}

#[inline(always)]
fn dot_as<const FUSED: bool>(x: &[f64], y: &[Dd]) -> Dd {
    let mut acc = Dd::default();
    for (&xi, yi) in x.iter().zip(y) {
        acc = acc.plus(Dd::of(xi).times_as::<FUSED>(*yi));
    }
    acc
}

/// D x in double-double (exact: each entry is one product) for the diagonal of `d`.
fn diagonal_product(d: MatRef<'_, f64>, x: &[f64]) -> Vec<Dd> {
    #[cfg(target_arch = "x86_64")]
    if fused_available() {
        // SAFETY: the running CPU supports FMA and AVX2, checked just above.
        return unsafe { diagonal_product_fma(d, x) };
    }
    diagonal_product_as::<false>(d, x)
}

/// [`diagonal_product`] compiled for FMA and AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "fma,avx2")]
fn diagonal_product_fma(d: MatRef<'_, f64>, x: &[f64]) -> Vec<Dd> {
    diagonal_product_as::<true>(d, x)
}

#[inline(always)]
fn diagonal_product_as<const FUSED: bool>(d: MatRef<'_, f64>, x: &[f64]) -> Vec<Dd> {
    x.iter()
        .enumerate()
        .map(|(i, &v)| {
            let (hi, lo) = two_prod_as::<FUSED>(d[(i, i)], v);
            Dd { hi, lo }
        })
        .collect()
}

/// The residual Bx − ρAx of a pair, from A x and B x in double-double, each entry rounded once.
pub(crate) fn pair_residual(ax: &[Dd], bx: &[Dd], rho: Dd) -> Vec<f64> {
    #[cfg(target_arch = "x86_64")]
    if fused_available() {
        // SAFETY: the running CPU supports FMA and AVX2, checked just above.
        return unsafe { pair_residual_fma(ax, bx, rho) };
    }
    pair_residual_as::<false>(ax, bx, rho)
}

/// [`pair_residual`] compiled for FMA and AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "fma,avx2")]
fn pair_residual_fma(ax: &[Dd], bx: &[Dd], rho: Dd) -> Vec<f64> {
    pair_residual_as::<true>(ax, bx, rho)
}

#[inline(always)]
fn pair_residual_as<const FUSED: bool>(ax: &[Dd], bx: &[Dd], rho: Dd) -> Vec<f64> {
    ax.iter()
        .zip(bx)
        .map(|(ax, bx)| bx.minus(rho.times_as::<FUSED>(*ax)).to_f64())
        .collect()
}

/// The residuals of a pair (ω², x) of the pencil and of its shift-inverted form, from A x and
/// B x in double-double, each rounded once: r = Bx − ω²Ax and s = Ax − θ(Bx − σAx).
pub(crate) fn pencil_residuals(
    ax: &[Dd],
    bx: &[Dd],
    (omega_sq, theta, sigma): (f64, f64, f64),
    r: &mut [f64],
    s: &mut [f64],
) {
    #[cfg(target_arch = "x86_64")]
    if fused_available() {
        // SAFETY: the running CPU supports FMA and AVX2, checked just above.
        return unsafe { pencil_residuals_fma(ax, bx, (omega_sq, theta, sigma), r, s) };
    }
    pencil_residuals_as::<false>(ax, bx, (omega_sq, theta, sigma), r, s);
}

/// [`pencil_residuals`] compiled for FMA and AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "fma,avx2")]
fn pencil_residuals_fma(ax: &[Dd], bx: &[Dd], scalars: (f64, f64, f64), r: &mut [f64], s: &mut [f64]) {
    pencil_residuals_as::<true>(ax, bx, scalars, r, s);
}

#[inline(always)]
fn pencil_residuals_as<const FUSED: bool>(
    ax: &[Dd],
    bx: &[Dd],
    (omega_sq, theta, sigma): (f64, f64, f64),
    r: &mut [f64],
    s: &mut [f64],
) {
    let (w, t, shift) = (Dd::of(omega_sq), Dd::of(theta), Dd::of(sigma));
    for (((ax, bx), r), s) in ax.iter().zip(bx).zip(r.iter_mut()).zip(s.iter_mut()) {
        *r = bx.minus(w.times_as::<FUSED>(*ax)).to_f64();
        *s = ax
            .minus(t.times_as::<FUSED>(bx.minus(shift.times_as::<FUSED>(*ax))))
            .to_f64();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cancellation_keeps_the_small_part() {
        // (1e16 + 1) − 1e16 is 0 in double but 1 in double-double.
        let a = Dd::of(1e16).plus(Dd::of(1.0));
        assert_eq!(a.minus(Dd::of(1e16)).to_f64(), 1.0);
        let third = Dd::of(1.0).over(Dd::of(3.0));
        // 3·(1/3) − 1 is at the 1e-32 level.
        assert!(third.times(Dd::of(3.0)).minus(Dd::of(1.0)).to_f64().abs() < 1e-31);
    }

    #[test]
    fn split_product_is_exact() {
        // (1 + u)(1 − u) = 1 − u², error −u² (not representable in one double's product).
        let u = f64::EPSILON;
        assert_eq!(two_prod(1.0 + u, 1.0 - u), (1.0, -u * u));
        // (1 + 2^−30)² = 1 + 2^−29 + 2^−60, error 2^−60; and the same near the overflow limit,
        // where the factor is scaled first.
        let a = 1.0 + 2f64.powi(-30);
        assert_eq!(two_prod(a, a), (1.0 + 2f64.powi(-29), 2f64.powi(-60)));
        let big = 2f64.powi(1000) * a;
        assert_eq!(
            two_prod(big, a),
            (2f64.powi(1000) * (1.0 + 2f64.powi(-29)), 2f64.powi(940))
        );
    }

    /// The FMA variants (taken on this CPU when it has FMA) give bit for bit what the split
    /// products give: both product errors are exact.
    #[test]
    fn fused_and_split_kernels_agree_bitwise() {
        let x: Vec<f64> = (0..50)
            .map(|i| ((i * 37 % 23) as f64 - 11.0) / 7.0 * 1e3f64.powi(i % 5))
            .collect();
        let ax: Vec<Dd> = x.iter().map(|&v| Dd::of(v).times(Dd::of(1.0 / 3.0))).collect();
        let bx: Vec<Dd> = x.iter().map(|&v| Dd::of(v * v).plus(Dd::of(1e-20))).collect();
        let scalars = (0.7, 1.0 / 0.7, -1e-3);
        let (mut r1, mut s1, mut r2, mut s2) = (vec![0.0; 50], vec![0.0; 50], vec![0.0; 50], vec![0.0; 50]);
        pencil_residuals(&ax, &bx, scalars, &mut r1, &mut s1);
        pencil_residuals_as::<false>(&ax, &bx, scalars, &mut r2, &mut s2);
        assert_eq!((r1, s1), (r2, s2));
        let d1 = dot(&x, &bx);
        let d2 = dot_as::<false>(&x, &bx);
        assert_eq!((d1.hi, d1.lo), (d2.hi, d2.lo));
    }

    #[test]
    fn matrix_vector_product_is_exact_on_a_cancelling_row() {
        let m = faer::mat![[1e12 + 1.0, -1e12], [-1e12, 1e12]];
        let y = mat_vec(m.as_ref(), &[1.0 + f64::EPSILON, 1.0]);
        // Row 0: (1e12 + 1)(1 + u) − 1e12 = 1 + u + 1e12·u exactly.
        let expected = 1.0 + f64::EPSILON + 1e12 * f64::EPSILON;
        assert!((y[0].to_f64() - expected).abs() <= 2.0 * f64::EPSILON * expected);
    }

    /// Four columns per pass (and the leftover columns one at a time) give the bits of one
    /// column at a time: the same operations per row, in the same order.
    #[test]
    fn four_columns_per_pass_change_no_bit() {
        let (n, k) = (29, 11);
        let m = faer::Mat::from_fn(n, k, |i, j| {
            ((i * 31 + j * 17) % 97) as f64 / 7.0 - 6.0 + 1e-9 * (i * j) as f64
        });
        let x: Vec<f64> = (0..k).map(|j| ((j * 13) % 29) as f64 / 3.0 - 4.5).collect();
        let (mut hi, mut lo) = (vec![0.0; n], vec![0.0; n]);
        accumulate(m.as_ref(), &x, &mut hi, &mut lo, two_prod);
        let (mut hi1, mut lo1) = (vec![0.0; n], vec![0.0; n]);
        for j in 0..k {
            accumulate(m.as_ref().subcols(j, 1), &x[j..j + 1], &mut hi1, &mut lo1, two_prod);
        }
        assert_eq!((hi, lo), (hi1, lo1));
    }

    /// A diagonal operand's products are the dense kernel's, bit for bit; a matrix with one
    /// off-diagonal entry is not taken for diagonal.
    #[test]
    fn diagonal_operands_give_the_dense_products() {
        let n = 13;
        let mut m = faer::Mat::from_fn(n, n, |i, j| if i == j { 1.0 / (i as f64 + 3.0) } else { 0.0 });
        let x: Vec<f64> = (0..n).map(|j| ((j * 13) % 29) as f64 / 3.0 - 4.5).collect();
        let operand = Operand::new(m.as_ref());
        assert!(matches!(operand.structure, Structure::Diagonal));
        let fast = operand.product(&x);
        let dense = mat_vec(m.as_ref(), &x);
        assert!(fast.iter().zip(&dense).all(|(f, d)| (f.hi, f.lo) == (d.hi, d.lo)));
        // One entry off the diagonal, below or above it: not diagonal.
        for (i, j) in [(n - 1, 0), (0, n - 1)] {
            let mut off = m.clone();
            off[(i, j)] = 0.5;
            let operand = Operand::new(off.as_ref());
            assert!(!matches!(operand.structure, Structure::Diagonal), "({i}, {j})");
            let fast = operand.product(&x);
            let dense = mat_vec(off.as_ref(), &x);
            assert!(fast.iter().zip(&dense).all(|(f, d)| (f.hi, f.lo) == (d.hi, d.lo)));
        }
        m[(1, 0)] = 1.0;
        assert!(!matches!(Operand::new(m.as_ref()).structure, Structure::Diagonal));
    }

    /// A banded matrix stored densely is taken for sparse, and its products have the values of
    /// the dense kernel (the zero terms it skips add exact zeros), also on a row whose terms
    /// cancel to a tiny sum; a dense matrix stays dense.
    #[test]
    fn sparse_operands_give_the_dense_products() {
        let n = 200;
        let band = faer::Mat::from_fn(n, n, |i, j| match i.abs_diff(j) {
            0 => 1e12 * (1.0 + i as f64 / 7.0),
            1 => -1e12 * (1.0 + i.min(j) as f64 / 7.0) + 0.25,
            3 => 1.0 / (1.0 + (i + j) as f64),
            _ => 0.0,
        });
        let x: Vec<f64> = (0..n).map(|j| 1.0 + ((j * 13) % 29) as f64 * f64::EPSILON).collect();
        let operand = Operand::new(band.as_ref());
        assert!(matches!(operand.structure, Structure::Sparse(_)));
        let fast = operand.product(&x);
        let dense = mat_vec(band.as_ref(), &x);
        for (i, (f, d)) in fast.iter().zip(&dense).enumerate() {
            assert!(f.hi == d.hi && f.lo == d.lo, "row {i}: {f:?} against {d:?}");
        }
        let full = faer::Mat::from_fn(n, n, |i, j| 1.0 / (1.0 + i as f64 + j as f64));
        assert!(matches!(Operand::new(full.as_ref()).structure, Structure::Dense));
    }

    #[test]
    fn rows_on_two_threads_change_no_bit() {
        let n = Tuning::DEFAULT.parallel_rows_from + 37;
        let m = faer::Mat::from_fn(n, n, |i, j| {
            ((i * 31 + j * 17) % 97) as f64 / 7.0 - 6.0 + 1e-9 * j as f64
        });
        let x: Vec<f64> = (0..n).map(|j| ((j * 13) % 29) as f64 / 3.0 - 4.5).collect();
        let split = mat_vec(m.as_ref(), &x);
        let (mut hi, mut lo) = (vec![0.0; n], vec![0.0; n]);
        accumulate_rows(m.as_ref(), &x, &mut hi, &mut lo);
        for i in 0..n {
            assert_eq!((split[i].hi, split[i].lo), (hi[i], lo[i]), "row {i}");
        }
    }
}
