//! The sparse shift-invert Lanczos solver against closed-form grid spectra (with repeated
//! eigenvalues), the dense solver, and bad input.

use mechanica_modal::faer::sparse::Triplet;
use mechanica_modal::{ModalError, SparseOptions, SparsePencil, count_below_sparse, families, solve_sparse};

const U: f64 = f64::EPSILON;

fn lowest(k: usize) -> SparseOptions {
    SparseOptions {
        count: k,
        ..SparseOptions::default()
    }
}

/// Every ω² within its bound of the closed form and within 1e-12 relative; groups match the
/// closed form's multiplicities; XᵀAX = I; the inertia check passed.
fn check_grid(nx: usize, ny: usize, k: usize, mass: f64) {
    let (a, b) = families::grid_laplacian(nx, ny);
    let a: Vec<_> = a.iter().map(|t| Triplet::new(t.row, t.col, mass * t.val)).collect();
    let p = SparsePencil::from_triplets(nx * ny, &a, &b).expect("valid");
    let sol = solve_sparse(&p, &lowest(k)).expect("solve");
    let exact: Vec<f64> = families::grid_omega_sq(nx, ny, k).iter().map(|w| w / mass).collect();
    assert_eq!(sol.modes.len(), k);
    for (m, w) in sol.modes.iter().zip(&exact) {
        let err = (m.omega_sq - w).abs();
        assert!(err <= m.error_bound, "ω² {} vs {w}: error {err:e} > bound {:e}", m.omega_sq, m.error_bound);
        assert!(err <= 1e-12 * w, "relative error {:e}", err / w);
        assert!(m.error_bound <= 1e-12 * w, "bound {:e} not tight", m.error_bound);
        assert!(m.backward_error.expect("vectors") <= 10.0 * U * (nx * ny) as f64);
    }
    let r = &sol.report;
    assert!(r.consistent, "{r:?}");
    assert!(r.orthogonality_error <= 1e3 * U, "{r:?}");
    eprintln!("{nx}x{ny} k={k}: {r:?}");
}

#[test]
fn square_grid_with_double_eigenvalues() {
    check_grid(100, 100, 10, 1.0);
}

#[test]
fn rectangular_grid_with_mass() {
    check_grid(120, 90, 8, 2.5);
}
