//! The mass matrix A(q) = \[α_kl\] of a kinematic tree (8.27–8.28) by a composite-rigid-body
//! recursion, the kinetic energy T = ½ q̇ᵀ A q̇, the generalized momenta ∂T/∂q̇ = A q̇, and the
//! centre of mass of the whole system with its Jacobian.
//!
//! With the motion columns (w_k, v_k) of the tree (see `mechanica_kinematics::tree`), every
//! body of the subtree of body j moves rigidly under q̇_k for k a coordinate of j, so
//! α_kl = ∫ρ ∂x/∂q_k·∂x/∂q_l dV over that subtree collapses onto its composite mass
//! properties (m_c, x_c, J_c), summed leaves-to-root with Steiner (3.27–3.29):
//! α_kl = m_c u_k·u_l + w_k·J_c w_l with u = w × (x_c − o) + v, for l a coordinate of j or of
//! one of its ancestors. Cost: O(n) for the composites plus O(depth) per column.
//!
//! With a prescribed (rheonomic) base motion, [`TreeMass::energy_split`] gives the split
//! T = T₀ + T₁ + T₂ (9.7–9.10): the drag field ∂x/∂t = v₀ + ω₀ × (x − p₀) of the base is a rigid
//! velocity field, so T₀ and b_k = ∫ρ ∂x/∂q_k·∂x/∂t dV collapse onto composite mass properties
//! exactly like α_kl.
//!
//! Every result is checked: an entry of A, a momentum, an energy or a centre of mass that
//! overflows f64 is [`MassError::NonFiniteResult`].

use crate::error::check_result;
use crate::validity::symmetric_part;
use crate::{MassError, MassProperties};
use mechanica_kinematics::tree::{BaseState, KinematicTree, Workspace};
use nalgebra::{Matrix3, Vector3};

/// The kinetic energy of a tree on a moving base split by powers of q̇ (9.7–9.10):
/// T₀ = ½∫ρ |∂x/∂t|² dV, T₁ = b·q̇ with b_k = ∫ρ ∂x/∂t·∂x/∂q_k dV, T₂ = ½ q̇ᵀ A q̇.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergySplit {
    /// T₀ (9.8): the energy of the drag motion alone (q̇ = 0), J.
    pub t0: f64,
    /// T₁ (9.9): the part linear in q̇, J.
    pub t1: f64,
    /// T₂ (9.10): the quadratic part ½ q̇ᵀ A q̇, J.
    pub t2: f64,
}

impl EnergySplit {
    /// T = T₀ + T₁ + T₂ (9.7).
    pub fn total(&self) -> f64 {
        self.t0 + self.t1 + self.t2
    }
}

/// A rigid velocity field u(x) = v + ω × (x − o): the drag velocity ∂x/∂t of the points of a
/// tree whose base moves (v, ω: velocity of the base origin o and angular velocity, world).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DragField {
    /// The base origin o = p_W0 (world), m.
    pub origin: Vector3<f64>,
    /// The base angular velocity ω₀ (world), rad/s.
    pub omega: Vector3<f64>,
    /// The velocity v₀ of the base origin (world), m/s.
    pub velocity: Vector3<f64>,
}

impl DragField {
    /// u(x) = v + ω × (x − o) at the world point `x`.
    pub fn velocity_at(&self, x: &Vector3<f64>) -> Vector3<f64> {
        self.velocity + self.omega.cross(&(x - self.origin))
    }
}

impl From<&BaseState> for DragField {
    /// The drag field of the base state (its pose's origin, angular velocity and velocity).
    fn from(base: &BaseState) -> Self {
        Self {
            origin: base.position,
            omega: base.omega,
            velocity: base.velocity,
        }
    }
}

/// The output buffers of [`TreeMass::energy_split`].
#[derive(Debug)]
pub struct SplitBuffers<'a> {
    /// A(q), dof × dof, column-major; must come in zeroed (see [`TreeMass::mass_matrix`]).
    pub mass_matrix: &'a mut [f64],
    /// b(q, t) = ∂T₁/∂q̇, dof entries.
    pub b: &'a mut [f64],
    /// The generalized momenta ∂T/∂q̇ = A q̇ + b, dof entries.
    pub momenta: &'a mut [f64],
}

