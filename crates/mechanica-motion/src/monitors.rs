//! Monitors of a run: the drift of the conserved quantity H (M.1)–(M.2) and the momenta of
//! coordinates the caller names cyclic.

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
    /// p_k at the start.
    pub initial: f64,
    /// p_k at the last step or sample.
    pub last: f64,
    /// max |p_k − p_k(0)| over the steps and samples.
    pub max_drift: f64,
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
    /// max |H − H(0)| / scale over the steps and samples.
    pub max_drift: f64,
    /// |H − H(0)| / scale at the last step or sample.
    pub last_drift: f64,
    /// The momenta of the coordinates named cyclic.
    pub cyclic: Vec<CyclicMomentum>,
}

/// The running state of the monitors.
#[derive(Debug, Clone)]
pub(crate) struct Tracker {
    invariant: Invariant,
    initial: f64,
    largest_kinetic: f64,
    max_change: f64,
    last_change: f64,
    cyclic: Vec<CyclicMomentum>,
}

impl Tracker {
    /// Starts from H₀ and the initial momenta p of the cyclic coordinates.
    pub(crate) fn new(invariant: Invariant, energy: f64, kinetic: f64, cyclic: &[usize], p: &[f64]) -> Self {
        Self {
            invariant,
            initial: energy,
            largest_kinetic: kinetic,
            max_change: 0.0,
            last_change: 0.0,
            cyclic: cyclic
                .iter()
                .map(|&k| CyclicMomentum {
                    coordinate: k,
                    initial: p[k],
                    last: p[k],
                    max_drift: 0.0,
                })
                .collect(),
        }
    }

    /// Records a sample with H, T₂ and the momenta p.
    pub(crate) fn record(&mut self, energy: f64, kinetic: f64, p: &[f64]) {
        self.largest_kinetic = self.largest_kinetic.max(kinetic);
        self.last_change = (energy - self.initial).abs();
        self.max_change = self.max_change.max(self.last_change);
        for c in &mut self.cyclic {
            c.last = p[c.coordinate];
            c.max_drift = c.max_drift.max((c.last - c.initial).abs());
        }
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
        }
    }
}
