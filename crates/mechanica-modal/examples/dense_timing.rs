//! Times the dense solver on the rotated fixed chain (masses 1 + i/n, random rotation) and
//! prints the worst relative error of the lowest 10 ω² against the closed form, the reported
//! bound, the refined modes and the wall time.
//! With `lumped` the masses stay diagonal and only the stiffness is rotated: A = D,
//! B = D^½ Qᵀ T Q D^½ (same ω²), the lumped-mass case.
//! `cargo run --release -p mechanica-modal --example dense_timing -- 2000 [auto|off|always] [values] [sketched] [lumped]`
use mechanica_modal::faer::Mat;
use mechanica_modal::{PencilProblem, Refinement, Residuals, SolveOptions, solve, testing};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args.first().and_then(|a| a.parse().ok()).unwrap_or(2000);
    let has = |word: &str| args.iter().any(|a| a == word);
    let refinement = if has("off") {
        Refinement::Off
    } else if has("always") {
        Refinement::Always
    } else {
        Refinement::Auto
    };
    let vectors = !has("values");
    let residuals = if has("sketched") {
        Residuals::Sketched
    } else {
        Residuals::Exact
    };
    let d: Vec<f64> = (0..n).map(|i| 1.0 + i as f64 / n as f64).collect();
    let a = Mat::from_fn(n, n, |i, j| if i == j { d[i] } else { 0.0 });
    let (_, t) = testing::fixed_chain(n);
    let b = Mat::from_fn(n, n, |i, j| (d[i] * d[j]).sqrt() * t[(i, j)]);
    let (a, b) = if has("lumped") {
        testing::lumped_chain(&d, 42)
    } else {
        testing::rotate(&a, &b, &testing::random_orthogonal(n, 42))
    };
    let p = match PencilProblem::new(a.as_ref(), b.as_ref()) {
        Ok(p) => p,
        Err(e) => return eprintln!("{e}"),
    };
    let options = SolveOptions {
        refinement,
        vectors,
        residuals,
        ..SolveOptions::default()
    };
    let exact = testing::fixed_chain_omega_sq(n);
    for _ in 0..2 {
        let clock = Instant::now();
        let sol = match solve(&p, &options) {
            Ok(s) => s,
            Err(e) => return eprintln!("{e}"),
        };
        let time = clock.elapsed().as_secs_f64();
        let (mut err, mut bound) = (0.0_f64, 0.0_f64);
        for (m, w) in sol.modes.iter().zip(&exact).take(10) {
            err = err.max((m.omega_sq - w).abs() / w);
            bound = bound.max(m.error_bound / w);
        }
        let refined = sol.accuracy.refinement_steps.iter().filter(|&&s| s > 0).count();
        if std::env::var("STAGES").is_ok() {
            let steps: Vec<usize> = sol
                .accuracy
                .refinement_steps
                .iter()
                .copied()
                .filter(|&s| s > 0)
                .collect();
            eprintln!("  stages {:?} refinement steps {steps:?}", sol.timings);
        }
        println!(
            "n {n} {refinement:?} {residuals:?} vectors {vectors}: {time:.3} s, lowest-10 rel err {err:.2e} (bound {bound:.2e}), refined {refined}, max eta {:?}, orth {:?}, sturm {:?}",
            sol.accuracy.max_backward_error,
            sol.accuracy.orthogonality_error,
            sol.accuracy
                .inertia_check
                .map(|c| (c.count.shift, c.count.below, c.consistent))
        );
    }
}
