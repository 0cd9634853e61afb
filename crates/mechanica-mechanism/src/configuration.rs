//! One evaluated configuration q of a mechanism: body poses, motion columns, the first and
//! second mass moments of every subtree, and the first and second derivatives of body points
//! with respect to q.
//!
//! **Point derivatives.** For a point x moving with body i, ∂x/∂q_k = w_k × x + a_k for every
//! coordinate k on the path from the root to i (zero otherwise), with (w_k, a_k) the motion
//! column of k referred to the world origin, a_k = v_k − w_k × o_{i(k)} (kinematics crate,
//! 1.37). When coordinate k precedes l on that path (k's joint carries l's joint rigidly),
//! ∂a_l/∂q_k and ∂w_l/∂q_k are the Lie bracket of the two columns, and the second derivative
//! collapses to
//!
//! ∂²x/∂q_k∂q_l = w_k × ∂x/∂q_l,
//!
//! which holds for revolute, prismatic and planar joints (translations precede the rotation)
//! and across joints. Within the rotation vector φ of one spherical or free joint the columns
//! are not carried rigidly by each other (R = R_ref exp(φ)); at φ = 0 the exact second
//! derivative is the symmetric part ½(w_k × ∂x/∂q_l + w_l × ∂x/∂q_k) of exp's Taylor series.
//! Hessians are therefore evaluated only at φ = 0 for those joints (see
//! [`crate::Mechanism::rebase`]); elsewhere [`MechanismError::NotRebased`] is returned.

use crate::MechanismError;
use mechanica_kinematics::tree::{KinematicTree, Workspace};
use mechanica_mass::MassProperties;
use nalgebra::{Matrix3, Vector3};

/// Mass moments of a set of bodies about the world origin (world components): the mass m,
/// the first moment h = ∫ρ x dV = m c, and the second moment S = ∫ρ x xᵀ dV.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Moments {
    /// Mass m.
    pub mass: f64,
    /// First moment h = m c.
    pub first: Vector3<f64>,
    /// Second moment S = ∫ρ x xᵀ dV = m c cᵀ + ½ tr(I_c) 1 − I_c.
    pub second: Matrix3<f64>,
}

impl Moments {
    /// No mass.
    pub fn zero() -> Self {
        Self {
            mass: 0.0,
            first: Vector3::zeros(),
            second: Matrix3::zeros(),
        }
    }

    /// The moments of a body whose mass properties are given in world components.
    pub fn of_world_body(body: &MassProperties) -> Self {
        let c = body.p_oc;
        let spread = Matrix3::identity() * (0.5 * body.inertia_c.trace()) - body.inertia_c;
        Self {
            mass: body.mass,
            first: c * body.mass,
            second: c * c.transpose() * body.mass + spread,
        }
    }

    pub(crate) fn add(&mut self, other: &Moments) {
        self.mass += other.mass;
        self.first += other.first;
        self.second += other.second;
    }
}

/// The motion column of coordinate k referred to the world origin: ∂x/∂q_k = w × x + a.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Column {
    /// w_k: angular velocity per unit q̇_k (world).
    pub w: Vector3<f64>,
    /// a_k = v_k − w_k × o_i: velocity of the world point at the origin per unit q̇_k.
    pub a: Vector3<f64>,
}

impl Column {
    /// ∂x/∂q_k for the world point x.
    pub fn at(&self, x: &Vector3<f64>) -> Vector3<f64> {
        self.w.cross(x) + self.a
    }
}

/// The mechanism evaluated at one configuration q (fixed base, or the rotating base frame at
/// rest): everything the potentials need.
#[derive(Debug)]
pub struct Configuration<'a> {
    /// The kinematic tree.
    pub tree: &'a KinematicTree,
    /// Its workspace, with positions updated at q.
    pub workspace: &'a Workspace,
    /// The coordinates.
    pub q: &'a [f64],
    columns: Vec<Column>,
    subtree: Vec<Moments>,
    /// For each coordinate: (rank on its root path, is a rotation-vector coordinate).
    rank: Vec<(usize, bool)>,
}

impl<'a> Configuration<'a> {
    /// Evaluates the columns and subtree moments at the workspace's current positions.
    /// `bodies` are the body mass properties in body frames.
    pub(crate) fn new(
        tree: &'a KinematicTree,
        workspace: &'a Workspace,
        q: &'a [f64],
        bodies: &[MassProperties],
    ) -> Result<Self, MechanismError> {
        let n = tree.dof();
        let mut columns = Vec::with_capacity(n);
        let mut rank = Vec::with_capacity(n);
        for k in 0..n {
            let (w, v) = workspace.motion_column(k)?;
            let i = tree
                .dof_body(k)
                .ok_or(MechanismError::Numerical("coordinate without a body"))?;
            let o = workspace.position(i)?;
            columns.push(Column { w, a: v - w.cross(&o) });
            let start = tree.dof_range(i).start;
            let rotation_vector = crate::mechanism::is_rotation_vector_coordinate(tree, i, k);
            // Rank along any root path: depth first, then the order within the joint.
            let depth = tree.depth(i).unwrap_or(0);
            rank.push((depth * 8 + (k - start), rotation_vector));
        }
        let mut subtree = Vec::with_capacity(bodies.len());
        for (i, body) in bodies.iter().enumerate() {
            let r = workspace.rotation(i)?;
            let world = MassProperties {
                mass: body.mass,
                p_oc: workspace.point_position(i, &body.p_oc)?,
                inertia_c: r.matrix() * body.inertia_c * r.matrix().transpose(),
            };
            subtree.push(Moments::of_world_body(&world));
        }
        for &i in tree.topological_order().iter().rev() {
            if let Some(p) = tree.parent(i) {
                let child = subtree[i];
                subtree[p].add(&child);
            }
        }
        Ok(Self {
            tree,
            workspace,
            q,
            columns,
            subtree,
            rank,
        })
    }

