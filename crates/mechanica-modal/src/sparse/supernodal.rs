//! Solves K X = R for a block of b right-hand sides with a supernodal Cholesky factor
//! K = Pᵀ L Lᵀ P (faer's numeric LLᵀ values on its symbolic analysis): the shift-invert operator
//! of the sparse Lanczos solver ([`crate::solve_sparse`]).
//!
//! faer's own supernodal solve dispatches a dense triangular solve and a matrix product per
//! supernode; on a 2-D grid most supernodes have one to a few columns, so that overhead
//! dominates (measured in docs/benchmarks.md). Here the b
//! right-hand sides are stored row-interleaved (entry (i, c) at i·b + c), so each entry of L is
//! read once per pass and used b times, and each supernode costs two short loops:
//!
//! - forward, L y = P r: for each supernode (columns s₀..s₀+w, below-diagonal rows P_s),
//!   y_j = (r_j − Σ_{i<j} L_ji y_i)/L_jj inside the diagonal block, then r_{P_s} −= L_{P_s,s} y_s;
//! - backward, Lᵀ x = y, supernodes in reverse: x_j = (y_j − Σ_{i>j} L_ij x_i)/L_jj with the
//!   sum over the diagonal block and the gathered rows P_s (already final).
//!
//! The arithmetic is that of any column-oriented triangular solve (same backward error bound).

use faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky;

/// A supernodal LLᵀ factor with its fill-reducing permutation, ready for block solves.
pub(crate) struct SupernodalSolver<'a> {
    symbolic: &'a SymbolicSupernodalCholesky<usize>,
    values: &'a [f64],
    /// fwd[i] = the original index of permuted row i (None: identity).
    fwd: Option<&'a [usize]>,
}

impl<'a> SupernodalSolver<'a> {
    /// The solver of K = Pᵀ L Lᵀ P, with `fwd` the forward array of P (faer's
    /// `SymbolicCholesky::perm().arrays().0`) and `values` the numeric factor.
    pub(crate) fn new(
        symbolic: &'a SymbolicSupernodalCholesky<usize>,
        values: &'a [f64],
        fwd: Option<&'a [usize]>,
    ) -> Self {
        Self { symbolic, values, fwd }
    }

    /// X ← K⁻¹X for the n × b column-major block `x`; `work` is resized to n·b.
    pub(crate) fn solve_in_place(&self, x: &mut [f64], b: usize, work: &mut Vec<f64>) {
        let n = self.symbolic.nrows();
        if n == 0 || b == 0 {
            return;
        }
        work.clear();
        work.resize(n * b, 0.0);
        for c in 0..b {
            let column = &x[n * c..n * (c + 1)];
            for i in 0..n {
                work[i * b + c] = column[self.fwd.map_or(i, |f| f[i])];
            }
        }
        // Column groups of 8, 4 or fewer share one kernel call; their values stay in registers.
        let mut first = 0;
        let mut local = Vec::new();
        while first < b {
            let group = match b - first {
                8.. => 8,
                4..8 => 4,
                rest => rest,
            };
            match group {
                1 => self.dispatch::<1>(work, b, first, &mut local),
                2 => self.dispatch::<2>(work, b, first, &mut local),
                3 => self.dispatch::<3>(work, b, first, &mut local),
                4 => self.dispatch::<4>(work, b, first, &mut local),
                _ => self.dispatch::<8>(work, b, first, &mut local),
            }
            first += group;
        }
        for c in 0..b {
            let column = &mut x[n * c..n * (c + 1)];
            for i in 0..n {
                column[self.fwd.map_or(i, |f| f[i])] = work[i * b + c];
            }
        }
    }

    /// The columns s₀..s₀+w, the below-diagonal rows and the (w + rows) × w column-major
    /// values of supernode s.
    fn supernode(&self, s: usize) -> (usize, usize, &'a [usize], &'a [f64]) {
        let symbolic = self.symbolic;
        let start = symbolic.supernode_begin()[s];
        let width = symbolic.supernode_end()[s] - start;
        let row_start = symbolic.col_ptr_for_row_idx()[s];
        let rows = &symbolic.row_idx()[row_start..row_start + symbolic.nnz_per_super()[s]];
        let ptr = symbolic.col_ptr_for_val();
        (start, width, rows, &self.values[ptr[s]..ptr[s + 1]])
    }

