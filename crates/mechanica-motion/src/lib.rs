//! Integration of the equations of motion of a mechanism in time (docs/theory.md,
//! "Integration in time", (M.1)–(M.14)), on the forward dynamics of `mechanica-dynamics`.
//!
//! - [`Simulation`]: a [`mechanica_dynamics::Dynamics`] with a [`Method`] and [`Options`]
//!   (applied forces [`Forcing`], cyclic coordinates, error estimation). [`Simulation::run`]
//!   records samples (t, q, q̇, H, estimated error) at a fixed interval; [`Stepper`] advances
//!   step by step.
//! - Methods ([`Method`]): explicit RK4 (M.3); Dormand–Prince 5(4) with PI control and dense
//!   output (M.4)–(M.7); Störmer–Verlet in (q, p = A q̇) (M.8)–(M.9); the implicit midpoint
//!   rule with Newton (M.10)–(M.11). Rotation-vector charts are re-centred before every step
//!   ([`chart`], (M.14)).
//! - Global error: a companion run at half the step (tolerances / 32) and the bound
//!   e ≤ ‖y − y_c‖ / (1 − ρ) (M.12)–(M.13) ([`ErrorEstimate`]).
//! - Monitors: drift of the energy or Jacobi integral (M.1)–(M.2), momenta of cyclic
//!   coordinates (9.3), and the linear and angular momentum of the whole mechanism
//!   (M.15)–(M.16) ([`Monitors`], [`system_momentum`]).
//! - Unilateral contacts ([`contacts`], (M.21)–(M.23)): [`Simulation::with_contacts`] locates
//!   each closing of a gap, resolves the impact with `mechanica-impulse`, and reports every
//!   impact's energy loss beside the integrator's drift over the free motion before it
//!   ([`ImpactEvent`]).
//! - Failures stop the run with [`MotionError::StepFailed`], carrying the time reached and
//!   the last good state.

pub mod chart;
pub mod contacts;
mod dopri;
pub mod error;
pub mod estimate;
pub mod forcing;
mod integrator;
mod iteration;
pub mod method;
mod midpoint;
pub mod momentum;
pub mod monitors;
mod projection;
pub mod rattle;
mod rk4;
pub mod simulation;
mod system;
mod verlet;

pub use contacts::{ImpactEvent, UnilateralContact};
pub use error::{MotionError, StepFailure};
pub use estimate::ErrorEstimate;
pub use forcing::{ForceFunction, Forcing};
pub use method::{MIN_RTOL, Method};
pub use momentum::{SystemMomentum, system_momentum};
pub use monitors::{ConstraintMonitor, CyclicMomentum, Invariant, MomentumDrift, Monitors};
pub use simulation::{DEFAULT_MAX_STEPS, MAX_SAMPLES, Options, Sample, Simulation, Stepper, Trajectory};
