//! The tuning choices of the modal solvers in one place: thread thresholds, block and panel
//! sizes, iteration limits and the tolerances that only decide how much work is done. None of
//! them changes what a result certifies: every reported bound holds whatever their values.
//!
//! The solvers read [`Tuning::DEFAULT`]. Constants that define an algorithm as published
//! (LAPACK's iteration limits and cluster gap of inverse iteration, the safe-range constants of
//! the QL iteration) stay with their algorithm; constants that are part of the accuracy
//! contract stay public where they belong ([`crate::dense::AUTO_REFINE_RELATIVE_BOUND`],
//! [`crate::certify::SKETCH_SIZE`], [`crate::certify::FAILURE_PROBABILITY`],
//! [`crate::problem::SYMMETRY_ULPS`]).

use std::time::Duration;

/// Thresholds, sizes and limits of the modal solvers (see the module documentation). Orders are
/// matrix orders n; the thread thresholds suit a two-core machine (measured in
/// docs/benchmarks.md).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tuning {
    // Dense solve.
    /// Dense problems below this order are solved on one thread (default 192): below a few
    /// hundred unknowns starting threads costs more than it saves.
    pub sequential_below: usize,
    /// From this order an all-modes solve puts work off its critical path (the norms, the
    /// sketch's rows, the bottom certificate) on idle core time (default 192, the first order
    /// solved on two threads): below the factorization's own thread threshold one core is idle
    /// while the other factors A.
    pub idle_time_from: usize,
    /// A values-only solve with [`crate::Refinement::Auto`] forms the vectors of its weakly
    /// bounded modes one by one when there are at most this many or n/4 of them, and all
    /// vectors beyond that (default 32): inverse iteration on a cluster orthogonalises in
    /// O(k²n), and all vectors cost about n³ more than values.
    pub flagged_vectors_up_to: usize,
    /// The largest cluster of nearly equal ω² that refinement treats as one block; larger ones
    /// keep the bounds of the reduction (default 64): a block step costs 4p double-double
    /// matrix-vector products, as many as p simple modes, and the Auto budget counts every
    /// member. A graded pencil's repeated eigenvalue (a complete graph of 50 masses over 12
    /// decades: ω² = 100 forty-nine times) can otherwise not be told from its zero mode.
    pub max_refined_cluster: usize,
    /// `Refinement::Auto` refines the weakly bounded modes of a selection from the lowest up, at
    /// most max(`auto_refined_at_least`, n / `auto_refined_fraction`) of them (default 64 and
    /// 16): each costs O(n²) double-double work, so refining all n of a graded pencil would cost
    /// many dense solves; with these defaults the certified solve of a randomly graded pencil
    /// costs at most about twice the plain one from n = 250 up, and up to about four times
    /// below (docs/benchmarks.md). At least
    /// [`Tuning::max_refined_cluster`], so that the largest cluster refined as one block fits.
    /// The others keep their (true, weaker) bounds.
    pub auto_refined_at_least: usize,
    /// See [`Tuning::auto_refined_at_least`].
    pub auto_refined_fraction: usize,

    // Cholesky factorization and reduction (module `linalg::reduce`).
    /// Orders at or below which the recursive Cholesky factorization calls faer's blocked
    /// kernel (default 128): orders 128–256 are equally fast (measured in docs/benchmarks.md).
    pub cholesky_base_case: usize,
    /// Orders at or below which the reduction C = L⁻¹BL⁻ᵀ uses two plain triangular solves
    /// (default 48): cheap at that size.
    pub reduce_base_case: usize,
    /// Width of the leading block split off by each step of the reduction (default 256): a block
    /// of fixed width keeps the reduction at n³ flops, as in LAPACK `dsygst`, where halving
    /// costs 4n³/3.
    pub reduce_block: usize,
    /// Below this order the factorization and the reduction run on one thread (default 640):
    /// their blocks are too small for the pool's wake-ups to pay (measured in
    /// docs/benchmarks.md).
    pub parallel_factor_from: usize,
    /// Trailing orders up to which a step of the reduction on exactly two threads runs as three
    /// two-thread phases of sequential kernels instead of faer's parallel kernels (default
    /// 1024): each faer call synchronizes the threads, while large products gain from faer's
    /// shared packing (measured in docs/benchmarks.md).
    pub split_step_up_to: usize,

    // Symmetric eigensolver (module `linalg::eigen`).
    /// Columns reduced per panel of the tridiagonalization before the trailing matrix is updated
    /// (default 32, LAPACK `dsytrd`'s default): wider panels are slower (measured in
    /// docs/benchmarks.md).
    pub panel: usize,
    /// Trailing orders from which half of each symmetric matrix-vector product of the
    /// tridiagonalization runs on a helper thread; smaller matrices use no helper at all
    /// (default 640): below it one thread is faster (measured in docs/benchmarks.md).
    pub parallel_symv_from: usize,
    /// Trailing orders from which the helper thread takes half of each panel's trailing update
    /// (default 128): faer's pool threads have gone to sleep during the panel and would contend
    /// with the spinning helper.
    pub split_update_from: usize,
    /// How long the tridiagonalization's helper spins for its next job before it parks (default
    /// 200 µs): long enough to catch the next column's product, short enough not to hold a core
    /// (measured in docs/benchmarks.md).
    pub symv_spin: Duration,
    /// Leaves of the tridiagonal divide and conquer of at most this many rows are solved by the
    /// implicit QL iteration (default 32, LAPACK's SMLSIZ is 25): a power of two, so that the
    /// halves of a power-of-two order are equal.
    pub leaf: usize,
    /// Secular-equation roots per merge from which the roots are shared between two threads
    /// (default 128): fewer cost less than a fork.
    pub parallel_roots_from: usize,

    // Machine use (module `runtime`) and double-double products (module `dd`).
    /// The fewest columns a thread's chunk of a column-chunked triangular solve or reflector
    /// application gets (default 64): fewer columns run as one chunk, which keeps the kernels'
    /// blocks full.
    pub columns_per_chunk: usize,
    /// Working matrices kept between dense solves at most (default 5): an all-pairs solve works
    /// in six n×n matrices, of which the caller keeps one.
    pub kept_matrices: usize,
    /// Working matrices smaller than this many bytes are not kept (default 1 MiB): the allocator
    /// reuses small blocks itself.
    pub kept_from_bytes: usize,
    /// A matrix with at most n²/this many nonzeros is multiplied by its nonzeros in
    /// double-double products and exact residual products (default 16): the sparse product
    /// touches scattered accumulators one term at a time, where the dense kernel runs four rows
    /// per instruction, so it wins only well below full density.
    pub sparse_fraction: usize,
    /// Orders from which a double-double matrix-vector product splits its rows between two
    /// threads (default 1000): a thread costs tens of microseconds, the product of an
    /// order-1000 matrix milliseconds.
    pub parallel_rows_from: usize,

    // Bottom-of-spectrum certificate on idle time (module `certify::idle_certificate`).
    /// Columns per sequential block of the idle thread's Cholesky factorization, between two
    /// looks at its stop flag (default 64): the hand-over waits at most one block.
    pub certificate_block: usize,
    /// The slowest rate (flops per second) at which the report expects the idle thread to
    /// finish its current block once asked (default 2e9): the wait for the hand-over is one
    /// block step at this rate.
    pub slowest_block_rate: f64,
    /// The fraction of the columns the idle thread must have factored for the report to wait
    /// for its hand-over (default 0.125, a third of the flops); before that the report factors
    /// alone.
    pub handover_from: f64,

    // Refinement (module `refine`).
    /// Newton steps per pair on the bordered system (default 12): the steps converge
    /// quadratically from a first-order accurate pair.
    pub max_newton_steps: usize,
    /// Projected Newton steps (through the reduced spectrum) before refinement gives up and
    /// falls back to a factorization (default 8): the projected step converges linearly, each
    /// step at least halving the correction.
    pub max_projected_steps: usize,
    /// A projected correction below this many ulps of x that no longer halves has reached
    /// rounding level, and the iteration stops (default 16): the bound comes from the final
    /// residual either way.
    pub stagnation_ulps: f64,

    // Sparse solve (module `sparse`).
    /// At or below this order the sparse solver converts to dense and calls [`crate::solve()`]
    /// (default 400): the dense solve is faster there.
    pub dense_limit: usize,
    /// Up to this order a sparse solve whose Lanczos iteration does not converge (a graded pencil
    /// whose shifted factor cannot be applied to the accuracy asked) is finished by the dense
    /// solver instead of returning [`crate::ModalError::LanczosNoConvergence`] (default 4000:
    /// n² doubles, about 128 MB per working matrix).
    pub dense_rescue_limit: usize,
    /// Relative Ritz residual to which the buffer modes above the k-th converge (default 1e-8):
    /// they only place the inertia shift τ in a real gap of relative width ≥ √u, and after
    /// Rayleigh–Ritz their ω² err by about its square.
    pub buffer_tolerance: f64,
    /// Relative Ritz residual at which the first Lanczos run's θ are good enough to place τ, so
    /// that the inertia count starts on a second thread (default 1e-6): their ω² then err by
    /// about 1e-12 relative.
    pub rough_tolerance: f64,
    /// Largest block size of a deflated Lanczos rerun (default 32): a rerun's block holds one
    /// vector per missing copy of an eigenvalue.
    pub max_rerun_block: usize,
    /// Fewest basis vectors of a Lanczos run (default 24); it holds max(2·nev + 4b, this):
    /// a larger basis saves no operator application, only orthogonalisation work (measured in
    /// docs/benchmarks.md).
    pub lanczos_min_basis: usize,
    /// Cholesky factorizations of B − σA tried with the automatic shift σ, each 1000 times lower
    /// than the last, before the solve reports [`crate::ModalError::NoDefiniteShift`]
    /// (default 6): from −√u·‖B‖/‖A‖ down to −1e15·√u·‖B‖/‖A‖.
    pub shift_attempts: usize,
}

