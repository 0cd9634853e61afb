//! Fork–join helpers that respect a [`Par`]: two closures, or column chunks of a matrix, on the
//! threads of Rayon's global pool when `par` allows more than one, else in turn.

use crate::tuning::Tuning;
use faer::{MatMut, Par};

/// Runs two closures, on two threads of Rayon's global pool when `par` allows more than one
/// (the pool, not `par`'s count, decides how many run at once).
pub(crate) fn join<A: Send, B: Send>(a: impl FnOnce() -> A + Send, b: impl FnOnce() -> B + Send, par: Par) -> (A, B) {
    match par {
        Par::Rayon(threads) if threads.get() > 1 => rayon::join(a, b),
        _ => (a(), b()),
    }
}

/// `f` of every item, on the threads of Rayon's global pool when `par` allows more than one and
/// there are at least two items; a single item runs on the calling thread, so that its own
/// products can still use the pool (inside a pool thread, `dd::mat_vec` runs on one thread).
pub(crate) fn map_items<T: Sync, R: Send>(items: &[T], par: Par, f: impl Fn(&T) -> R + Sync + Send) -> Vec<R> {
    match par {
        Par::Rayon(threads) if threads.get() > 1 && items.len() > 1 => {
            use rayon::prelude::*;
            items.par_iter().map(f).collect()
        }
        _ => items.iter().map(f).collect(),
    }
}

/// Runs `solve` on column chunks of `rhs`, one chunk per thread of `par` (each chunk solved
/// sequentially). For triangular solves with many right-hand sides this keeps every thread on
/// whole columns, which is faster than faer's parallel triangular solve (measured in
/// docs/benchmarks.md).
pub(crate) fn by_column_chunks(rhs: MatMut<'_, f64>, par: Par, solve: &(dyn Fn(MatMut<'_, f64>) + Sync)) {
    by_column_chunks_at(rhs, par, &|_, chunk| solve(chunk));
}

/// [`by_column_chunks`], telling `solve` the index in `rhs` of its chunk's first column.
pub(crate) fn by_column_chunks_at(rhs: MatMut<'_, f64>, par: Par, solve: &(dyn Fn(usize, MatMut<'_, f64>) + Sync)) {
    let threads = match par {
        Par::Rayon(threads) => threads
            .get()
            .min(rhs.ncols() / Tuning::DEFAULT.columns_per_chunk)
            .max(1),
        Par::Seq => 1,
    };
    split_columns(rhs, 0, threads, solve);
}

fn split_columns(rhs: MatMut<'_, f64>, first: usize, threads: usize, solve: &(dyn Fn(usize, MatMut<'_, f64>) + Sync)) {
    if threads <= 1 {
        return solve(first, rhs);
    }
    let left_threads = threads / 2;
    let split = rhs.ncols() * left_threads / threads;
    let (left, right) = rhs.split_at_col_mut(split);
    rayon::join(
        || split_columns(left, first, left_threads, solve),
        || split_columns(right, first + split, threads - left_threads, solve),
    );
}
