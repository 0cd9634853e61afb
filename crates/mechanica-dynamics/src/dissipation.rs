//! Rayleigh dissipation (FM 4.62–4.66): linear dampers whose forces are −∂D/∂q̇ of a
//! dissipation function D = ½ q̇ᵀ C(q) q̇ ≥ 0, so that they take the power 2D out of the
//! mechanism (FM 4.66).
//!
//! - [`Damper::Joint`]: D = ½ c q̇_k² on one coordinate; Q_k = −c q̇_k.
//! - [`Damper::Points`]: linear friction between two points (FM 4.62): with the relative
//!   velocity v = ẋ_a − ẋ_b, D = ½ c |v|² and the force −c v on a, +c v on b.
//! - [`Damper::Dashpot`]: the same along the line between the points: with the unit vector
//!   e = (x_a − x_b)/|x_a − x_b|, D = ½ c (e·v)² and the force −c (e·v) e on a. Its direction is
//!   undefined when the points meet, which is [`DynamicsError::Dissipation`].
//!
//! A point on the ground (`Anchor { body: None, .. }`) is fixed in the base frame; with a
//! rotating frame it moves with the frame, so the damper resists motion relative to the frame.

use crate::error::DynamicsError;
use crate::spatial::Wrench;
use mechanica_kinematics::tree::{KinematicTree, Workspace};
use mechanica_mechanism::Anchor;
use nalgebra::Vector3;

/// A linear damper (see the module docs). Coefficients are ≥ 0 and finite.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Damper {
    /// D = ½ c q̇_k²: c in N·m·s/rad (revolute) or N·s/m (prismatic).
    Joint {
        /// The coordinate k.
        coordinate: usize,
        /// c ≥ 0.
        coefficient: f64,
    },
    /// D = ½ c |ẋ_a − ẋ_b|², c in N·s/m.
    Points {
        /// First point.
        a: Anchor,
        /// Second point.
        b: Anchor,
        /// c ≥ 0.
        coefficient: f64,
    },
    /// D = ½ c (e·(ẋ_a − ẋ_b))² along the line between the points, c in N·s/m.
    Dashpot {
        /// First point.
        a: Anchor,
        /// Second point.
        b: Anchor,
        /// c ≥ 0.
        coefficient: f64,
    },
}

/// A point's world position and velocity; ground points are fixed in the base frame.
fn point_motion(ws: &Workspace, anchor: &Anchor) -> Result<(Vector3<f64>, Vector3<f64>), DynamicsError> {
    match anchor.body {
        Some(body) => Ok((
            ws.point_position(body, &anchor.point)?,
            ws.point_velocity(body, &anchor.point)?,
        )),
        None => {
            let base = ws.base();
            let x = base.rotation * anchor.point + base.position;
            Ok((x, base.velocity + base.omega.cross(&(x - base.position))))
        }
    }
}

impl Damper {
    /// A short name for reports and errors.
    pub fn name(&self) -> String {
        match self {
            Damper::Joint { coordinate, .. } => format!("joint damper on q{coordinate}"),
            Damper::Points { a, b, .. } => format!("damper {} – {}", anchor_name(a), anchor_name(b)),
            Damper::Dashpot { a, b, .. } => format!("dashpot {} – {}", anchor_name(a), anchor_name(b)),
        }
    }

    /// The coefficient c.
    pub fn coefficient(&self) -> f64 {
        match self {
            Damper::Joint { coefficient, .. }
            | Damper::Points { coefficient, .. }
            | Damper::Dashpot { coefficient, .. } => *coefficient,
        }
    }

    /// Checks the coefficient (finite, ≥ 0), the coordinate or bodies, and the points.
    pub(crate) fn validate(&self, tree: &KinematicTree) -> Result<(), DynamicsError> {
        let c = self.coefficient();
        if !(c.is_finite() && c >= 0.0) {
            return Err(DynamicsError::OutOfRange {
                what: "damping coefficient",
                requirement: "finite and ≥ 0",
                value: c,
            });
        }
        match self {
            Damper::Joint { coordinate, .. } if *coordinate >= tree.dof() => Err(DynamicsError::NoSuchCoordinate {
                what: "joint damper",
                index: *coordinate,
                dof: tree.dof(),
            }),
            Damper::Joint { .. } => Ok(()),
            Damper::Points { a, b, .. } | Damper::Dashpot { a, b, .. } => {
                check_anchor(tree, a)?;
                check_anchor(tree, b)
            }
        }
    }

    /// Adds the damper's forces at the state in `ws` (velocities computed): point forces as
    /// wrenches about each body's origin into `wrenches`, joint forces into `joint`. Returns D.
    pub(crate) fn apply(
        &self,
        ws: &Workspace,
        q_dot: &[f64],
        wrenches: &mut [Wrench],
        joint: &mut [f64],
    ) -> Result<f64, DynamicsError> {
        match self {
            Damper::Joint {
                coordinate,
                coefficient,
            } => {
                let rate = q_dot[*coordinate];
                joint[*coordinate] -= coefficient * rate;
                Ok(0.5 * coefficient * rate * rate)
            }
            Damper::Points { a, b, coefficient } => {
                let ((_, va), (_, vb)) = (point_motion(ws, a)?, point_motion(ws, b)?);
                let v = va - vb;
                self.apply_pair(ws, a, b, -v * *coefficient, wrenches)?;
                Ok(0.5 * coefficient * v.norm_squared())
            }
            Damper::Dashpot { a, b, coefficient } => {
                let ((xa, va), (xb, vb)) = (point_motion(ws, a)?, point_motion(ws, b)?);
                let d = xa - xb;
                let length = d.norm();
                if length == 0.0 || !length.is_finite() {
                    return Err(DynamicsError::Dissipation {
                        name: self.name(),
                        reason: "its points coincide, so the dashpot's direction is undefined",
                    });
                }
                let e = d / length;
                let rate = e.dot(&(va - vb));
                self.apply_pair(ws, a, b, -e * (coefficient * rate), wrenches)?;
                Ok(0.5 * coefficient * rate * rate)
            }
        }
    }

