//! The error estimate of a Lie-group run of the free body from three runs of the same method
//! with a = ⌊n/2⌋, n and 2n equal steps (docs/theory.md, "Lie-group integration of the free
//! body", error estimate).
//!
//! With d₁ the difference of the runs with a and n steps and d₂ that of the runs with n and 2n,
//! a method of order p in its asymptotic range has d₁/d₂ ≈ ρ = ((n/a)ᵖ − 1)/(1 − 2⁻ᵖ) (2ᵖ for
//! a = n/2), and the 2n run's error is d₂/(2ᵖ − 1). Three regimes, decided on every run:
//!
//! - **Phase lost**: a difference above [`UNRESOLVED`] (rad, or relative for ω), or a run
//!   with ⌊n/2⌋ steps that overflowed (beyond the method's stability). The runs no
//!   longer approximate each other, so nothing is inferred from them; the estimate is the
//!   largest error there can be: π for the attitude (the largest geodesic angle), and
//!   1 + ‖ω₂ₙ‖·I_max/Γ₀ for ω, since the exact motion keeps Γ₀ = |Iω(0)| ≤ I_max‖ω‖.
//! - **Asymptotic**: d₁/d₂ within a factor 2 of ρ for the attitude and for ω alike; the
//!   estimate is d₂, an upper bound with the margin 2ᵖ − 1.
//! - **Otherwise** (rounding-dominated, or convergence not yet at its order): 2d₂ + d₁/(2ᵖ − 1).
//!   The second term bounds the truncation error of the run with n steps if d₁ is truncation;
//!   the first allows for the 2n run's own rounding being of the size of the two runs' spread.
//!
//! Every estimate adds the rounding allowance 2n·ε·(1 + θ), θ = (Γ₀/I_min)·t the largest angle
//! the body can sweep (‖ω‖ ≤ Γ₀/I_min since Γ₀ = |Iω| is conserved): a
//! step's rounding, of relative size ε, shifts the motion's energy and so its frequencies, and
//! the phase error it starts grows in proportion to the angle still to be swept.

use mechanica_kinematics::rotation::log_map;
use mechanica_kinematics::scaling::norm;
use nalgebra::Vector3;

use super::lie_group::{LieEstimate, LieSolution};

/// The difference (rad, or relative for ω) above which the runs are taken to have lost the
/// phase of the motion: the geodesic angle is then no longer linear in the phase error.
pub const UNRESOLVED: f64 = 0.1;

/// The run with ⌊n/2⌋ steps of an estimate.
pub(super) enum HalfRun<'a> {
    /// n < 2: there is none.
    Absent,
    /// It overflowed or left the range of the rotation vector: the step count n/2 is beyond
    /// the method's stability, so the runs are treated as having lost the phase.
    Failed,
    /// It ran.
    Ran(&'a LieSolution),
}

/// The runs an estimate is formed from.
pub(super) struct Runs<'a> {
    /// The run with ⌊n/2⌋ steps.
    pub half: HalfRun<'a>,
    /// The run with n steps.
    pub coarse: &'a LieSolution,
    /// The run with 2n steps, the one reported.
    pub fine: LieSolution,
}

/// The estimate of the fine run's error for a method of order `order` over `duration`;
/// `moments` and `omega0` give the bound on ω used when the phase is lost and the angle swept.
pub(super) fn estimate(
    runs: Runs<'_>,
    order: u32,
    moments: &Vector3<f64>,
    omega0: &Vector3<f64>,
    duration: f64,
) -> LieEstimate {
    let swept = norm(&(moments / moments.min()).component_mul(omega0)) * duration;
    let rounding = (runs.fine.steps as f64 * f64::EPSILON * (1.0 + swept)).min(f64::MAX);
    let amplification = 2f64.powi(order as i32);
    let recent = differences(runs.coarse, &runs.fine);
    let (earlier, predicted_ratio) = match runs.half {
        HalfRun::Ran(half) if half.steps > 0 => {
            let refinement = runs.coarse.steps as f64 / half.steps as f64;
            let ratio = (refinement.powi(order as i32) - 1.0) / (1.0 - 1.0 / amplification);
            (differences(half, runs.coarse), Some(ratio))
        }
        // No third run: d₁ is taken as its asymptotic value, so the rule below gives about 3d₂.
        _ => (recent.map(|d| d * amplification), None),
    };
    let phase_lost =
        matches!(runs.half, HalfRun::Failed) || recent.iter().chain(earlier.iter()).any(|&d| d > UNRESOLVED);
    let [attitude_error, omega_error] = if phase_lost {
        [std::f64::consts::PI, largest_omega_error(&runs.fine, moments, omega0)]
    } else {
        // The run is in its asymptotic range only if the attitude and ω both converge at the
        // method's order: one ratio near ρ by coincidence (long steps) is not evidence.
        let asymptotic = predicted_ratio.is_some_and(|ratio| {
            (0..2).all(|k| earlier[k] >= 0.5 * ratio * recent[k] && earlier[k] <= 2.0 * ratio * recent[k])
        });
        [0, 1].map(|k| {
            if asymptotic {
                recent[k]
            } else {
                2.0 * recent[k] + earlier[k] / (amplification - 1.0)
            }
        })
    };
    LieEstimate {
        solution: runs.fine,
        attitude_error: attitude_error + rounding,
        omega_error: omega_error + rounding,
    }
}

/// The geodesic angle ‖log(R_aᵀR_b)‖ and ‖ω_a − ω_b‖/‖ω_b‖ (absolute for ω_b = 0).
fn differences(a: &LieSolution, b: &LieSolution) -> [f64; 2] {
    let attitude = log_map(&(a.rotation.transpose() * b.rotation)).norm();
    let scale = norm(&b.omega);
    let gap = norm(&(a.omega - b.omega));
    [attitude, if scale > 0.0 { gap / scale } else { gap }]
}

/// 1 + ‖ω‖·I_max/Γ₀ ≥ ‖ω − ω_exact‖/‖ω_exact‖ for any exact motion with Γ₀ = |Iω(0)|.
fn largest_omega_error(fine: &LieSolution, moments: &Vector3<f64>, omega0: &Vector3<f64>) -> f64 {
    // Γ₀/I_max = ‖(I/I_max)∘ω(0)‖, formed without overflow.
    let momentum_per_moment = norm(&(moments / moments.max()).component_mul(omega0));
    if momentum_per_moment > 0.0 {
        (1.0 + norm(&fine.omega) / momentum_per_moment).min(f64::MAX)
    } else {
        f64::MAX
    }
}
