//! Criterion benchmarks: the dense symmetric-definite solver of det(λA + B) = 0.
//!
//! Problem: [`rotated_fixed_chain`]: a fixed–fixed spring chain with masses 1..2, rotated by a
//! random orthogonal Q (dense A and B with the closed-form spectrum of the unit chain), at
//! n = 200 and 1000. Larger n (2000, 4000) are timed by the report generator
//! `benches/modal_report.rs` (median of 3 runs; criterion's minimum of 10 samples would take
//! minutes per series there), which also measures the errors of every method.
//!
//! Series, all in the same run:
//! - `mechanica_all_pairs`: `solve` with all pairs, the full accuracy report and Sturm check;
//! - `mechanica_values_only`: `solve` without vectors (a-priori bounds and Sturm check);
//! - `faer_reduction_sygst` vs `faer_reduction_two_solves`: the symmetric (sygst-like)
//!   reduction C = L⁻¹BL⁻ᵀ against two full triangular solves, both after the same Cholesky;
//! - `faer_evd_of_c`: faer's self-adjoint eigensolver on the reduced C alone;
//! - `nalgebra_all_pairs`: the peer pipeline in nalgebra (Cholesky, L⁻¹BL⁻ᵀ by two triangular
//!   solves, SymmetricEigen, back-transform).
//! - `lapack_dsygvd_all_pairs`, `lapack_dsygvd_values_only`: LAPACK `dsygvd` (divide and
//!   conquer, the driver of SciPy `eigh`) from the system OpenBLAS with its default threads,
//!   linked by `benches/build.rs` when found (skipped with a note otherwise). Run with
//!   `OPENBLAS_CORETYPE=Haswell` where OpenBLAS falls back to its slow `Prescott` kernels (see
//!   `modal_report.rs`). The input copies LAPACK needs (it overwrites A and B) are inside the
//!   timed region, as mechanica copies too.
//!
//! tools/modal_scipy_bench.py times SciPy's `eigh` on the same family from Python
//! (tools/modal_scipy_bench.out).
//!
//! Group `modal_sparse`: the 10 lowest modes of the 300×300 grid Laplacian (n = 90 000) by
//! `solve_sparse` (shift-invert block Lanczos, inertia-certified). Peer: SciPy `eigsh`
//! (ARPACK + SuperLU shift-invert), timed by tools/modal_sparse_scipy.py on the same matrix,
//! numbers in tools/modal_sparse_scipy.out.
//!
//! Group `modal_stiff`: all pairs of the graded stiff chain (unit masses, stiffnesses over 12
//! decades, n = 500), where `Refinement::Auto` certifies the weakly bounded low half of the
//! spectrum (220 modes) with double-double residuals: `mechanica_all_pairs_auto` against
//! `mechanica_all_pairs_off` (the plain reduction) and LAPACK `dsygvd`, which gives the lowest
//! mode 2e-5 relative error and no bound: the ratios are the price of the certified digits.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use mechanica::modal::faer::Par;
use mechanica::modal::linalg::reduce::{cholesky_and_reduce, reduce_two_solves};
use mechanica::modal::{PencilProblem, SolveOptions, SparsePencil, SparseSolveOptions, solve, solve_sparse};
use mechanica_benches::lapack;
use mechanica_benches::modal::{nalgebra_all_pairs, rotated_fixed_chain, to_col_major, to_nalgebra};
use mechanica_modal::testing;
use std::hint::black_box;

const SIZES: [usize; 2] = [200, 1000];

