//! Helpers shared by the modal test families.

use faer::Mat;
use faer::sparse::Triplet;

/// The nonzero entries of a dense matrix, column by column, for the sparse solver.
pub fn triplets(m: &Mat<f64>) -> Vec<Triplet<usize, usize, f64>> {
    let mut t = Vec::new();
    for j in 0..m.ncols() {
        for i in 0..m.nrows() {
            if m[(i, j)] != 0.0 {
                t.push(Triplet::new(i, j, m[(i, j)]));
            }
        }
    }
    t
}
