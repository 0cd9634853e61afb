//! [`Simulation`]: the public entry point. A run integrates from (q₀, q̇₀) at t = 0 with the
//! chosen [`Method`], alongside a companion run that gives the global error estimate (M.13),
//! and records samples at a fixed output interval with the monitors of [`crate::monitors`].
//! [`Stepper`] is the same step by step (advance to a time, read the state).

use crate::contacts::run::ContactRun;
use crate::contacts::{ImpactEvent, UnilateralContact};
use crate::error::{MotionError, StepFailure, check_vector};
use crate::estimate::{ErrorEstimate, estimate};
use crate::forcing::Forcing;
use crate::integrator::Integrator;
use crate::integrator::Point;
use crate::method::Method;
use crate::monitors::{Invariant, Measurement, Monitors, Tracker};
use crate::system::System;
use mechanica_dynamics::{ConstrainedDynamics, Constraint, Dynamics};
use std::sync::Arc;

/// The most samples a run records: (t_end / output_interval) + 1 must not exceed it.
pub const MAX_SAMPLES: usize = 1_000_000;

/// The default limit of steps per run (each of the main and the companion run).
pub const DEFAULT_MAX_STEPS: usize = 100_000_000;

/// The default limit of impacts per run (each of the main and the companion run).
pub const DEFAULT_MAX_IMPACTS: usize = 100_000;

/// Options of a simulation.
#[derive(Debug, Clone)]
pub struct Options {
    /// The applied generalized forces τ.
    pub forcing: Forcing,
    /// Coordinates whose momenta p_k = (A q̇)_k are monitored (cyclic coordinates).
    pub cyclic: Vec<usize>,
    /// Run the companion and report global error estimates (doubles the cost or more).
    pub estimate_error: bool,
    /// The most steps of each run; more fail with [`StepFailure::TooManySteps`].
    pub max_steps: usize,
    /// The most impacts of each run with contacts; more fail with
    /// [`StepFailure::TooManyImpacts`].
    pub max_impacts: usize,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            forcing: Forcing::None,
            cyclic: Vec::new(),
            estimate_error: true,
            max_steps: DEFAULT_MAX_STEPS,
            max_impacts: DEFAULT_MAX_IMPACTS,
        }
    }
}

/// One recorded state. q and q̇ are in the reporting chart ([`crate::chart`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// Time, s.
    pub t: f64,
    /// Coordinates q.
    pub q: Vec<f64>,
    /// Velocities q̇.
    pub q_dot: Vec<f64>,
    /// H = T₂ + U* − τ_c·q (M.1), J: the energy, or the Jacobi integral in a rotating frame.
    pub energy: f64,
    /// The global error estimate (M.13), when the companion runs.
    pub error: Option<ErrorEstimate>,
}

/// The result of [`Simulation::run`].
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory {
    /// Samples at t = 0, Δ, 2Δ, … and t_end.
    pub samples: Vec<Sample>,
    /// The monitors over the samples.
    pub monitors: Monitors,
    /// Steps of the main run.
    pub steps: usize,
    /// Steps of the companion run (0 without it).
    pub companion_steps: usize,
    /// The impacts of the main run, in time order (empty without contacts).
    pub impacts: Vec<ImpactEvent>,
}

/// A mechanism's dynamics (with holonomic constraints or without) with a method and options,
/// ready to integrate.
#[derive(Debug, Clone)]
pub struct Simulation {
    dynamics: ConstrainedDynamics,
    method: Method,
    options: Options,
    contacts: Arc<[UnilateralContact]>,
}

impl Simulation {
    /// Checks the method's parameters, a constant τ's length and the cyclic coordinates.
    pub fn new(dynamics: Dynamics, method: Method, options: Options) -> Result<Self, MotionError> {
        Self::constrained(ConstrainedDynamics::new(dynamics), method, options)
    }

