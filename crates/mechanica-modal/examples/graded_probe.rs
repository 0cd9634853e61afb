//! Random graded spring systems against their double-double reference, per family and mode of
//! use: values outside their bounds, misclassified systems, the worst relative error of the five
//! lowest non-rigid modes and their loosest relative bound. `cargo run --release -p mechanica-modal --features testing --example
//! graded_probe -- N SEEDS [auto|values|lowest|always|off|sparse]`.
use faer::sparse::Triplet;
use mechanica_modal::testing::graded::{GradedFamily, Shape, spring_tree, tree_pencil_spectrum};
use mechanica_modal::{
    ModeKind, PencilProblem, Refinement, Selection, SolveOptions, SparsePencil, SparseSolveOptions, solve, solve_sparse,
};

fn triplets(m: &faer::Mat<f64>) -> Vec<Triplet<usize, usize, f64>> {
    let mut t = Vec::new();
    for j in 0..m.ncols() {
        for i in 0..m.nrows() {
            if m[(i, j)] != 0.0 {
                t.push(Triplet::new(i, j, m[(i, j)]));
            }
        }
    }
    t
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(30);
    let seeds: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(10);
    let mode = args.get(3).cloned().unwrap_or_else(|| "auto".into());
    if mode == "cost" {
        return cost(n, seeds);
    }
    for (shape, fixed) in [
        (Shape::Chain, true),
        (Shape::Tree, true),
        (Shape::Chain, false),
        (Shape::Tree, false),
    ] {
        let (mut outside, mut miscl, mut worst, mut loosest, mut errs) = (0, 0, 0.0f64, 0.0f64, 0);
        for seed in 0..seeds {
            let sys = spring_tree(&GradedFamily::new(n, shape, fixed), seed);
            let reference = tree_pencil_spectrum(&sys);
            let p = PencilProblem::new(sys.a.as_ref(), sys.b.as_ref()).expect("valid pencil");
            let mut o = SolveOptions::default();
            match mode.as_str() {
                "values" => o.vectors = false,
                "lowest" => o.selection = Selection::Lowest(5),
                "always" => o.refinement = Refinement::Always,
                "off" => o.refinement = Refinement::Off,
                _ => {}
            }
            let modes = if mode == "sparse" {
                let sp = SparsePencil::from_triplets(n, &triplets(&sys.a), &triplets(&sys.b)).expect("valid pencil");
                let so = SparseSolveOptions {
                    count: 6,
                    ..SparseSolveOptions::default()
                };
                solve_sparse(&sp, &so).map(|s| s.modes)
            } else {
                solve(&p, &o).map(|s| s.modes)
            };
            let modes = match modes {
                Ok(m) => m,
                Err(e) => {
                    errs += 1;
                    println!("  {shape:?} {fixed} seed {seed}: {e}");
                    continue;
                }
            };
            let zeros = modes.iter().filter(|m| m.kind == ModeKind::Zero).count();
            let all = modes.len() == n;
            if (all && zeros != sys.rigid_modes) || zeros > sys.rigid_modes {
                miscl += 1;
                println!("  seed {seed}: {zeros} zero modes");
            }
            for (k, (m, r)) in modes.iter().zip(&reference).enumerate() {
                let err = (m.omega_sq - r).abs();
                if err.is_nan() || err > m.error_bound {
                    outside += 1;
                    if outside < 4 {
                        println!(
                            "  seed {seed} mode {k}: {} ref {r} err {err:e} bound {:e}",
                            m.omega_sq, m.error_bound
                        );
                    }
                }
                if k < 5 + sys.rigid_modes && k >= sys.rigid_modes {
                    worst = worst.max(err / r.abs());
                    loosest = loosest.max(m.error_bound / r.abs());
                }
            }
        }
        println!(
            "{shape:?} fixed={fixed} n={n} {mode}: outside {outside}, misclassified {miscl}, errors {errs}, worst rel low5 {worst:e}, loosest rel bound low5 {loosest:e}"
        );
    }
}

/// Median wall times of a certified (`Refinement::Auto`) and a plain (`Refinement::Off`) solve of
/// fixed graded trees, 15 of each taken alternately (a drift of the machine's speed touches
/// both), and their ratio.
fn cost(n: usize, seeds: u64) {
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    for seed in 0..seeds {
        let sys = spring_tree(&GradedFamily::new(n, Shape::Tree, true), seed);
        let p = PencilProblem::new(sys.a.as_ref(), sys.b.as_ref()).expect("valid pencil");
        let time = |refinement| {
            let clock = std::time::Instant::now();
            let options = SolveOptions {
                refinement,
                ..SolveOptions::default()
            };
            solve(&p, &options).expect("solve");
            clock.elapsed().as_secs_f64()
        };
        let (plain, certified): (Vec<f64>, Vec<f64>) =
            (0..15).map(|_| (time(Refinement::Off), time(Refinement::Auto))).unzip();
        let fastest = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
        let fastest_ratio = fastest(&certified) / fastest(&plain);
        let (plain, certified) = (median(plain), median(certified));
        let detail = solve(&p, &SolveOptions::default()).expect("solve");
        let refined = detail.accuracy.refinement_steps.iter().filter(|&&s| s > 0).count();
        let steps: usize = detail.accuracy.refinement_steps.iter().sum();
        println!(
            "  stages {:?}, refined modes {refined}, Newton steps {steps}",
            detail.timings
        );
        println!(
            "n {n} seed {seed}: plain {:.3} ms, certified {:.3} ms, ratio {:.2} (of the fastest runs {fastest_ratio:.2})",
            plain * 1e3,
            certified * 1e3,
            certified / plain
        );
    }
}
