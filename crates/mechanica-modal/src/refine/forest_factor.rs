//! K = B − σA factored as LDLᵀ without fill when the off-diagonal pattern of A and B together
//! is a forest (spring chains and spring trees with lumped or consistent masses, numbered in
//! any order): eliminating each tree from its leaves towards a root makes no fill, so a factor
//! costs O(n) and a solve O(n), without the per-column pattern search of a general sparse LU.
//!
//! There is no pivoting. The elimination is rooted, for each shift, at the coordinate where the
//! start vector of the refined mode is largest: the pivot that vanishes as σ nears the
//! eigenvalue is then the root's, which multiplies nothing (the twisted factorizations of
//! Parlett and Dhillon choose their twist index the same way, where the eigenvector is
//! largest). Elsewhere a pivot can still be small when σ is near an eigenvalue of a subtree; the
//! factor is then declined once its element growth Σ_c k_ic²/|d_c| at some coordinate i exceeds
//! [`GROWTH_LIMIT`] times the row sum Σ_j |k_ij|, since the factorization is the exact one of
//! a K + ΔK with |ΔK| ≤ γ_n |L||D||Lᵀ| (Higham, *Accuracy and Stability of Numerical
//! Algorithms*, 2nd ed., Theorem 9.3 for LU without pivoting, with U = DLᵀ; no definiteness is
//! needed), and that growth is what |L||D||Lᵀ| adds to |d_i| on its diagonal. The caller
//! then uses the LU with partial pivoting. The factor only drives Newton steps whose residuals are measured in double-double, so its
//! accuracy decides how fast they converge, never what they converge to.

use crate::linalg::forest_order::{ForestOrder, leaves_first};
use faer::sparse::SymbolicSparseColMatRef;

/// Largest element growth, relative to the row sums of |K|, of an accepted factor: 2²⁰, a
/// backward error of about 1e-10 relative to each row.
const GROWTH_LIMIT: f64 = 1_048_576.0;

/// The off-diagonal pattern of a symmetric sparse matrix stored by columns (both triangles),
/// when it is a forest: each coordinate's neighbours with the position of their coupling among
/// the stored values, and the position of each diagonal entry.
pub(crate) struct ForestPattern {
    starts: Vec<usize>,
    neighbours: Vec<(usize, usize)>,
    diagonal: Vec<Option<usize>>,
}

impl ForestPattern {
    /// None when the off-diagonal pattern has a cycle or an odd number of entries. The pattern
    /// is read as symmetric (each coupling serves L and Lᵀ): A and B are symmetrised before.
    pub(crate) fn of(pattern: SymbolicSparseColMatRef<'_, usize>) -> Option<Self> {
        let n = pattern.ncols();
        let mut starts = Vec::with_capacity(n + 1);
        let mut neighbours = Vec::new();
        let mut diagonal = vec![None; n];
        let mut position = 0;
        for j in 0..n {
            starts.push(neighbours.len());
            for i in pattern.row_idx_of_col(j) {
                if i == j {
                    diagonal[j] = Some(position);
                } else {
                    neighbours.push((i, position));
                }
                position += 1;
            }
        }
        starts.push(neighbours.len());
        let forest = Self {
            starts,
            neighbours,
            diagonal,
        };
        let edges = forest.neighbours.len() / 2;
        let symmetric = forest.neighbours.len().is_multiple_of(2);
        (symmetric && edges < n.max(1) && forest.leaves_first(0).is_some()).then_some(forest)
    }

