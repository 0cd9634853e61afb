//! Kinematic trees: bodies connected by joints, forward kinematics, body velocities and
//! accelerations, point and angular-velocity Jacobians ∂x/∂q_k (1.37) and their time
//! derivatives, with an optional prescribed (rheonomic) motion of the base.
//!
//! # Building
//! [`TreeBuilder::add_body`] names each body's parent (or `None` for the body attached to the
//! base), its [`Joint`] and the joint placement X_PJ. Parents may be named before they are
//! added; [`TreeBuilder::build`] validates the whole tree: at least one body, exactly one root,
//! every parent index in range, no cycles (every body reaches the root), unit joint axes and
//! finite placements. Body indices are the order of `add_body` calls; coordinates are laid out
//! body by body in that order ([`KinematicTree::dof_range`]).
//!
//! # Computing
//! A [`Workspace`] (from [`KinematicTree::workspace`]) holds every per-call buffer, so the
//! computations below allocate nothing:
//! 1. [`KinematicTree::update_positions`]: body poses R_WB, p_WB and the *motion columns*;
//! 2. [`KinematicTree::update_velocities`]: ω_B, v_B and the column rates;
//! 3. [`KinematicTree::update_accelerations`]: ω̇_B, a_B.
//!
//! # Motion columns (the interface for the mass matrix)
//! For every degree of freedom k, owned by body i = [`KinematicTree::dof_body`]`(k)`, the
//! workspace stores the world-frame pair (w_k, v_k) ([`Workspace::motion_column`]): the angular
//! velocity of body i, and the velocity of body i's origin o_i, produced by q̇_k = 1 with all
//! other q̇ zero. Every body b in the subtree of i moves rigidly with i under q̇_k, so for any
//! point x of such a body
//!
//! ∂x/∂q_k = w_k × (x − o_i) + v_k,   ∂ω_b/∂q̇_k = w_k,
//!
//! and both vanish when i is not an ancestor of b (or b itself). These columns are the joint
//! motion subspaces S_i in world coordinates, referenced to o_i. A composite-rigid-body
//! recursion gets A(q) from them: with the composite (subtree) mass m_c, centre of mass x_c and
//! central inertia J_c of the subtree of body j, accumulated leaves-to-root along
//! [`KinematicTree::topological_order`] reversed with Steiner (3.27–3.29), and for k a DOF of
//! body j and l a DOF of j or of an ancestor of j (shift both columns to x_c:
//! u_k = w_k × (x_c − o_j) + v_k, u_l = w_l × (x_c − o_{i(l)}) + v_l):
//!
//! A_kl = m_c u_k·u_l + w_k·J_c w_l   (the Gram form α_kl = ∫ρ ∂x/∂q_k·∂x/∂q_l dV of (8.28)).
//!
//! [`Workspace::column_at`] does the shift. The column rates ([`Workspace::motion_column_rate`])
//! give the Jacobian rates J̇ for the velocity-product terms.
//!
//! # Base motion
//! By default the root's parent is the fixed world. [`Workspace::set_base`] prescribes the base
//! frame's pose, velocity and acceleration at the current time (e.g. from a [`BaseMotion`] such
//! as [`SteadyRotation`] for the rotating-frame equilibrium of §8e). x = x(q, t) is then
//! rheonomic and ∂x/∂t at fixed q is the drag velocity of the base ([`Workspace::drag_velocity`]).
//!
//! # Errors
//! Inputs are checked (lengths, finiteness, rotation vectors of spherical and free joints no
//! longer than [`crate::rotation::ROTATION_VECTOR_LIMIT`]), and so are results: a pose,
//! velocity, acceleration, Jacobian entry or point quantity that overflows f64 is
//! [`KinematicsError::NonFiniteResult`]. An update that fails invalidates the stage it was
//! computing and the later ones (positions before velocities before accelerations), so nothing
//! computed from overflowed values can be read.

mod joint;
mod workspace;

pub use joint::Joint;
pub use workspace::Workspace;

use crate::KinematicsError;
use crate::rotation::{exp_unchecked, right_jacobian};
use nalgebra::{Isometry3, Matrix3, Rotation3, Unit, Vector3};

/// One body as given to the builder.
#[derive(Debug, Clone, Copy, PartialEq)]
struct BodySpec {
    parent: Option<usize>,
    joint: Joint,
    placement: Isometry3<f64>,
}

