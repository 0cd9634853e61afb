//! Times an all-pairs solve of the graded stiff chain (unit masses, spring stiffnesses graded
//! over 12 decades, `testing::graded_exponents`), where Auto refinement certifies the weakly
//! bounded low half of the spectrum, and prints the modes refined and the stage timings.
//! `cargo run --release -p mechanica-modal --example graded_timing -- 1000`
use mechanica_modal::{PencilProblem, SolveOptions, solve, testing};

fn main() {
    let n: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(1000);
    let (a, b) = testing::spring_chain(&testing::graded_exponents(n, 12), &vec![0; n]);
    let p = match PencilProblem::new(a.as_ref(), b.as_ref()) {
        Ok(p) => p,
        Err(e) => return eprintln!("{e}"),
    };
    for _ in 0..2 {
        let clock = std::time::Instant::now();
        let sol = match solve(&p, &SolveOptions::default()) {
            Ok(s) => s,
            Err(e) => return eprintln!("{e}"),
        };
        let refined = sol.accuracy.refinement_steps.iter().filter(|&&s| s > 0).count();
        println!(
            "n {n}: {:.3} s, {refined} modes refined, {:?}",
            clock.elapsed().as_secs_f64(),
            sol.timings
        );
    }
}