    /// The factorization of K = B − shift·A, with B's and A's values at the stored positions,
    /// eliminated towards `root` (and towards the lowest coordinate of every other tree);
    /// None when a pivot is zero or not finite, or the growth exceeds [`GROWTH_LIMIT`].
    pub(crate) fn factor(&self, b: &[f64], a: &[f64], shift: f64, root: usize) -> Option<ForestFactor> {
        let (leaves_first, parent) = self.leaves_first(root)?;
        let entry = |p: Option<usize>| p.map_or(0.0, |p| b[p] - shift * a[p]);
        let mut pivots: Vec<f64> = self.diagonal.iter().map(|&p| entry(p)).collect();
        let mut row_sums: Vec<f64> = pivots.iter().map(|d| d.abs()).collect();
        for (i, sum) in row_sums.iter_mut().enumerate() {
            *sum += self
                .neighbours_of(i)
                .iter()
                .map(|&(_, p)| entry(Some(p)).abs())
                .sum::<f64>();
        }
        let mut growth = vec![0.0_f64; pivots.len()];
        let mut multipliers = vec![0.0_f64; pivots.len()];
        for &node in &leaves_first {
            let d = pivots[node];
            if d == 0.0 || !d.is_finite() || growth[node] > GROWTH_LIMIT * row_sums[node] {
                return None;
            }
            if let Some((up, p)) = parent[node] {
                let coupling = entry(Some(p));
                multipliers[node] = coupling / d;
                pivots[up] -= multipliers[node] * coupling;
                growth[up] += (multipliers[node] * coupling).abs();
            }
        }
        let parent = parent.iter().map(|p| p.map(|(up, _)| up)).collect();
        Some(ForestFactor {
            leaves_first,
            parent,
            multipliers,
            pivots,
        })
    }

    fn neighbours_of(&self, i: usize) -> &[(usize, usize)] {
        &self.neighbours[self.starts[i]..self.starts[i + 1]]
    }

    /// An elimination order with every coordinate before its parent, the tree of `root` rooted
    /// there, and each coordinate's parent with the position of their coupling; None when a
    /// coordinate is reached twice (a cycle).
    fn leaves_first(&self, root: usize) -> Option<ForestOrder<usize>> {
        leaves_first(self.diagonal.len(), std::iter::once(root), |i| self.neighbours_of(i))
    }
}

/// K = LDLᵀ of [`ForestPattern::factor`]: the unit lower factor L has the entry `multipliers[c]`
/// at (parent of c, c).
pub(crate) struct ForestFactor {
    leaves_first: Vec<usize>,
    parent: Vec<Option<usize>>,
    multipliers: Vec<f64>,
    pivots: Vec<f64>,
}