    /// A simulation of a mechanism with holonomic constraints f(q) = 0 (the constraints of
    /// `dynamics`, with its dampers and loads). [`Method::Rattle`] keeps the constraints by
    /// multipliers (M.17); the other methods integrate the index-1 equations (M.18) and
    /// project onto f = 0 and J q̇ = 0 after every step (M.19). Either way the monitors report
    /// the drift max ‖f(q)‖₂ and max ‖J q̇‖₂ (M.20). The initial state should satisfy the
    /// constraints; the first step moves it onto them, and the monitors include its drift.
    ///
    /// Checks as [`Simulation::new`], and refuses a coordinate constraint on a rotation vector
    /// of a spherical or free joint (its chart moves during the run, (M.14)).
    pub fn constrained(dynamics: ConstrainedDynamics, method: Method, options: Options) -> Result<Self, MotionError> {
        method.validate()?;
        let tree = dynamics.dynamics().tree();
        for constraint in dynamics.constraints() {
            if let Constraint::Coordinate { index, .. } = constraint
                && crate::chart::is_rotation_coordinate(tree, *index)
            {
                return Err(MotionError::NoSuchCoordinate {
                    what: "coordinate constraint on a rotation vector (charts move during a run)",
                    index: *index,
                    dof: tree.dof(),
                });
            }
        }
        let n = dynamics.dof();
        options.forcing.validate(n)?;
        if let Some(&index) = options.cyclic.iter().find(|&&k| k >= n) {
            return Err(MotionError::NoSuchCoordinate {
                what: "cyclic coordinate",
                index,
                dof: n,
            });
        }
        Ok(Self {
            dynamics,
            method,
            options,
            contacts: Arc::new([]),
        })
    }

    /// The same simulation with unilateral contacts (replacing any given before): every
    /// closing of a gap is located and resolved as an impact ([`crate::contacts`],
    /// (M.21)–(M.23)). Fails with [`MotionError::InvalidContact`] for a contact that names a
    /// missing body, has a non-unit normal, a non-finite point or offset or an invalid law,
    /// and for a mechanism with holonomic constraints, a rotating frame or a prescribed base
    /// motion. Without contacts a run takes exactly the steps it takes without this call.
    pub fn with_contacts(mut self, contacts: Vec<UnilateralContact>) -> Result<Self, MotionError> {
        crate::contacts::validate(&contacts, &self.dynamics)?;
        self.contacts = contacts.into();
        Ok(self)
    }

    /// The method.
    pub fn method(&self) -> Method {
        self.method
    }

    /// Starts a step-by-step integration from (q₀, q̇₀) at t = 0 (given in the mechanism's
    /// charts). Fails when the initial state is not finite or the dynamics cannot be
    /// evaluated there.
    pub fn start(&self, q0: &[f64], q_dot0: &[f64]) -> Result<Stepper, MotionError> {
        Stepper::new(self, q0, q_dot0)
    }

    /// Integrates from (q₀, q̇₀) at t = 0 to `t_end` (> 0) and records samples every
    /// `output_interval` (> 0) and at t_end. Refuses more than [`MAX_SAMPLES`] samples. A
    /// failed step stops the run with [`MotionError::StepFailed`].
    pub fn run(&self, q0: &[f64], q_dot0: &[f64], t_end: f64, output_interval: f64) -> Result<Trajectory, MotionError> {
        self.run_observed(q0, q_dot0, t_end, output_interval, &mut |_| ())
    }