fn dense(c: &mut Criterion) {
    let mut group = c.benchmark_group("modal_dense");
    group.sample_size(10);
    let par = mechanica::modal::faer::get_global_parallelism();
    for n in SIZES {
        let (a, b) = rotated_fixed_chain(n);
        let problem = match PencilProblem::new(a.as_ref(), b.as_ref()) {
            Ok(p) => p,
            Err(e) => panic!("benchmark pencil is valid: {e}"),
        };
        group.bench_with_input(BenchmarkId::new("mechanica_all_pairs", n), &problem, |bch, p| {
            bch.iter(|| solve(black_box(p), &SolveOptions::default()).map(|s| s.modes[0].omega_sq))
        });
        let values_only = SolveOptions {
            vectors: false,
            ..SolveOptions::default()
        };
        group.bench_with_input(BenchmarkId::new("mechanica_values_only", n), &problem, |bch, p| {
            bch.iter(|| solve(black_box(p), &values_only).map(|s| s.modes[0].omega_sq))
        });
        let Some((l, reduced)) = cholesky_and_reduce(a.as_ref(), b.as_ref(), par) else {
            panic!("benchmark mass matrix is positive definite")
        };
        group.bench_with_input(BenchmarkId::new("faer_reduction_sygst", n), &(), |bch, _| {
            bch.iter(|| cholesky_and_reduce(black_box(a.as_ref()), b.as_ref(), par).map(|(_, c)| c[(0, 0)]))
        });
        group.bench_with_input(BenchmarkId::new("faer_reduction_two_solves", n), &(), |bch, _| {
            bch.iter(|| {
                a.as_ref()
                    .llt(mechanica::modal::faer::Side::Lower)
                    .map(|llt| reduce_two_solves(llt.L(), black_box(b.as_ref()), par)[(0, 0)])
            })
        });
        group.bench_with_input(BenchmarkId::new("faer_evd_of_c", n), &reduced, |bch, cm| {
            bch.iter(|| {
                cm.self_adjoint_eigen(mechanica::modal::faer::Side::Lower)
                    .map(|e| e.S()[0])
            })
        });
        let (na, nb) = (to_nalgebra(a.as_ref()), to_nalgebra(b.as_ref()));
        group.bench_with_input(BenchmarkId::new("nalgebra_all_pairs", n), &(), |bch, _| {
            bch.iter(|| nalgebra_all_pairs(black_box(&na), &nb).map(|(w, _)| w[0]))
        });
        if lapack::available() {
            // LAPACK solves K z = ω² M z: stiffness first, then mass.
            let (k, m) = (to_col_major(b.as_ref()), to_col_major(a.as_ref()));
            group.bench_with_input(BenchmarkId::new("lapack_dsygvd_all_pairs", n), &(), |bch, _| {
                bch.iter(|| lapack::dsygvd(black_box(&k), &m, n, true).map(|e| e.values[0]))
            });
            group.bench_with_input(BenchmarkId::new("lapack_dsygvd_values_only", n), &(), |bch, _| {
                bch.iter(|| lapack::dsygvd(black_box(&k), &m, n, false).map(|e| e.values[0]))
            });
        } else {
            println!("note: built without OpenBLAS, the lapack_dsygvd series are skipped");
        }
        let _ = (&l, Par::Seq);
    }
    group.finish();
}

fn sparse(c: &mut Criterion) {
    let mut group = c.benchmark_group("modal_sparse");
    group.sample_size(10);
    let side = 300;
    let (a, b) = testing::grid_laplacian(side, side);
    let pencil = match SparsePencil::from_triplets(side * side, &a, &b) {
        Ok(p) => p,
        Err(e) => panic!("benchmark grid is valid: {e}"),
    };
    let options = SparseSolveOptions {
        count: 10,
        ..SparseSolveOptions::default()
    };
    group.bench_with_input(
        BenchmarkId::new("mechanica_lowest10_grid", side * side),
        &pencil,
        |bch, p| bch.iter(|| solve_sparse(black_box(p), &options).map(|s| s.modes[0].omega_sq)),
    );
    group.finish();
}

fn stiff(c: &mut Criterion) {
    let mut group = c.benchmark_group("modal_stiff");
    group.sample_size(10);
    let n = 500;
    let (a, b) = testing::spring_chain(&testing::graded_exponents(n, 12), &vec![0; n]);
    let problem = match PencilProblem::new(a.as_ref(), b.as_ref()) {
        Ok(p) => p,
        Err(e) => panic!("benchmark pencil is valid: {e}"),
    };
    for (name, refinement) in [
        ("mechanica_all_pairs_auto", mechanica::modal::Refinement::Auto),
        ("mechanica_all_pairs_off", mechanica::modal::Refinement::Off),
    ] {
        let options = SolveOptions {
            refinement,
            ..SolveOptions::default()
        };
        group.bench_with_input(BenchmarkId::new(name, n), &problem, |bch, p| {
            bch.iter(|| solve(black_box(p), &options).map(|s| s.modes[0].omega_sq))
        });
    }
    if lapack::available() {
        let (k, m) = (to_col_major(b.as_ref()), to_col_major(a.as_ref()));
        group.bench_with_input(BenchmarkId::new("lapack_dsygvd_all_pairs", n), &(), |bch, _| {
            bch.iter(|| lapack::dsygvd(black_box(&k), &m, n, true).map(|e| e.values[0]))
        });
    }
    group.finish();
}

criterion_group!(benches, dense, sparse, stiff);
criterion_main!(benches);
