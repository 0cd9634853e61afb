//! The sparse solver's second thread (the inertia count beside Lanczos, half of the residual
//! bounds) changes no result: with faer's global parallelism sequential the same modes come back,
//! bit for bit. Alone in its test binary, because that setting is process-wide.

use mechanica_modal::faer::{self, Par};
use mechanica_modal::{SparsePencil, SparseSolveOptions, solve_sparse, testing};

#[test]
fn two_threads_and_one_give_the_same_modes() {
    let side = 45; // n = 2025: above the dense fallback
    let k = 12;
    let (a, b) = testing::grid_laplacian(side, side);
    let pencil = SparsePencil::from_triplets(side * side, &a, &b).expect("a valid pencil");
    let options = SparseSolveOptions {
        count: k,
        ..SparseSolveOptions::default()
    };
    faer::set_global_parallelism(Par::rayon(2));
    let parallel = solve_sparse(&pencil, &options).expect("solves on two threads");
    faer::set_global_parallelism(Par::Seq);
    let sequential = solve_sparse(&pencil, &options).expect("solves on one thread");
    assert!(parallel.report.consistent && sequential.report.consistent);
    assert_eq!(parallel.modes.len(), k);
    let exact = testing::grid_omega_sq(side, side, k);
    for ((p, s), w) in parallel.modes.iter().zip(&sequential.modes).zip(&exact) {
        // Same Lanczos run, same Rayleigh–Ritz, same per-pair residual arithmetic.
        assert_eq!(p.omega_sq.to_bits(), s.omega_sq.to_bits());
        assert_eq!(p.backward_error, s.backward_error);
        // Both within their bounds of the closed form (itself rounded to a few ulps).
        for mode in [p, s] {
            let error = (mode.omega_sq - w).abs();
            assert!(
                error <= mode.error_bound + 8.0 * f64::EPSILON * w,
                "{error:e} > {:e}",
                mode.error_bound
            );
        }
    }
}