/// Collects bodies and joints; [`TreeBuilder::build`] validates them into a [`KinematicTree`].
#[derive(Debug, Clone, Default)]
pub struct TreeBuilder {
    bodies: Vec<BodySpec>,
}

impl TreeBuilder {
    /// An empty builder.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a body hanging from `parent` (a body index, possibly of a body added later, or
    /// `None` for the root, attached to the base) by `joint`, whose frame J sits at
    /// `placement` = X_PJ in the parent's frame (in the base frame for the root). Returns the
    /// new body's index. Nothing is checked until [`TreeBuilder::build`].
    pub fn add_body(&mut self, parent: Option<usize>, joint: Joint, placement: Isometry3<f64>) -> usize {
        self.bodies.push(BodySpec {
            parent,
            joint,
            placement,
        });
        self.bodies.len() - 1
    }

    /// Number of bodies added so far.
    pub fn len(&self) -> usize {
        self.bodies.len()
    }

    /// True when no body was added.
    pub fn is_empty(&self) -> bool {
        self.bodies.is_empty()
    }

    /// Validates the tree (see the module docs) and returns it.
    pub fn build(self) -> Result<KinematicTree, KinematicsError> {
        let n = self.bodies.len();
        if n == 0 {
            return Err(KinematicsError::EmptyTree);
        }
        let root = self.checked_root()?;
        let order = self.depth_first_order(root)?;
        let (dof_start, dof_body, nv) = self.dof_layout();
        let depth = self.depths(&order);
        let previous_dof = self.previous_dofs(&order, &dof_start, nv);
        Ok(KinematicTree {
            parent: self.bodies.iter().map(|b| b.parent).collect(),
            joint: self.bodies.iter().map(|b| normalized_joint(b.joint)).collect(),
            r_pj: self
                .bodies
                .iter()
                .map(|b| *b.placement.rotation.to_rotation_matrix().matrix())
                .collect(),
            p_pj: self.bodies.iter().map(|b| b.placement.translation.vector).collect(),
            r_ref: vec![Matrix3::identity(); n],
            rev_terms: self.bodies.iter().map(revolute_terms).collect(),
            order,
            dof_start,
            dof_body,
            depth,
            previous_dof,
            nv,
        })
    }

    /// The root (the one body without a parent), checking every body on the way: parent index
    /// in range, finite placement, finite unit joint axis.
    fn checked_root(&self) -> Result<usize, KinematicsError> {
        let n = self.bodies.len();
        let mut root = None;
        for (body, spec) in self.bodies.iter().enumerate() {
            match spec.parent {
                None => match root {
                    None => root = Some(body),
                    Some(first) => return Err(KinematicsError::MultipleRoots { first, second: body }),
                },
                Some(parent) if parent >= n => {
                    return Err(KinematicsError::ParentOutOfRange {
                        body,
                        parent,
                        bodies: n,
                    });
                }
                Some(_) => {}
            }
            check_placement_and_axis(body, spec)?;
        }
        root.ok_or(KinematicsError::NoRoot)
    }

    /// The bodies in depth-first order from `root` (children in index order), each parent
    /// before its children; a body never reached lies on or below a cycle, which is an error.
    fn depth_first_order(&self, root: usize) -> Result<Vec<usize>, KinematicsError> {
        let n = self.bodies.len();
        // Children lists (compressed: the children of b are children[child_start[b]..child_start[b + 1]]).
        let mut child_start = vec![0usize; n + 1];
        for spec in &self.bodies {
            if let Some(p) = spec.parent {
                child_start[p + 1] += 1;
            }
        }
        for i in 0..n {
            child_start[i + 1] += child_start[i];
        }
        let mut children = vec![0usize; child_start[n]];
        let mut fill = child_start.clone();
        for (body, spec) in self.bodies.iter().enumerate() {
            if let Some(p) = spec.parent {
                children[fill[p]] = body;
                fill[p] += 1;
            }
        }
        let mut order = Vec::with_capacity(n);
        let mut visited = vec![false; n];
        let mut stack = vec![root];
        while let Some(b) = stack.pop() {
            if visited[b] {
                continue;
            }
            visited[b] = true;
            order.push(b);
            for &c in children[child_start[b]..child_start[b + 1]].iter().rev() {
                stack.push(c);
            }
        }
        if let Some(body) = visited.iter().position(|v| !v) {
            return Err(KinematicsError::Cycle { body });
        }
        Ok(order)
    }