/// The inner product ∫ρ (a + α × (x − c))·(b + β × (x − c)) dV of two rigid velocity fields over
/// a body with mass m, centre c and central tensor J, given by their velocities a, b at the
/// centre: m a·b + α·J β (the cross terms vanish since ∫ρ (x − c) dV = 0, and
/// ∫ρ (α × y)·(β × y) dV = α·J β by (3.17)).
#[inline]
fn field_product(
    body: &MassProperties,
    a: &Vector3<f64>,
    alpha: &Vector3<f64>,
    b: &Vector3<f64>,
    beta: &Vector3<f64>,
) -> f64 {
    body.mass * a.dot(b) + alpha.dot(&(body.inertia_c * beta))
}

/// The mass properties of every body of a tree (in its own body frame) and the buffers of the
/// recursion, sized once.
#[derive(Debug, Clone, PartialEq)]
pub struct TreeMass {
    bodies: Vec<MassProperties>,
    composite: Vec<MassProperties>,
    /// Per body: the moments of its subtree about the root's origin (for the mass matrix).
    subtree_moments: Vec<MomentsAbout>,
    /// Per coordinate l: the motion column (w_l, v̄_l) with v̄_l = v_l + (o_j − r) × w_l, the
    /// velocity per unit q̇_l of the body point at the reference r (see `mass_matrix`).
    columns: Vec<(Vector3<f64>, Vector3<f64>)>,
}

/// The union of two bodies in one frame; zero-mass parts are allowed: a massless link, or a
/// rotor whose tensor is the same about every point (no Steiner term without mass) and adds to
/// the other part's.
fn union(a: &MassProperties, b: &MassProperties) -> MassProperties {
    let with_rotor = |massive: &MassProperties, rotor: &MassProperties| MassProperties {
        inertia_c: massive.inertia_c + rotor.inertia_c,
        ..*massive
    };
    if b.mass == 0.0 {
        return with_rotor(a, b);
    }
    if a.mass == 0.0 {
        return with_rotor(b, a);
    }
    let mass = a.mass + b.mass;
    let c = a.p_oc + (b.p_oc - a.p_oc) * (b.mass / mass);
    MassProperties {
        mass,
        p_oc: c,
        inertia_c: a.inertia_about(&c) + b.inertia_about(&c),
    }
}

/// The mass moments of a set of bodies about a fixed world point r: the mass m, the first
/// moment h = Σ m_b (c_b − r) and the inertia tensor about r, I_r = Σ J_b + m_b [y_b]ₓᵀ[y_b]ₓ
/// with y_b = c_b − r (Steiner, 3.27–3.29). All three add over bodies, so the moments of a
/// subtree are the sums of its bodies' moments, with no division and no change of point.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct MomentsAbout {
    mass: f64,
    first: Vector3<f64>,
    second: Matrix3<f64>,
}

impl MomentsAbout {
    /// The moments about r of a body of mass `mass`, centre `centre` and central tensor `j`
    /// (symmetric; world components). A massless body has only its tensor (a rotor; zero for a
    /// massless link), about every point.
    fn of_body(mass: f64, centre: &Vector3<f64>, j: &Matrix3<f64>, r: &Vector3<f64>) -> Self {
        if mass == 0.0 {
            return Self {
                second: *j,
                ..Self::default()
            };
        }
        let y = centre - r;
        let h = y * mass;
        let (xx, yy, zz) = (h.x * y.x, h.y * y.y, h.z * y.z);
        let (xy, xz, yz) = (h.x * y.y, h.x * y.z, h.y * y.z);
        let steiner = Matrix3::new(yy + zz, -xy, -xz, -xy, xx + zz, -yz, -xz, -yz, xx + yy);
        Self {
            mass,
            first: h,
            second: j + steiner,
        }
    }

    fn add(&mut self, other: &Self) {
        self.mass += other.mass;
        self.first += other.first;
        self.second += other.second;
    }

    /// The momentum (linear p, angular L about r) of the set moving rigidly with angular
    /// velocity w and velocity v̄ of the point at r: p = m v̄ + w × h, L = I_r w + h × v̄.
    #[inline]
    fn momentum(&self, w: &Vector3<f64>, v: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
        (
            v * self.mass + w.cross(&self.first),
            self.second * w + self.first.cross(v),
        )
    }
}

