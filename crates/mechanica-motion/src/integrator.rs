//! One integration of the equations of motion: a method, a copy of the system whose charts
//! move with the motion, and the state reached. [`Integrator::advance_to`] integrates to a
//! given time and gives the state there; a failed step leaves the last good state in place.

use crate::chart::{ReportingChart, recentre};
use crate::dopri::DormandPrince;
use crate::error::StepFailure;
use crate::method::Method;
use crate::monitors::Tracker;
use crate::rk4::Rk4;
use crate::system::System;

/// The stepping part of a method.
#[derive(Debug, Clone)]
enum Engine {
    Rk4(Box<Rk4>, f64),
    Verlet(f64),
    Midpoint(f64),
    /// The largest step and the multipliers of the last step (the next step's first guess).
    Rattle(f64, Vec<f64>),
    Adaptive(Box<DormandPrince>),
}

/// A state (t, q, q̇) in the integrator's current charts.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Point {
    pub t: f64,
    pub q: Vec<f64>,
    pub q_dot: Vec<f64>,
}

/// One run of one method (module docs).
#[derive(Debug, Clone)]
pub(crate) struct Integrator {
    system: System,
    chart: ReportingChart,
    engine: Engine,
    t: f64,
    /// y = (q, q̇), 2n entries, in the current charts.
    y: Vec<f64>,
    steps: usize,
    max_steps: usize,
    /// The monitors, updated after every step when present.
    tracker: Option<Tracker>,
}

impl Integrator {
    /// An integration of `system` by `method` (validated) from (q₀, q̇₀) at t = 0.
    pub(crate) fn new(system: System, method: Method, q0: &[f64], q_dot0: &[f64], max_steps: usize) -> Self {
        let n = system.dof();
        let engine = match method {
            Method::Rk4 { step } => Engine::Rk4(Box::new(Rk4::new(n)), step),
            Method::StormerVerlet { step } => Engine::Verlet(step),
            Method::ImplicitMidpoint { step } => Engine::Midpoint(step),
            Method::Rattle { step } => Engine::Rattle(step, vec![0.0; system.constraints_equations()]),
            Method::DormandPrince { rtol, atol } => Engine::Adaptive(Box::new(DormandPrince::new(n, rtol, atol))),
        };
        let chart = ReportingChart::of(system.dynamics().tree());
        Self {
            system,
            chart,
            engine,
            t: 0.0,
            y: [q0, q_dot0].concat(),
            steps: 0,
            max_steps,
            tracker: None,
        }
    }

    /// Follows the monitors after every step from now on.
    pub(crate) fn set_tracker(&mut self, tracker: Tracker) {
        self.tracker = Some(tracker);
    }

    /// The monitors, when followed.
    pub(crate) fn tracker(&self) -> Option<&Tracker> {
        self.tracker.as_ref()
    }

    /// The monitors, when followed, for recording.
    pub(crate) fn tracker_mut(&mut self) -> Option<&mut Tracker> {
        self.tracker.as_mut()
    }

    /// Records H, T₂ and the momenta of the state reached in the monitors.
    fn monitor_step(&mut self) -> Result<(), StepFailure> {
        if self.tracker.is_none() {
            return Ok(());
        }
        let point = self.point();
        let measurement = self.system.measure(&point.q, &point.q_dot)?;
        if let Some(tracker) = &mut self.tracker {
            tracker.record(&measurement);
        }
        Ok(())
    }

    /// Sets the most steps of the run, counted from t = 0 (the steps taken so far included).
    pub(crate) fn set_max_steps(&mut self, max_steps: usize) {
        self.max_steps = max_steps;
    }

    /// Steps taken so far (accepted steps for the adaptive method).
    pub(crate) fn steps(&self) -> usize {
        self.steps
    }

    /// The system with its current charts.
    pub(crate) fn system(&self) -> &System {
        &self.system
    }

    /// The system with its current charts, for evaluation.
    pub(crate) fn system_mut(&mut self) -> &mut System {
        &mut self.system
    }

    /// The state reached, in the current charts.
    pub(crate) fn point(&self) -> Point {
        let n = self.y.len() / 2;
        Point {
            t: self.t,
            q: self.y[..n].to_vec(),
            q_dot: self.y[n..].to_vec(),
        }
    }

    /// `point` (in the current charts) rewritten in the reporting chart ([`crate::chart`]).
    pub(crate) fn report(&self, point: &Point) -> Result<Point, StepFailure> {
        let mut reported = point.clone();
        if !self.chart.is_trivial() {
            self.chart
                .report(self.system.dynamics().tree(), &mut reported.q, &mut reported.q_dot)?;
        }
        Ok(reported)
    }

    /// Re-centres the charts at the current state and counts the step to come.
    fn prepare_step(&mut self) -> Result<(), StepFailure> {
        if self.steps >= self.max_steps {
            return Err(StepFailure::TooManySteps { limit: self.max_steps });
        }
        self.steps += 1;
        if self.chart.is_trivial() {
            return Ok(());
        }
        let n = self.y.len() / 2;
        let (q, v) = self.y.split_at_mut(n);
        recentre(&mut self.system, q, v)?;
        if let Engine::Adaptive(dopri) = &mut self.engine {
            dopri.invalidate();
        }
        Ok(())
    }

