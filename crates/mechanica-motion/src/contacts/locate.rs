//! Locating the first zero of the gaps inside a step (M.22).
//!
//! The gap function is φ(t) = min g_i(t) over the open (armed) contacts. A step from t₀ to t₁
//! has an event when φ(t₁) ≤ 0, or when the cubic Hermite interpolant of some gap (from g and
//! ġ at both ends) dips to ≤ 0 inside the step and the re-integrated state at the dip has
//! φ ≤ 0. The zero is then bracketed by φ(a) > 0 ≥ φ(b) and narrowed by the Illinois variant of
//! regula falsi, each trial state re-integrated from t₀ in one partial step of the method. The
//! search stops when |φ(b)| ≤ [`LOCATION_TOLERANCE`]·max(φ(t₀), |φ(b₀)|) or when the bracket is
//! at the rounding of t; the event is the state at b, so the located penetration is reported
//! and never hidden. A dip that the Hermite interpolant misses (a gap that closes and opens
//! again inside one step by less than the interpolant's error) is not detected.

use super::UnilateralContact;
use super::gap::{Gap, gaps};
use crate::error::StepFailure;
use crate::integrator::Integrator;

/// The relative tolerance on the gap at a located event.
pub const LOCATION_TOLERANCE: f64 = 1e-12;

/// The most Illinois iterations (each halves the bracket or better once it is steady).
const MAX_ITERATIONS: usize = 200;

/// A located event: the state at its time, and the gap level below which a contact counts as
/// closed there.
pub(crate) struct Event {
    pub state: Integrator,
    pub tolerance: f64,
}

/// The gap and rate of every contact at the state reached by `run`.
pub(crate) fn gaps_of(run: &Integrator, contacts: &[UnilateralContact]) -> Result<Vec<Gap>, StepFailure> {
    let point = run.point();
    gaps(run.system().dynamics().tree(), contacts, &point.q, &point.q_dot)
}

/// φ: the smallest gap of the armed contacts (+∞ when none is armed).
fn closest(gaps: &[Gap], armed: &[bool]) -> f64 {
    gaps.iter()
        .zip(armed)
        .filter(|(_, armed)| **armed)
        .map(|(g, _)| g.value)
        .fold(f64::INFINITY, f64::min)
}

/// `saved` advanced to `t` in one partial step (t inside the step that followed `saved`).
pub(crate) fn trial(saved: &Integrator, t: f64) -> Result<Integrator, StepFailure> {
    let mut run = saved.clone();
    run.advance_to(t, t)?;
    Ok(run)
}

/// The first event in the step from `saved` (gaps `before`) to `stepped` (gaps `after`), or
/// `None` (module docs).
pub(crate) fn first_event(
    saved: &Integrator,
    (before, after): (&[Gap], &[Gap]),
    stepped: &Integrator,
    armed: &[bool],
    contacts: &[UnilateralContact],
) -> Result<Option<Event>, StepFailure> {
    let (t0, t1) = (saved.time(), stepped.time());
    let phi0 = closest(before, armed);
    let phi1 = closest(after, armed);
    let end = if phi1 <= 0.0 {
        (t1, phi1, stepped.clone())
    } else {
        let Some(s) = earliest_dip(before, after, armed, t1 - t0) else {
            return Ok(None);
        };
        let t = t0 + s * (t1 - t0);
        let state = trial(saved, t)?;
        let phi = closest(&gaps_of(&state, contacts)?, armed);
        if phi > 0.0 {
            return Ok(None);
        }
        (t, phi, state)
    };
    let tolerance = LOCATION_TOLERANCE * phi0.max(-end.1);
    let state = illinois(saved, (t0, phi0), end, tolerance, (armed, contacts))?;
    Ok(Some(Event { state, tolerance }))
}

