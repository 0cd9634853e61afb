//! A mechanism: a kinematic tree with mass properties, gravity, an optional steadily rotating
//! base frame, and potentials. It evaluates U*(q) with its exact gradient and Hessian, the
//! mass matrix A(q) and the gyroscopic matrix G(q) of the relative motion.

use crate::potentials::{Potential, PotentialSum, UniformField};
use crate::{Configuration, MechanismError};
use faer::Mat;
use mechanica_kinematics::tree::{KinematicTree, Workspace};
use mechanica_mass::MassProperties;
use mechanica_mass::mechanism::TreeMass;
use nalgebra::{Unit, Vector3};
use std::sync::Arc;

/// The base frame turning at the constant rate Ω about a fixed axis through its origin (§8e).
/// Everything is then computed in that frame: the equilibrium is a relative equilibrium of
/// U* = U − T₀ (8.56–8.58) and small motions feel the Coriolis coupling G.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RotatingFrame {
    /// Unit axis (base-frame components).
    pub axis: Unit<Vector3<f64>>,
    /// Rate Ω (rad/s).
    pub rate: f64,
}

/// A kinematic tree with mass properties and loads.
#[derive(Debug, Clone)]
pub struct Mechanism {
    tree: KinematicTree,
    bodies: Vec<MassProperties>,
    tree_mass: TreeMass,
    gravity: Vector3<f64>,
    rotation: Option<RotatingFrame>,
    potentials: Vec<Arc<dyn Potential>>,
    limits: Vec<(f64, f64)>,
}

/// True when coordinate k of `body` is part of a spherical or free joint's rotation vector.
pub(crate) fn is_rotation_vector_coordinate(tree: &KinematicTree, body: usize, k: usize) -> bool {
    let range = tree.dof_range(body);
    tree.joint(body).is_some_and(|j| j.has_rotation_vector()) && k + 3 >= range.end
}

impl Mechanism {
    /// A mechanism from a tree and one mass-properties value per body (body frame), without
    /// loads. Massless bodies are allowed (they make A singular; see the modal crate).
    pub fn new(tree: KinematicTree, bodies: Vec<MassProperties>) -> Result<Self, MechanismError> {
        let tree_mass = TreeMass::new(&tree, bodies.clone())?;
        let n = tree.dof();
        Ok(Self {
            tree,
            bodies,
            tree_mass,
            gravity: Vector3::zeros(),
            rotation: None,
            potentials: Vec::new(),
            limits: vec![(f64::NEG_INFINITY, f64::INFINITY); n],
        })
    }

    /// The tree.
    pub fn tree(&self) -> &KinematicTree {
        &self.tree
    }

    /// The body mass properties (body frames).
    pub fn bodies(&self) -> &[MassProperties] {
        &self.bodies
    }

    /// Number of coordinates.
    pub fn dof(&self) -> usize {
        self.tree.dof()
    }

    /// Gravity g (base-frame components, m/s²).
    pub fn gravity(&self) -> Vector3<f64> {
        self.gravity
    }

    /// The rotating frame, if any.
    pub fn rotating_frame(&self) -> Option<RotatingFrame> {
        self.rotation
    }

    /// The potentials added so far.
    pub fn potentials(&self) -> &[Arc<dyn Potential>] {
        &self.potentials
    }

    /// The joint limits (lower, upper) per coordinate.
    pub fn limits(&self) -> &[(f64, f64)] {
        &self.limits
    }

    fn check_field(gravity: &Vector3<f64>, rotation: &Option<RotatingFrame>) -> Result<(), MechanismError> {
        crate::error::check_all_finite(gravity.iter(), "gravity")?;
        if let Some(frame) = rotation {
            crate::error::check_finite(frame.rate, "rotation rate")?;
            crate::error::check_all_finite(frame.axis.iter(), "rotation axis")?;
            let g = gravity.norm();
            if g > 0.0 && frame.rate != 0.0 {
                let sine = frame.axis.cross(gravity).norm() / g;
                if sine > 1e-12 {
                    return Err(MechanismError::GravityNotAlongAxis {
                        angle_deg: sine.clamp(-1.0, 1.0).asin().to_degrees(),
                    });
                }
            }
        }
        Ok(())
    }

    /// Sets uniform gravity (base-frame components).
    pub fn set_gravity(&mut self, gravity: Vector3<f64>) -> Result<(), MechanismError> {
        Self::check_field(&gravity, &self.rotation)?;
        self.gravity = gravity;
        Ok(())
    }

