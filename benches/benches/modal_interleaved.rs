//! Dense all-pairs solves against LAPACK `dsygvd`, interleaved: every round runs each method
//! once, in turn, so that a machine whose speed drifts (shared cores, other tenants) slows all
//! methods alike; the median over the rounds and its ratio to dsygvd's median are printed.
//!
//! `OPENBLAS_CORETYPE=Haswell cargo bench -p mechanica-benches --bench modal_interleaved -- 1000 2000 4000`
//! (sizes optional; rounds: `ROUNDS=7`, default 5; `METHODS=sketched` keeps only the methods whose
//! label contains that text, and the LAPACK rows). Problem: [`rotated_fixed_chain`], or with
//! `FAMILY=lumped` [`lumped_fixed_chain`] (diagonal masses, dense stiffness), where a third LAPACK
//! row scales C = D^−½ B D^−½ by hand and calls `dsyevd`, what an expert LAPACK user would do;
//! its time includes the scaling and the back-scaling of the vectors. Values-only rows are
//! compared with `dsygvd` without vectors, the others with `dsygvd` with vectors.
//!
//! Besides the ratio of medians, each row gives the median of the per-round ratios (a method's
//! time over `dsygvd`'s in the same round, which cancels the machine's slow drifts) and a 90 %
//! bootstrap interval of that median (2000 resamples of the rounds). The order of the methods is
//! rotated from one round to the next, so that no method always runs right after LAPACK.

use mechanica::modal::{PencilProblem, Refinement, Residuals, SolveOptions, solve};
use mechanica_benches::lapack;
use mechanica_benches::modal::{lumped_fixed_chain, rotated_fixed_chain, to_col_major};
use std::time::{Duration, Instant};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let sizes: Vec<usize> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let sizes = if sizes.is_empty() { vec![1000, 2000] } else { sizes };
    let rounds: usize = std::env::var("ROUNDS").ok().and_then(|r| r.parse().ok()).unwrap_or(5);
    if !lapack::available() {
        println!("LAPACK not available (built without OpenBLAS): nothing to compare");
        return;
    }
    println!(
        "LAPACK: OpenBLAS {} threads, kernels {}; {rounds} interleaved rounds",
        lapack::threads().unwrap_or(0),
        lapack::core_name().unwrap_or_default()
    );
    let mech = |refinement, residuals| SolveOptions {
        refinement,
        residuals,
        ..SolveOptions::default()
    };
    let values_only = SolveOptions {
        vectors: false,
        refinement: Refinement::Off,
        ..SolveOptions::default()
    };
    let lumped = std::env::var("FAMILY").is_ok_and(|f| f == "lumped");
    // (label, mechanica's options or None for LAPACK, whether vectors are computed)
    let values_auto = SolveOptions {
        refinement: Refinement::Auto,
        ..values_only
    };
    let methods: [(&str, Option<SolveOptions>, bool); 8] = [
        (
            "mechanica all pairs (Auto, exact report)",
            Some(SolveOptions::default()),
            true,
        ),
        (
            "mechanica all pairs (Auto, sketched report)",
            Some(mech(Refinement::Auto, Residuals::Sketched)),
            true,
        ),
        (
            "mechanica all pairs (Off, exact report)",
            Some(mech(Refinement::Off, Residuals::Exact)),
            true,
        ),
        (
            "mechanica all pairs (Off, sketched report)",
            Some(mech(Refinement::Off, Residuals::Sketched)),
            true,
        ),
        ("LAPACK dsygvd all pairs", None, true),
        ("mechanica values only (Off, a-priori bounds)", Some(values_only), false),
        (
            "mechanica values only (Auto, weakly bounded modes measured)",
            Some(values_auto),
            false,
        ),
        ("LAPACK dsygvd values only", None, false),
    ];
    let filter = std::env::var("METHODS").unwrap_or_default();
    let methods: Vec<_> = methods
        .into_iter()
        .filter(|(label, options, _)| options.is_none() || label.contains(filter.as_str()))
        .collect();
    println!("| n | method | median s | ratio to dsygvd | paired ratio, median [90 % interval] | min s | max s |");
    println!("|---|---|---|---|---|---|---|");
    for n in sizes {
        let (a, b) = if lumped {
            lumped_fixed_chain(n)
        } else {
            rotated_fixed_chain(n)
        };
        let Ok(problem) = PencilProblem::new(a.as_ref(), b.as_ref()) else {
            println!("| {n} | the pencil is invalid | | | | |");
            continue;
        };
        let (ka, kb) = (to_col_major(b.as_ref()), to_col_major(a.as_ref()));
        let mut times = vec![Vec::new(); methods.len()];
        let masses: Vec<f64> = (0..n).map(|i| a[(i, i)]).collect();
        let mut scaled_times = Vec::new();
        for round in 0..rounds {
            if lumped {
                let clock = Instant::now();
                let ok = std::hint::black_box(scaled_dsyevd(&ka, &masses, n)).is_ok();
                scaled_times.push(clock.elapsed().as_secs_f64());
                if !ok {
                    println!("| {n} | hand-scaled dsyevd failed | | | | |");
                }
                std::thread::sleep(Duration::from_millis(200));
            }
            for turn in 0..methods.len() {
                let k = (turn + round) % methods.len();
                let (_, options, vectors) = &methods[k];
                let clock = Instant::now();
                let ok = match options {
                    Some(o) => std::hint::black_box(solve(&problem, o)).is_ok(),
                    None => std::hint::black_box(lapack::dsygvd(&ka, &kb, n, *vectors)).is_ok(),
                };
                times[k].push(clock.elapsed().as_secs_f64());
                if !ok {
                    println!("| {n} | {} failed | | | | |", methods[k].0);
                }
                // OpenBLAS threads spin after a call; let them sleep before the next method.
                std::thread::sleep(Duration::from_millis(200));
            }
        }
        // Each mechanica row is compared with LAPACK computing the same (with or without vectors).
        let lapack_times = |vectors: bool| {
            let k = methods
                .iter()
                .position(|(_, o, v)| o.is_none() && *v == vectors)
                .unwrap_or(methods.len() - 1);
            &times[k]
        };
        for (k, (label, _, vectors)) in methods.iter().enumerate() {
            println!(
                "| {n} | {label} | {} |",
                row_statistics(&times[k], lapack_times(*vectors))
            );
        }
        if lumped {
            println!(
                "| {n} | LAPACK dsyevd on D^−½BD^−½, scaled by hand (all pairs) | {} |",
                row_statistics(&scaled_times, lapack_times(true))
            );
        }
    }
}