impl ForestFactor {
    /// K⁻¹r: forward through the leaves, the pivots, back from the roots.
    pub(crate) fn solve(&self, r: &[f64]) -> Vec<f64> {
        let mut y = r.to_vec();
        for &node in &self.leaves_first {
            if let Some(up) = self.parent[node] {
                y[up] -= self.multipliers[node] * y[node];
            }
        }
        y.iter_mut().zip(&self.pivots).for_each(|(v, d)| *v /= d);
        for &node in self.leaves_first.iter().rev() {
            if let Some(up) = self.parent[node] {
                y[node] -= self.multipliers[node] * y[up];
            }
        }
        y
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::graded::SplitMix;
    use faer::Mat;

    /// A random symmetric matrix on a random tree of order n (random parents, a random
    /// numbering), its dense form, the symbolic pattern by columns and the values.
    fn random_tree_matrix(rng: &mut SplitMix, n: usize) -> (Mat<f64>, faer::sparse::SparseColMat<usize, f64>) {
        let mut label: Vec<usize> = (0..n).collect();
        for i in (1..n).rev() {
            label.swap(i, rng.below(i + 1));
        }
        let mut dense = Mat::<f64>::zeros(n, n);
        for k in 0..n {
            dense[(label[k], label[k])] = rng.uniform(-1.0, 1.0) * 10f64.powf(6.0 * rng.unit());
            if k > 0 {
                let (i, j) = (label[k], label[rng.below(k)]);
                let coupling = rng.uniform(-1.0, 1.0) * 10f64.powf(6.0 * rng.unit());
                dense[(i, j)] = coupling;
                dense[(j, i)] = coupling;
            }
        }
        let mut triplets = Vec::new();
        for j in 0..n {
            for i in 0..n {
                if dense[(i, j)] != 0.0 {
                    triplets.push(faer::sparse::Triplet::new(i, j, dense[(i, j)]));
                }
            }
        }
        let sparse = faer::sparse::SparseColMat::try_new_from_triplets(n, n, &triplets).expect("valid triplets");
        (dense, sparse)
    }

    #[test]
    fn solves_random_trees_rooted_anywhere() {
        let mut rng = SplitMix::new(17);
        for _ in 0..200 {
            let n = 1 + rng.below(40);
            let (dense, sparse) = random_tree_matrix(&mut rng, n);
            let pattern = ForestPattern::of(sparse.symbolic()).expect("a tree");
            let values = sparse.val();
            let zeros = vec![0.0; values.len()];
            let Some(factor) = pattern.factor(values, &zeros, 0.0, rng.below(n)) else {
                continue; // growth beyond the limit: declined, which the caller handles
            };
            let x: Vec<f64> = (0..n).map(|_| rng.uniform(-1.0, 1.0)).collect();
            let r: Vec<f64> = (0..n).map(|i| (0..n).map(|j| dense[(i, j)] * x[j]).sum()).collect();
            let solved = factor.solve(&r);
            // Backward check: the residual of the computed solution against |K||x̂| (the
            // factor's backward error with growth at most GROWTH_LIMIT).
            for i in 0..n {
                let residual: f64 = (0..n).map(|j| dense[(i, j)] * solved[j]).sum::<f64>() - r[i];
                let scale: f64 = (0..n).map(|j| (dense[(i, j)] * solved[j]).abs()).sum::<f64>() + r[i].abs();
                assert!(
                    residual.abs() <= 1e-9 * scale.max(f64::MIN_POSITIVE),
                    "row {i}: {residual} vs {scale}"
                );
            }
        }
    }

    #[test]
    fn the_shift_enters_every_stored_entry() {
        // K = B − 2A with A tridiagonal (a consistent mass) on a chain 0 – 1 – 2.
        let triplets: Vec<_> = [(0, 0), (1, 0), (0, 1), (1, 1), (2, 1), (1, 2), (2, 2)]
            .into_iter()
            .map(|(i, j)| faer::sparse::Triplet::new(i, j, 1.0))
            .collect();
        let pattern_matrix =
            faer::sparse::SparseColMat::<usize, f64>::try_new_from_triplets(3, 3, &triplets).expect("valid");
        let b = [4.0, -1.0, -1.0, 4.0, -1.0, -1.0, 4.0];
        let a = [1.0, 0.25, 0.25, 1.0, 0.25, 0.25, 1.0];
        let pattern = ForestPattern::of(pattern_matrix.symbolic()).expect("a chain");
        let factor = pattern.factor(&b, &a, 2.0, 1).expect("nonsingular");
        // K = [[2, −1.5, 0], [−1.5, 2, −1.5], [0, −1.5, 2]]; K·(1, 1, 1) = (0.5, −1, 0.5).
        let x = factor.solve(&[0.5, -1.0, 0.5]);
        for v in x {
            assert!((v - 1.0).abs() < 1e-14, "{v}");
        }
    }

    #[test]
    fn cycles_and_dense_patterns_are_not_forests() {
        let ring: Vec<_> = [(0, 1), (1, 2), (2, 0)]
            .into_iter()
            .flat_map(|(i, j)| [(i, j), (j, i), (i, i)])
            .map(|(i, j)| faer::sparse::Triplet::new(i, j, 1.0))
            .collect();
        let ring = faer::sparse::SparseColMat::<usize, f64>::try_new_from_triplets(3, 3, &ring).expect("valid");
        assert!(ForestPattern::of(ring.symbolic()).is_none());
        let two_chains: Vec<_> = [(0, 1), (2, 3)]
            .into_iter()
            .flat_map(|(i, j)| [(i, j), (j, i), (i, i), (j, j)])
            .map(|(i, j)| faer::sparse::Triplet::new(i, j, 1.0))
            .collect();
        let two_chains =
            faer::sparse::SparseColMat::<usize, f64>::try_new_from_triplets(4, 4, &two_chains).expect("valid");
        assert!(ForestPattern::of(two_chains.symbolic()).is_some());
    }

    #[test]
    fn a_zero_pivot_is_declined() {
        // [[1, 1], [1, 1]] is singular: the second pivot is exactly zero.
        let triplets: Vec<_> = [(0, 0), (1, 0), (0, 1), (1, 1)]
            .into_iter()
            .map(|(i, j)| faer::sparse::Triplet::new(i, j, 1.0))
            .collect();
        let m = faer::sparse::SparseColMat::<usize, f64>::try_new_from_triplets(2, 2, &triplets).expect("valid");
        let pattern = ForestPattern::of(m.symbolic()).expect("an edge");
        let identity = [1.0, 0.0, 0.0, 1.0];
        assert!(pattern.factor(m.val(), &identity, 0.0, 0).is_none());
        assert!(pattern.factor(m.val(), &identity, -1.0, 0).is_some());
    }
}