impl Tuning {
    /// The values the solvers use.
    pub const DEFAULT: Tuning = Tuning {
        sequential_below: 192,
        idle_time_from: 192,
        flagged_vectors_up_to: 32,
        max_refined_cluster: 64,
        auto_refined_at_least: 64,
        auto_refined_fraction: 16,
        cholesky_base_case: 128,
        reduce_base_case: 48,
        reduce_block: 256,
        parallel_factor_from: 640,
        split_step_up_to: 1024,
        panel: 32,
        parallel_symv_from: 640,
        split_update_from: 128,
        symv_spin: Duration::from_micros(200),
        leaf: 32,
        parallel_roots_from: 128,
        columns_per_chunk: 64,
        kept_matrices: 5,
        kept_from_bytes: 1 << 20,
        sparse_fraction: 16,
        parallel_rows_from: 1000,
        certificate_block: 64,
        slowest_block_rate: 2e9,
        handover_from: 0.125,
        max_newton_steps: 12,
        max_projected_steps: 8,
        stagnation_ulps: 16.0,
        dense_limit: 400,
        dense_rescue_limit: 4000,
        buffer_tolerance: 1e-8,
        rough_tolerance: 1e-6,
        max_rerun_block: 32,
        lanczos_min_basis: 24,
        shift_attempts: 6,
    };
}

impl Default for Tuning {
    fn default() -> Self {
        Self::DEFAULT
    }
}
