//! Times the dense solve of a lumped chain with massless nodes: unit springs between two walls
//! through n = 2m + 1 nodes, the even ones massless (A diagonal and semidefinite), so the solve
//! condenses m + 1 massless coordinates and finds m finite modes with ω² = 2 sin²(kπ/(2(m + 1))).
//! Prints the wall time, the lowest ω² against that closed form and the stage times.
//! `cargo run --release -p mechanica-modal --example massless_timing -- 1000`
use mechanica_modal::faer::Mat;
use mechanica_modal::{PencilProblem, Residuals, SolveOptions, solve, testing};
use std::time::Instant;

fn main() {
    let m: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(1000);
    let n = 2 * m + 1;
    let (_, b) = testing::fixed_chain(n);
    let a = Mat::from_fn(n, n, |i, j| if i == j && i % 2 == 1 { 1.0 } else { 0.0 });
    let problem = match PencilProblem::new(a.as_ref(), b.as_ref()) {
        Ok(p) => p,
        Err(e) => return eprintln!("{e}"),
    };
    let options = SolveOptions {
        residuals: Residuals::Sketched,
        ..SolveOptions::default()
    };
    let s = (std::f64::consts::PI / (2.0 * (m + 1) as f64)).sin();
    let exact = 2.0 * s * s;
    for _ in 0..3 {
        let clock = Instant::now();
        match solve(&problem, &options) {
            Ok(sol) => println!(
                "n {n}: {:.3} s, lowest ω² {:.6e} (closed form {exact:.6e}, bound {:.1e}), {:?}",
                clock.elapsed().as_secs_f64(),
                sol.modes[0].omega_sq,
                sol.modes[0].error_bound,
                sol.timings
            ),
            Err(e) => return eprintln!("{e}"),
        }
    }
}
