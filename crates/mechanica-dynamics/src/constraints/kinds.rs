//! The holonomic constraints f(q) = 0 that close loops or prescribe coordinates.
//!
//! Each [`Constraint`] contributes m equations f_r(q) = 0 whose gradients with respect to the
//! points they involve are world directions: the reaction they transmit is the force
//! −Σ_r λ_r ∇_x f_r at each point (FM 4.61 with λ of the opposite sign, see
//! [`super`]). All directions and offsets are world (base-frame) components.

use crate::error::{DynamicsError, check_input};
use mechanica_kinematics::tree::KinematicTree;
use mechanica_mechanism::Anchor;
use nalgebra::Vector3;

/// A holonomic constraint between body points, or on one coordinate.
///
/// Points are [`Anchor`]s: a body point (body coordinates) or a ground point (world
/// coordinates, `body: None`). Directions and normals need not be unit vectors: they are
/// normalised when the constraint is added ([`super::ConstrainedDynamics::add_constraint`]),
/// and a plane's offset is divided by the normal's length with it.
#[derive(Debug, Clone, PartialEq)]
pub enum Constraint {
    /// The points a and b coincide along each of the given world directions d_r:
    /// f_r = d_r·(x_a − x_b) (one equation per direction, 1 to 3 directions, which must be
    /// independent). [`Constraint::points_coincide`] gives all three axes (a ball joint
    /// closing a loop); a planar loop closed by a pin needs only the two in-plane directions,
    /// the out-of-plane equation being redundant.
    PointsCoincide {
        /// The first point; the reported reaction force acts on it.
        a: Anchor,
        /// The second point; the opposite force acts on it.
        b: Anchor,
        /// World directions along which the points coincide.
        directions: Vec<Vector3<f64>>,
    },
    /// A body point held on the fixed plane n·x = offset: f = n·x − offset.
    PointOnPlane {
        /// The point.
        point: Anchor,
        /// The plane's normal n (world).
        normal: Vector3<f64>,
        /// The plane's offset along n, m.
        offset: f64,
    },
    /// A massless rod between two points: f = |x_a − x_b| − length. The multiplier is the
    /// rod's tension (N, positive when the rod pulls the points together).
    Distance {
        /// The first point; the reported reaction force acts on it.
        a: Anchor,
        /// The second point; the opposite force acts on it.
        b: Anchor,
        /// The rod length L > 0, m.
        length: f64,
    },
    /// A prescribed (locked) coordinate: f = q_index − value. The multiplier is the
    /// generalized force the lock applies, with its sign reversed.
    Coordinate {
        /// The coordinate.
        index: usize,
        /// Its prescribed value (rad or m).
        value: f64,
    },
}

impl Constraint {
    /// The points a and b coincide along the three world axes.
    pub fn points_coincide(a: Anchor, b: Anchor) -> Self {
        Self::PointsCoincide {
            a,
            b,
            directions: vec![Vector3::x(), Vector3::y(), Vector3::z()],
        }
    }

    /// The number of equations m of the constraint.
    pub fn equation_count(&self) -> usize {
        match self {
            Self::PointsCoincide { directions, .. } => directions.len(),
            _ => 1,
        }
    }

    /// A short name of the constraint's kind.
    pub fn kind_name(&self) -> &'static str {
        match self {
            Self::PointsCoincide { .. } => "points coincide",
            Self::PointOnPlane { .. } => "point on plane",
            Self::Distance { .. } => "distance",
            Self::Coordinate { .. } => "coordinate",
        }
    }

    /// The constraint checked against `tree`, with unit directions and normal (see the type's
    /// docs). Errors: bodies or coordinates out of range, non-finite data, zero directions,
    /// 0 or more than 3 directions, a non-positive length.
    pub(crate) fn checked(&self, tree: &KinematicTree) -> Result<Self, DynamicsError> {
        match self {
            Self::PointsCoincide { a, b, directions } => {
                check_anchor(a, tree, "constraint point a")?;
                check_anchor(b, tree, "constraint point b")?;
                if directions.is_empty() || directions.len() > 3 {
                    return Err(DynamicsError::OutOfRange {
                        what: "number of coincidence directions",
                        requirement: "1 to 3",
                        value: directions.len() as f64,
                    });
                }
                let unit = directions
                    .iter()
                    .map(|d| unit_vector(d, "coincidence direction"))
                    .collect::<Result<_, _>>()?;
                Ok(Self::PointsCoincide {
                    a: *a,
                    b: *b,
                    directions: unit,
                })
            }
            Self::PointOnPlane { point, normal, offset } => {
                check_anchor(point, tree, "constraint point")?;
                check_input(&[*offset], "plane offset")?;
                let length = normal.norm();
                Ok(Self::PointOnPlane {
                    point: *point,
                    normal: unit_vector(normal, "plane normal")?,
                    offset: offset / length,
                })
            }
            Self::Distance { a, b, length } => {
                check_anchor(a, tree, "constraint point a")?;
                check_anchor(b, tree, "constraint point b")?;
                check_input(&[*length], "rod length")?;
                if *length <= 0.0 {
                    return Err(DynamicsError::OutOfRange {
                        what: "rod length",
                        requirement: "> 0",
                        value: *length,
                    });
                }
                Ok(self.clone())
            }
            Self::Coordinate { index, value } => {
                check_input(&[*value], "prescribed coordinate value")?;
                if *index >= tree.dof() {
                    return Err(DynamicsError::NoSuchCoordinate {
                        what: "coordinate constraint",
                        index: *index,
                        dof: tree.dof(),
                    });
                }
                Ok(self.clone())
            }
        }
    }
}

/// Ok when the anchor's point is finite and its body exists.
fn check_anchor(anchor: &Anchor, tree: &KinematicTree, what: &'static str) -> Result<(), DynamicsError> {
    check_input(anchor.point.as_slice(), what)?;
    match anchor.body {
        Some(body) if body >= tree.body_count() => Err(DynamicsError::NoSuchBody {
            what,
            body,
            bodies: tree.body_count(),
        }),
        _ => Ok(()),
    }
}

/// v/|v| for a finite, non-zero v (formed without underflow or overflow, see
/// `mechanica_kinematics::scaling::unit`).
fn unit_vector(v: &Vector3<f64>, what: &'static str) -> Result<Vector3<f64>, DynamicsError> {
    check_input(v.as_slice(), what)?;
    mechanica_kinematics::scaling::unit(v).ok_or(DynamicsError::OutOfRange {
        what,
        requirement: "a non-zero vector",
        value: 0.0,
    })
}
