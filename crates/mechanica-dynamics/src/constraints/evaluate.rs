//! f(q), its Jacobian J = ∂f/∂q and the bias γ = −J̇ q̇ of a list of constraints, from the
//! point Jacobians (1.37) and point bias accelerations of the kinematics crate.
//!
//! For a body point x, ẋ = J_x q̇ and ẍ = J_x q̈ + b_x with b_x the point's acceleration at
//! q̈ = 0 ([`KinematicTree::point_bias_acceleration`]). Then, with d = x_a − x_b:
//! - coincidence along a fixed d_r: J = d_rᵀ (J_a − J_b), γ = −d_r·(b_a − b_b);
//! - point on a plane: J = nᵀ J_x, γ = −n·b_x;
//! - distance, u = d/|d|: J = uᵀ (J_a − J_b) and, since u̇·ḋ = (|ḋ|² − (u·ḋ)²)/|d|,
//!   γ = −u·(b_a − b_b) − (|ḋ|² − (u·ḋ)²)/|d|;
//! - coordinate: J = e_kᵀ, γ = 0.
//!
//! These are exact (no differencing). The kinematics run in the base frame with the base at
//! rest, so in a steadily rotating frame f, J and γ describe the relative motion, as q does.

use super::kinds::Constraint;
use crate::error::DynamicsError;
use faer::Mat;
use mechanica_kinematics::tree::{KinematicTree, Workspace};
use mechanica_mechanism::Anchor;
use nalgebra::Vector3;

/// Position, velocity, Jacobian (3×n, column-major) and bias acceleration of one point.
struct PointMotion {
    x: Vector3<f64>,
    v: Vector3<f64>,
    jacobian: Vec<f64>,
    bias: Vector3<f64>,
}

impl PointMotion {
    fn of(tree: &KinematicTree, ws: &Workspace, anchor: &Anchor) -> Result<Self, DynamicsError> {
        let n = tree.dof();
        let mut jacobian = vec![0.0; 3 * n];
        let Some(body) = anchor.body else {
            return Ok(Self {
                x: anchor.point,
                v: Vector3::zeros(),
                jacobian,
                bias: Vector3::zeros(),
            });
        };
        tree.point_jacobian(ws, body, &anchor.point, &mut jacobian)?;
        Ok(Self {
            x: ws.point_position(body, &anchor.point)?,
            v: ws.point_velocity(body, &anchor.point)?,
            jacobian,
            bias: tree.point_bias_acceleration(ws, body, &anchor.point)?,
        })
    }

    fn column(&self, k: usize) -> Vector3<f64> {
        Vector3::new(self.jacobian[3 * k], self.jacobian[3 * k + 1], self.jacobian[3 * k + 2])
    }
}

/// Where a constraint's reaction acts, and the gradients ∇_{x_a} f_r of its equations.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ReactionGeometry {
    /// World position of the first point (a, or the plane's point); None for a coordinate.
    pub point: Option<Vector3<f64>>,
    /// World position of the second point of a pair.
    pub opposite_point: Option<Vector3<f64>>,
    /// ∇_{x_a} f_r of each equation (the opposite at b); empty for a coordinate.
    pub gradients: Vec<Vector3<f64>>,
}

/// Everything the solvers need from the constraints at one state.
#[derive(Debug, Clone)]
pub(crate) struct Evaluated {
    /// f(q), one entry per equation.
    pub value: Vec<f64>,
    /// The magnitude of the terms f_r is computed from (its rounding scale).
    pub value_scale: Vec<f64>,
    /// J = ∂f/∂q, m×n.
    pub jacobian: Mat<f64>,
    /// The magnitude Σ_k |terms of J_rk| of each row: a row far smaller is rounding noise.
    pub row_scale: Vec<f64>,
    /// γ = −J̇ q̇.
    pub bias: Vec<f64>,
    /// J q̇.
    pub velocity: Vec<f64>,
    /// Per constraint, the geometry of its reaction.
    pub geometry: Vec<ReactionGeometry>,
}

/// One equation's value f, the magnitude of its terms, and its bias γ.
struct Row {
    value: f64,
    value_scale: f64,
    bias: f64,
}

