//! Checks two facts about faer 0.24 behind the dense solver's design (run with
//! `cargo run --release -p mechanica-modal --example faer_facts`):
//! 1. `generalized_eigen` (QZ) accuracy and time on a rotated unit chain (exact spectrum known)
//!    at n = 200 and 600, against `mechanica_modal::solve` on the same pencil;
//! 2. whether `partial_self_adjoint_eigen` panics for small n relative to the requested count.

use mechanica_modal::faer::dyn_stack::{MemBuffer, MemStack};
use mechanica_modal::faer::matrix_free::eigen::{
    PartialEigenParams, partial_self_adjoint_eigen, partial_self_adjoint_eigen_scratch,
};
use mechanica_modal::faer::{Col, Mat, Par};
use mechanica_modal::{PencilProblem, SolveOptions, solve, testing};
use std::time::Instant;

fn main() {
    for n in [200, 600] {
        let q = testing::random_orthogonal(n, 3);
        let (a, b) = testing::rotate(&Mat::identity(n, n), &testing::fixed_chain(n).1, &q);
        let exact = testing::fixed_chain_omega_sq(n);
        let t = Instant::now();
        let qz = b.generalized_eigen(&a);
        let t_qz = t.elapsed().as_secs_f64();
        let qz_err = match qz {
            Ok(g) => {
                let mut w: Vec<f64> = (0..n).map(|i| (g.S_a()[i] / g.S_b()[i]).re).collect();
                w.sort_by(f64::total_cmp);
                w.iter().zip(&exact).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / 4.0
            }
            Err(e) => {
                println!("n = {n}: QZ failed: {e:?}");
                f64::NAN
            }
        };
        let t = Instant::now();
        let p = PencilProblem::new(a.as_ref(), b.as_ref()).expect("valid");
        let sol = solve(&p, &SolveOptions::default()).expect("solve");
        let t_ours = t.elapsed().as_secs_f64();
        let ours = sol
            .modes
            .iter()
            .zip(&exact)
            .map(|(m, y)| (m.omega_sq - y).abs())
            .fold(0.0, f64::max)
            / 4.0;
        println!(
            "n = {n}: QZ max |Δω²|/‖C‖ = {qz_err:.2e} in {t_qz:.3} s; mechanica {ours:.2e} in {t_ours:.3} s (η max {:.2e})",
            sol.accuracy.max_backward_error.unwrap_or(f64::NAN)
        );
    }
    for (n, nev) in [(40, 5), (64, 5), (100, 5), (100, 40), (300, 5)] {
        let (_, b) = testing::fixed_chain(n);
        let result = std::panic::catch_unwind(|| {
            let params = PartialEigenParams::default();
            let mut mem = MemBuffer::new(partial_self_adjoint_eigen_scratch(&b, nev, Par::Seq, params));
            let mut vecs = Mat::<f64>::zeros(n, nev);
            let mut vals = vec![0.0; nev];
            let v0 = Col::<f64>::from_fn(n, |i| 1.0 + i as f64);
            let info = partial_self_adjoint_eigen(
                vecs.as_mut(),
                &mut vals,
                &b,
                v0.as_ref(),
                1e-12,
                Par::Seq,
                MemStack::new(&mut mem),
                params,
            );
            info.n_converged_eigen
        });
        match result {
            Ok(k) => println!("partial_self_adjoint_eigen n = {n}, nev = {nev}: ok, {k} converged"),
            Err(_) => println!("partial_self_adjoint_eigen n = {n}, nev = {nev}: PANICKED"),
        }
    }
}
