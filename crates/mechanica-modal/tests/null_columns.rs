//! Pencils whose stiffness has columns that are exactly zero (coordinates no potential depends
//! on) among graded coupled ones: B = [0 0; 0 B₁] in a random numbering, A dense and graded,
//! so e_j (j a zero column) gives B e_j = 0 and ω² = 0 exactly, z times, and every other ω² is
//! positive (B₁ positive definite; the Schur complement of A keeps the pencil definite on the
//! rest). Every mode of the z exact zeros must be called zero, never undecided, whatever tiny
//! bound the solve gives it; every other mode oscillatory.

use faer::Mat;
use mechanica_modal::testing::graded::SplitMix;
use mechanica_modal::testing::random_orthogonal;
use mechanica_modal::{ModeKind, PencilProblem, Selection, SolveOptions, solve};
use proptest::prelude::*;

/// Q diag(λ) Qᵀ with λ = 10^U(−spread, 0), symmetrised, then scaled by D = diag(10^U(±grading)).
fn graded_spd(rng: &mut SplitMix, n: usize, seed: u64, spread: f64, grading: f64) -> Mat<f64> {
    let q = random_orthogonal(n, seed);
    let lambda: Vec<f64> = (0..n).map(|_| 10f64.powf(rng.uniform(-spread, 0.0))).collect();
    let d: Vec<f64> = (0..n).map(|_| 10f64.powf(rng.uniform(-grading, grading))).collect();
    let m = Mat::from_fn(n, n, |i, j| {
        (0..n).map(|k| q[(i, k)] * lambda[k] * q[(j, k)]).sum::<f64>()
    });
    Mat::from_fn(n, n, |i, j| d[i] * 0.5 * (m[(i, j)] + m[(j, i)]) * d[j])
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn exactly_zero_columns_give_zero_modes_and_nothing_else_does(
        seed in any::<u64>(),
        n in 3usize..40,
        zero_fraction in 0.05..0.5_f64,
        lowest in any::<bool>(),
    ) {
        let mut rng = SplitMix::new(seed);
        let z = ((n as f64 * zero_fraction) as usize).clamp(1, n - 1);
        let a = graded_spd(&mut rng, n, seed, 3.0, 3.0);
        let stiff = graded_spd(&mut rng, n - z, seed ^ 1, 4.0, 2.0);
        // A random numbering: the first z of a random permutation are the zero columns.
        let mut order: Vec<usize> = (0..n).collect();
        for i in (1..n).rev() {
            order.swap(i, rng.below(i + 1));
        }
        let mut place = vec![None; n];
        for (k, &i) in order[z..].iter().enumerate() {
            place[i] = Some(k);
        }
        let b = Mat::from_fn(n, n, |i, j| match (place[i], place[j]) {
            (Some(p), Some(q)) => stiff[(p, q)],
            _ => 0.0,
        });
        let problem = PencilProblem::new(a.as_ref(), b.as_ref()).expect("valid pencil");
        let selection = if lowest { Selection::Lowest((z + 2).min(n)) } else { Selection::All };
        let options = SolveOptions { selection, ..SolveOptions::default() };
        let modes = solve(&problem, &options).expect("dense solve").modes;
        for (rank, mode) in modes.iter().enumerate() {
            if rank < z {
                prop_assert_eq!(mode.kind, ModeKind::Zero, "rank {} of z = {}: {:?}", rank, z, mode);
                prop_assert!(mode.omega_sq.abs() <= mode.error_bound);
            } else {
                prop_assert!(matches!(mode.kind, ModeKind::Oscillatory { .. }), "rank {}: {:?}", rank, mode);
            }
        }
    }
}
