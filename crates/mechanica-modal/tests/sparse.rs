//! The sparse shift-invert Lanczos solver against closed-form grid spectra (with repeated
//! eigenvalues), the dense solver, and bad input.

use mechanica_modal::faer::sparse::Triplet;
use mechanica_modal::{ModalError, SparsePencil, SparseSolveOptions, count_below_sparse, solve_sparse, testing};

const U: f64 = f64::EPSILON;

fn lowest(k: usize) -> SparseSolveOptions {
    SparseSolveOptions {
        count: k,
        ..SparseSolveOptions::default()
    }
}

/// Every ω² within its bound of the closed form and within 1e-12 relative; groups match the
/// closed form's multiplicities; XᵀAX = I; the inertia check passed.
fn check_grid(nx: usize, ny: usize, k: usize, mass: f64) {
    let (a, b) = testing::grid_laplacian(nx, ny);
    let a: Vec<_> = a.iter().map(|t| Triplet::new(t.row, t.col, mass * t.val)).collect();
    let p = SparsePencil::from_triplets(nx * ny, &a, &b).expect("valid");
    let sol = solve_sparse(&p, &lowest(k)).expect("solve");
    let exact: Vec<f64> = testing::grid_omega_sq(nx, ny, k).iter().map(|w| w / mass).collect();
    assert_eq!(sol.modes.len(), k);
    for (m, w) in sol.modes.iter().zip(&exact) {
        let err = (m.omega_sq - w).abs();
        assert!(
            err <= m.error_bound,
            "ω² {} vs {w}: error {err:e} > bound {:e}",
            m.omega_sq,
            m.error_bound
        );
        assert!(err <= 1e-12 * w, "relative error {:e}", err / w);
        assert!(m.error_bound <= 1e-12 * w, "bound {:e} not tight", m.error_bound);
        assert!(m.backward_error.expect("vectors") <= 10.0 * U * (nx * ny) as f64);
    }
    let r = &sol.report;
    assert!(r.consistent, "{r:?}");
    assert!(r.orthogonality_error <= 1e3 * U, "{r:?}");
}

#[test]
fn square_grid_with_double_eigenvalues() {
    check_grid(100, 100, 10, 1.0);
}

#[test]
fn rectangular_grid_with_mass() {
    check_grid(120, 90, 8, 2.5);
}

/// A diagonal pencil with an exactly triple eigenvalue and a single-vector Krylov space (block
/// size 1): all three copies come back as an A-orthonormal group, and the inertia count agrees.
#[test]
fn inertia_guard_recovers_a_triple_eigenvalue() {
    let n = 600;
    let diag = |i: usize| if i < 3 { 1.0 } else { 1.5 + i as f64 };
    let a: Vec<_> = (0..n).map(|i| Triplet::new(i, i, 1.0)).collect();
    let b: Vec<_> = (0..n).map(|i| Triplet::new(i, i, diag(i))).collect();
    let p = SparsePencil::from_triplets(n, &a, &b).expect("valid");
    let sol = solve_sparse(
        &p,
        &SparseSolveOptions {
            count: 5,
            block_size: 1,
            ..SparseSolveOptions::default()
        },
    )
    .expect("solve");
    let got: Vec<f64> = sol.modes.iter().map(|m| m.omega_sq).collect();
    let exact = [1.0, 1.0, 1.0, 4.5, 5.5];
    for (g, e) in got.iter().zip(&exact) {
        assert!((g - e).abs() <= 1e-13 * e, "{got:?}");
    }
    assert!(sol.report.consistent);
    assert_eq!(sol.groups[0].multiplicity, 3);
    assert!(sol.report.orthogonality_error <= 1e3 * U);
}