    /// Integrates to `target` (≥ the time reached; adaptive steps never pass `horizon` ≥
    /// `target`) and gives the state at `target` in the current charts. Fixed-step methods
    /// divide [t, target] into equal steps no longer than their step.
    pub(crate) fn advance_to(&mut self, target: f64, horizon: f64) -> Result<Point, StepFailure> {
        while self.t < target {
            self.step_toward(target, horizon)?;
        }
        self.state_at(target)
    }

    /// The time reached by the last step (past the last target for the adaptive method, whose
    /// steps run to the horizon).
    pub(crate) fn time(&self) -> f64 {
        self.t
    }

    /// Takes one step from the time reached towards `target` (> the time reached): for the
    /// fixed-step methods the next of the equal steps no longer than their step that divide
    /// [t, target], ending exactly at `target` on the last; for the adaptive method one
    /// accepted step, which may pass `target` but not `horizon` ≥ `target`.
    pub(crate) fn step_toward(&mut self, target: f64, horizon: f64) -> Result<(), StepFailure> {
        let largest = match self.engine {
            Engine::Rk4(_, h) | Engine::Verlet(h) | Engine::Midpoint(h) | Engine::Rattle(h, _) => h,
            Engine::Adaptive(_) => return self.adaptive_step(target, horizon),
        };
        let remaining = target - self.t;
        let count = (remaining / largest * (1.0 - 1e-12)).ceil().max(1.0);
        let h = remaining / count;
        let n = self.y.len() / 2;
        self.prepare_step()?;
        let mut q_new = self.y[..n].to_vec();
        let mut v_new = self.y[n..].to_vec();
        self.fixed_step(&mut q_new, &mut v_new, h)?;
        self.y[..n].copy_from_slice(&q_new);
        self.y[n..].copy_from_slice(&v_new);
        self.t = if count <= 1.0 { target } else { self.t + h };
        self.monitor_step()
    }

    /// Replaces the velocities of the state reached by `q_dot` (the same charts), as an impact
    /// does; the adaptive method's first stage is recomputed.
    pub(crate) fn jump_velocity(&mut self, q_dot: &[f64]) {
        let n = self.y.len() / 2;
        self.y[n..].copy_from_slice(q_dot);
        if let Engine::Adaptive(dopri) = &mut self.engine {
            dopri.invalidate();
        }
    }

    /// One step of a fixed-step method from the state reached, into (q, q̇), followed by the
    /// projection onto the constraints (M.19) for every method but RATTLE.
    /// A system without coordinates has nothing to move (and no Newton matrix to factor).
    fn fixed_step(&mut self, q: &mut [f64], v: &mut [f64], h: f64) -> Result<(), StepFailure> {
        if q.is_empty() {
            return Ok(());
        }
        let system = &mut self.system;
        match &mut self.engine {
            Engine::Rk4(rk4, _) => rk4.step(system, self.t, q, v, h)?,
            Engine::Verlet(_) => crate::verlet::step(system, self.t, q, v, h)?,
            Engine::Midpoint(_) => crate::midpoint::step(system, self.t, q, v, h)?,
            Engine::Rattle(_, lambda) => return crate::rattle::step(system, self.t, (q, v), h, lambda),
            Engine::Adaptive(_) => {}
        }
        crate::projection::project(system, q, v)
    }

    /// One accepted Dormand–Prince step not passing `horizon.max(target)`.
    fn adaptive_step(&mut self, target: f64, horizon: f64) -> Result<(), StepFailure> {
        self.prepare_step()?;
        let Engine::Adaptive(dopri) = &mut self.engine else {
            return Ok(());
        };
        let mut y = self.y.clone();
        let mut t = self.t;
        dopri.step(&mut self.system, &mut t, &mut y, horizon.max(target))?;
        if self.system.is_constrained() {
            let n = y.len() / 2;
            let (q, v) = y.split_at_mut(n);
            crate::projection::project(&mut self.system, q, v)?;
            dopri.invalidate();
        }
        self.y = y;
        self.t = t;
        self.monitor_step()
    }

    /// The state at `target`, in the current charts: the state reached when the last step
    /// ended there, else (adaptive method, `target` inside the last step) its dense output
    /// projected onto the constraints.
    pub(crate) fn state_at(&mut self, target: f64) -> Result<Point, StepFailure> {
        if self.t == target {
            return Ok(self.point());
        }
        let mut y = vec![0.0; self.y.len()];
        if let Engine::Adaptive(dopri) = &self.engine {
            dopri.interpolate(target, &mut y);
        }
        crate::error::check_finite(&y, "interpolated state")?;
        let n = y.len() / 2;
        let (q, v) = y.split_at_mut(n);
        crate::projection::project(&mut self.system, q, v)?;
        Ok(Point {
            t: target,
            q: y[..n].to_vec(),
            q_dot: y[n..].to_vec(),
        })
    }
}