    /// The coordinate layout, body by body in index order: the first coordinate of each body
    /// (n + 1 entries, the last = dof), the body owning each coordinate, and the dof.
    fn dof_layout(&self) -> (Vec<usize>, Vec<usize>, usize) {
        let mut dof_start = Vec::with_capacity(self.bodies.len() + 1);
        let mut dof_body = Vec::new();
        let mut nv = 0;
        for (body, spec) in self.bodies.iter().enumerate() {
            dof_start.push(nv);
            nv += spec.joint.dof();
            dof_body.extend(std::iter::repeat_n(body, spec.joint.dof()));
        }
        dof_start.push(nv);
        (dof_start, dof_body, nv)
    }

    /// Each coordinate's predecessor on its root path (see [`KinematicTree::previous_dof`]),
    /// from a parents-first `order` and the coordinate ranges `dof_start`.
    fn previous_dofs(&self, order: &[usize], dof_start: &[usize], nv: usize) -> Vec<Option<usize>> {
        let mut previous = vec![None; nv];
        // The last coordinate on the path from the base to each body, the body's own included.
        let mut last_on_path: Vec<Option<usize>> = vec![None; self.bodies.len()];
        for &b in order {
            let above = self.bodies[b].parent.and_then(|p| last_on_path[p]);
            let range = dof_start[b]..dof_start[b + 1];
            for k in range.clone() {
                previous[k] = if k == range.start { above } else { Some(k - 1) };
            }
            last_on_path[b] = range.last().or(above);
        }
        previous
    }

    /// The number of joints between each body and the base, from a parents-first `order`.
    fn depths(&self, order: &[usize]) -> Vec<usize> {
        let mut depth = vec![0usize; self.bodies.len()];
        for &b in order {
            if let Some(p) = self.bodies[b].parent {
                depth[b] = depth[p] + 1;
            }
        }
        depth
    }
}

/// Ok when body `body`'s placement is finite and its revolute or prismatic axis is finite and
/// of unit length within [`crate::rotation::AXIS_TOLERANCE`].
fn check_placement_and_axis(body: usize, spec: &BodySpec) -> Result<(), KinematicsError> {
    let iso = &spec.placement;
    let values = iso.translation.vector.iter().chain(iso.rotation.coords.iter()).copied();
    if let Some(value) = values.clone().find(|v| !v.is_finite()) {
        return Err(KinematicsError::NonFiniteEntry {
            what: "body placement",
            index: body,
            value,
        });
    }
    if let Joint::Revolute { axis } | Joint::Prismatic { axis } = spec.joint {
        if let Some(value) = axis.iter().copied().find(|v| !v.is_finite()) {
            return Err(KinematicsError::NonFiniteEntry {
                what: "joint axis",
                index: body,
                value,
            });
        }
        let norm = axis.norm();
        if (norm - 1.0).abs() > crate::rotation::AXIS_TOLERANCE {
            return Err(KinematicsError::JointAxisNotUnit { body, norm });
        }
    }
    Ok(())
}

/// The joint with its revolute or prismatic axis normalised exactly.
fn normalized_joint(joint: Joint) -> Joint {
    match joint {
        Joint::Revolute { axis } => Joint::Revolute {
            axis: crate::scaling::unit(&axis).unwrap_or(axis),
        },
        Joint::Prismatic { axis } => Joint::Prismatic {
            axis: crate::scaling::unit(&axis).unwrap_or(axis),
        },
        other => other,
    }
}

/// For a revolute joint, (R_PJ [a]×, R_PJ [a]×², R_PJ a) with the normalised axis a; zeros
/// for every other joint (see [`KinematicTree`]'s `rev_terms`).
fn revolute_terms(b: &BodySpec) -> (Matrix3<f64>, Matrix3<f64>, Vector3<f64>) {
    let r = *b.placement.rotation.to_rotation_matrix().matrix();
    match b.joint {
        Joint::Revolute { axis } => {
            let axis = crate::scaling::unit(&axis).unwrap_or(axis);
            let k = crate::rotation::skew(&axis);
            (r * k, r * k * k, r * axis)
        }
        _ => (Matrix3::zeros(), Matrix3::zeros(), Vector3::zeros()),
    }
}