/// The count of the sparse LBLᵀ inertia equals the closed-form count on a grid, at shifts
/// between eigenvalues.
#[test]
fn sparse_inertia_counts_grid_modes() {
    let (nx, ny) = (60, 50);
    let (a, b) = testing::grid_laplacian(nx, ny);
    let p = SparsePencil::from_triplets(nx * ny, &a, &b).expect("valid");
    let exact = testing::grid_omega_sq(nx, ny, 40);
    for j in [0usize, 5, 17, 38] {
        let shift = 0.5 * (exact[j] + exact[j + 1]);
        if exact[j + 1] - exact[j] < 1e-9 {
            continue;
        }
        let c = count_below_sparse(&p, shift).expect("count");
        assert_eq!(c.count.below, j + 1, "shift {shift}");
    }
}

#[test]
fn unstable_modes_lower_the_shift() {
    // B = Laplacian − I/16 on a 30×30 grid (exact in binary): the lowest modes have ω² < 0.
    let (nx, ny) = (30, 30);
    let (a, b) = testing::grid_laplacian(nx, ny);
    let b: Vec<_> = b
        .iter()
        .map(|t| Triplet::new(t.row, t.col, if t.row == t.col { t.val - 0.0625 } else { t.val }))
        .collect();
    let p = SparsePencil::from_triplets(nx * ny, &a, &b).expect("valid");
    let sol = solve_sparse(&p, &lowest(4)).expect("solve");
    let exact: Vec<f64> = testing::grid_omega_sq(nx, ny, 4).iter().map(|w| w - 0.0625).collect();
    assert!(exact[0] < 0.0);
    for (m, w) in sol.modes.iter().zip(&exact) {
        // The closed form itself is rounded: a few u of the unshifted ω².
        let reference_rounding = 4.0 * U * (w + 0.0625);
        assert!(
            (m.omega_sq - w).abs() <= m.error_bound + reference_rounding,
            "{} vs {w}",
            m.omega_sq
        );
    }
    assert!(sol.report.shift_attempts > 1);
    assert!(sol.report.consistent);
}

#[test]
fn bad_sparse_input_is_located() {
    let t = |r, c, v| Triplet::new(r, c, v);
    let a = [t(0, 0, 1.0), t(1, 1, 1.0)];
    assert!(matches!(
        SparsePencil::from_triplets(2, &a, &[t(0, 5, 1.0)]),
        Err(ModalError::IndexOutOfRange { what: "B", col: 5, .. })
    ));
    assert!(matches!(
        SparsePencil::from_triplets(2, &a, &[t(1, 0, 1.0)]),
        Err(ModalError::NotSymmetric { what: "B", .. })
    ));
    let p = SparsePencil::from_triplets(2, &a, &a).expect("valid");
    assert!(matches!(
        solve_sparse(&p, &lowest(3)),
        Err(ModalError::TooManyModes {
            requested: 3,
            available: 2
        })
    ));
    assert!(matches!(
        solve_sparse(&p, &lowest(0)),
        Err(ModalError::TooManyModes { .. })
    ));
    assert!(matches!(
        solve_sparse(
            &p,
            &SparseSolveOptions {
                shift: Some(f64::NAN),
                ..lowest(1)
            }
        ),
        Err(ModalError::BadShift(_))
    ));
    assert!(count_below_sparse(&p, f64::INFINITY).is_err());
    // A shift above a mode cannot be factored: a typed error naming the pivot.
    let (ga, gb) = testing::grid_laplacian(25, 25);
    let g = SparsePencil::from_triplets(625, &ga, &gb).expect("valid");
    assert!(matches!(
        solve_sparse(
            &g,
            &SparseSolveOptions {
                shift: Some(0.5),
                ..lowest(2)
            }
        ),
        Err(ModalError::NoDefiniteShift { .. })
    ));
    // An indefinite mass matrix is refused.
    let neg: Vec<_> = (0..625).map(|i| t(i, i, if i == 7 { -1.0 } else { 1.0 })).collect();
    let bad = SparsePencil::from_triplets(625, &neg, &gb).expect("valid shapes");
    assert!(solve_sparse(&bad, &lowest(2)).is_err());
}

