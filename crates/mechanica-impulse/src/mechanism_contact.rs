//! Contacts of a mechanism with the environment or between two of its bodies: contact
//! Jacobians, the contact-space (Delassus) matrix W = J A⁻¹ Jᵀ, and the single frictional
//! impact solved by the impulse-parameterised process of [`crate::contact_space`].
//!
//! A contact i pairs a body point x_i (which receives +P_i) with either the static
//! environment or a point of another body (which receives −P_i); its unit normal n_i points
//! from the environment (or the other body) into x_i's body, like the normal of the two-body
//! contact (7.72). The relative velocity u_i = ẋ_i − ẋ_other = J_i q̇ (+ drag velocities of a
//! prescribed base motion) jumps by
//!
//! ```text
//!   Δu = J A⁻¹ Jᵀ P = W P,       J = [J_1; …; J_m] (3m × n),
//! ```
//!
//! because A Δq̇ = Jᵀ P (7.115–7.117). Each contact's rows are expressed in its contact frame
//! (t₁, t₂, n) (world tangents from the normal). W is assembled as W = Xᵀ X with X = L⁻¹ Jᵀ,
//! so it is symmetric positive semidefinite to round-off even when rank deficient (redundant
//! contacts, planar mechanisms, contacts on the same body).

use crate::ImpulseError;
use crate::body::{orthonormal_complement, unit_vector};
use crate::contact_space::{ContactLaw, ContactMode, ImpactOptions, resolve_validated};
use crate::error::{check_all_finite, check_result};
use crate::mechanism::{BodyPoint, MechanismInertia, dot, point_jacobian_into};
use mechanica_kinematics::tree::{KinematicTree, Workspace};
use nalgebra::{Matrix3, Vector3};

/// Relative threshold of the numerical rank of W: a pivot of the diagonally pivoted Cholesky
/// factorisation of W counts as zero when it is ≤ `DELASSUS_RANK_RELATIVE`·max W_ii.
pub const DELASSUS_RANK_RELATIVE: f64 = 1e-10;

/// One contact of a mechanism (world frame W).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MechanismContact {
    /// The body point that receives the impulse +P.
    pub point: BodyPoint,
    /// The body point that receives −P, or `None` for the static environment (ground, wall).
    pub other: Option<BodyPoint>,
    /// Unit normal from the environment (or `other`'s body) into `point`'s body. Approach
    /// means u·n < 0.
    pub normal_w: Vector3<f64>,
    /// Restitution, friction and restitution law of the contact.
    pub law: ContactLaw,
}

/// The contact-space description of m contacts of a mechanism at one configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactSpace {
    m: usize,
    n: usize,
    /// Contact frames: columns (t₁, t₂, n), world components.
    frames: Vec<Matrix3<f64>>,
    /// J in contact frames: 3m × n, column-major; rows 3i, 3i+1, 3i+2 = t₁, t₂, n of contact i.
    jacobian: Vec<f64>,
    /// X = L⁻¹ Jᵀ: n × 3m, column-major.
    x: Vec<f64>,
    /// W = J A⁻¹ Jᵀ in contact frames: 3m × 3m, column-major.
    delassus: Vec<f64>,
    /// u⁻ in contact frames (3m).
    u_before: Vec<f64>,
    rank: usize,
}