/// A validated kinematic tree (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct KinematicTree {
    parent: Vec<Option<usize>>,
    joint: Vec<Joint>,
    r_pj: Vec<Matrix3<f64>>,
    p_pj: Vec<Vector3<f64>>,
    r_ref: Vec<Matrix3<f64>>,
    /// For revolute joints, (R_PJ [a]×, R_PJ [a]×², R_PJ a), so that
    /// R_PB = R_PJ + sin q · R_PJ[a]× + (1 − cos q) · R_PJ[a]×² (Rodrigues) costs no product.
    rev_terms: Vec<(Matrix3<f64>, Matrix3<f64>, Vector3<f64>)>,
    order: Vec<usize>,
    dof_start: Vec<usize>,
    dof_body: Vec<usize>,
    depth: Vec<usize>,
    previous_dof: Vec<Option<usize>>,
    nv: usize,
}

impl KinematicTree {
    /// Number of bodies.
    pub fn body_count(&self) -> usize {
        self.parent.len()
    }

    /// Number of coordinates q (= number of velocities q̇).
    pub fn dof(&self) -> usize {
        self.nv
    }

    /// The parent of `body` (`None` for the root).
    pub fn parent(&self, body: usize) -> Option<usize> {
        self.parent.get(body).copied().flatten()
    }

    /// All parent links, indexed by body.
    pub fn parents(&self) -> &[Option<usize>] {
        &self.parent
    }

    /// The joint of `body`.
    pub fn joint(&self, body: usize) -> Option<&Joint> {
        self.joint.get(body)
    }

    /// The joint placement X_PJ of `body` as (R_PJ, p_PJ).
    pub fn placement(&self, body: usize) -> Option<(Matrix3<f64>, Vector3<f64>)> {
        Some((*self.r_pj.get(body)?, self.p_pj[body]))
    }

    /// Bodies ordered so that each parent comes before its children (root first). Reverse it
    /// for leaves-to-root recursions (composite rigid bodies).
    pub fn topological_order(&self) -> &[usize] {
        &self.order
    }

    /// Number of joints between `body` and the base (the root has depth 0).
    pub fn depth(&self, body: usize) -> Option<usize> {
        self.depth.get(body).copied()
    }

    /// The coordinate indices of `body`'s joint.
    pub fn dof_range(&self, body: usize) -> std::ops::Range<usize> {
        match self.dof_start.get(body + 1) {
            Some(&end) => self.dof_start[body]..end,
            None => 0..0,
        }
    }

    /// The coordinate before `k` on its path to the base: k − 1 within k's joint, else the last
    /// coordinate of the nearest ancestor joint that has one (`None` at the first coordinate of
    /// a root path, or when k is out of range). Following it from k visits every coordinate
    /// that carries k, k's own included, in O(depth) with no joint of zero coordinates on the way.
    pub fn previous_dof(&self, k: usize) -> Option<usize> {
        self.previous_dof.get(k).copied().flatten()
    }

    /// The body whose joint owns coordinate `k`.
    pub fn dof_body(&self, k: usize) -> Option<usize> {
        self.dof_body.get(k).copied()
    }

    /// True when `ancestor` is `body` or lies on its path to the root.
    pub fn is_ancestor_or_self(&self, ancestor: usize, body: usize) -> bool {
        let mut b = Some(body);
        while let Some(i) = b {
            if i == ancestor {
                return true;
            }
            b = self.parent(i);
        }
        false
    }

    /// The reference orientation R_ref of a spherical or free joint (identity otherwise).
    pub fn reference_rotation(&self, body: usize) -> Option<Rotation3<f64>> {
        self.r_ref.get(body).map(|m| Rotation3::from_matrix_unchecked(*m))
    }

    /// A workspace sized for this tree.
    pub fn workspace(&self) -> Workspace {
        Workspace::new(self.body_count(), self.nv)
    }