/// A row's statistics of `times` against the LAPACK times of the same rounds: median, ratio of
/// medians, median of the per-round ratios with its 90 % bootstrap interval, min and max.
fn row_statistics(times: &[f64], reference: &[f64]) -> String {
    let (lo, hi) = (
        times.iter().copied().fold(f64::INFINITY, f64::min),
        times.iter().copied().fold(0.0, f64::max),
    );
    let m = median(times.to_vec());
    let paired: Vec<f64> = times
        .iter()
        .zip(reference)
        .map(|(ours, lapack)| ours / lapack)
        .collect();
    let (low, high) = bootstrap_median_interval(&paired);
    format!(
        "{m:.3} | {:.2} | {:.2} [{low:.2}, {high:.2}] | {lo:.3} | {hi:.3}",
        m / median(reference.to_vec()),
        median(paired),
    )
}

/// The 5th and 95th percentiles of the median of `samples` resampled with replacement (2000
/// resamples drawn by a fixed linear congruential generator, so that a run can be repeated).
fn bootstrap_median_interval(samples: &[f64]) -> (f64, f64) {
    if samples.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut draw = || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((state >> 33) as usize) % samples.len()
    };
    let mut sorted: Vec<f64> = (0..2000)
        .map(|_| median((0..samples.len()).map(|_| samples[draw()]).collect()))
        .collect();
    sorted.sort_by(f64::total_cmp);
    (sorted[sorted.len() / 20], sorted[sorted.len() * 19 / 20])
}

/// All pairs of a lumped-mass pencil the way an expert calls LAPACK: C = D^−½ B D^−½ formed by
/// hand, `dsyevd`, then X = D^−½ Y.
fn scaled_dsyevd(stiffness: &[f64], masses: &[f64], n: usize) -> Result<Vec<f64>, lapack::LapackError> {
    let inverse_root: Vec<f64> = masses.iter().map(|m| m.sqrt().recip()).collect();
    let mut c = stiffness.to_vec();
    for j in 0..n {
        for i in 0..n {
            c[i + j * n] *= inverse_root[i] * inverse_root[j];
        }
    }
    let values = lapack::dsyevd(&mut c, n, true)?;
    for j in 0..n {
        for i in 0..n {
            c[i + j * n] *= inverse_root[i];
        }
    }
    std::hint::black_box(&c);
    Ok(values)
}
