//! The torque-free rigid body (Euler–Poinsot): Euler's equations, the exact solution in
//! Jacobi's elliptic functions, and the special functions it needs, written here from the
//! formulas of DLMF §19 and §22 and Carlson (1995). docs/theory.md, "The torque-free rigid body
//! (Euler–Poinsot)", states the mathematics and the measured accuracy.
//!
//! - [`euler`]: the right-hand sides of Euler's equations (7.41) with a torque and of the
//!   attitude kinematics Ṙ = R[ω]×, for integrators.
//! - [`exact`]: [`TorqueFreeBody`], ω(t) and R(t) in closed form for any principal moments and
//!   initial state, as the reference that integrators are judged by.
//! - [`lie_group`]: [`LieIntegrator`], Lie-group integrators of (R, ω) that keep R on SO(3):
//!   RKMK of order 4 and a Lie–Poisson splitting into rotations about the principal axes,
//!   composed to order 4, 6 or 8 ([`splitting`]), with error estimates ([`estimate`]).
//! - [`carlson`], [`elliptic`], [`jacobi`]: R_F, R_D, R_J, R_C; K, F, Π; sn, cn, dn, am.

pub mod carlson;
mod double_double;
pub mod elliptic;
pub mod estimate;
pub mod euler;
pub mod exact;
pub mod jacobi;
pub mod lie_group;
mod rkmk;
pub mod splitting;

pub use carlson::{carlson_rc, carlson_rd, carlson_rf, carlson_rj};
pub use elliptic::{EllipticModulus, elliptic_f, elliptic_k, elliptic_pi, elliptic_pi_complete};
pub use euler::{attitude_rate, euler_rates};
pub use exact::{Regime, TorqueFreeBody};
pub use jacobi::{JacobiValues, jacobi_amplitude, jacobi_elliptic};
pub use lie_group::{LieEstimate, LieIntegrator, LieMethod, LieSolution, MAX_LIE_STEPS, STALLED_DOUBLINGS};