    /// Makes the base frame turn steadily (or stops it with None). Gravity must be along the axis.
    pub fn set_rotating_frame(&mut self, rotation: Option<RotatingFrame>) -> Result<(), MechanismError> {
        Self::check_field(&self.gravity, &rotation)?;
        self.rotation = rotation;
        Ok(())
    }

    /// Adds a potential after validating it against the tree; returns its index.
    pub fn add_potential(&mut self, potential: impl Potential + 'static) -> Result<usize, MechanismError> {
        potential.validate(&self.tree)?;
        self.potentials.push(Arc::new(potential));
        Ok(self.potentials.len() - 1)
    }

    /// Limits coordinate k to [lower, upper] in equilibrium searches (not allowed on
    /// rotation-vector coordinates, which are re-centred by [`Mechanism::rebase`]).
    pub fn set_limits(&mut self, k: usize, lower: f64, upper: f64) -> Result<(), MechanismError> {
        let body = self.tree.dof_body(k).ok_or(MechanismError::NoSuchCoordinate {
            what: "joint limit",
            index: k,
            dof: self.dof(),
        })?;
        if lower.is_nan() || upper.is_nan() || lower > upper || is_rotation_vector_coordinate(&self.tree, body, k) {
            return Err(MechanismError::BadLimits { index: k, lower, upper });
        }
        self.limits[k] = (lower, upper);
        Ok(())
    }

    /// True when some joint uses rotation-vector coordinates (spherical or free).
    pub fn has_rotation_vectors(&self) -> bool {
        (0..self.tree.body_count()).any(|i| self.tree.joint(i).is_some_and(|j| j.has_rotation_vector()))
    }

    /// Folds the rotation vectors of `q` into the tree's reference orientations and zeroes
    /// them, without moving any body (see `KinematicTree::rebase`). Hessians in those
    /// coordinates are exact only at φ = 0.
    pub fn rebase(&mut self, q: &mut [f64]) -> Result<(), MechanismError> {
        let mut q_dot = vec![0.0; q.len()];
        self.tree.rebase(q, &mut q_dot)?;
        Ok(())
    }

    fn check_q(&self, q: &[f64]) -> Result<(), MechanismError> {
        if q.len() != self.dof() {
            return Err(MechanismError::WrongLength {
                what: "q",
                expected: self.dof(),
                got: q.len(),
            });
        }
        crate::error::check_all_finite(q, "q")
    }

    /// Forward kinematics at q with the base at rest (the rotating frame's own view).
    pub(crate) fn positions(&self, q: &[f64]) -> Result<Workspace, MechanismError> {
        self.check_q(q)?;
        let mut ws = self.tree.workspace();
        self.tree.update_positions(&mut ws, q)?;
        Ok(ws)
    }

    /// The field part of U*: gravity plus, in a rotating frame, −T₀ (8.56–8.58).
    pub fn field(&self) -> UniformField {
        match self.rotation {
            Some(frame) => UniformField::rotating(self.gravity, &frame.axis, frame.rate),
            None => UniformField::gravity(self.gravity),
        }
    }

    /// Whether gravity or a rotating frame contributes to U*.
    pub(crate) fn field_is_active(&self) -> bool {
        self.gravity != Vector3::zeros() || self.rotation.is_some()
    }

    /// U*(q) = U(q) − T₀(q) with its exact gradient and, when asked, its exact Hessian B(q) =
    /// ∂²U*/∂q∂q (8.85). Errors name the potential that failed.
    pub fn potential(&self, q: &[f64], with_hessian: bool) -> Result<PotentialSum, MechanismError> {
        let ws = self.positions(q)?;
        let config = Configuration::new(&self.tree, &ws, q, &self.bodies)?;
        let mut sum = PotentialSum::new(self.dof(), with_hessian);
        if self.field_is_active() {
            self.field().accumulate(&config, &mut sum)?;
        }
        for potential in &self.potentials {
            potential.accumulate(&config, &mut sum)?;
        }
        crate::error::check_finite(sum.value, "potential energy")?;
        crate::error::check_all_finite(&sum.gradient, "potential gradient")?;
        if let Some(h) = &sum.hessian {
            for j in 0..h.ncols() {
                crate::error::check_all_finite(h.col(j).iter(), "potential Hessian")?;
            }
        }
        Ok(sum)
    }

