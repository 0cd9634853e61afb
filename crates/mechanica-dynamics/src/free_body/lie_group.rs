//! Lie-group integrators of the torque-free rigid body: the attitude R ∈ SO(3) (body → space,
//! Ṙ = R[ω]× (7.24)) and the body-frame angular velocity ω in principal axes (Euler's equations
//! (7.41) with M = 0), advanced so that R stays a rotation to rounding without renormalisation.
//!
//! - [`LieMethod::Rkmk4`]: Runge–Kutta–Munthe-Kaas of order 4.
//! - [`LieMethod::Splitting2`], [`LieMethod::Splitting4`], [`LieMethod::Splitting6`],
//!   [`LieMethod::Splitting8`]: the Lie–Poisson splitting into three rotations about the
//!   principal axes ([`super::splitting`]), symmetric (order 2) and composed to order 4, 6, 8.
//!   Each sub-step is an exact rotation, so |L| = |Iω| is conserved to rounding and the method
//!   is symplectic on the momentum sphere.
//!
//! [`LieIntegrator::integrate_with_estimate`] runs the method with ⌊n/2⌋, n and 2n steps and
//! reports the finest run with an error estimate formed from the three ([`super::estimate`]).

use nalgebra::{Matrix3, Rotation3, Vector3};

use super::estimate::{HalfRun, Runs, estimate};
use super::rkmk::rkmk4_step;
use super::splitting::{
    COMPOSITION_4, COMPOSITION_6, COMPOSITION_8, MomentumInvariants, composition_weights, flow_sequence, splitting_step,
};
use crate::error::{DynamicsError, check_input, check_result};

/// The most steps one integration may take (2³⁰); the estimate's companion run counts double.
pub const MAX_LIE_STEPS: u64 = 1 << 30;

/// Doublings in a row over which an estimate that falls by less than half ends
/// [`LieIntegrator::integrate_to_tolerance`] as not converging.
pub const STALLED_DOUBLINGS: usize = 4;

/// The largest ‖RᵀR − I‖ (max entry) accepted for an initial attitude.
pub const ROTATION_TOLERANCE: f64 = 1e-12;

/// A Lie-group method for the free rigid body.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LieMethod {
    /// Runge–Kutta–Munthe-Kaas with the classical RK4 tableau, order 4.
    Rkmk4,
    /// The symmetric splitting Φ₁(h/2) Φ₂(h/2) Φ₃(h) Φ₂(h/2) Φ₁(h/2), order 2.
    Splitting2,
    /// The splitting composed by the triple jump, order 4.
    Splitting4,
    /// The splitting composed with Yoshida's 7 weights, order 6.
    Splitting6,
    /// The splitting composed with Yoshida's 15 weights, order 8.
    Splitting8,
}

impl LieMethod {
    /// The order p of the method: the global error is O(hᵖ) over a fixed time.
    pub fn order(self) -> u32 {
        match self {
            LieMethod::Splitting2 => 2,
            LieMethod::Rkmk4 | LieMethod::Splitting4 => 4,
            LieMethod::Splitting6 => 6,
            LieMethod::Splitting8 => 8,
        }
    }

    /// Every method, in order of increasing cost per step.
    pub const ALL: [LieMethod; 5] = [
        LieMethod::Splitting2,
        LieMethod::Rkmk4,
        LieMethod::Splitting4,
        LieMethod::Splitting6,
        LieMethod::Splitting8,
    ];
}

/// The state after an integration.
#[derive(Debug, Clone, PartialEq)]
pub struct LieSolution {
    /// The attitude R (body → space).
    pub rotation: Rotation3<f64>,
    /// The body-frame angular velocity ω (rad/s).
    pub omega: Vector3<f64>,
    /// The number of steps taken.
    pub steps: u64,
}

/// A solution with its error estimate.
#[derive(Debug, Clone, PartialEq)]
pub struct LieEstimate {
    /// The run with 2n steps.
    pub solution: LieSolution,
    /// The estimated geodesic angle ‖log(R_exactᵀ R_2n)‖ (rad), at most π plus the rounding
    /// allowance 2n·ε·(1 + θ), θ the largest angle the body can sweep; see [`super::estimate`]
    /// for how it is formed.
    pub attitude_error: f64,
    /// The estimated ‖ω_2n − ω_exact‖/‖ω_exact‖.
    pub omega_error: f64,
}