impl TreeMass {
    /// One mass-properties value per body of `tree`, each in the body's own frame B (centre
    /// p_BC and central tensor in B). Masses must be finite and ≥ 0 (massless links are
    /// allowed); tensors must be finite. A bad body fails with [`MassError::Body`] naming it.
    pub fn new(tree: &KinematicTree, bodies: Vec<MassProperties>) -> Result<Self, MassError> {
        if bodies.len() != tree.body_count() {
            return Err(MassError::WrongLength {
                what: "body mass properties (one per tree body)",
                expected: tree.body_count(),
                got: bodies.len(),
            });
        }
        for (body, b) in bodies.iter().enumerate() {
            let check = || -> Result<(), MassError> {
                crate::error::check_finite(b.mass, "body mass")?;
                crate::error::check_all_finite(b.p_oc.iter(), "body centre of mass")?;
                crate::error::check_all_finite(b.inertia_c.iter(), "body inertia")?;
                if b.mass < 0.0 {
                    return Err(MassError::NonPositiveMass(b.mass));
                }
                Ok(())
            };
            check().map_err(|error| MassError::Body {
                body,
                error: Box::new(error),
            })?;
        }
        let composite = bodies.clone();
        let subtree_moments = vec![MomentsAbout::default(); bodies.len()];
        let columns = vec![(Vector3::zeros(), Vector3::zeros()); tree.dof()];
        Ok(Self {
            bodies,
            composite,
            subtree_moments,
            columns,
        })
    }

    /// Body `i`'s mass properties in world components at the pose in `ws`: centre R p_BC + o,
    /// central tensor R J Rᵀ (symmetrized).
    fn body_in_world(&self, ws: &Workspace, i: usize) -> Result<MassProperties, MassError> {
        let body = &self.bodies[i];
        let rotation = ws.rotation(i)?;
        let rotation = rotation.matrix();
        Ok(MassProperties {
            mass: body.mass,
            p_oc: rotation * body.p_oc + ws.position(i)?,
            inertia_c: symmetric_part(&(rotation * body.inertia_c * rotation.transpose())),
        })
    }

    /// Fills the composites (subtree mass properties in world components) from the poses of
    /// the last `update_positions` in `ws`.
    fn update_composites(&mut self, tree: &KinematicTree, ws: &Workspace) -> Result<(), MassError> {
        for i in 0..self.bodies.len() {
            self.composite[i] = self.body_in_world(ws, i)?;
        }
        for &i in tree.topological_order().iter().rev() {
            if let Some(p) = tree.parent(i) {
                self.composite[p] = union(&self.composite[p], &self.composite[i]);
            }
        }
        Ok(())
    }

    /// Fills the subtree moments about `r` (world) from the poses of the last
    /// `update_positions` in `ws`: each body's moments, then children added into parents.
    fn update_subtree_moments(
        &mut self,
        tree: &KinematicTree,
        ws: &Workspace,
        r: &Vector3<f64>,
    ) -> Result<(), MassError> {
        for i in 0..self.bodies.len() {
            let body = self.body_in_world(ws, i)?;
            self.subtree_moments[i] = MomentsAbout::of_body(body.mass, &body.p_oc, &body.inertia_c, r);
        }
        for &i in tree.topological_order().iter().rev() {
            if let Some(p) = tree.parent(i) {
                let child = self.subtree_moments[i];
                self.subtree_moments[p].add(&child);
            }
        }
        Ok(())
    }

