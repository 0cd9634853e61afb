//! A run with contacts: the steps of one integrator checked for contact events, which are
//! located and resolved as they come ([`super`]).

use super::gap::Gap;
use super::locate::{earliest_reopening, first_event, gaps_of, trial};
use super::{ImpactEvent, UnilateralContact, impact};
use crate::error::StepFailure;
use crate::integrator::{Integrator, Point};
use std::sync::Arc;

/// Impacts per contact allowed at one instant (the time not advancing between them) before
/// [`ContactRun::advance_to`] reports sustained contact: a simultaneous impact of several
/// contacts is resolved as one, so a few per contact already mean they repeat.
pub(crate) const STALLED_IMPACTS_PER_CONTACT: usize = 4;

/// The contact state that goes with one integrator.
#[derive(Debug, Clone)]
pub(crate) struct ContactRun {
    contacts: Arc<[UnilateralContact]>,
    /// Open contacts, whose closing is an event (g > 0 at the state reached, or reopened
    /// since their last impact).
    armed: Vec<bool>,
    /// The gaps at the state reached.
    last: Vec<Gap>,
    events: Vec<ImpactEvent>,
    /// H after the last impact, or at t = 0.
    segment_start: f64,
    max_impacts: usize,
}

impl ContactRun {
    /// The contacts of `run` at its initial state, with H there `energy`. A contact closed
    /// there (g ≤ 0) is not armed until it opens.
    pub(crate) fn new(
        contacts: Arc<[UnilateralContact]>,
        run: &Integrator,
        energy: f64,
        max_impacts: usize,
    ) -> Result<Self, StepFailure> {
        let last = gaps_of(run, &contacts)?;
        Ok(Self {
            armed: last.iter().map(|g| g.value > 0.0).collect(),
            last,
            contacts,
            events: Vec::new(),
            segment_start: energy,
            max_impacts,
        })
    }

    /// The impacts so far.
    pub(crate) fn events(&self) -> &[ImpactEvent] {
        &self.events
    }

    /// Integrates `run` to `target` (no step passes it), resolving the impacts on the way,
    /// and gives the state at `target` in the current charts. A failure leaves `run` at the
    /// start of the step that failed.
    ///
    /// Impacts that follow one another at one instant without the time advancing (the
    /// velocities an impact leaves still close a contact at once) end the run, after
    /// [`STALLED_IMPACTS_PER_CONTACT`] per contact, as the sustained contact they amount to.
    pub(crate) fn advance_to(&mut self, run: &mut Integrator, target: f64) -> Result<Point, StepFailure> {
        let mut stalled = 0;
        while run.time() < target {
            let saved = run.clone();
            run.step_toward(target, target)
                .map_err(|failure| self.accumulation(failure))?;
            if let Err(failure) = self.after_step(&saved, run) {
                *run = saved;
                return Err(self.accumulation(failure));
            }
            stalled = if run.time() > saved.time() { 0 } else { stalled + 1 };
            if stalled > STALLED_IMPACTS_PER_CONTACT * self.contacts.len().max(1) {
                return Err(self.accumulation(StepFailure::StepSizeUnderflow { step: 0.0 }));
            }
        }
        run.state_at(target)
    }

    /// Checks the step from `saved` to `run` for events and resolves the first. A closed
    /// contact that may have opened and closed again inside the step cuts the step back to
    /// its peak, where it is armed if open.
    fn after_step(&mut self, saved: &Integrator, run: &mut Integrator) -> Result<(), StepFailure> {
        let mut after = gaps_of(run, &self.contacts)?;
        let h = run.time() - saved.time();
        if let Some(s) = earliest_reopening(&self.last, &after, &self.armed, h) {
            *run = trial(saved, saved.time() + s * h)?;
            after = gaps_of(run, &self.contacts)?;
        }
        match first_event(saved, (&self.last, &after), run, &self.armed, &self.contacts)? {
            Some(event) => {
                *run = event.state;
                self.impact(run, event.tolerance)
            }
            None => self.open_step(after),
        }
    }

    /// A step size at the rounding level of t after impacts is impacts accumulating (flights
    /// shorter than t can resolve): reported as the sustained contact they tend to, at the
    /// contact of the last impact.
    fn accumulation(&self, failure: StepFailure) -> StepFailure {
        let last_contact = self.events.last().and_then(|e| e.contacts.first().copied());
        match (&failure, last_contact) {
            (StepFailure::StepSizeUnderflow { .. }, Some(i)) => StepFailure::SustainedContact {
                contact: i,
                gap: self.last[i].value,
                rate: self.last[i].rate,
            },
            _ => failure,
        }
    }

    /// After a step without event: a closed contact that closes further is sustained contact;
    /// a contact that opened is armed.
    fn open_step(&mut self, after: Vec<Gap>) -> Result<(), StepFailure> {
        for (i, g) in after.iter().enumerate() {
            if !self.armed[i] && g.value <= 0.0 && g.rate < 0.0 {
                return Err(StepFailure::SustainedContact {
                    contact: i,
                    gap: g.value,
                    rate: g.rate,
                });
            }
            self.armed[i] |= g.value > 0.0;
        }
        self.last = after;
        Ok(())
    }

    /// Resolves the impact at the located event reached by `run`: every armed contact closed
    /// to within `tolerance` and closing takes part. None closing: the event was a graze.
    fn impact(&mut self, run: &mut Integrator, tolerance: f64) -> Result<(), StepFailure> {
        let gaps = gaps_of(run, &self.contacts)?;
        let hitting: Vec<usize> = (0..gaps.len())
            .filter(|&i| self.armed[i] && gaps[i].value <= tolerance.max(0.0) && gaps[i].rate < 0.0)
            .collect();
        if hitting.is_empty() {
            self.armed = gaps.iter().map(|g| g.value > 0.0).collect();
            self.last = gaps;
            return Ok(());
        }
        if self.events.len() >= self.max_impacts {
            return Err(StepFailure::TooManyImpacts {
                limit: self.max_impacts,
            });
        }
        let event = impact::resolve(run, &self.contacts, (&hitting, &gaps), self.segment_start)?;
        self.segment_start = event.energy_after;
        self.events.push(event);
        let after = gaps_of(run, &self.contacts)?;
        for (i, g) in after.iter().enumerate() {
            self.armed[i] = !hitting.contains(&i) && g.value > 0.0;
        }
        self.last = after;
        Ok(())
    }
}