    /// Number of coordinates.
    pub fn dof(&self) -> usize {
        self.columns.len()
    }

    /// The origin-referred motion column of coordinate k.
    pub fn column(&self, k: usize) -> Column {
        self.columns[k]
    }

    /// The moments of the subtree rooted at `body` (world, about the origin).
    pub fn subtree_moments(&self, body: usize) -> Moments {
        self.subtree[body]
    }

    /// The moments of the whole mechanism.
    pub fn total_moments(&self) -> Moments {
        let mut total = Moments::zero();
        for i in 0..self.tree.body_count() {
            if self.tree.parent(i).is_none() {
                total.add(&self.subtree[i]);
            }
        }
        total
    }

    /// The coordinates on the root path of `body`, root first (within a joint in its own order).
    pub fn path_coordinates(&self, body: usize) -> Vec<usize> {
        let mut path = Vec::new();
        let mut b = Some(body);
        while let Some(i) = b {
            for k in self.tree.dof_range(i).rev() {
                path.push(k);
            }
            b = self.tree.parent(i);
        }
        path.reverse();
        path
    }

    /// For two coordinates k, l on one root path: (earlier, later) in the carrying order, and
    /// whether both are rotation-vector coordinates of the same joint.
    pub(crate) fn ordered(&self, k: usize, l: usize) -> (usize, usize, bool) {
        let block = self.same_rotation_block(k, l);
        if self.rank[k].0 <= self.rank[l].0 {
            (k, l, block)
        } else {
            (l, k, block)
        }
    }

    /// True when k and l are both rotation-vector coordinates of the same joint.
    pub(crate) fn same_rotation_block(&self, k: usize, l: usize) -> bool {
        self.rank[k].1
            && self.rank[l].1
            && self.tree.dof_body(k).is_some()
            && self.tree.dof_body(k) == self.tree.dof_body(l)
    }

    /// The coordinates that carry `late` or are `late` itself: `late`, then each
    /// [`KinematicTree::previous_dof`] on its path to the base. Each pair of coordinates on one
    /// root path is (carrier, `late`) for exactly one `late`, so a loop over all `late` and
    /// their carriers visits every such pair once, in O(n·depth).
    pub(crate) fn carriers(&self, late: usize) -> impl Iterator<Item = usize> + '_ {
        std::iter::successors(Some(late), |&k| self.tree.previous_dof(k))
    }

    /// Errors unless the rotation vector of the joint owning k is zero (see the module docs).
    pub(crate) fn require_rebased(&self, k: usize) -> Result<(), MechanismError> {
        let i = self.tree.dof_body(k).unwrap_or(0);
        let range = self.tree.dof_range(i);
        let joint = self.tree.joint(i);
        if let Some(joint) = joint
            && joint.has_rotation_vector()
        {
            let start = range.end - 3;
            if self.q[start..range.end].iter().any(|&phi| phi != 0.0) {
                return Err(MechanismError::NotRebased { body: i });
            }
        }
        Ok(())
    }

    /// The world position of the point with body coordinates `p_b` (ground when `body` is None:
    /// then `p_b` is already a world point).
    pub fn point(&self, body: Option<usize>, p_b: &Vector3<f64>) -> Result<Vector3<f64>, MechanismError> {
        match body {
            Some(i) => Ok(self.workspace.point_position(i, p_b)?),
            None => Ok(*p_b),
        }
    }

    /// Adds c·∂x/∂q_k for the world point x moving with `body` (ground: nothing) into the
    /// 3×n column-major array `jacobian`.
    pub fn add_point_jacobian(&self, body: Option<usize>, x: &Vector3<f64>, c: f64, jacobian: &mut [f64]) {
        let Some(body) = body else { return };
        for k in self.path_coordinates(body) {
            let col = self.columns[k].at(x) * c;
            for r in 0..3 {
                jacobian[3 * k + r] += col[r];
            }
        }
    }

    /// Adds Σ f·∂²x/∂q_k∂q_l (both orders) into `hessian` (n×n) for the world point x moving
    /// with `body` (ground: nothing). Exact by the rule of the module docs.
    pub fn add_point_hessian(
        &self,
        body: Option<usize>,
        x: &Vector3<f64>,
        f: &Vector3<f64>,
        hessian: &mut faer::Mat<f64>,
    ) -> Result<(), MechanismError> {
        let Some(body) = body else { return Ok(()) };
        let path = self.path_coordinates(body);
        for (ia, &k) in path.iter().enumerate() {
            for &l in &path[ia..] {
                let (first, second, block) = self.ordered(k, l);
                let value = if block {
                    self.require_rebased(k)?;
                    let (ck, cl) = (self.columns[k], self.columns[l]);
                    0.5 * f.dot(&(ck.w.cross(&cl.at(x)) + cl.w.cross(&ck.at(x))))
                } else {
                    let (cf, cs) = (self.columns[first], self.columns[second]);
                    f.dot(&cf.w.cross(&cs.at(x)))
                };
                hessian[(k, l)] += value;
                if k != l {
                    hessian[(l, k)] += value;
                }
            }
        }
        Ok(())
    }
}