/// A free rigid body with a chosen Lie-group method.
///
/// Frames: the body axes are the principal axes in the order of `moments`; ω is body-frame
/// (rad/s); R maps body components to space components, as in [`super::TorqueFreeBody`].
#[derive(Debug, Clone)]
pub struct LieIntegrator {
    moments: Vector3<f64>,
    inverse_moments: Vector3<f64>,
    method: LieMethod,
    /// The splitting's sub-flows (axis, fraction of h); empty for RKMK.
    flows: Vec<(usize, f64)>,
}

impl LieIntegrator {
    /// The integrator for principal `moments` (finite, > 0, and obeying the triangle inequality
    /// I_a ≤ I_b + I_c of a real body).
    ///
    /// Errors: [`DynamicsError::NonFiniteInput`], [`DynamicsError::OutOfRange`] for a moment
    /// ≤ 0 or a largest moment above the sum of the other two.
    pub fn new(moments: Vector3<f64>, method: LieMethod) -> Result<Self, DynamicsError> {
        check_moments(&moments)?;
        let mut order = [0usize, 1, 2];
        order.sort_by(|&a, &b| moments[a].total_cmp(&moments[b]));
        let one_side: &[f64] = match method {
            LieMethod::Rkmk4 | LieMethod::Splitting2 => &[],
            LieMethod::Splitting4 => &COMPOSITION_4,
            LieMethod::Splitting6 => &COMPOSITION_6,
            LieMethod::Splitting8 => &COMPOSITION_8,
        };
        let flows = match method {
            LieMethod::Rkmk4 => Vec::new(),
            _ => flow_sequence(&composition_weights(one_side), order),
        };
        Ok(Self {
            moments,
            inverse_moments: moments.map(|m| 1.0 / m),
            method,
            flows,
        })
    }

    /// The method.
    pub fn method(&self) -> LieMethod {
        self.method
    }

    /// (R, ω) at t = `duration` from (R(0), ω(0)) = (`r0`, `omega0`) with n = ⌈duration/max_step⌉
    /// equal steps (n = 0 for duration = 0; a quotient within 4ε of an integer is taken as that
    /// integer).
    ///
    /// R(t) is a product of exact rotations, so ‖RᵀR − I‖ grows at most like c·n·ε. The global
    /// error is O(hᵖ), p = [`LieMethod::order`]; [`Self::integrate_with_estimate`] estimates it.
    ///
    /// Errors: a non-finite input; [`DynamicsError::OutOfRange`] for a duration < 0, a
    /// max_step ≤ 0, or an `r0` with ‖RᵀR − I‖ above [`ROTATION_TOLERANCE`];
    /// [`DynamicsError::TooManySteps`] when n exceeds [`MAX_LIE_STEPS`];
    /// [`DynamicsError::NonFiniteResult`] on overflow.
    pub fn integrate(
        &self,
        r0: &Rotation3<f64>,
        omega0: &Vector3<f64>,
        duration: f64,
        max_step: f64,
    ) -> Result<LieSolution, DynamicsError> {
        let steps = step_count(duration, max_step, 1)?;
        check_state(r0, omega0)?;
        self.run(r0, omega0, duration, steps)
    }

    /// [`Self::integrate`] with 2n steps and its error estimate from the runs with ⌊n/2⌋, n and
    /// 2n steps ([`super::estimate`]): the difference of the last two where the three runs
    /// converge at the method's order (the true error is then that difference divided by about
    /// 2ᵖ − 1); a larger, conservative value where they do not; and the largest possible error
    /// (π for the attitude) where the runs have lost the phase of the motion. Errors: those of
    /// [`Self::integrate`], with the cap applied to 2n.
    pub fn integrate_with_estimate(
        &self,
        r0: &Rotation3<f64>,
        omega0: &Vector3<f64>,
        duration: f64,
        max_step: f64,
    ) -> Result<LieEstimate, DynamicsError> {
        let steps = step_count(duration, max_step, 2)?;
        check_state(r0, omega0)?;
        let half = self.half_run(r0, omega0, duration, steps);
        let coarse = self.run(r0, omega0, duration, steps)?;
        let fine = self.run(r0, omega0, duration, 2 * steps)?;
        Ok(self.estimate(half_of(&half), &coarse, fine, omega0, duration))
    }

