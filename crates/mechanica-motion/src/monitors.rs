//! Monitors of a run: the drift of the conserved quantity H (M.1)–(M.2), the momenta of
//! coordinates the caller names cyclic (9.3), the linear and angular momentum of the whole
//! mechanism (M.15)–(M.16), and the drift ‖f(q)‖₂, ‖J q̇‖₂ of holonomic constraints (M.20).

use crate::momentum::SystemMomentum;
use nalgebra::Vector3;

/// Which conserved quantity H = T₂ + U* − τ_c·q measures (M.1)–(M.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Invariant {
    /// The energy T + U (fixed or prescribed base).
    Energy,
    /// The Jacobi integral T₂ − T₀ + U of a steadily rotating frame (M.2).
    JacobiIntegral,
}

/// The momentum p_k = (A q̇)_k of a coordinate named cyclic over the run.
#[derive(Debug, Clone, PartialEq)]
pub struct CyclicMomentum {
    /// The coordinate k.
    pub coordinate: usize,
    /// p_k at the start (or just after the last impact of a run with contacts).
    pub initial: f64,
    /// p_k at the last step or sample.
    pub last: f64,
    /// max |p_k − p_k(0)| over the steps and samples (with contacts, p_k(0) restarts after
    /// each impact).
    pub max_drift: f64,
}

/// A momentum vector of the whole mechanism over the run (world components). A component is a
/// first integral only when the external forces have no resultant (P) or no moment about the
/// origin of W (L) along it: a free-floating base (free joint at the root) with no gravity
/// component along the axis for P, or with the axis parallel to gravity (or no gravity) for L;
/// no springs or dampers to the world, no applied generalized forces on the root joint. A fixed
/// base exerts reactions, so there only the components the joints cannot transmit are
/// conserved (L along a root revolute axis parallel to gravity: the cyclic momentum of that
/// joint). The monitor reports every component; which are conserved is the caller's knowledge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MomentumDrift {
    /// The value at the start (or just after the last impact of a run with contacts).
    pub initial: Vector3<f64>,
    /// The value at the last step or sample.
    pub last: Vector3<f64>,
    /// Componentwise max |x − x(0)| over the steps and samples (with contacts, x(0) restarts
    /// after each impact).
    pub max_drift: Vector3<f64>,
    /// The largest |x| (Euclidean) over the steps and samples: the scale of the drift.
    pub scale: f64,
}

impl MomentumDrift {
    fn new(initial: Vector3<f64>) -> Self {
        Self {
            initial,
            last: initial,
            max_drift: Vector3::zeros(),
            scale: initial.norm(),
        }
    }

    fn rebase(&mut self, value: Vector3<f64>) {
        self.initial = value;
    }

    fn record(&mut self, value: Vector3<f64>) {
        self.last = value;
        self.max_drift = self.max_drift.sup(&(value - self.initial).abs());
        self.scale = self.scale.max(value.norm());
    }

    /// max |e·(x − x(0))| bounded by the componentwise drifts: Σ |e_i| max_drift_i, for the unit
    /// axis e (exact when e is a coordinate axis).
    pub fn drift_along(&self, axis: &Vector3<f64>) -> f64 {
        axis.abs().dot(&self.max_drift)
    }
}

/// The drift of the holonomic constraints f(q) = 0 over a run (M.20): ‖f(q)‖₂ and ‖J(q) q̇‖₂
/// (mixed units when the equations mix lengths and angles). Zero for a mechanism without
/// constraints.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ConstraintMonitor {
    /// max ‖f(q)‖₂ over the steps and samples.
    pub max_position: f64,
    /// max ‖J(q) q̇‖₂ over the steps and samples.
    pub max_velocity: f64,
    /// ‖f(q)‖₂ at the last step or sample.
    pub last_position: f64,
    /// ‖J(q) q̇‖₂ at the last step or sample.
    pub last_velocity: f64,
}

impl ConstraintMonitor {
    fn record(&mut self, (position, velocity): (f64, f64)) {
        self.last_position = position;
        self.last_velocity = velocity;
        self.max_position = self.max_position.max(position);
        self.max_velocity = self.max_velocity.max(velocity);
    }
}