    /// [`Simulation::run`], calling `observe` with each sample as it is recorded (for progress
    /// reports).
    pub fn run_observed(
        &self,
        q0: &[f64],
        q_dot0: &[f64],
        t_end: f64,
        output_interval: f64,
        observe: &mut dyn FnMut(&Sample),
    ) -> Result<Trajectory, MotionError> {
        positive(t_end, "t_end")?;
        positive(output_interval, "output interval")?;
        let requested = (t_end / output_interval).ceil() + 1.0;
        if requested.is_nan() || requested > MAX_SAMPLES as f64 {
            return Err(MotionError::TooManySamples {
                requested,
                limit: MAX_SAMPLES,
            });
        }
        let count = requested as usize;
        let mut stepper = self.start(q0, q_dot0)?;
        stepper.horizon = t_end;
        let mut samples = Vec::with_capacity(count);
        samples.push(stepper.sample().clone());
        observe(stepper.sample());
        for i in 1..count {
            let t = (i as f64 * output_interval).min(t_end);
            let sample = stepper.advance(t)?;
            observe(sample);
            samples.push(sample.clone());
        }
        Ok(Trajectory {
            samples,
            monitors: stepper.monitors(),
            steps: stepper.main.steps(),
            companion_steps: stepper.companion.as_ref().map_or(0, |c| c.steps()),
            impacts: stepper.impacts().to_vec(),
        })
    }
}

fn positive(value: f64, what: &'static str) -> Result<(), MotionError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(MotionError::OutOfRange {
            what,
            requirement: "> 0 and finite",
            value,
        })
    }
}

/// A step-by-step integration (see [`Simulation::start`]).
#[derive(Debug, Clone)]
pub struct Stepper {
    main: Integrator,
    companion: Option<Integrator>,
    /// The contact states of the main and the companion run (when there are contacts).
    main_contacts: Option<ContactRun>,
    companion_contacts: Option<ContactRun>,
    ratio: f64,
    sample: Sample,
    /// Adaptive steps do not pass this time (the end of a run; the target of each advance
    /// when infinite).
    horizon: f64,
}

impl Stepper {
    fn new(simulation: &Simulation, q0: &[f64], q_dot0: &[f64]) -> Result<Self, MotionError> {
        let n = simulation.dynamics.dof();
        check_vector(q0, n, "q0")?;
        check_vector(q_dot0, n, "q_dot0")?;
        let options = &simulation.options;
        let system = System::new(simulation.dynamics.clone(), options.forcing.clone());
        let mut main = Integrator::new(system.clone(), simulation.method, q0, q_dot0, options.max_steps);
        let companion = options
            .estimate_error
            .then(|| Integrator::new(system, simulation.method.companion(), q0, q_dot0, options.max_steps));
        let invariant = match simulation.dynamics.dynamics().mechanism().rotating_frame() {
            Some(_) => Invariant::JacobiIntegral,
            None => Invariant::Energy,
        };
        let point = main.point();
        let fail = |cause: StepFailure| MotionError::StepFailed {
            t: 0.0,
            q: q0.to_vec(),
            q_dot: q_dot0.to_vec(),
            cause,
        };
        let mut probe = vec![0.0; n];
        main.system_mut()
            .acceleration(0.0, q0, q_dot0, &mut probe)
            .map_err(fail)?;
        let start = main.system_mut().measure(q0, q_dot0).map_err(fail)?;
        let energy = start.energy;
        main.set_tracker(Tracker::new(invariant, &start, &options.cyclic));
        let contact_run = |run: &Integrator| -> Result<Option<ContactRun>, MotionError> {
            if simulation.contacts.is_empty() {
                return Ok(None);
            }
            let contacts = simulation.contacts.clone();
            ContactRun::new(contacts, run, energy, options.max_impacts)
                .map(Some)
                .map_err(fail)
        };
        let main_contacts = contact_run(&main)?;
        let companion_contacts = match &companion {
            Some(c) => contact_run(c)?,
            None => None,
        };
        let sample = Sample {
            t: 0.0,
            q: q0.to_vec(),
            q_dot: q_dot0.to_vec(),
            energy,
            error: companion.as_ref().map(|_| estimate(&point, &point, 0.0, 0)),
        };
        Ok(Self {
            main,
            companion,
            main_contacts,
            companion_contacts,
            ratio: simulation.method.companion_ratio(),
            sample,
            horizon: f64::INFINITY,
        })
    }