    /// The runs with n₀, 2n₀, 4n₀, … steps until the estimate of [`Self::integrate_with_estimate`]
    /// is ≤ `tolerance` for both the attitude (rad) and ω (relative); n₀ = ⌈duration/max_step⌉.
    ///
    /// Errors: those of [`Self::integrate`]; [`DynamicsError::OutOfRange`] for a tolerance that
    /// is not > 0; [`DynamicsError::TooManySteps`] when the estimate is still above the
    /// tolerance at [`MAX_LIE_STEPS`]; [`DynamicsError::NotConverged`] when the estimate has
    /// stopped decreasing above the tolerance (it fell by less than half over
    /// [`STALLED_DOUBLINGS`] doublings in a row while the phase was resolved: the rounding
    /// floor of the method on this motion).
    pub fn integrate_to_tolerance(
        &self,
        r0: &Rotation3<f64>,
        omega0: &Vector3<f64>,
        duration: f64,
        max_step: f64,
        tolerance: f64,
    ) -> Result<LieEstimate, DynamicsError> {
        check_input(&[tolerance], "tolerance")?;
        if tolerance <= 0.0 {
            return Err(DynamicsError::OutOfRange {
                what: "tolerance",
                requirement: "> 0",
                value: tolerance,
            });
        }
        let mut steps = step_count(duration, max_step, 2)?;
        check_state(r0, omega0)?;
        let mut half = self.half_run(r0, omega0, duration, steps);
        let mut coarse = self.run(r0, omega0, duration, steps)?;
        let (mut previous, mut stalled, mut doublings) = (f64::INFINITY, 0, 0);
        loop {
            let fine = self.run(r0, omega0, duration, 2 * steps)?;
            let estimate = self.estimate(half_of(&half), &coarse, fine.clone(), omega0, duration);
            let worst = estimate.attitude_error.max(estimate.omega_error);
            if worst <= tolerance {
                return Ok(estimate);
            }
            let resolved = estimate.attitude_error < std::f64::consts::PI;
            stalled = if resolved && worst > 0.5 * previous {
                stalled + 1
            } else {
                0
            };
            if stalled >= STALLED_DOUBLINGS {
                return Err(DynamicsError::NotConverged {
                    what: "free-body integration to the tolerance (the estimate stopped decreasing)",
                    iterations: doublings,
                    residual: worst,
                });
            }
            if 4 * steps > MAX_LIE_STEPS {
                return Err(DynamicsError::TooManySteps {
                    what: "free-body integration to the tolerance",
                    steps: 4.0 * steps as f64,
                    cap: MAX_LIE_STEPS,
                });
            }
            (previous, doublings, steps) = (worst, doublings + 1, 2 * steps);
            half = Some(Ok(coarse));
            coarse = fine;
        }
    }

    /// The run with ⌊n/2⌋ steps for the estimate, when n ≥ 2; its failure is kept, not
    /// returned (see [`HalfRun::Failed`]).
    fn half_run(
        &self,
        r0: &Rotation3<f64>,
        omega0: &Vector3<f64>,
        duration: f64,
        steps: u64,
    ) -> Option<Result<LieSolution, DynamicsError>> {
        (steps >= 2).then(|| self.run(r0, omega0, duration, steps / 2))
    }

    /// The estimate of `fine` from the runs before it.
    fn estimate(
        &self,
        half: HalfRun<'_>,
        coarse: &LieSolution,
        fine: LieSolution,
        omega0: &Vector3<f64>,
        duration: f64,
    ) -> LieEstimate {
        let runs = Runs { half, coarse, fine };
        estimate(runs, self.method.order(), &self.moments, omega0, duration)
    }

