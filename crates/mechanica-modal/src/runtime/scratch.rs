//! Working matrices kept from one dense solve for the next.
//!
//! An all-pairs solve of order n works in six n×n matrices (the copies of A and B, three of
//! divide and conquer, and the bottom certificate's), of which the caller keeps one (the mode
//! shapes). Fresh memory costs a page fault per 4 KiB on its first write, and the allocator
//! returns large blocks to the system when they are freed, so that each solve would fault its
//! working set anew. Freed working matrices of at least [`crate::Tuning::kept_from_bytes`] are
//! kept here, at most [`crate::Tuning::kept_matrices`] of them, and the next solve takes them
//! instead of allocating, which halves its page faults (measured in docs/benchmarks.md).
//!
//! The memory stays with the process after the solve (at n = 4000, up to 5 × 128 MB, less than
//! the solve's own peak), as optimised BLAS libraries keep their buffers; [`release`] (C:
//! `mech_modal_release_scratch`) gives it back to the system.

use crate::tuning::Tuning;
use faer::Mat;
use std::sync::Mutex;

/// Kept matrices with the shape they were given back in (their storage holds at least that).
#[derive(Default)]
struct Pool {
    kept: Vec<Mat<f64>>,
}

impl Pool {
    /// The smallest kept matrix whose shape covers rows × cols, in the shape it was given back in.
    fn take(&mut self, rows: usize, cols: usize) -> Option<Mat<f64>> {
        let fitting = self
            .kept
            .iter()
            .enumerate()
            .filter(|(_, m)| m.nrows() >= rows && m.ncols() >= cols)
            .min_by_key(|(_, m)| m.nrows() * m.ncols())
            .map(|(index, _)| index)?;
        Some(self.kept.swap_remove(fitting))
    }

    /// Keeps `matrix` when it is large enough, dropping the smallest one beyond
    /// [`crate::Tuning::kept_matrices`].
    fn give_back(&mut self, matrix: Mat<f64>) {
        if matrix.nrows() * matrix.ncols() * size_of::<f64>() < Tuning::DEFAULT.kept_from_bytes {
            return;
        }
        self.kept.push(matrix);
        if self.kept.len() > Tuning::DEFAULT.kept_matrices
            && let Some((smallest, _)) = self.kept.iter().enumerate().min_by_key(|(_, m)| m.nrows() * m.ncols())
        {
            self.kept.swap_remove(smallest);
        }
    }
}

static POOL: Mutex<Pool> = Mutex::new(Pool { kept: Vec::new() });

/// An empty matrix (0×0) whose storage holds rows × cols without reallocating: kept storage
/// when some fits, else new storage, allocated on the calling thread (whose heap is the
/// process's main one when called from the solve; memory of a pool thread's heap is returned to
/// the system when freed). Fill it with `resize_with`.
pub(crate) fn empty(rows: usize, cols: usize) -> Mat<f64> {
    let mut matrix = stale(rows, cols);
    matrix.truncate(0, 0);
    matrix
}

/// A rows × cols matrix of unspecified entries without a pass over its memory: kept storage
/// truncated to that shape (the values a previous solve left), else new storage as an empty
/// 0×0 matrix that the caller fills with `resize_with` (its first write faults the pages in).
pub(crate) fn stale(rows: usize, cols: usize) -> Mat<f64> {
    let kept = POOL.lock().ok().and_then(|mut pool| pool.take(rows, cols));
    match kept {
        Some(mut matrix) => {
            matrix.truncate(rows, cols);
            matrix
        }
        None => Mat::with_capacity(rows, cols),
    }
}

/// Keeps a working matrix the solve no longer needs, for the next solve.
pub(crate) fn give_back(matrix: Mat<f64>) {
    if let Ok(mut pool) = POOL.lock() {
        pool.give_back(matrix);
    }
}

/// Returns the kept working matrices to the system; the next dense solve allocates afresh.
pub fn release() {
    let kept = POOL.lock().map(|mut pool| std::mem::take(&mut pool.kept));
    drop(kept);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn large(n: usize, value: f64) -> Mat<f64> {
        Mat::from_fn(n, n, |_, _| value)
    }

    /// A kept matrix's storage serves the next request of its shape, and every entry of the
    /// matrix handed out is the new one.
    #[test]
    fn kept_storage_is_reused_and_refilled() {
        let mut pool = Pool::default();
        let old = large(400, 7.0);
        let storage = old.as_ptr();
        pool.give_back(old);
        let mut reused = pool.take(400, 400).expect("kept");
        assert_eq!((reused.nrows(), reused.ncols()), (400, 400));
        reused.truncate(300, 200);
        assert_eq!(reused[(299, 199)], 7.0, "truncated, the stale values stay");
        reused.truncate(0, 0);
        reused.resize_with(400, 400, |i, j| (i + 400 * j) as f64);
        assert_eq!(reused.as_ptr(), storage);
        for j in 0..400 {
            for i in 0..400 {
                assert_eq!(reused[(i, j)], (i + 400 * j) as f64);
            }
        }
        assert!(pool.take(400, 400).is_none());
    }

    /// The smallest kept matrix that covers the request is taken; none that is too small.
    #[test]
    fn the_smallest_fitting_matrix_is_taken() {
        let mut pool = Pool::default();
        pool.give_back(large(600, 1.0));
        pool.give_back(large(400, 2.0));
        assert!(pool.take(700, 700).is_none());
        let taken = pool.take(380, 380).expect("fits");
        let taken_storage = taken.as_ptr();
        let rest = pool.take(380, 380).expect("the larger one");
        assert_ne!(taken_storage, rest.as_ptr());
        assert_eq!(pool.kept.len(), 0);
        let mut small_first = Pool::default();
        small_first.give_back(large(400, 2.0));
        let small_storage = small_first.kept[0].as_ptr();
        small_first.give_back(large(600, 1.0));
        assert_eq!(small_first.take(380, 380).map(|m| m.as_ptr()), Some(small_storage));
    }

    /// Small matrices are not kept, and at most `Tuning::kept_matrices` large ones (the smallest
    /// goes).
    #[test]
    fn the_pool_is_bounded() {
        let mut pool = Pool::default();
        pool.give_back(large(100, 0.0));
        assert!(pool.kept.is_empty());
        for k in 0..Tuning::DEFAULT.kept_matrices + 2 {
            pool.give_back(large(400 + k, 0.0));
        }
        assert_eq!(pool.kept.len(), Tuning::DEFAULT.kept_matrices);
        let smallest = pool.kept.iter().map(|m| m.nrows()).min();
        assert_eq!(smallest, Some(402));
    }
}
