//! The loads of a mechanism other than gravity, gathered at one state: the potentials' forces
//! (−∂U/∂q, FM 4.72), the dampers' forces (−∂D/∂q̇, FM 4.65) and the velocity-dependent
//! potentials' forces (FM 4.90).
//!
//! Forces that act through body points become wrenches about each body's origin, so that the
//! joint reactions see them; the rest acts on the coordinates themselves (joint springs, joint
//! dampers, generalized forces) and is carried by the joints like an actuator's force. A
//! user potential that reports no point forces is treated as acting on the coordinates.

use crate::error::DynamicsError;
use crate::model::{Dynamics, State};
use crate::spatial::Wrench;
use mechanica_mechanism::PointForce;

/// What produced a load.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum LoadKind {
    /// A potential of the mechanism (spring, constant force, user potential).
    Potential,
    /// A Rayleigh damper.
    Damper,
    /// A velocity-dependent potential.
    VelocityPotential,
}

/// One load's generalized force Q (4.35) at the state, in the units of the coordinates
/// (N for lengths, N·m for angles), as it enters the right-hand side of Lagrange's equations.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadTerm {
    /// The load's name.
    pub name: String,
    /// What it is.
    pub kind: LoadKind,
    /// Its generalized force Q, one entry per coordinate.
    pub force: Vec<f64>,
}

/// Adds point forces to per-body wrenches about the bodies' origins.
fn add_point_forces(
    dynamics_origin: impl Fn(usize) -> nalgebra::Vector3<f64>,
    forces: &[PointForce],
    wrenches: &mut [Wrench],
) {
    for f in forces {
        wrenches[f.body] += Wrench::of_force_at(f.force, &(f.point - dynamics_origin(f.body)));
    }
}

impl Dynamics {
    /// True when the mechanism has loads besides gravity.
    pub(crate) fn has_loads(&self) -> bool {
        !(self.mechanism.potentials().is_empty() && self.dampers.is_empty() && self.velocity_potentials.is_empty())
    }

    /// Fills `self.loads` (wrenches about the body origins) and `self.joint_loads` at `state`
    /// (positions and velocities already in the workspace). With `detail`, also returns each
    /// load's generalized force. Returns D, the dampers' dissipation function, with the terms.
    pub(crate) fn evaluate_loads(
        &mut self,
        state: &State<'_>,
        detail: bool,
    ) -> Result<(f64, Vec<LoadTerm>), DynamicsError> {
        self.loads.fill(Wrench::zero());
        self.joint_loads.fill(0.0);
        let mut terms = Vec::new();
        if !self.has_loads() {
            return Ok((0.0, terms));
        }
        let n = self.dof();
        let positions: Vec<_> = (0..self.tree().body_count())
            .map(|i| self.ws.position(i))
            .collect::<Result<_, _>>()?;
        let origin = |i: usize| positions[i];
        for (name, sum) in self.mechanism.potential_terms(state.q)? {
            let mut point_wrenches = vec![Wrench::zero(); positions.len()];
            add_point_forces(origin, &sum.point_forces, &mut point_wrenches);
            let through_points = self.generalized_force_of(&point_wrenches)?;
            for k in 0..n {
                self.joint_loads[k] += -sum.gradient[k] - through_points[k];
            }
            for (total, w) in self.loads.iter_mut().zip(&point_wrenches) {
                *total += *w;
            }
            if detail {
                let force = sum.gradient.iter().map(|g| -g).collect();
                terms.push(LoadTerm {
                    name,
                    kind: LoadKind::Potential,
                    force,
                });
            }
        }
        let mut dissipation = 0.0;
        for damper in self.dampers.clone() {
            let mut wrenches = vec![Wrench::zero(); positions.len()];
            let mut joint = vec![0.0; n];
            dissipation += damper.apply(&self.ws, state.q_dot, &mut wrenches, &mut joint)?;
            self.add_term(
                &wrenches,
                &joint,
                detail.then(|| (damper.name(), LoadKind::Damper)),
                &mut terms,
            )?;
        }
        for potential in self.velocity_potentials.clone() {
            let mut forces = Vec::new();
            potential.point_forces(&self.ws, state.t, &mut forces)?;
            let mut wrenches = vec![Wrench::zero(); positions.len()];
            add_point_forces(origin, &forces, &mut wrenches);
            let kind = (potential.name(), LoadKind::VelocityPotential);
            self.add_term(&wrenches, &vec![0.0; n], detail.then_some(kind), &mut terms)?;
        }
        crate::error::check_result(&self.joint_loads, "generalized load")?;
        crate::error::check_result([dissipation].iter(), "dissipation function")?;
        Ok((dissipation, terms))
    }

    /// Adds one load's wrenches and joint forces to the totals; with a label, records its
    /// generalized force as a term.
    fn add_term(
        &mut self,
        wrenches: &[Wrench],
        joint: &[f64],
        label: Option<(String, LoadKind)>,
        terms: &mut Vec<LoadTerm>,
    ) -> Result<(), DynamicsError> {
        for (total, w) in self.loads.iter_mut().zip(wrenches) {
            *total += *w;
        }
        for (total, j) in self.joint_loads.iter_mut().zip(joint) {
            *total += j;
        }
        if let Some((name, kind)) = label {
            let mut force = self.generalized_force_of(wrenches)?;
            for (f, j) in force.iter_mut().zip(joint) {
                *f += j;
            }
            terms.push(LoadTerm { name, kind, force });
        }
        Ok(())
    }
}