impl ContactSpace {
    /// Assembles J, W and u⁻ for `contacts` of `tree` at the configuration of `ws` (positions
    /// updated), moving with `q_dot`, with the factored mass matrix `inertia` of the same
    /// configuration. Every contact is validated (body indices, finite points, unit normal,
    /// restitution in [0, 1], friction ≥ 0); errors name the contact ([`ImpulseError::InContact`]).
    pub fn new(
        tree: &KinematicTree,
        ws: &Workspace,
        inertia: &MechanismInertia,
        q_dot: &[f64],
        contacts: &[MechanismContact],
    ) -> Result<Self, ImpulseError> {
        let n = tree.dof();
        inertia.check_len("mass matrix dimension (tree dof)", n)?;
        inertia.check_len("q_dot", q_dot.len())?;
        check_all_finite("q_dot", q_dot.iter())?;
        let m = contacts.len();
        let mut frames = Vec::with_capacity(m);
        let mut jacobian = vec![0.0; 3 * m * n];
        let mut u_before = vec![0.0; 3 * m];
        let mut j_point = vec![0.0; 3 * n];
        let mut j_other = vec![0.0; 3 * n];
        for (i, contact) in contacts.iter().enumerate() {
            let in_contact = |source| ImpulseError::InContact {
                contact: i,
                source: Box::new(source),
            };
            let normal = unit_vector("contact normal", &contact.normal_w).map_err(in_contact)?;
            contact.law.validate().map_err(in_contact)?;
            point_jacobian_into(tree, ws, "contact point", &contact.point, &mut j_point).map_err(in_contact)?;
            let mut drag = ws
                .drag_velocity(contact.point.body, &contact.point.p_bq)
                .map_err(|e| in_contact(e.into()))?;
            if let Some(other) = &contact.other {
                point_jacobian_into(tree, ws, "other contact point", other, &mut j_other).map_err(in_contact)?;
                for (a, b) in j_point.iter_mut().zip(&j_other) {
                    *a -= b;
                }
                drag -= ws
                    .drag_velocity(other.body, &other.p_bq)
                    .map_err(|e| in_contact(e.into()))?;
            }
            let (t1, t2) = orthonormal_complement(&normal);
            let frame = Matrix3::from_columns(&[t1, t2, normal]);
            let u_w = Vector3::from_fn(|r, _| (0..n).map(|k| j_point[3 * k + r] * q_dot[k]).sum::<f64>()) + drag;
            for (row, axis) in [t1, t2, normal].iter().enumerate() {
                let r = 3 * i + row;
                for k in 0..n {
                    jacobian[r + 3 * m * k] =
                        axis.x * j_point[3 * k] + axis.y * j_point[3 * k + 1] + axis.z * j_point[3 * k + 2];
                }
                u_before[r] = axis.dot(&u_w);
            }
            frames.push(frame);
        }
        let rows = 3 * m;
        let (x, delassus) = delassus(inertia, &jacobian, n, rows);
        check_result("contact velocity before the impact", u_before.iter())?;
        check_result("Delassus matrix W", delassus.iter())?;
        let rank = numerical_rank(rows, &delassus);
        Ok(Self {
            m,
            n,
            frames,
            jacobian,
            x,
            delassus,
            u_before,
            rank,
        })
    }

    /// Number of contacts m.
    pub fn contact_count(&self) -> usize {
        self.m
    }

    /// The contact Jacobian J in contact frames (3m × n, column-major; rows t₁, t₂, n per contact).
    pub fn jacobian(&self) -> &[f64] {
        &self.jacobian
    }

    /// The Delassus matrix W = J A⁻¹ Jᵀ in contact frames (3m × 3m, column-major).
    pub fn delassus(&self) -> &[f64] {
        &self.delassus
    }

    /// The pre-impact relative velocities u⁻ in contact frames (3m: t₁, t₂, n per contact).
    pub fn u_before(&self) -> &[f64] {
        &self.u_before
    }

    /// The contact frame of contact `i`: columns (t₁, t₂, n), world components.
    pub fn frame(&self, i: usize) -> Option<&Matrix3<f64>> {
        self.frames.get(i)
    }

    /// Numerical rank of W (pivoted Cholesky, threshold [`DELASSUS_RANK_RELATIVE`]).
    pub fn rank(&self) -> usize {
        self.rank
    }

    /// The 3×3 diagonal block W_ii of contact `i`, in world components.
    pub fn block_w(&self, i: usize) -> Matrix3<f64> {
        let rows = 3 * self.m;
        let w_c = Matrix3::from_fn(|r, c| self.delassus[3 * i + r + rows * (3 * i + c)]);
        let f = self.frames[i];
        f * w_c * f.transpose()
    }