    /// The mass matrix A(q) (8.28) at the configuration of the last `update_positions` in `ws`,
    /// into `out` (dof × dof, column-major; kg, kg·m or kg·m² by the units of q_k and q_l), by
    /// the composite-rigid-body recursion: exact up to rounding, symmetric by construction.
    /// Only the entries of coordinate pairs on one root path are written; the others are zero
    /// in A and are left as they are, so `out` must come in zeroed. Fails when `out` has the
    /// wrong length or `ws` holds no positions for `tree`.
    pub fn mass_matrix(&mut self, tree: &KinematicTree, ws: &Workspace, out: &mut [f64]) -> Result<(), MassError> {
        let n = tree.dof();
        if out.len() != n * n {
            return Err(MassError::WrongLength {
                what: "mass matrix output (dof²)",
                expected: n * n,
                got: out.len(),
            });
        }
        if self.columns.len() != n {
            self.columns.resize(n, (Vector3::zeros(), Vector3::zeros()));
        }
        // Moments are taken about the root's origin r, so that the per-pair work is two dot
        // products: with v̄_l = v_l + (o_j − r) × w_l, the velocity of the subtree's points is
        // u_l(x) = w_l × (x − r) + v̄_l, and α_kl = ∫ρ u_k·u_l dV = w_l·L_k + v̄_l·p_k with the
        // momentum (p_k, L_k about r) of the subtree moving with u_k ([`MomentsAbout`]).
        // Taking r on the tree keeps the rounding relative to its size.
        let root = tree.topological_order().first().copied().unwrap_or(0);
        let r = ws.position(root)?;
        self.update_subtree_moments(tree, ws, &r)?;
        for i in 0..tree.body_count() {
            let d = ws.position(i)? - r;
            for l in tree.dof_range(i) {
                let (w, v) = ws.motion_column(l)?;
                self.columns[l] = (w, v + d.cross(&w));
            }
        }
        // a·0 is 0 for a finite a and NaN otherwise: one sum tells whether any entry written
        // is not finite, without a second pass over the n² entries.
        let mut poison = 0.0;
        for i in 0..tree.body_count() {
            let moments = self.subtree_moments[i];
            for k in tree.dof_range(i) {
                let (w_k, v_k) = self.columns[k];
                // A massless subtree has zero moments and gives exact zeros.
                let (p, l_k) = moments.momentum(&w_k, &v_k);
                // k itself, the earlier coordinates of its joint, then every ancestor's.
                let mut carrier = Some(k);
                while let Some(l) = carrier {
                    let (w_l, v_l) = &self.columns[l];
                    let a = w_l.dot(&l_k) + v_l.dot(&p);
                    poison += a * 0.0;
                    out[k + n * l] = a;
                    out[l + n * k] = a;
                    carrier = tree.previous_dof(l);
                }
            }
        }
        if poison == 0.0 {
            Ok(())
        } else {
            check_result(out.iter(), "mass matrix")
        }
    }

    /// The generalized momenta ∂T/∂q̇ = A q̇ (7.113; EB1911 §22 (16)) and the kinetic energy
    /// T = ½ q̇ᵀ A q̇ for a fixed base, computing A into `a_out` (dof × dof, column-major,
    /// zeroed by the caller as for [`TreeMass::mass_matrix`]).
    /// With a moving base these are T₂ and its momenta only; see [`TreeMass::energy_split`].
    pub fn momenta_and_energy(
        &mut self,
        tree: &KinematicTree,
        ws: &Workspace,
        q_dot: &[f64],
        a_out: &mut [f64],
        momenta_out: &mut [f64],
    ) -> Result<f64, MassError> {
        let n = tree.dof();
        for (what, len) in [("q_dot", q_dot.len()), ("momenta output", momenta_out.len())] {
            if len != n {
                return Err(MassError::WrongLength {
                    what,
                    expected: n,
                    got: len,
                });
            }
        }
        crate::error::check_all_finite(q_dot.iter(), "q_dot")?;
        self.mass_matrix(tree, ws, a_out)?;
        let mut t = 0.0;
        for k in 0..n {
            let mut s = 0.0;
            for l in 0..n {
                s += a_out[k + n * l] * q_dot[l];
            }
            momenta_out[k] = s;
            t += 0.5 * q_dot[k] * s;
        }
        check_result(momenta_out.iter(), "generalized momenta")?;
        check_result([t].iter(), "kinetic energy")?;
        Ok(t)
    }