    /// `steps` equal steps over `duration` from a validated state.
    fn run(
        &self,
        r0: &Rotation3<f64>,
        omega0: &Vector3<f64>,
        duration: f64,
        steps: u64,
    ) -> Result<LieSolution, DynamicsError> {
        let mut rotation = *r0.matrix();
        let mut omega = *omega0;
        if steps > 0 {
            let h = duration / steps as f64;
            match self.method {
                LieMethod::Rkmk4 => {
                    for _ in 0..steps {
                        rkmk4_step(&self.moments, &mut rotation, &mut omega, h)?;
                    }
                }
                _ => {
                    let mut momentum = self.moments.component_mul(&omega);
                    let invariants = MomentumInvariants::of(&momentum, &self.inverse_moments);
                    for _ in 0..steps {
                        splitting_step(&self.flows, &self.inverse_moments, &mut rotation, &mut momentum, h);
                        invariants.project(&mut momentum, &self.inverse_moments);
                    }
                    omega = momentum.component_mul(&self.inverse_moments);
                }
            }
        }
        check_result(rotation.iter().chain(omega.iter()), "free-body state")?;
        Ok(LieSolution {
            rotation: Rotation3::from_matrix_unchecked(rotation),
            omega,
            steps,
        })
    }
}

/// The half run as the estimate sees it.
fn half_of(half: &Option<Result<LieSolution, DynamicsError>>) -> HalfRun<'_> {
    match half {
        None => HalfRun::Absent,
        Some(Err(_)) => HalfRun::Failed,
        Some(Ok(run)) => HalfRun::Ran(run),
    }
}

/// Finite, positive moments obeying the triangle inequality.
fn check_moments(moments: &Vector3<f64>) -> Result<(), DynamicsError> {
    check_input(moments.as_slice(), "principal moments")?;
    if let Some(&bad) = moments.iter().find(|m| **m <= 0.0) {
        return Err(DynamicsError::OutOfRange {
            what: "principal moment",
            requirement: "> 0",
            value: bad,
        });
    }
    let largest = moments.max();
    let excess = largest - (moments.sum() - largest);
    if excess > 4.0 * f64::EPSILON * largest {
        return Err(DynamicsError::OutOfRange {
            what: "largest principal moment minus the sum of the other two (triangle inequality)",
            requirement: "≤ 0",
            value: excess,
        });
    }
    Ok(())
}

/// A finite ω and a finite R with ‖RᵀR − I‖ ≤ [`ROTATION_TOLERANCE`].
fn check_state(r0: &Rotation3<f64>, omega0: &Vector3<f64>) -> Result<(), DynamicsError> {
    check_input(r0.matrix().as_slice(), "initial attitude R(0)")?;
    check_input(omega0.as_slice(), "initial angular velocity ω(0)")?;
    let defect = (r0.matrix().transpose() * r0.matrix() - Matrix3::identity()).amax();
    // Written so that a NaN (RᵀR of entries near f64::MAX is ∞ − ∞) fails the check.
    let is_rotation = defect <= ROTATION_TOLERANCE && r0.matrix().determinant() > 0.0;
    if !is_rotation {
        return Err(DynamicsError::OutOfRange {
            what: "orthonormality defect ‖RᵀR − I‖ of R(0) (det R(0) > 0)",
            requirement: "≤ 1e-12",
            value: defect,
        });
    }
    Ok(())
}

/// n = ⌈duration/max_step⌉, checked so that `factor`·n ≤ [`MAX_LIE_STEPS`].
fn step_count(duration: f64, max_step: f64, factor: u64) -> Result<u64, DynamicsError> {
    check_input(&[duration], "duration")?;
    check_input(&[max_step], "step")?;
    if duration < 0.0 {
        return Err(DynamicsError::OutOfRange {
            what: "duration",
            requirement: "≥ 0",
            value: duration,
        });
    }
    if max_step <= 0.0 {
        return Err(DynamicsError::OutOfRange {
            what: "step",
            requirement: "> 0",
            value: max_step,
        });
    }
    let quotient = duration / max_step;
    let mut steps = quotient.ceil();
    // A quotient within 4ε of an integer n (duration = n·max_step to rounding) counts n steps.
    if steps >= 1.0 && quotient - (steps - 1.0) <= 4.0 * f64::EPSILON * quotient {
        steps -= 1.0;
    }
    let requested = steps * factor as f64;
    if requested > MAX_LIE_STEPS as f64 {
        return Err(DynamicsError::TooManySteps {
            what: "free-body integration",
            steps: requested,
            cap: MAX_LIE_STEPS,
        });
    }
    Ok(steps as u64)
}