    /// u⁻ of contact `i` in world components.
    pub fn u_before_w(&self, i: usize) -> Vector3<f64> {
        self.frames[i] * Vector3::new(self.u_before[3 * i], self.u_before[3 * i + 1], self.u_before[3 * i + 2])
    }

    /// Δq̇ = A⁻¹ Jᵀ P = L⁻ᵀ X P for contact-frame impulses `p` (3m).
    pub(crate) fn delta_q_dot(&self, inertia: &MechanismInertia, p: &[f64]) -> Vec<f64> {
        let n = self.n;
        let mut y = vec![0.0; n];
        for (r, &pr) in p.iter().enumerate() {
            if pr != 0.0 {
                for (yk, xk) in y.iter_mut().zip(&self.x[n * r..n * r + n]) {
                    *yk += xk * pr;
                }
            }
        }
        inertia.backward_in_place(&mut y);
        y
    }

    /// The energy change P·(u⁻ + ½ W P) of contact-frame impulses `p`.
    pub(crate) fn energy_change(&self, p: &[f64]) -> f64 {
        let rows = 3 * self.m;
        let mut total = 0.0;
        for c in 0..rows {
            if p[c] == 0.0 {
                continue;
            }
            let wp: f64 = (0..rows).map(|r| self.delassus[c + rows * r] * p[r]).sum();
            total += p[c] * (self.u_before[c] + 0.5 * wp);
        }
        total
    }
}

/// The numerical rank of a symmetric PSD matrix (column-major `k`×`k`) by Cholesky with
/// diagonal pivoting: pivots ≤ [`DELASSUS_RANK_RELATIVE`]·max diagonal end the factorisation.
fn numerical_rank(k: usize, w: &[f64]) -> usize {
    let mut a = w.to_vec();
    let max = (0..k).map(|i| a[i + k * i]).fold(0.0, f64::max);
    if max <= 0.0 {
        return 0;
    }
    let tol = DELASSUS_RANK_RELATIVE * max;
    let mut perm: Vec<usize> = (0..k).collect();
    for step in 0..k {
        // Choose the largest remaining diagonal.
        let (best, pivot) = (step..k)
            .map(|i| (i, a[perm[i] + k * perm[i]]))
            .fold((step, f64::NEG_INFINITY), |acc, x| if x.1 > acc.1 { x } else { acc });
        if pivot.is_nan() || pivot <= tol {
            return step;
        }
        perm.swap(step, best);
        let p = perm[step];
        let root = pivot.sqrt();
        // Schur complement update of the remaining rows/columns.
        let col: Vec<f64> = perm[step + 1..].iter().map(|&i| a[i + k * p] / root).collect();
        for (u, &i) in perm[step + 1..].iter().enumerate() {
            for (v, &j) in perm[step + 1..].iter().enumerate() {
                a[i + k * j] -= col[u] * col[v];
            }
        }
    }
    k
}

/// Whether a mechanism impact was solved by the exact impulse process or by the simultaneous
/// multi-contact model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImpactModel {
    /// One contact, the impulse-parameterised process of [`crate::contact_space`] (Newton,
    /// Poisson or Stronge as the contact's law says).
    Process,
    /// Several contacts, the simultaneous two-phase model of [`crate::multi_contact`].
    Simultaneous,
}

/// The outcome at one contact of a mechanism impact (world frame W).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactOutcome {
    /// Total impulse P on `point`'s body (the other body receives −P), N·s.
    pub impulse_w: Vector3<f64>,
    /// Normal impulse P·n ≥ 0.
    pub normal_impulse: f64,
    /// Tangential (friction) impulse P − (P·n) n.
    pub tangential_impulse_w: Vector3<f64>,
    /// Normal impulse at the end of compression.
    pub compression_impulse: f64,
    /// Relative velocity before the impact, u⁻.
    pub u_before_w: Vector3<f64>,
    /// Relative velocity after the impact, u⁺ = u⁻ + Σ_j W_ij P_j.
    pub u_after_w: Vector3<f64>,
    /// Contact mode (for the simultaneous model: NoImpact, Frictionless, Stick or Slip at the end).
    pub mode: ContactMode,
}

