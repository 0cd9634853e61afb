//! Times the sparse solver on an N×N grid Laplacian (default 300: n = 90 000, 10 lowest modes)
//! and prints the report. `cargo run --release -p mechanica-modal --example sparse_grid -- 300 10`
use mechanica_modal::{SparsePencil, SparseSolveOptions, solve_sparse, testing};
use std::time::Instant;

fn main() {
    let args: Vec<usize> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let side = args.first().copied().unwrap_or(300);
    let k = args.get(1).copied().unwrap_or(10);
    if std::env::var("SEQ").is_ok() {
        mechanica_modal::faer::set_global_parallelism(mechanica_modal::faer::Par::Seq);
    }
    let (a, b) = testing::grid_laplacian(side, side);
    let clock = Instant::now();
    let p = match SparsePencil::from_triplets(side * side, &a, &b) {
        Ok(p) => p,
        Err(e) => return eprintln!("{e}"),
    };
    let assembled = clock.elapsed();
    let clock = Instant::now();
    let sol = match solve_sparse(
        &p,
        &SparseSolveOptions {
            count: k,
            block_size: std::env::var("BLOCK")
                .ok()
                .and_then(|b| b.parse().ok())
                .unwrap_or(SparseSolveOptions::default().block_size),
            tolerance: std::env::var("TOL").ok().and_then(|b| b.parse().ok()).unwrap_or(1e-12),
            ..SparseSolveOptions::default()
        },
    ) {
        Ok(s) => s,
        Err(e) => return eprintln!("{e}"),
    };
    let solved = clock.elapsed();
    let exact = testing::grid_omega_sq(side, side, k);
    let worst = sol
        .modes
        .iter()
        .zip(&exact)
        .map(|(m, w)| (m.omega_sq - w).abs() / w)
        .fold(0.0, f64::max);
    println!(
        "n = {}, k = {k}: validate {assembled:?}, solve {solved:?}, max relative error {worst:.2e}",
        side * side
    );
    println!("{:#?}", sol.report);
}