#[test]
fn matrix_market_files_feed_the_solver() {
    let (nx, ny) = (22, 21);
    let (a, b) = testing::grid_laplacian(nx, ny);
    let n = nx * ny;
    let ma = mechanica_modal::parse_matrix_market(&mechanica_modal::sparse::matrix_market::symmetric_to_string(n, &a))
        .expect("A parses");
    let mb = mechanica_modal::parse_matrix_market(&mechanica_modal::sparse::matrix_market::symmetric_to_string(n, &b))
        .expect("B parses");
    let p = SparsePencil::from_triplets(n, &ma.entries, &mb.entries).expect("valid");
    let sol = solve_sparse(&p, &lowest(3)).expect("solve");
    for (m, w) in sol.modes.iter().zip(testing::grid_omega_sq(nx, ny, 3)) {
        assert!((m.omega_sq - w).abs() <= m.error_bound);
    }
}

#[test]
fn faer_sparse_matrices_are_accepted() {
    use mechanica_modal::faer::sparse::SparseColMat;
    let (nx, ny) = (21, 20);
    let (a, b) = testing::grid_laplacian(nx, ny);
    let n = nx * ny;
    let to_faer = |t: &[Triplet<usize, usize, f64>]| {
        SparseColMat::<usize, f64>::try_new_from_triplets(n, n, t).expect("valid triplets")
    };
    let (fa, fb) = (to_faer(&a), to_faer(&b));
    let p = SparsePencil::new(fa.as_ref(), fb.as_ref()).expect("valid");
    assert_eq!(p.nnz(), (n, b.len()));
    let sol = solve_sparse(&p, &lowest(2)).expect("solve");
    for (m, w) in sol.modes.iter().zip(testing::grid_omega_sq(nx, ny, 2)) {
        assert!((m.omega_sq - w).abs() <= m.error_bound);
    }
}

/// A tolerance that is not a finite number in (0, 1) is refused before any work.
#[test]
fn bad_tolerances_are_refused() {
    let (a, b) = testing::grid_laplacian(25, 25);
    let p = SparsePencil::from_triplets(625, &a, &b).expect("valid pencil");
    for tolerance in [f64::NAN, f64::INFINITY, 0.0, -1e-12, 1.0, 2.0] {
        let options = SparseSolveOptions { tolerance, ..lowest(3) };
        assert!(
            matches!(solve_sparse(&p, &options), Err(ModalError::BadTolerance(t)) if t.to_bits() == tolerance.to_bits()),
            "{tolerance}"
        );
    }
    assert!(
        solve_sparse(
            &p,
            &SparseSolveOptions {
                tolerance: 1e-8,
                ..lowest(3)
            }
        )
        .is_ok()
    );
}

/// A unit mass on a soft spring (1e-3) beside a stiff chain (springs of 1e11): its mode,
/// ω² = 1e-3, is oscillatory, although a normwise estimate of what rounding the data could
/// change (u·‖B‖_F·‖x‖² ≈ 3e-3 here) would call it zero.
#[test]
fn a_soft_mode_beside_stiff_springs_is_oscillatory() {
    let n = 2000;
    let a: Vec<Triplet<usize, usize, f64>> = (0..n).map(|i| Triplet::new(i, i, 1.0)).collect();
    let mut b = Vec::new();
    for i in 0..n - 1 {
        // Stiff chain on 0..n−1, grounded at 0 and free at n − 2.
        b.push(Triplet::new(i, i, if i + 2 < n { 2e11 } else { 1e11 }));
        if i + 2 < n {
            b.push(Triplet::new(i, i + 1, -1e11));
            b.push(Triplet::new(i + 1, i, -1e11));
        }
    }
    b.push(Triplet::new(n - 1, n - 1, 1e-3));
    let p = SparsePencil::from_triplets(n, &a, &b).expect("valid pencil");
    let sol = solve_sparse(&p, &lowest(3)).expect("solve");
    let low = &sol.modes[0];
    assert!(
        (low.omega_sq - 1e-3).abs() <= low.error_bound + 1e-18,
        "{:e}",
        low.omega_sq
    );
    assert!(
        matches!(low.kind, mechanica_modal::ModeKind::Oscillatory { .. }),
        "{:?}",
        low.kind
    );
}
