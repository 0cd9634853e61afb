//! Soft modes under stiff springs: planar chains of point masses on massless links, hanging
//! straight (q = 0) with no gravity and a torsional spring in every joint, masses and
//! stiffnesses graded at random (not monotonically) over many decades. B = diag(k) is positive
//! definite, so every mode oscillates; a soft mode must not be called zero because a stiff
//! spring elsewhere dominates ‖B‖.
//!
//! The reference is independent of the tree's assembly: in absolute link angles the mass
//! matrix of such a chain is A_abs[i][j] = M_max(i,j) l_i l_j with M_k the mass beyond link k
//! (all cosines are 1 at q = 0), and the relative joint angles map to absolute ones by a unit
//! lower-triangular sum, so A = Tᵀ A_abs T is a sum of positive terms, exact to a few ulps
//! entry by entry. That pencil is solved with refinement.

use faer::Mat;
use mechanica_kinematics::tree::{Joint, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mechanism::potentials::JointSpring;
use mechanica_mechanism::{Mechanism, Stability, mechanism_modes};
use mechanica_modal::{ModeKind, PencilProblem, Refinement, SolveOptions, solve};
use nalgebra::{Isometry3, Vector3};
use proptest::prelude::*;

struct Chain {
    masses: Vec<f64>,
    lengths: Vec<f64>,
    stiffnesses: Vec<f64>,
}

/// The mechanism: joint i about y at the end of link i − 1, point mass m_i at −l_i z.
fn mechanism(chain: &Chain) -> Mechanism {
    let mut builder = TreeBuilder::new();
    let mut parent = None;
    let mut bodies = Vec::new();
    for (i, (&m, &l)) in chain.masses.iter().zip(&chain.lengths).enumerate() {
        let offset = if i == 0 { 0.0 } else { -chain.lengths[i - 1] };
        let placement = Isometry3::translation(0.0, 0.0, offset);
        parent = Some(builder.add_body(parent, Joint::Revolute { axis: Vector3::y() }, placement));
        bodies.push(MassProperties::point(m, Vector3::new(0.0, 0.0, -l)).expect("mass"));
    }
    let mut mechanism = Mechanism::new(builder.build().expect("tree"), bodies).expect("mechanism");
    mechanism.set_gravity(Vector3::zeros()).expect("gravity");
    for (i, &k) in chain.stiffnesses.iter().enumerate() {
        mechanism
            .add_potential(JointSpring {
                coordinate: i,
                stiffness: k,
                rest: 0.0,
            })
            .expect("spring");
    }
    mechanism
}

/// A = Tᵀ A_abs T: A[i][j] = Σ_{a ≥ i, b ≥ j} M_max(a,b) l_a l_b.
fn reference_mass_matrix(chain: &Chain) -> Mat<f64> {
    let n = chain.masses.len();
    let beyond: Vec<f64> = (0..n).map(|k| chain.masses[k..].iter().sum()).collect();
    let abs = |a: usize, b: usize| beyond[a.max(b)] * chain.lengths[a] * chain.lengths[b];
    Mat::from_fn(n, n, |i, j| {
        (i..n)
            .flat_map(|a| (j..n).map(move |b| (a, b)))
            .map(|(a, b)| abs(a, b))
            .sum()
    })
}

/// (n² + 3)u ω² |x|ᵀ A |x| for the reference mode `mode` of `solution`.
fn reference_rounding(a: &Mat<f64>, solution: &mechanica_modal::ModalSolution, mode: &mechanica_modal::Mode) -> f64 {
    let n = a.nrows();
    let Some(x) = &solution.vectors else {
        return f64::INFINITY;
    };
    let Some(k) = solution.modes.iter().position(|m| std::ptr::eq(m, mode)) else {
        return f64::INFINITY;
    };
    let weight: f64 = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .map(|(i, j)| x[(i, k)].abs() * a[(i, j)] * x[(j, k)].abs())
        .sum();
    (n * n + 3) as f64 * f64::EPSILON * mode.omega_sq.abs() * weight
}

fn random_chain(seed: u64, n: usize) -> Chain {
    let mut state = seed ^ 0x9e37_79b9_7f4a_7c15;
    let mut uniform = |lo: f64, hi: f64| {
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        lo + (hi - lo) * (((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64)
    };
    let masses = (0..n).map(|_| 10f64.powf(uniform(-6.0, 2.0))).collect();
    let lengths = (0..n).map(|_| 10f64.powf(uniform(-1.0, 1.0))).collect();
    let stiffnesses = (0..n).map(|_| 10f64.powf(uniform(-2.0, 12.0))).collect();
    Chain {
        masses,
        lengths,
        stiffnesses,
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn soft_modes_under_stiff_springs_oscillate_within_their_bounds(seed in any::<u64>(), n in 2usize..24) {
        let chain = random_chain(seed, n);
        let mut mech = mechanism(&chain);
        let modes = mechanism_modes(&mut mech, &vec![0.0; n], &SolveOptions::default()).expect("modes");
        let b = Mat::from_fn(n, n, |i, j| if i == j { chain.stiffnesses[i] } else { 0.0 });
        let a = reference_mass_matrix(&chain);
        let options = SolveOptions { refinement: Refinement::Always, ..SolveOptions::default() };
        let reference = solve(&PencilProblem::new(a.as_ref(), b.as_ref()).expect("pencil"), &options).expect("solve");
        prop_assert_eq!(modes.solution.modes.len(), n);
        for (mode, exact) in modes.solution.modes.iter().zip(&reference.modes) {
            prop_assert!(matches!(mode.kind, ModeKind::Oscillatory { .. }), "{:?}: ω² = {} ± {}", mode.kind, mode.omega_sq, mode.error_bound);
            // The reported bound covers the solve and the assembly of A and B. The reference's
            // A is exact to (n² + 3)u entry by entry (sums of positive terms), which moves its
            // ω² by at most (n² + 3)u ω² |x|ᵀA|x| for its A-normalised x.
            let allowance = mode.error_bound + exact.error_bound + reference_rounding(&a, &reference, exact);
            prop_assert!((mode.omega_sq - exact.omega_sq).abs() <= allowance,
                "ω² = {} against {} (bounds {:.1e}, {:.1e})", mode.omega_sq, exact.omega_sq, mode.error_bound, exact.error_bound);
        }
        prop_assert_eq!(modes.stability, Stability::Stable);
        // The soft mode is resolved: B's assembly is charged to it through its own tiny motion
        // of the stiff coordinates, not through ‖B‖.
        let lowest = &modes.solution.modes[0];
        prop_assert!(lowest.error_bound <= 1e-6 * lowest.omega_sq, "bound {:.1e} on ω² = {}", lowest.error_bound, lowest.omega_sq);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Springs scaled by 2^k (k from 400 to 640, stiffnesses up to 1e205, whose squares
    /// overflow): the modes are those of the unscaled chain times 2^k, within the two bounds,
    /// and every bound is finite (the assembly error's Frobenius norms were formed from
    /// squares and came out NaN).
    #[test]
    fn huge_stiffnesses_scale_the_modes_and_their_bounds(seed in any::<u64>(), n in 2usize..9, k in 400i32..640) {
        let chain = random_chain(seed, n);
        let scale = 2f64.powi(k);
        let scaled = Chain {
            masses: chain.masses.clone(),
            lengths: chain.lengths.clone(),
            stiffnesses: chain.stiffnesses.iter().map(|s| s * scale).collect(),
        };
        let unit = mechanism_modes(&mut mechanism(&chain), &vec![0.0; n], &SolveOptions::default()).expect("modes");
        let big = mechanism_modes(&mut mechanism(&scaled), &vec![0.0; n], &SolveOptions::default()).expect("modes");
        for (small, large) in unit.solution.modes.iter().zip(&big.solution.modes) {
            prop_assert!(large.error_bound.is_finite() && large.omega_sq.is_finite(), "ω² = {} ± {}", large.omega_sq, large.error_bound);
            let allowance = large.error_bound + small.error_bound * scale;
            prop_assert!((large.omega_sq - small.omega_sq * scale).abs() <= allowance,
                "ω² = {:e} against {:e} × 2^{}", large.omega_sq, small.omega_sq, k);
        }
    }
}

/// A chain whose two softest modes were buried under the stiff modes' rounding (|ω²| below
/// u·n·max ω², few enough to pass for rigid-body modes): the solve must reverse the pencil,
/// since B is positive definite, and find them, not call them zero.
#[test]
fn buried_soft_modes_are_found() {
    let chain = random_chain(705, 7);
    let mut mech = mechanism(&chain);
    let modes = mechanism_modes(&mut mech, &[0.0; 7], &SolveOptions::default()).expect("modes");
    assert_eq!(modes.stability, Stability::Stable);
    let a = reference_mass_matrix(&chain);
    let b = Mat::from_fn(7, 7, |i, j| if i == j { chain.stiffnesses[i] } else { 0.0 });
    let options = SolveOptions {
        refinement: Refinement::Always,
        ..SolveOptions::default()
    };
    let reference = solve(&PencilProblem::new(a.as_ref(), b.as_ref()).expect("pencil"), &options).expect("solve");
    for (mode, exact) in modes.solution.modes.iter().zip(&reference.modes).take(2) {
        assert!(
            (mode.omega_sq - exact.omega_sq).abs() <= 1e-8 * exact.omega_sq,
            "{} against {}",
            mode.omega_sq,
            exact.omega_sq
        );
    }
}