    /// [`Self::solve_group`], compiled for AVX2 when the CPU has it (wider vectors only: no
    /// operation is fused, so the result is the same on every CPU).
    fn dispatch<const W: usize>(&self, y: &mut [f64], stride: usize, first: usize, local: &mut Vec<f64>) {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: the running CPU supports AVX2, checked just above; the function has no
                // other requirement.
                unsafe { self.solve_group_avx2::<W>(y, stride, first, local) };
                return;
            }
        }
        self.solve_group::<W>(y, stride, first, local);
    }

    /// [`Self::solve_group`] compiled for AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn solve_group_avx2<const W: usize>(&self, y: &mut [f64], stride: usize, first: usize, local: &mut Vec<f64>) {
        self.solve_group::<W>(y, stride, first, local);
    }

    /// Columns first..first+W of the row-interleaved block (row stride `stride`) ← (LLᵀ)⁻¹ of
    /// themselves. `local` holds a supernode's below-diagonal rows (W per row).
    #[inline(always)]
    fn solve_group<const W: usize>(&self, y: &mut [f64], stride: usize, first: usize, local: &mut Vec<f64>) {
        let at = |row: usize| row * stride + first;
        // Forward: y ← L⁻¹y; the below-diagonal update is accumulated in `local`, then
        // scattered once per supernode.
        for s in 0..self.symbolic.n_supernodes() {
            let (start, width, rows, block) = self.supernode(s);
            let height = width + rows.len();
            local.clear();
            local.resize(rows.len() * W, 0.0);
            for j in 0..width {
                let column = &block[j * height..(j + 1) * height];
                let inverse = 1.0 / column[j];
                let mut yj = [0.0; W];
                let target = &mut y[at(start + j)..at(start + j) + W];
                for (value, t) in yj.iter_mut().zip(target.iter_mut()) {
                    *value = *t * inverse;
                    *t = *value;
                }
                for (i, l) in column[j + 1..width].iter().enumerate() {
                    let target = &mut y[at(start + j + 1 + i)..at(start + j + 1 + i) + W];
                    for (t, value) in target.iter_mut().zip(&yj) {
                        *t -= l * value;
                    }
                }
                for (acc, l) in local.chunks_exact_mut(W).zip(&column[width..]) {
                    for (t, value) in acc.iter_mut().zip(&yj) {
                        *t += l * value;
                    }
                }
            }
            for (&r, acc) in rows.iter().zip(local.chunks_exact(W)) {
                let target = &mut y[at(r)..at(r) + W];
                for (t, value) in target.iter_mut().zip(acc) {
                    *t -= value;
                }
            }
        }
        // Backward: y ← L⁻ᵀy; the below-diagonal rows (final already) are gathered once per
        // supernode; four accumulators shorten the dependency chain of each dot product.
        for s in (0..self.symbolic.n_supernodes()).rev() {
            let (start, width, rows, block) = self.supernode(s);
            let height = width + rows.len();
            local.clear();
            for &r in rows {
                local.extend_from_slice(&y[at(r)..at(r) + W]);
            }
            for j in (0..width).rev() {
                let column = &block[j * height..(j + 1) * height];
                let mut sums = [[0.0; W]; 4];
                let mut quads = local.chunks_exact(4 * W).zip(column[width..].chunks_exact(4));
                for (x, l) in quads.by_ref() {
                    for (q, sum) in sums.iter_mut().enumerate() {
                        for c in 0..W {
                            sum[c] += l[q] * x[q * W + c];
                        }
                    }
                }
                let done = rows.len() / 4 * 4;
                for (p, l) in column[width + done..].iter().enumerate() {
                    for c in 0..W {
                        sums[p][c] += l * local[(done + p) * W + c];
                    }
                }
                for (i, l) in column[j + 1..width].iter().enumerate() {
                    let source = at(start + j + 1 + i);
                    for c in 0..W {
                        sums[3][c] += l * y[source + c];
                    }
                }
                let inverse = 1.0 / column[j];
                let target = &mut y[at(start + j)..at(start + j) + W];
                for (c, t) in target.iter_mut().enumerate() {
                    *t = (*t - ((sums[0][c] + sums[1][c]) + (sums[2][c] + sums[3][c]))) * inverse;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing;
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::sparse::linalg::SupernodalThreshold;
    use faer::sparse::linalg::cholesky::{
        CholeskySymbolicParams, LltRef, SymbolicCholeskyRaw, SymmetricOrdering, factorize_symbolic_cholesky,
    };
    use faer::sparse::{SparseColMat, Triplet};
    use faer::{Conj, MatMut, Par, Side};

    /// K x for the full-storage triplets of K.
    fn apply(entries: &[Triplet<usize, usize, f64>], x: &[f64], n: usize, b: usize) -> Vec<f64> {
        let mut y = vec![0.0; n * b];
        for c in 0..b {
            for t in entries {
                y[t.row + n * c] += t.val * x[t.col + n * c];
            }
        }
        y
    }

    /// Grid Laplacian plus a varying diagonal (positive definite, many small supernodes), and a
    /// dense block coupling the first `dense` unknowns (one wide supernode).
    fn test_matrix(side: usize, dense: usize) -> (usize, Vec<Triplet<usize, usize, f64>>) {
        let n = side * side;
        let (_, mut entries) = testing::grid_laplacian(side, side);
        for i in 0..n {
            entries.push(Triplet::new(i, i, 0.1 + (i % 7) as f64 * 0.3));
        }
        for i in 0..dense {
            for j in 0..dense {
                if i != j {
                    entries.push(Triplet::new(i, j, 0.01 / (1.0 + (i + j) as f64)));
                }
            }
        }
        (n, entries)
    }

    #[test]
    fn agrees_with_faer_and_solves_the_system() {
        for (side, dense, b) in [(12, 0, 1), (20, 0, 3), (15, 40, 2), (9, 81, 5), (10, 30, 13)] {
            let (n, entries) = test_matrix(side, dense);
            let k = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &entries).expect("valid");
            let symbolic = factorize_symbolic_cholesky(
                k.symbolic(),
                Side::Lower,
                SymmetricOrdering::Amd,
                CholeskySymbolicParams {
                    supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                    ..Default::default()
                },
            )
            .expect("symbolic");
            let mut values = vec![0.0; symbolic.len_val()];
            let mut mem = MemBuffer::new(symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()));
            symbolic
                .factorize_numeric_llt(
                    &mut values,
                    k.as_ref(),
                    Side::Lower,
                    Default::default(),
                    Par::Seq,
                    MemStack::new(&mut mem),
                    Default::default(),
                )
                .expect("positive definite");
            let SymbolicCholeskyRaw::Supernodal(supernodal) = symbolic.raw() else {
                panic!("forced supernodal");
            };
            let rhs: Vec<f64> = (0..n * b).map(|i| ((i * 37 % 101) as f64 - 50.0) / 7.0).collect();
            let mut ours = rhs.clone();
            let fwd = symbolic.perm().map(|p| p.arrays().0);
            SupernodalSolver::new(supernodal, &values, fwd).solve_in_place(&mut ours, b, &mut Vec::new());
            let mut theirs = rhs.clone();
            let mut mem = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(b, Par::Seq));
            LltRef::new(&symbolic, &values).solve_in_place_with_conj(
                Conj::No,
                MatMut::from_column_major_slice_mut(&mut theirs, n, b),
                Par::Seq,
                MemStack::new(&mut mem),
            );
            let scale = theirs.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let difference = ours.iter().zip(&theirs).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
            assert!(difference <= 1e-12 * scale, "side {side}: {difference:e} of {scale:e}");
            let residual = apply(&entries, &ours, n, b);
            let worst = residual
                .iter()
                .zip(&rhs)
                .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
            let rhs_scale = rhs.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            assert!(worst <= 1e-12 * rhs_scale, "side {side}: residual {worst:e}");
        }
    }
}