/// f, J, γ of `constraints` at the positions and velocities in `ws` (base at rest).
pub(crate) fn evaluate(
    tree: &KinematicTree,
    ws: &Workspace,
    constraints: &[Constraint],
) -> Result<Evaluated, DynamicsError> {
    let n = tree.dof();
    let m: usize = constraints.iter().map(Constraint::equation_count).sum();
    let mut out = Evaluated {
        value: Vec::with_capacity(m),
        value_scale: Vec::with_capacity(m),
        jacobian: Mat::zeros(m, n),
        row_scale: Vec::with_capacity(m),
        bias: Vec::with_capacity(m),
        velocity: vec![0.0; m],
        geometry: Vec::with_capacity(constraints.len()),
    };
    for constraint in constraints {
        let geometry = out.push(tree, ws, constraint)?;
        out.geometry.push(geometry);
    }
    for r in 0..m {
        out.velocity[r] = (0..n).map(|k| out.jacobian[(r, k)] * ws.q_dot()[k]).sum();
    }
    crate::error::check_result(
        out.value.iter().chain(&out.bias).chain(&out.velocity),
        "constraint value",
    )?;
    Ok(out)
}

/// A ground point at the origin (no motion).
fn ground() -> Anchor {
    Anchor {
        body: None,
        point: Vector3::zeros(),
    }
}

fn pair_geometry(pa: &PointMotion, pb: &PointMotion, gradients: Vec<Vector3<f64>>) -> ReactionGeometry {
    ReactionGeometry {
        point: Some(pa.x),
        opposite_point: Some(pb.x),
        gradients,
    }
}

impl Evaluated {
    /// Appends the equations of `constraint` and returns the geometry of its reaction.
    fn push(
        &mut self,
        tree: &KinematicTree,
        ws: &Workspace,
        constraint: &Constraint,
    ) -> Result<ReactionGeometry, DynamicsError> {
        Ok(match constraint {
            Constraint::PointsCoincide { a, b, directions } => {
                let (pa, pb) = (PointMotion::of(tree, ws, a)?, PointMotion::of(tree, ws, b)?);
                for d in directions {
                    let row = Row {
                        value: d.dot(&(pa.x - pb.x)),
                        value_scale: pa.x.norm() + pb.x.norm(),
                        bias: -d.dot(&(pa.bias - pb.bias)),
                    };
                    self.push_pair_row(&row, d, &pa, &pb);
                }
                pair_geometry(&pa, &pb, directions.clone())
            }
            Constraint::PointOnPlane { point, normal, offset } => {
                let p = PointMotion::of(tree, ws, point)?;
                let row = Row {
                    value: normal.dot(&p.x) - offset,
                    value_scale: p.x.norm() + offset.abs(),
                    bias: -normal.dot(&p.bias),
                };
                self.push_pair_row(&row, normal, &p, &PointMotion::of(tree, ws, &ground())?);
                ReactionGeometry {
                    point: Some(p.x),
                    opposite_point: None,
                    gradients: vec![*normal],
                }
            }
            Constraint::Distance { a, b, length } => {
                let (pa, pb) = (PointMotion::of(tree, ws, a)?, PointMotion::of(tree, ws, b)?);
                let d = pa.x - pb.x;
                let distance = d.norm();
                if !(distance > 0.0 && distance.is_finite()) {
                    return Err(DynamicsError::OutOfRange {
                        what: "distance between the points of a rod constraint",
                        requirement: "> 0 and finite",
                        value: distance,
                    });
                }
                let u = d / distance;
                let d_dot = pa.v - pb.v;
                let along = u.dot(&d_dot);
                let row = Row {
                    value: distance - length,
                    value_scale: pa.x.norm() + pb.x.norm() + length,
                    bias: -u.dot(&(pa.bias - pb.bias)) - (d_dot.norm_squared() - along * along) / distance,
                };
                self.push_pair_row(&row, &u, &pa, &pb);
                pair_geometry(&pa, &pb, vec![u])
            }
            Constraint::Coordinate { index, value } => {
                let r = self.value.len();
                self.value.push(ws.q()[*index] - value);
                self.value_scale.push(ws.q()[*index].abs() + value.abs());
                self.jacobian[(r, *index)] = 1.0;
                self.row_scale.push(1.0);
                self.bias.push(0.0);
                ReactionGeometry {
                    point: None,
                    opposite_point: None,
                    gradients: Vec::new(),
                }
            }
        })
    }

    /// Appends the equation `row` whose Jacobian row is dᵀ (J_a − J_b).
    fn push_pair_row(&mut self, row: &Row, d: &Vector3<f64>, pa: &PointMotion, pb: &PointMotion) {
        let r = self.value.len();
        let mut scale = 0.0;
        for k in 0..self.jacobian.ncols() {
            let (ca, cb) = (pa.column(k), pb.column(k));
            self.jacobian[(r, k)] = d.dot(&(ca - cb));
            scale += ca.norm() + cb.norm();
        }
        self.value.push(row.value);
        self.value_scale.push(row.value_scale);
        self.row_scale.push(scale);
        self.bias.push(row.bias);
    }

    /// The number of equations m.
    pub fn equations(&self) -> usize {
        self.value.len()
    }
}