    fn check_vector(&self, v: &[f64], what: &'static str) -> Result<(), KinematicsError> {
        if v.len() != self.nv {
            return Err(KinematicsError::WrongLength {
                what,
                expected: self.nv,
                got: v.len(),
            });
        }
        if let Some((index, &value)) = v.iter().enumerate().find(|(_, x)| !x.is_finite()) {
            return Err(KinematicsError::NonFiniteEntry { what, index, value });
        }
        Ok(())
    }

    /// Re-centres the exponential coordinates of every spherical and free joint (see
    /// [`Joint`]): R_ref ← R_ref exp(φ), φ ← 0, and φ̇ ← J_r(φ) φ̇ so that the body velocities
    /// are unchanged. Poses are unchanged; workspaces must be updated again. Everything is
    /// computed and checked before anything changes: on an error (a rotation vector beyond
    /// [`crate::rotation::ROTATION_VECTOR_LIMIT`], a rate that overflows) the tree, `q` and
    /// `q_dot` are left as they were.
    pub fn rebase(&mut self, q: &mut [f64], q_dot: &mut [f64]) -> Result<(), KinematicsError> {
        self.check_vector(q, "q")?;
        self.check_vector(q_dot, "q_dot")?;
        let mut updates = Vec::new();
        for body in 0..self.body_count() {
            let joint = self.joint[body];
            if !joint.has_rotation_vector() {
                continue;
            }
            let s = self.dof_start[body] + joint.rotation_offset();
            let phi = Vector3::new(q[s], q[s + 1], q[s + 2]);
            crate::rotation::check_rotation_vector(&phi, "joint rotation vector")?;
            let phi_dot = Vector3::new(q_dot[s], q_dot[s + 1], q_dot[s + 2]);
            let w = right_jacobian(&phi) * phi_dot;
            crate::rotation::check_result(w.iter(), "re-centred joint rate")?;
            let fixed = crate::rotation::orthonormalize_matrix(&(self.r_ref[body] * exp_unchecked(&phi).matrix()))?;
            updates.push((body, s, *fixed.rotation.matrix(), w));
        }
        for (body, s, r_ref, w) in updates {
            self.r_ref[body] = r_ref;
            q[s..s + 3].fill(0.0);
            q_dot[s..s + 3].copy_from_slice(w.as_slice());
        }
        Ok(())
    }
}

/// The pose, velocity and acceleration of the base frame (the root's parent) in the world,
/// at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaseState {
    /// R_W0.
    pub rotation: Rotation3<f64>,
    /// p_W0 (world).
    pub position: Vector3<f64>,
    /// Angular velocity of the base (world).
    pub omega: Vector3<f64>,
    /// Velocity of the base origin (world).
    pub velocity: Vector3<f64>,
    /// Angular acceleration of the base (world).
    pub omega_dot: Vector3<f64>,
    /// Acceleration of the base origin (world).
    pub acceleration: Vector3<f64>,
}

impl Default for BaseState {
    fn default() -> Self {
        BaseState {
            rotation: Rotation3::identity(),
            position: Vector3::zeros(),
            omega: Vector3::zeros(),
            velocity: Vector3::zeros(),
            omega_dot: Vector3::zeros(),
            acceleration: Vector3::zeros(),
        }
    }
}

/// A prescribed motion of the base as a function of time (rheonomic constraint).
pub trait BaseMotion {
    /// The base state at time t.
    fn state_at(&self, t: f64) -> BaseState;
}

/// The base turning at a constant rate about a fixed axis through the world origin (§8e):
/// R_W0(t) = exp(t Ω a), ω = Ω a, origin fixed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SteadyRotation {
    /// Unit axis (world).
    pub axis: Unit<Vector3<f64>>,
    /// Rate Ω (rad/s).
    pub rate: f64,
}

impl BaseMotion for SteadyRotation {
    /// R_W0 = the rotation by Ω t about the axis (the angle reduced exactly, as
    /// [`crate::rotation::rotation_from_axis_angle`] does); a product Ω t that overflows gives
    /// a non-finite rotation, which [`Workspace::set_base`] refuses.
    fn state_at(&self, t: f64) -> BaseState {
        let omega = self.axis.into_inner() * self.rate;
        BaseState {
            rotation: Rotation3::from_matrix_unchecked(crate::rotation::axis_angle_matrix(&self.axis, self.rate * t)),
            omega,
            ..BaseState::default()
        }
    }
}

#[cfg(test)]
mod tests;