    /// The last recorded sample.
    pub fn sample(&self) -> &Sample {
        &self.sample
    }

    /// The monitors over every step and sample so far.
    pub fn monitors(&self) -> Monitors {
        // The tracker is set when the stepper starts; the fallback is never used.
        self.main.tracker().map_or_else(
            || Tracker::new(Invariant::Energy, &Measurement::nothing(), &[]).monitors(),
            Tracker::monitors,
        )
    }

    /// The impacts of the main run so far, in time order (empty without contacts).
    pub fn impacts(&self) -> &[ImpactEvent] {
        self.main_contacts.as_ref().map_or(&[], ContactRun::events)
    }

    /// Steps of the main run so far.
    pub fn steps(&self) -> usize {
        self.main.steps()
    }

    /// Sets the most steps of each run (the main run and the companion), counted from t = 0
    /// with the steps already taken, in place of [`Options::max_steps`]: an advance that
    /// needs more fails with [`StepFailure::TooManySteps`] and leaves the stepper at its last
    /// good state, so the limit bounds the work of every later advance whatever its target.
    pub fn set_max_steps(&mut self, max_steps: usize) {
        self.main.set_max_steps(max_steps);
        if let Some(companion) = &mut self.companion {
            companion.set_max_steps(max_steps);
        }
    }

    /// Integrates to `t` (finite, ≥ the time of the last sample) and records the sample there.
    /// A failed step gives [`MotionError::StepFailed`] with the last good state of the main
    /// run; the stepper then stays at that state (a later advance retries from it).
    pub fn advance(&mut self, t: f64) -> Result<&Sample, MotionError> {
        if !t.is_finite() || t < self.sample.t {
            return Err(MotionError::OutOfRange {
                what: "target time",
                requirement: "finite and ≥ the time reached",
                value: t,
            });
        }
        let horizon = if self.horizon.is_finite() { self.horizon } else { t };
        let point = advance(&mut self.main, self.main_contacts.as_mut(), t, horizon);
        let point = point.map_err(|c| failure(&self.main, c))?;
        let reported = self.main.report(&point).map_err(|c| failure(&self.main, c))?;
        let error = match &mut self.companion {
            Some(companion) => {
                let other = advance(companion, self.companion_contacts.as_mut(), t, horizon);
                let other = other.map_err(|c| failure(&self.main, c))?;
                let other = companion.report(&other).map_err(|c| failure(&self.main, c))?;
                Some(estimate(&reported, &other, self.ratio, self.main.steps()))
            }
            None => None,
        };
        let measured = self.main.system_mut().measure(&point.q, &point.q_dot);
        let measurement = measured.map_err(|c| failure(&self.main, c))?;
        if let Some(tracker) = self.main.tracker_mut() {
            tracker.record(&measurement);
        }
        let energy = measurement.energy;
        self.sample = Sample {
            t,
            q: reported.q,
            q_dot: reported.q_dot,
            energy,
            error,
        };
        Ok(&self.sample)
    }
}

/// `run` integrated to `t` (adaptive steps not passing `horizon`), through its contacts'
/// impacts when it has contacts (whose steps then never pass `t`).
fn advance(
    run: &mut Integrator,
    contacts: Option<&mut ContactRun>,
    t: f64,
    horizon: f64,
) -> Result<Point, StepFailure> {
    match contacts {
        Some(contacts) => contacts.advance_to(run, t),
        None => run.advance_to(t, horizon),
    }
}

/// The typed error of a failed step, with the main run's last good state.
fn failure(main: &Integrator, cause: StepFailure) -> MotionError {
    let point = main.point();
    let reported = main.report(&point).unwrap_or(point);
    MotionError::StepFailed {
        t: reported.t,
        q: reported.q,
        q_dot: reported.q_dot,
        cause,
    }
}