    /// The split T = T₀ + T₁ + T₂ (9.7–9.10) for a tree whose base moves with the drag field
    /// `drag` (usually `DragField::from(ws.base())`), at the positions of the last
    /// `update_positions` and the velocities `q_dot`. Writes A(q), b(q, t) and the generalized
    /// momenta ∂T/∂q̇ = A q̇ + b into `out` (its `mass_matrix` zeroed by the caller as for
    /// [`TreeMass::mass_matrix`]).
    ///
    /// The drag field ∂x/∂t = v₀ + ω₀ × (x − p₀) is rigid, so with the composite (m_c, x_c, J_c)
    /// of the subtree moved by q_k: b_k = m_c u_k·u(x_c) + w_k·J_c ω₀, and T₀ is the energy of the
    /// whole system moving with the drag field: ½ m |u(x₀)|² + ½ ω₀·J₀ ω₀ (König, 3.41).
    pub fn energy_split(
        &mut self,
        tree: &KinematicTree,
        ws: &Workspace,
        drag: &DragField,
        q_dot: &[f64],
        out: SplitBuffers<'_>,
    ) -> Result<EnergySplit, MassError> {
        let n = tree.dof();
        let SplitBuffers {
            mass_matrix: a_out,
            b: b_out,
            momenta: momenta_out,
        } = out;
        for (what, len) in [
            ("q_dot", q_dot.len()),
            ("b output", b_out.len()),
            ("momenta output", momenta_out.len()),
        ] {
            if len != n {
                return Err(MassError::WrongLength {
                    what,
                    expected: n,
                    got: len,
                });
            }
        }
        crate::error::check_all_finite(q_dot.iter(), "q_dot")?;
        crate::error::check_all_finite(
            drag.origin.iter().chain(drag.omega.iter()).chain(drag.velocity.iter()),
            "drag field",
        )?;
        self.mass_matrix(tree, ws, a_out)?;
        self.update_composites(tree, ws)?;
        let omega0 = drag.omega;
        let mut t0 = 0.0;
        for i in 0..tree.body_count() {
            let c = self.composite[i];
            if c.mass == 0.0 && c.inertia_c == Matrix3::zeros() {
                // A massless subtree carries no energy (as in mass_matrix).
                b_out[tree.dof_range(i)].fill(0.0);
                continue;
            }
            let u_c = drag.velocity_at(&c.p_oc);
            if tree.parent(i).is_none() {
                t0 += 0.5 * field_product(&c, &u_c, &omega0, &u_c, &omega0);
            }
            let o_i = ws.position(i)?;
            for k in tree.dof_range(i) {
                let (w_k, v_k) = ws.motion_column(k)?;
                let u_k = w_k.cross(&(c.p_oc - o_i)) + v_k;
                b_out[k] = field_product(&c, &u_k, &w_k, &u_c, &omega0);
            }
        }
        let (mut t1, mut t2) = (0.0, 0.0);
        for k in 0..n {
            let mut s = 0.0;
            for l in 0..n {
                s += a_out[k + n * l] * q_dot[l];
            }
            t2 += 0.5 * q_dot[k] * s;
            t1 += b_out[k] * q_dot[k];
            momenta_out[k] = s + b_out[k];
        }
        let split = EnergySplit { t0, t1, t2 };
        check_result(b_out.iter(), "velocity coupling b")?;
        check_result(momenta_out.iter(), "generalized momenta")?;
        check_result([t0, t1, t2, split.total()].iter(), "kinetic energy")?;
        Ok(split)
    }

    /// The mass properties of the whole system in world components (centre x₀ and central
    /// tensor), and the Jacobian ∂x₀/∂q into `jacobian_out` (3 × dof, column-major):
    /// column k = (m_c/m) (w_k × (x_c − o_i) + v_k) with the composite of k's body i.
    pub fn centre_of_mass(
        &mut self,
        tree: &KinematicTree,
        ws: &Workspace,
        jacobian_out: &mut [f64],
    ) -> Result<MassProperties, MassError> {
        let n = tree.dof();
        if jacobian_out.len() != 3 * n {
            return Err(MassError::WrongLength {
                what: "centre-of-mass Jacobian output (3·dof)",
                expected: 3 * n,
                got: jacobian_out.len(),
            });
        }
        self.update_composites(tree, ws)?;
        let root = (0..tree.body_count()).find(|&b| tree.parent(b).is_none()).unwrap_or(0);
        let total = self.composite[root];
        check_result([total.mass].iter(), "total mass")?;
        if total.mass <= 0.0 {
            return Err(MassError::NonPositiveTotalMass(total.mass));
        }
        check_result(
            total.p_oc.iter().chain(total.inertia_c.iter()),
            "system mass properties",
        )?;
        for i in 0..tree.body_count() {
            let c = self.composite[i];
            let o_i = ws.position(i)?;
            for k in tree.dof_range(i) {
                let (w_k, v_k) = ws.motion_column(k)?;
                let col: Vector3<f64> = (w_k.cross(&(c.p_oc - o_i)) + v_k) * (c.mass / total.mass);
                jacobian_out[3 * k..3 * k + 3].copy_from_slice(col.as_slice());
            }
        }
        check_result(jacobian_out.iter(), "centre-of-mass Jacobian")?;
        Ok(total)
    }
}