    /// Adds the force `f` at point a and −`f` at point b.
    fn apply_pair(
        &self,
        ws: &Workspace,
        a: &Anchor,
        b: &Anchor,
        f: Vector3<f64>,
        wrenches: &mut [Wrench],
    ) -> Result<(), DynamicsError> {
        for (anchor, force) in [(a, f), (b, -f)] {
            if let Some(body) = anchor.body {
                let r = ws.rotation(body)? * anchor.point;
                wrenches[body] += Wrench::of_force_at(force, &r);
            }
        }
        Ok(())
    }
}

fn anchor_name(anchor: &Anchor) -> String {
    match anchor.body {
        Some(body) => format!("body {body}"),
        None => "ground".to_string(),
    }
}

fn check_anchor(tree: &KinematicTree, anchor: &Anchor) -> Result<(), DynamicsError> {
    crate::error::check_input(anchor.point.as_slice(), "damper point")?;
    match anchor.body {
        Some(body) if body >= tree.body_count() => Err(DynamicsError::NoSuchBody {
            what: "damper point",
            body,
            bodies: tree.body_count(),
        }),
        _ => Ok(()),
    }
}

/// The relative point Jacobian ∂(x_a − x_b)/∂q (3×dof, column-major) at the positions in `ws`;
/// a ground point contributes nothing (it does not move with q).
fn relative_jacobian(tree: &KinematicTree, ws: &Workspace, a: &Anchor, b: &Anchor) -> Result<Vec<f64>, DynamicsError> {
    let n = tree.dof();
    let mut out = vec![0.0; 3 * n];
    let mut part = vec![0.0; 3 * n];
    for (anchor, sign) in [(a, 1.0), (b, -1.0)] {
        if let Some(body) = anchor.body {
            tree.point_jacobian(ws, body, &anchor.point, &mut part)?;
            for (o, p) in out.iter_mut().zip(&part) {
                *o += sign * p;
            }
        }
    }
    Ok(out)
}

impl Damper {
    /// Adds this damper's part of the damping matrix C(q) (D = ½ q̇ᵀ C q̇, FM 4.64) at the
    /// positions in `ws` into `c` (dof × dof): c on the diagonal for a joint damper,
    /// c Jᵀ J for linear friction between points and c (eᵀJ)ᵀ(eᵀJ) for a dashpot, with J the
    /// relative point Jacobian.
    pub(crate) fn add_to_damping_matrix(
        &self,
        tree: &KinematicTree,
        ws: &Workspace,
        c: &mut faer::Mat<f64>,
    ) -> Result<(), DynamicsError> {
        let n = tree.dof();
        match self {
            Damper::Joint {
                coordinate,
                coefficient,
            } => c[(*coordinate, *coordinate)] += coefficient,
            Damper::Points { a, b, coefficient } => {
                let j = relative_jacobian(tree, ws, a, b)?;
                for k in 0..n {
                    for l in 0..n {
                        let dot: f64 = (0..3).map(|r| j[3 * k + r] * j[3 * l + r]).sum();
                        c[(k, l)] += coefficient * dot;
                    }
                }
            }
            Damper::Dashpot { a, b, coefficient } => {
                let ((xa, _), (xb, _)) = (point_motion(ws, a)?, point_motion(ws, b)?);
                let d = xa - xb;
                let length = d.norm();
                if length == 0.0 || !length.is_finite() {
                    return Err(DynamicsError::Dissipation {
                        name: self.name(),
                        reason: "its points coincide, so the dashpot's direction is undefined",
                    });
                }
                let e = d / length;
                let j = relative_jacobian(tree, ws, a, b)?;
                let row: Vec<f64> = (0..n).map(|k| (0..3).map(|r| e[r] * j[3 * k + r]).sum()).collect();
                for k in 0..n {
                    for l in 0..n {
                        c[(k, l)] += coefficient * row[k] * row[l];
                    }
                }
            }
        }
        Ok(())
    }
}

impl crate::Dynamics {
    /// The damping matrix C(q) of the dampers (FM 4.64): symmetric, positive semidefinite, with
    /// D = ½ q̇ᵀ C q̇ and the dampers' generalized force −C q̇ (FM 4.65).
    pub fn damping_matrix(&mut self, q: &[f64]) -> Result<faer::Mat<f64>, DynamicsError> {
        let n = self.dof();
        self.update_state(&crate::State::new(q, &vec![0.0; n]))?;
        let tree = self.mechanism.tree();
        let mut c = faer::Mat::zeros(n, n);
        for damper in &self.dampers {
            damper.add_to_damping_matrix(tree, &self.ws, &mut c)?;
        }
        for j in 0..n {
            crate::error::check_result(c.col(j).iter(), "damping matrix")?;
        }
        Ok(c)
    }
}