/// X = L⁻¹ Jᵀ (n × `rows`, column r solves L x = row r of J) and W = Xᵀ X (`rows` × `rows`),
/// both column-major, for the contact Jacobian `jacobian` (`rows` × n, column-major).
fn delassus(inertia: &MechanismInertia, jacobian: &[f64], n: usize, rows: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n * rows];
    for r in 0..rows {
        let col = &mut x[n * r..n * r + n];
        for k in 0..n {
            col[k] = jacobian[r + rows * k];
        }
        inertia.forward_in_place(col);
    }
    let mut w = vec![0.0; rows * rows];
    for c in 0..rows {
        for r in c..rows {
            let value = dot(&x[n * r..n * r + n], &x[n * c..n * c + n]);
            w[r + rows * c] = value;
            w[c + rows * r] = value;
        }
    }
    (x, w)
}

/// The outcome of an impact of a mechanism at one or more contacts.
#[derive(Debug, Clone, PartialEq)]
pub struct MechanismImpact {
    /// One outcome per contact, in input order.
    pub contacts: Vec<ContactOutcome>,
    /// Δq̇ = A⁻¹ Jᵀ P (7.117).
    pub delta_q_dot: Vec<f64>,
    /// q̇⁺ = q̇⁻ + Δq̇.
    pub q_dot_after: Vec<f64>,
    /// T⁻ = ½ q̇⁻ᵀ A q̇⁻ (J).
    pub energy_before: f64,
    /// ΔT = P·(u⁻ + ½ W P) (J); equal to Q·(q̇⁻ + ½Δq̇) with Q = JᵀP.
    pub energy_change: f64,
    /// Largest complementarity residual over the contacts (m/s); 0 for the exact process.
    pub complementarity_residual: f64,
    /// Iterations (sweeps) of the simultaneous model, or steps of the single-contact process.
    pub iterations: usize,
    /// For the single-contact process: its reported impulse error (N·s); 0 otherwise.
    pub integration_error: f64,
    /// True when the residual met the requested tolerance (always true for the process).
    pub converged: bool,
    /// Numerical rank of the Delassus matrix W (3m × 3m).
    pub delassus_rank: usize,
    /// The factor s ∈ [0, 1] applied to the restitution impulses by the energy guard of the
    /// simultaneous model (1 = untouched; see [`crate::multi_contact`]).
    pub restitution_scale: f64,
    /// Which model resolved the impact.
    pub model: ImpactModel,
}

