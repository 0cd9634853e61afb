//! Data-parallel helpers on scoped standard threads, for the mesh passes.

/// Meshes with fewer triangles than this are handled on the calling thread only (starting
/// threads costs tens of microseconds).
pub const PARALLEL_MIN_TRIANGLES: usize = 1 << 16;

/// The number of threads for a mesh of `triangles` triangles: 1 below
/// [`PARALLEL_MIN_TRIANGLES`], else the available parallelism, with at least half of
/// [`PARALLEL_MIN_TRIANGLES`] triangles per thread.
pub(crate) fn worker_count(triangles: usize) -> usize {
    static AVAILABLE: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    if triangles < PARALLEL_MIN_TRIANGLES {
        return 1;
    }
    let available = *AVAILABLE.get_or_init(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    available.min(triangles / (PARALLEL_MIN_TRIANGLES / 2)).max(1)
}

/// `work` applied to every item, the first on the calling thread and the others on scoped
/// threads; results in item order.
pub(crate) fn map_in_parallel<T: Send, R: Send>(items: Vec<T>, work: impl Fn(T) -> R + Sync) -> Vec<R> {
    let mut items = items.into_iter();
    let Some(first) = items.next() else {
        return Vec::new();
    };
    let work = &work;
    std::thread::scope(|scope| {
        let handles: Vec<_> = items.map(|item| scope.spawn(move || work(item))).collect();
        let mut results = Vec::with_capacity(handles.len() + 1);
        results.push(work(first));
        // The workers run library code on checked inputs; if one panicked anyway, that bug is
        // re-raised here rather than hidden.
        results.extend(
            handles
                .into_iter()
                .map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e))),
        );
        results
    })
}