/// Narrows the bracket φ(a) > 0 ≥ φ(b) to the tolerance (module docs); gives the state at b.
fn illinois(
    saved: &Integrator,
    (mut a, phi_a): (f64, f64),
    (mut b, mut phi_b, mut state): (f64, f64, Integrator),
    tolerance: f64,
    (armed, contacts): (&[bool], &[UnilateralContact]),
) -> Result<Integrator, StepFailure> {
    let (mut weight_a, mut weight_b) = (phi_a, phi_b);
    let mut last_side = 0;
    for _ in 0..MAX_ITERATIONS {
        if -phi_b <= tolerance || b - a <= 4.0 * f64::EPSILON * b.abs() {
            break;
        }
        let mut t = b - weight_b * (b - a) / (weight_b - weight_a);
        if !(t > a && t < b) {
            t = 0.5 * (a + b);
        }
        let candidate = trial(saved, t)?;
        let phi = closest(&gaps_of(&candidate, contacts)?, armed);
        if phi > 0.0 {
            (a, weight_a) = (t, phi);
            if last_side == 1 {
                weight_b *= 0.5;
            }
            last_side = 1;
        } else {
            (b, phi_b, weight_b, state) = (t, phi, phi, candidate);
            if last_side == -1 {
                weight_a *= 0.5;
            }
            last_side = -1;
        }
    }
    Ok(state)
}

/// The earliest s ∈ (0, 1) at which the cubic Hermite interpolant of an armed contact's gap
/// over a step of length `h` has a minimum ≤ 0, for gaps that close at the start of the step
/// and open at its end.
fn earliest_dip(before: &[Gap], after: &[Gap], armed: &[bool], h: f64) -> Option<f64> {
    before
        .iter()
        .zip(after)
        .zip(armed)
        .filter(|(_, armed)| **armed)
        .filter_map(|((g0, g1), _)| hermite_dip(*g0, *g1, h))
        .reduce(f64::min)
}

/// The minimum of the cubic Hermite gap p(s) on (0, 1) when ġ₀ < 0 < ġ₁ and p there is ≤ 0.
fn hermite_dip(g0: Gap, g1: Gap, h: f64) -> Option<f64> {
    if !(g0.rate < 0.0 && g1.rate > 0.0) {
        return None;
    }
    let (s, p) = hermite_extremum(g0, g1, h);
    (p <= 0.0).then_some(s)
}

/// The maximum of the cubic Hermite gap p(s) on (0, 1) when ġ₀ > 0 > ġ₁.
fn hermite_peak(g0: Gap, g1: Gap, h: f64) -> Option<f64> {
    (g0.rate > 0.0 && g1.rate < 0.0).then(|| hermite_extremum(g0, g1, h).0)
}

/// The extremum (s, p(s)) of the cubic Hermite gap on (0, 1) over a step of length `h`, for
/// end rates of opposite signs: p′ is a quadratic with those signs at 0 and 1, so it changes
/// sign once on (0, 1); its zero is found by bisection.
fn hermite_extremum(g0: Gap, g1: Gap, h: f64) -> (f64, f64) {
    let (d0, d1) = (h * g0.rate, h * g1.rate);
    let slope = |s: f64| {
        (6.0 * s * s - 6.0 * s) * (g0.value - g1.value)
            + (3.0 * s * s - 4.0 * s + 1.0) * d0
            + (3.0 * s * s - 2.0 * s) * d1
    };
    let rising_first = d0 > 0.0;
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if (slope(mid) > 0.0) == rising_first {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let s = 0.5 * (lo + hi);
    let (s2, s3) = (s * s, s * s * s);
    let p = (2.0 * s3 - 3.0 * s2 + 1.0) * g0.value
        + (s3 - 2.0 * s2 + s) * d0
        + (3.0 * s2 - 2.0 * s3) * g1.value
        + (s3 - s2) * d1;
    (s, p)
}

/// The earliest s ∈ (0, 1) at which a closed contact (not armed) that was opening at the start
/// of a step of length `h` and is closed and closing at its end peaks on its cubic Hermite
/// gap: it may have opened and closed again inside the step.
pub(crate) fn earliest_reopening(before: &[Gap], after: &[Gap], armed: &[bool], h: f64) -> Option<f64> {
    before
        .iter()
        .zip(after)
        .zip(armed)
        .filter(|((_, g1), armed)| !**armed && g1.value <= 0.0)
        .filter_map(|((g0, g1), _)| hermite_peak(*g0, *g1, h))
        .reduce(f64::min)
}