/// Validates a contact-frame impulse solution and assembles the impact report.
pub(crate) fn assemble_impact(
    space: &ContactSpace,
    inertia: &MechanismInertia,
    q_dot: &[f64],
    p: &[f64],
    modes: &[ContactMode],
    compression: &[f64],
) -> Result<MechanismImpact, ImpulseError> {
    let m = space.m;
    let rows = 3 * m;
    let delta_q_dot = space.delta_q_dot(inertia, p);
    let q_dot_after: Vec<f64> = q_dot.iter().zip(&delta_q_dot).map(|(a, b)| a + b).collect();
    let mut contacts = Vec::with_capacity(m);
    for i in 0..m {
        let f = space.frames[i];
        let pc = Vector3::new(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
        let du = Vector3::from_fn(|r, _| {
            (0..rows)
                .map(|c| space.delassus[3 * i + r + rows * c] * p[c])
                .sum::<f64>()
        });
        let u_before_w = space.u_before_w(i);
        let impulse_w = f * pc;
        contacts.push(ContactOutcome {
            impulse_w,
            normal_impulse: pc.z,
            tangential_impulse_w: f.column(0) * pc.x + f.column(1) * pc.y,
            compression_impulse: compression[i],
            u_before_w,
            u_after_w: u_before_w + f * du,
            mode: modes[i],
        });
    }
    let energy_before = inertia.kinetic_energy(q_dot)?;
    let energy_change = space.energy_change(p);
    let impact = MechanismImpact {
        contacts,
        delta_q_dot,
        q_dot_after,
        energy_before,
        energy_change,
        complementarity_residual: 0.0,
        iterations: 0,
        integration_error: 0.0,
        converged: true,
        delassus_rank: space.rank,
        restitution_scale: 1.0,
        model: ImpactModel::Process,
    };
    impact.check_finite()?;
    Ok(impact)
}

impl MechanismImpact {
    /// Fails with [`ImpulseError::NonFiniteResult`] naming the first result that is not finite.
    pub(crate) fn check_finite(&self) -> Result<(), ImpulseError> {
        for c in &self.contacts {
            check_result(
                "contact impulse",
                c.impulse_w.iter().chain(c.tangential_impulse_w.iter()),
            )?;
            check_result("normal impulse", [c.normal_impulse, c.compression_impulse].iter())?;
            check_result("contact velocity after the impact", c.u_after_w.iter())?;
        }
        check_result("velocity jump Δq̇", self.delta_q_dot.iter())?;
        check_result("velocities after the impact", self.q_dot_after.iter())?;
        check_result("kinetic energy", [self.energy_before, self.energy_change].iter())?;
        check_result(
            "accuracy report",
            [
                self.complementarity_residual,
                self.integration_error,
                self.restitution_scale,
            ]
            .iter(),
        )
    }
}

/// Resolves the impact of a mechanism at a single contact with the impulse-parameterised
/// process of [`crate::contact_space`] (the same Newton/Poisson/Stronge semantics, modes and
/// swerving-slip integration as the two-body [`crate::contact::resolve_contact`]), using the contact's 3×3
/// Delassus block W = J A⁻¹ Jᵀ (7.115–7.117).
pub fn resolve_single_contact(
    tree: &KinematicTree,
    ws: &Workspace,
    inertia: &MechanismInertia,
    q_dot: &[f64],
    contact: &MechanismContact,
    options: &ImpactOptions,
) -> Result<MechanismImpact, ImpulseError> {
    let space = ContactSpace::new(tree, ws, inertia, q_dot, std::slice::from_ref(contact))?;
    resolve_single_in_space(&space, inertia, q_dot, contact, options)
}

/// [`resolve_single_contact`] on an assembled one-contact space.
pub(crate) fn resolve_single_in_space(
    space: &ContactSpace,
    inertia: &MechanismInertia,
    q_dot: &[f64],
    contact: &MechanismContact,
    options: &ImpactOptions,
) -> Result<MechanismImpact, ImpulseError> {
    let w = space.block_w(0);
    let u = space.u_before_w(0);
    let n = space.frames[0].column(2).into_owned();
    let w_nn = space.delassus[2 + 3 * 2];
    let u_n = space.u_before[2];
    if u_n < 0.0 && w_nn <= 1e-14 * w.amax() {
        return Err(ImpulseError::ContactImmovable { contact: 0, w_nn, u_n });
    }
    let result = resolve_validated(&w, &u, &n, &contact.law, options).map_err(|e| ImpulseError::InContact {
        contact: 0,
        source: Box::new(e),
    })?;
    let p_c = space.frames[0].transpose() * result.impulse_w;
    let mut impact = assemble_impact(
        space,
        inertia,
        q_dot,
        p_c.as_slice(),
        &[result.mode],
        &[result.compression_impulse],
    )?;
    impact.iterations = result.steps;
    impact.integration_error = result.integration_error;
    impact.check_finite()?;
    Ok(impact)
}