/// The monitors of a run over every step of the main run and every sample. H is conserved only without dampers, without
/// velocity-dependent potentials that do work, without a time-dependent base motion and with
/// τ constant or zero; otherwise its change is the work of those forces, reported as drift.
#[derive(Debug, Clone, PartialEq)]
pub struct Monitors {
    /// What H is.
    pub invariant: Invariant,
    /// H at the start, J.
    pub initial: f64,
    /// The energy scale, J: the largest kinetic energy T₂ over the steps and samples (at
    /// least the smallest positive f64).
    pub scale: f64,
    /// max |H − H(0)| / scale over the steps and samples. With contacts H(0) restarts just
    /// after each impact (M.23): the impacts' own changes are in the impact events.
    pub max_drift: f64,
    /// |H − H(0)| / scale at the last step or sample.
    pub last_drift: f64,
    /// The momenta of the coordinates named cyclic.
    pub cyclic: Vec<CyclicMomentum>,
    /// The linear momentum P of the whole mechanism (M.15), kg·m/s.
    pub linear_momentum: MomentumDrift,
    /// The angular momentum L of the whole mechanism about the origin of W (M.16), kg·m²/s.
    pub angular_momentum: MomentumDrift,
    /// The drift of the holonomic constraints (M.20).
    pub constraints: ConstraintMonitor,
}

/// What the monitors record at one state: H, T₂, the generalized momenta p = A q̇ and the
/// momenta of the whole mechanism.
#[derive(Debug, Clone)]
pub(crate) struct Measurement {
    pub energy: f64,
    pub kinetic: f64,
    pub p: Vec<f64>,
    pub momentum: SystemMomentum,
    /// (‖f(q)‖₂, ‖J q̇‖₂), zero without constraints.
    pub constraint_drift: (f64, f64),
}

impl Measurement {
    /// Zero everywhere (no state measured).
    pub(crate) fn nothing() -> Self {
        Self {
            energy: 0.0,
            kinetic: 0.0,
            p: Vec::new(),
            momentum: SystemMomentum {
                linear: Vector3::zeros(),
                angular: Vector3::zeros(),
            },
            constraint_drift: (0.0, 0.0),
        }
    }
}

/// The running state of the monitors.
#[derive(Debug, Clone)]
pub(crate) struct Tracker {
    invariant: Invariant,
    initial: f64,
    /// H at the start of the current free segment (t = 0, or just after the last impact).
    reference: f64,
    largest_kinetic: f64,
    max_change: f64,
    last_change: f64,
    cyclic: Vec<CyclicMomentum>,
    linear: MomentumDrift,
    angular: MomentumDrift,
    constraints: ConstraintMonitor,
}

impl Tracker {
    /// Starts from the initial measurement, following the momenta of the `cyclic` coordinates.
    pub(crate) fn new(invariant: Invariant, start: &Measurement, cyclic: &[usize]) -> Self {
        Self {
            invariant,
            initial: start.energy,
            reference: start.energy,
            largest_kinetic: start.kinetic,
            max_change: 0.0,
            last_change: 0.0,
            cyclic: cyclic
                .iter()
                .map(|&k| CyclicMomentum {
                    coordinate: k,
                    initial: start.p[k],
                    last: start.p[k],
                    max_drift: 0.0,
                })
                .collect(),
            linear: MomentumDrift::new(start.momentum.linear),
            angular: MomentumDrift::new(start.momentum.angular),
            constraints: {
                let mut monitor = ConstraintMonitor::default();
                monitor.record(start.constraint_drift);
                monitor
            },
        }
    }

    /// Records the measurement of one step or sample.
    pub(crate) fn record(&mut self, m: &Measurement) {
        self.largest_kinetic = self.largest_kinetic.max(m.kinetic);
        self.last_change = (m.energy - self.reference).abs();
        self.max_change = self.max_change.max(self.last_change);
        for c in &mut self.cyclic {
            c.last = m.p[c.coordinate];
            c.max_drift = c.max_drift.max((c.last - c.initial).abs());
        }
        self.linear.record(m.momentum.linear);
        self.angular.record(m.momentum.angular);
        self.constraints.record(m.constraint_drift);
    }

    /// Restarts the drifts' references at the state just after an impact (M.23): the change of
    /// H and of the momenta across an impact is the impact's, reported with it, not drift.
    pub(crate) fn rebase(&mut self, m: &Measurement) {
        self.reference = m.energy;
        for c in &mut self.cyclic {
            c.initial = m.p[c.coordinate];
        }
        self.linear.rebase(m.momentum.linear);
        self.angular.rebase(m.momentum.angular);
        self.record(m);
    }

    /// The monitors so far.
    pub(crate) fn monitors(&self) -> Monitors {
        let scale = self.largest_kinetic.max(f64::MIN_POSITIVE);
        Monitors {
            invariant: self.invariant,
            initial: self.initial,
            scale,
            max_drift: self.max_change / scale,
            last_drift: self.last_change / scale,
            cyclic: self.cyclic.clone(),
            linear_momentum: self.linear,
            angular_momentum: self.angular,
            constraints: self.constraints,
        }
    }
}