    /// Each added potential evaluated on its own at q (the field of gravity and rotation is not
    /// included): its name, U, ∂U/∂q and the point forces through which it acts (see
    /// [`PotentialSum::point_forces`]). No Hessians. Errors name the potential that failed.
    pub fn potential_terms(&self, q: &[f64]) -> Result<Vec<(String, PotentialSum)>, MechanismError> {
        let ws = self.positions(q)?;
        let config = Configuration::new(&self.tree, &ws, q, &self.bodies)?;
        let mut terms = Vec::with_capacity(self.potentials.len());
        for potential in &self.potentials {
            let mut sum = PotentialSum::new(self.dof(), false);
            potential.accumulate(&config, &mut sum)?;
            crate::error::check_finite(sum.value, "potential energy")?;
            crate::error::check_all_finite(&sum.gradient, "potential gradient")?;
            terms.push((potential.name(), sum));
        }
        Ok(terms)
    }

    /// The mass matrix A(q) (8.28) of the motion relative to the base.
    pub fn mass_matrix(&mut self, q: &[f64]) -> Result<Mat<f64>, MechanismError> {
        let mut ws = self.tree.workspace();
        let n = self.dof();
        let mut a = vec![0.0; n * n];
        self.mass_matrix_into(q, &mut ws, &mut a)?;
        Ok(Mat::from_fn(n, n, |i, j| a[i + n * j]))
    }

    /// A(q) as [`Mechanism::mass_matrix`], written into `out` (dof × dof, column-major, every
    /// entry overwritten) with the positions of q computed in `ws`, a workspace of this
    /// mechanism's tree (its velocities and accelerations are discarded). Allocates nothing
    /// once the mechanism has evaluated one mass matrix. Fails when q or `out` has the wrong
    /// length, q is not finite, or `ws` belongs to another tree.
    pub fn mass_matrix_into(&mut self, q: &[f64], ws: &mut Workspace, out: &mut [f64]) -> Result<(), MechanismError> {
        self.check_q(q)?;
        self.tree.update_positions(ws, q)?;
        out.fill(0.0);
        self.tree_mass.mass_matrix(&self.tree, ws, out)?;
        Ok(())
    }

    /// A componentwise bound E on the rounding of the field's part of B(q) as
    /// [`Mechanism::potential`] forms it (gravity and the rotating frame's −T₀; zero without
    /// them): |B_computed − B_exact| ≤ E entry by entry, with the rounding model of
    /// docs/theory.md, "Assembly error of A and B". Rotation vectors must be zero, as for the
    /// Hessian.
    pub fn field_hessian_rounding(&self, q: &[f64]) -> Result<Mat<f64>, MechanismError> {
        crate::assembly_error::AssemblyError::field_rounding(self, q)
    }

    /// The gyroscopic matrix G(q) of the motion relative to a rotating frame (zero without
    /// one): G_kl = 2 ∫ρ ∂x/∂q_k · (Ω × ∂x/∂q_l) dV, skew-symmetric, so that small motions obey
    /// A δ̈ + G δ̇ + B δ = 0. With the subtree moments (m, h, S) of the later of k, l:
    /// G_kl = 2 Ω·[−S (w_k × w_l) + (w_l × h) × a_k + a_l × (w_k × h) + m a_l × a_k]
    ///      = 2 [w_k·(h × (Ω × a_l) − w_l × SΩ) + a_k·(Ω × (w_l × h) + m Ω × a_l)],
    /// linear in k's column, so each later coordinate l costs O(depth): O(n·depth) in all.
    pub fn gyroscopic_matrix(&self, q: &[f64]) -> Result<Mat<f64>, MechanismError> {
        let ws = self.positions(q)?;
        let n = self.dof();
        let mut g = Mat::zeros(n, n);
        let Some(frame) = self.rotation else { return Ok(g) };
        let omega = frame.axis.into_inner() * frame.rate;
        let config = Configuration::new(&self.tree, &ws, q, &self.bodies)?;
        for late in 0..n {
            let body = self.tree.dof_body(late).unwrap_or(0);
            let m = config.subtree_moments(body);
            let cl = config.column(late);
            let on_w = m.first.cross(&omega.cross(&cl.a)) - cl.w.cross(&(m.second * omega));
            let on_a = omega.cross(&cl.w.cross(&m.first)) + omega.cross(&cl.a) * m.mass;
            for early in config.carriers(late).filter(|&e| e != late) {
                let ce = config.column(early);
                let value = 2.0 * (ce.w.dot(&on_w) + ce.a.dot(&on_a));
                g[(early, late)] = value;
                g[(late, early)] = -value;
            }
        }
        Ok(g)
    }
}
