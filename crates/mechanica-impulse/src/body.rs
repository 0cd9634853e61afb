//! The rigid body as the impulse crate sees it: centre of mass, velocity state and its
//! *mobility* G, the 6×6 map from an impulse (S, M₀S about the centre of mass) to the jump
//! of the velocity state (ΔV₀, ΔΩ) (7.67–7.68, 7.85–7.86):
//!
//! ```text
//!   (ΔV₀, ΔΩ) = G (S, M₀S),      G = diag(m⁻¹ I, J₀⁻¹)  for a free body.
//! ```
//!
//! Working with inverses makes the limiting bodies first-class inputs:
//! - infinite mass or inertia (a static body, a kinematically driven body, a locked axis) is
//!   a zero in G ([`RigidBody::from_inverse`], [`RigidBody::fixed`]);
//! - a hinge (7.87*–7.91*) removes the constrained directions from G, so the hinge impulse
//!   never has to be solved for explicitly ([`RigidBody::hinged_at_point`],
//!   [`RigidBody::hinged_on_axis`]);
//! - degenerate inertia (a rod: zero axial inertia; a point: zero inertia) enters through the
//!   pseudo-inverse J₀⁺. That is exact as long as no impulse has a moment about a
//!   zero-inertia axis: an impulse through a point on the rod's axis (or the point mass
//!   itself) has none, and every other impulse is rejected with
//!   [`ImpulseError::ZeroInertiaAxisExcited`], because a finite impulsive moment about an
//!   axis without inertia would give an infinite spin. The rotation about such an axis is
//!   left unchanged, which is the limit of a thin rod.
//!
//! All vectors are expressed in the world frame W; `p_WC` is the centre of mass C.

use crate::ImpulseError;
use crate::compensated::{Dd, inverse3, two_sum};
use crate::contact_frame::{ContactFrame, FrameMatrix, FrameVector};
use crate::error::{check_all_finite, check_finite, check_result};
use mechanica_mass::MassProperties;
use nalgebra::{DMatrix, Matrix3, Matrix6, SMatrix, Vector3, Vector6};

/// Relative threshold below which an eigenvalue of an inertia tensor counts as zero:
/// eigenvalues ≤ `INERTIA_ZERO_RELATIVE · λ_max` are treated as exactly zero (a rod or a point).
/// 1e-12 is ~5000 ulps: wide enough for tensors assembled by Steiner sums and rotations, and
/// below the inertia ratio 6 r²/L² of any physical rod (a 1 km rod of 1 mm radius still has
/// 6e-12); bodies more slender than that should be modelled as rods.
pub const INERTIA_ZERO_RELATIVE: f64 = 1e-12;

/// Tolerance for a contact point to lie on a zero-inertia axis: |a × d| ≤ tol·max(|d|, L)
/// where L is the larger of |p_WC| and 1 m (so round-off in world coordinates is absorbed).
pub const AXIS_ALIGNMENT_TOLERANCE: f64 = 1e-9;

/// Tolerance for unit vectors (normals, axes): |‖n‖ − 1| ≤ 1e-9. The vector is then
/// renormalised, so callers may pass normals computed in single steps of f64 arithmetic.
pub const UNIT_TOLERANCE: f64 = 1e-9;

/// Checks that `n` is finite and of unit length within [`UNIT_TOLERANCE`]; returns it renormalised.
pub(crate) fn unit_vector(what: &'static str, n: &Vector3<f64>) -> Result<Vector3<f64>, ImpulseError> {
    check_all_finite(what, n.iter())?;
    let norm = n.norm();
    if (norm - 1.0).abs() > UNIT_TOLERANCE {
        return Err(ImpulseError::NotUnit { what, norm });
    }
    Ok(n / norm)
}

/// The velocity Jacobian of a body point: v_P = J_P (v_WC, ω_W) = v_WC + ω × (p_WP − p_WC),
/// i.e. J_P = [I, −[d]×] with d = p_WP − p_WC (7.92).
pub(crate) fn point_jacobian(d: &Vector3<f64>) -> SMatrix<f64, 3, 6> {
    let mut j = SMatrix::<f64, 3, 6>::zeros();
    j.fixed_view_mut::<3, 3>(0, 0).copy_from(&Matrix3::identity());
    j.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-d.cross_matrix()));
    j
}

/// A rigid body at the instant of an impact (world frame W).
#[derive(Debug, Clone, PartialEq)]
pub struct RigidBody {
    p_wc: Vector3<f64>,
    v_wc: Vector3<f64>,
    w_w: Vector3<f64>,
    mobility: Matrix6<f64>,
    /// The remainder of the mobility beyond one rounding (G = mobility + mobility_lo), when it
    /// was computed rather than given: the inverse mass and inertia of a free body.
    mobility_lo: Matrix6<f64>,
    /// For a hinged body, the columns b_k of the factor G = Σ b_k b_kᵀ: a contact mobility
    /// formed from them is exactly of the rank of the allowed motions.
    mobility_factor: Vec<Vector6<f64>>,
    zero_inertia_axes: [Vector3<f64>; 3],
    zero_inertia_count: usize,
}

/// The response of one body to an impulse: post-impact velocities and energy change.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyResponse {
    /// Velocity of the centre of mass just after, V₀ (W frame, m/s).
    pub v_wc_after: Vector3<f64>,
    /// Angular velocity just after, Ω (W frame, rad/s).
    pub w_w_after: Vector3<f64>,
    /// Kinetic-energy change ΔT = ½ S·(V₀ + v₀) + ½ M₀S·(Ω + ω) (7.107), J. For a body of
    /// infinite mass that moves this is the work the impulse does on its driver.
    pub energy_change: f64,
}

impl BodyResponse {
    /// Fails with [`ImpulseError::NonFiniteResult`] naming the first result that is not finite.
    pub(crate) fn check_finite(&self) -> Result<(), ImpulseError> {
        check_result("velocity after the impulse", self.v_wc_after.iter())?;
        check_result("angular velocity after the impulse", self.w_w_after.iter())?;
        check_result("energy change", [self.energy_change].iter())
    }
}

impl RigidBody {
    /// A free body with the mass properties `props`, **expressed in the world frame W**
    /// (`props.p_oc` is p_WC and `props.inertia_c` the central inertia J₀ in W axes), moving
    /// with centre-of-mass velocity `v_wc` and angular velocity `w_w`.
    ///
    /// Degenerate central inertia (rod, point) is accepted; see the module notes.
    pub fn from_mass_properties(
        props: &MassProperties,
        v_wc: Vector3<f64>,
        w_w: Vector3<f64>,
    ) -> Result<Self, ImpulseError> {
        check_finite("mass", props.mass)?;
        if props.mass <= 0.0 {
            return Err(ImpulseError::NonPositiveMass {
                what: "mass",
                value: props.mass,
            });
        }
        check_all_finite("centre of mass", props.p_oc.iter())?;
        check_all_finite("central inertia", props.inertia_c.iter())?;
        let (inverse, axes, count) = symmetric_pseudo_inverse("central inertia", &props.inertia_c)?;
        check_result(
            "inverse mass and inertia (mass or inertia too small)",
            [1.0 / props.mass].iter().chain(inverse.iter()),
        )?;
        let mut body = Self::with_mobility(props.p_oc, v_wc, w_w, 1.0 / props.mass, &inverse)?;
        body.zero_inertia_axes = axes;
        body.zero_inertia_count = count;
        body.set_exact_inverse(props)?;
        Ok(body)
    }

    /// For a free body without zero-inertia axes: the inverse mass and the inverse central
    /// inertia recomputed in double-double, J⁻¹ by the adjugate (accurate beyond one rounding
    /// for any condition the pseudo-inverse keeps), stored as mobility + mobility_lo.
    fn set_exact_inverse(&mut self, props: &MassProperties) -> Result<(), ImpulseError> {
        if self.zero_inertia_count > 0 {
            return Ok(());
        }
        let sym = props.inertia_c * 0.5 + props.inertia_c.transpose() * 0.5;
        let Some((inverse, inverse_lo)) = inverse3(&sym) else {
            return Ok(());
        };
        check_result("inverse inertia", inverse.iter())?;
        let inverse_mass = Dd::new(1.0).div(Dd::new(props.mass));
        for k in 0..3 {
            self.mobility[(k, k)] = inverse_mass.hi;
            self.mobility_lo[(k, k)] = inverse_mass.lo;
        }
        self.mobility.fixed_view_mut::<3, 3>(3, 3).copy_from(&inverse);
        self.mobility_lo.fixed_view_mut::<3, 3>(3, 3).copy_from(&inverse_lo);
        Ok(())
    }

    /// A body given by its inverse mass `inverse_mass` ≥ 0 and inverse central inertia
    /// `inverse_inertia_w` (symmetric positive semidefinite, W axes). Zero inverse mass is an
    /// infinite mass; a zero eigenvalue of the inverse inertia is a locked rotation axis
    /// (infinite inertia). Both zero: a static or kinematically driven body.
    pub fn from_inverse(
        inverse_mass: f64,
        inverse_inertia_w: &Matrix3<f64>,
        p_wc: Vector3<f64>,
        v_wc: Vector3<f64>,
        w_w: Vector3<f64>,
    ) -> Result<Self, ImpulseError> {
        check_finite("inverse mass", inverse_mass)?;
        if inverse_mass < 0.0 {
            return Err(ImpulseError::NegativeInverseMass {
                what: "inverse mass",
                value: inverse_mass,
            });
        }
        check_all_finite("inverse inertia", inverse_inertia_w.iter())?;
        check_symmetric_psd("inverse inertia", inverse_inertia_w)?;
        Self::with_mobility(p_wc, v_wc, w_w, inverse_mass, inverse_inertia_w)
    }

    /// An immovable body at rest (infinite mass and inertia), e.g. the ground; `p_wc` is any
    /// reference point.
    pub fn fixed(p_wc: Vector3<f64>) -> Result<Self, ImpulseError> {
        Self::from_inverse(0.0, &Matrix3::zeros(), p_wc, Vector3::zeros(), Vector3::zeros())
    }

    fn with_mobility(
        p_wc: Vector3<f64>,
        v_wc: Vector3<f64>,
        w_w: Vector3<f64>,
        inverse_mass: f64,
        inverse_inertia_w: &Matrix3<f64>,
    ) -> Result<Self, ImpulseError> {
        check_all_finite("centre of mass", p_wc.iter())?;
        check_all_finite("velocity", v_wc.iter())?;
        check_all_finite("angular velocity", w_w.iter())?;
        let mut mobility = Matrix6::zeros();
        mobility
            .fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(Matrix3::identity() * inverse_mass));
        let sym = (inverse_inertia_w + inverse_inertia_w.transpose()) * 0.5;
        mobility.fixed_view_mut::<3, 3>(3, 3).copy_from(&sym);
        Ok(Self {
            p_wc,
            v_wc,
            w_w,
            mobility,
            mobility_lo: Matrix6::zeros(),
            mobility_factor: Vec::new(),
            zero_inertia_axes: [Vector3::zeros(); 3],
            zero_inertia_count: 0,
        })
    }

    /// The same body held by a spherical hinge at the world-fixed point `p_wh` (7.87*–7.91*):
    /// the velocity of H is kept zero by a hinge impulse that does no work. The body's
    /// velocity must already satisfy the hinge (|v_H| within 1e-9·(|v₀| + |ω|·|p_WH − p_WC|)
    /// plus 1e-300), otherwise [`ImpulseError::ConstraintViolated`].
    pub fn hinged_at_point(&self, p_wh: &Vector3<f64>) -> Result<Self, ImpulseError> {
        check_all_finite("hinge point", p_wh.iter())?;
        let c = point_jacobian(&(p_wh - self.p_wc));
        self.constrained(DMatrix::from_iterator(3, 6, c.iter().copied()), "hinge point")
    }

    /// The same body held by a revolute hinge: the world-fixed point `p_wh` stays at rest and
    /// the body can rotate only about the unit `axis_w` through it (7.87*–7.91*). The
    /// velocity must already satisfy the hinge (see [`RigidBody::hinged_at_point`]).
    pub fn hinged_on_axis(&self, p_wh: &Vector3<f64>, axis_w: &Vector3<f64>) -> Result<Self, ImpulseError> {
        check_all_finite("hinge point", p_wh.iter())?;
        let a = unit_vector("hinge axis", axis_w)?;
        let (b1, b2) = orthonormal_complement(&a);
        let jp = point_jacobian(&(p_wh - self.p_wc));
        let mut c = DMatrix::zeros(5, 6);
        c.view_mut((0, 0), (3, 6)).copy_from(&jp);
        for (row, b) in [(3, b1), (4, b2)] {
            for k in 0..3 {
                c[(row, 3 + k)] = b[k];
            }
        }
        self.constrained(c, "hinge axis")
    }

    /// Restricts the mobility to the null space of the constraint rows `c` (C x = 0), with the
    /// constraint impulse eliminated: G' = G − G Cᵀ (C G Cᵀ)⁺ C G. It is formed as
    /// G' = (L Q)(L Q)ᵀ with G = L Lᵀ and Q an orthonormal basis of null(C L), so that G' is
    /// positive semidefinite with the exact rank of the allowed motions (a revolute hinge
    /// leaves rank one) up to the rounding of its entries; the difference form leaves the
    /// constrained directions at the rounding of G times the condition of C G Cᵀ.
    fn constrained(&self, c: DMatrix<f64>, what: &'static str) -> Result<Self, ImpulseError> {
        let x = self.state();
        let residual = (&c * DMatrix::from_column_slice(6, 1, x.as_slice())).norm();
        let lever = c.rows(0, 3).columns(3, 3).norm();
        let tolerance = 1e-9 * (self.v_wc.norm() + self.w_w.norm() * lever) + 1e-300;
        if residual > tolerance {
            return Err(ImpulseError::ConstraintViolated {
                what,
                residual,
                tolerance,
            });
        }
        let l = mobility_square_root(&self.mobility);
        let mut cl = DMatrix::zeros(6, 6);
        cl.rows_mut(0, c.nrows())
            .copy_from(&(&c * DMatrix::from_column_slice(6, 6, l.as_slice())));
        let svd = cl.svd(false, true);
        let v_t = svd.v_t.ok_or(ImpulseError::Singular {
            what: "hinge constraint (SVD did not converge)",
            value: 0.0,
        })?;
        let largest = svd.singular_values.max();
        let mut mobility = Matrix6::zeros();
        check_result("hinged mobility", l.iter())?;
        let mut factor = Vec::new();
        for k in 0..6 {
            if svd.singular_values[k] <= 1e-12 * largest {
                let q = Vector6::from_iterator(v_t.row(k).iter().copied());
                let b = l * q;
                mobility += b * b.transpose();
                factor.push(b);
            }
        }
        Ok(Self {
            mobility,
            mobility_lo: Matrix6::zeros(),
            mobility_factor: factor,
            ..self.clone()
        })
    }

    /// Position of the centre of mass p_WC.
    pub fn p_wc(&self) -> Vector3<f64> {
        self.p_wc
    }
    /// Velocity of the centre of mass v_WC (just before the impact).
    pub fn v_wc(&self) -> Vector3<f64> {
        self.v_wc
    }
    /// Angular velocity ω_W (just before the impact).
    pub fn w_w(&self) -> Vector3<f64> {
        self.w_w
    }
    /// The 6×6 mobility G (rows/columns: v then ω; W frame, about C).
    pub fn mobility(&self) -> &Matrix6<f64> {
        &self.mobility
    }
    /// The velocity state (v_WC, ω_W) stacked.
    pub fn state(&self) -> Vector6<f64> {
        Vector6::new(
            self.v_wc.x,
            self.v_wc.y,
            self.v_wc.z,
            self.w_w.x,
            self.w_w.y,
            self.w_w.z,
        )
    }

    /// Velocity of the body point at `p_wp`: v₀ + ω × (p − x₀) (7.92).
    pub fn velocity_at(&self, p_wp: &Vector3<f64>) -> Vector3<f64> {
        self.v_wc + self.w_w.cross(&(p_wp - self.p_wc))
    }

    /// This body's share (W, u) of a contact at `p_wp` in the contact frame `frame`, each to
    /// about twice the working precision ([`ContactFrame::body_terms`]); the lever p − x₀ is
    /// split exactly.
    pub(crate) fn contact_terms(&self, frame: &ContactFrame, p_wp: &Vector3<f64>) -> (FrameMatrix, FrameVector) {
        let (mut d, mut d_lo) = (Vector3::zeros(), Vector3::zeros());
        for k in 0..3 {
            (d[k], d_lo[k]) = two_sum(p_wp[k], -self.p_wc[k]);
        }
        if self.mobility_factor.is_empty() {
            frame.body_terms((&self.mobility, &self.mobility_lo), &self.state(), (&d, &d_lo))
        } else {
            frame.factored_body_terms(&self.mobility_factor, &self.state(), (&d, &d_lo))
        }
    }

    /// The 3×3 point mobility W_P = J_P G J_Pᵀ: Δv_P = W_P S for an impulse S at `p_wp`.
    pub fn point_mobility(&self, p_wp: &Vector3<f64>) -> Matrix3<f64> {
        let j = point_jacobian(&(p_wp - self.p_wc));
        let w = j * self.mobility * j.transpose();
        (w + w.transpose()) * 0.5
    }

    /// For a free body of finite mass (not hinged): its inverse mass γ > 0 and inverse central
    /// inertia W (the blocks of G = diag(γI, W)).
    pub(crate) fn free_mobility(&self) -> Option<(f64, Matrix3<f64>)> {
        let gamma = self.mobility[(0, 0)];
        (self.mobility_factor.is_empty() && gamma > 0.0)
            .then(|| (gamma, self.mobility.fixed_view::<3, 3>(3, 3).into_owned()))
    }

    /// Fails if an impulse at `p_wp` could have a moment about a zero-inertia axis.
    pub(crate) fn check_impulse_point(&self, what: &'static str, p_wp: &Vector3<f64>) -> Result<(), ImpulseError> {
        if self.zero_inertia_count == 0 {
            return Ok(());
        }
        let d = p_wp - self.p_wc;
        let scale = d.norm().max(self.p_wc.norm()).max(1.0);
        for a in &self.zero_inertia_axes[..self.zero_inertia_count] {
            // The moment of a unit impulse s about C is d × s; its largest component along a is |a × d|.
            let moment = a.cross(&d).norm();
            if moment > AXIS_ALIGNMENT_TOLERANCE * scale {
                return Err(ImpulseError::ZeroInertiaAxisExcited {
                    what,
                    axis: [a.x, a.y, a.z],
                    moment,
                });
            }
        }
        Ok(())
    }

    /// Fails if the impulsive moment `m_cs_w` (about C) has a component about a zero-inertia axis
    /// larger than 1e-9 of its norm.
    fn check_moment(&self, m_cs_w: &Vector3<f64>) -> Result<(), ImpulseError> {
        for a in &self.zero_inertia_axes[..self.zero_inertia_count] {
            let moment = a.dot(m_cs_w);
            if moment.abs() > AXIS_ALIGNMENT_TOLERANCE * m_cs_w.norm() {
                return Err(ImpulseError::ZeroInertiaAxisExcited {
                    what: "impulsive moment",
                    axis: [a.x, a.y, a.z],
                    moment,
                });
            }
        }
        Ok(())
    }

    /// Applies the impulse `s_w` and the impulsive moment `m_cs_w` about the centre of mass
    /// (7.61–7.68): Δp = S, ΔD₀ = M₀S, i.e. (ΔV₀, ΔΩ) = G (S, M₀S). Returns the post-impact
    /// velocities and ΔT (7.107). For a hinged body the hinge impulse is included implicitly
    /// (it does no work).
    pub fn apply_impulse(&self, s_w: &Vector3<f64>, m_cs_w: &Vector3<f64>) -> Result<BodyResponse, ImpulseError> {
        check_all_finite("impulse", s_w.iter())?;
        check_all_finite("impulsive moment", m_cs_w.iter())?;
        self.check_moment(m_cs_w)?;
        let response = self.respond(s_w, m_cs_w);
        response.check_finite()?;
        Ok(response)
    }

    /// Applies the impulse `s_w` acting at the point `p_wr` together with the impulsive moment
    /// `m_rs_w` about R. The moment about the centre of mass is M₀S = M_RS + (r − x₀) × S
    /// (7.70), and the impulse law about R holds for any R moving with bounded velocity (7.71).
    pub fn apply_impulse_at(
        &self,
        s_w: &Vector3<f64>,
        p_wr: &Vector3<f64>,
        m_rs_w: &Vector3<f64>,
    ) -> Result<BodyResponse, ImpulseError> {
        check_all_finite("impulse", s_w.iter())?;
        check_all_finite("point of application", p_wr.iter())?;
        check_all_finite("impulsive moment", m_rs_w.iter())?;
        let m_cs = m_rs_w + (p_wr - self.p_wc).cross(s_w);
        check_result("impulsive moment about the centre of mass", m_cs.iter())?;
        self.check_moment(&m_cs)?;
        let response = self.respond(s_w, &m_cs);
        response.check_finite()?;
        Ok(response)
    }

    /// The response to a validated impulse (S, M₀S).
    pub(crate) fn respond(&self, s_w: &Vector3<f64>, m_cs_w: &Vector3<f64>) -> BodyResponse {
        let impulse = Vector6::new(s_w.x, s_w.y, s_w.z, m_cs_w.x, m_cs_w.y, m_cs_w.z);
        let delta = self.mobility * impulse;
        let v_after = self.v_wc + delta.fixed_rows::<3>(0);
        let w_after = self.w_w + delta.fixed_rows::<3>(3);
        // (7.107): ½ S·(V₀ + v₀) + ½ M₀S·(Ω + ω), written as impulse·(x⁻ + ½ Δx) so that the
        // hinge reaction (absent from `impulse`) is correctly excluded: it does no work.
        let x = self.state();
        let energy_change = impulse.dot(&(x + delta * 0.5));
        BodyResponse {
            v_wc_after: v_after,
            w_w_after: w_after,
            energy_change,
        }
    }
}

/// Two unit vectors completing `a` to a right-handed orthonormal basis (b1, b2, a).
pub(crate) fn orthonormal_complement(a: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    // Pick the world axis least aligned with a (Frisvad-style choice without the singularity).
    let helper = if a.x.abs() <= a.y.abs() && a.x.abs() <= a.z.abs() {
        Vector3::x()
    } else if a.y.abs() <= a.z.abs() {
        Vector3::y()
    } else {
        Vector3::z()
    };
    let b1 = a.cross(&helper).normalize();
    let b2 = a.cross(&b1);
    (b1, b2)
}

/// Fails unless `m` is symmetric (relative asymmetry ≤ 1e-10) and its eigenvalues are
/// ≥ −1e-12·λ_max.
pub(crate) fn check_symmetric_psd(what: &'static str, m: &Matrix3<f64>) -> Result<(), ImpulseError> {
    let scale = m.amax();
    let asymmetry = (m - m.transpose()).amax();
    if asymmetry > 1e-10 * scale {
        return Err(ImpulseError::InvalidInertia {
            what,
            detail: "asymmetry",
            value: asymmetry,
        });
    }
    let eig = ((m + m.transpose()) * 0.5).symmetric_eigenvalues();
    let min = eig.min();
    if min < -INERTIA_ZERO_RELATIVE * eig.max().max(0.0) {
        return Err(ImpulseError::InvalidInertia {
            what,
            detail: "smallest eigenvalue",
            value: min,
        });
    }
    Ok(())
}

/// A square root L of a symmetric positive semidefinite 6×6 mobility, G = L Lᵀ, from its
/// eigen-decomposition (eigenvalues below zero by rounding are taken as zero).
fn mobility_square_root(g: &Matrix6<f64>) -> Matrix6<f64> {
    let eig = ((g + g.transpose()) * 0.5).symmetric_eigen();
    let mut l = eig.eigenvectors;
    for k in 0..6 {
        let root = eig.eigenvalues[k].max(0.0).sqrt();
        l.column_mut(k).scale_mut(root);
    }
    l
}

/// A pseudo-inverse, the unit vectors spanning the null space, and how many there are.
type PseudoInverse = (Matrix3<f64>, [Vector3<f64>; 3], usize);

/// The pseudo-inverse of a symmetric PSD 3×3 tensor, and the unit eigenvectors of its zero
/// eigenvalues (≤ [`INERTIA_ZERO_RELATIVE`]·λ_max; all three for the zero tensor).
fn symmetric_pseudo_inverse(what: &'static str, m: &Matrix3<f64>) -> Result<PseudoInverse, ImpulseError> {
    check_symmetric_psd(what, m)?;
    let eig = ((m + m.transpose()) * 0.5).symmetric_eigen();
    let max = eig.eigenvalues.max();
    let mut inverse = Matrix3::zeros();
    let mut axes = [Vector3::zeros(); 3];
    let mut count = 0;
    for k in 0..3 {
        let v = eig.eigenvectors.column(k).into_owned();
        let lambda = eig.eigenvalues[k];
        if lambda > INERTIA_ZERO_RELATIVE * max && lambda > 0.0 {
            inverse += v * v.transpose() / lambda;
        } else {
            axes[count] = v;
            count += 1;
        }
    }
    Ok((inverse, axes, count))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rod_along_x(mass: f64, length: f64) -> MassProperties {
        let mut props = MassProperties::point(mass, Vector3::zeros()).expect("valid");
        props.inertia_c = Matrix3::from_diagonal(&Vector3::new(0.0, 1.0, 1.0)) * (mass * length * length / 12.0);
        props
    }

    #[test]
    fn impulse_through_the_centre_only_translates() {
        let props = rod_along_x(2.0, 1.0);
        let body = RigidBody::from_mass_properties(&props, Vector3::new(1.0, 0.0, 0.0), Vector3::zeros()).expect("ok");
        let r = body
            .apply_impulse(&Vector3::new(0.0, 4.0, 0.0), &Vector3::zeros())
            .expect("ok");
        assert_eq!(r.v_wc_after, Vector3::new(1.0, 2.0, 0.0));
        assert_eq!(r.w_w_after, Vector3::zeros());
        // (7.107) against the direct difference ½m(|V|² − |v|²) = ½·2·(5 − 1) = 4.
        assert!((r.energy_change - 4.0).abs() < 1e-14);
    }

    #[test]
    fn impulse_at_the_rod_end_spins_it_about_the_perpendicular_axis() {
        // Rod of mass m, length L along x; impulse S ŷ at x = L/2: ΔV = S/m, ΔΩ = (L/2)S/(mL²/12) = 6S/(mL).
        let (m, l, s) = (3.0, 2.0, 1.5);
        let body = RigidBody::from_mass_properties(&rod_along_x(m, l), Vector3::zeros(), Vector3::zeros()).expect("ok");
        let r = body
            .apply_impulse_at(
                &Vector3::new(0.0, s, 0.0),
                &Vector3::new(l / 2.0, 0.0, 0.0),
                &Vector3::zeros(),
            )
            .expect("ok");
        assert!((r.v_wc_after.y - s / m).abs() < 1e-15);
        assert!((r.w_w_after.z - 6.0 * s / (m * l)).abs() < 1e-14);
        // Direct energy: ½ m V² + ½ J Ω².
        let t = 0.5 * m * (s / m).powi(2) + 0.5 * (m * l * l / 12.0) * (6.0 * s / (m * l)).powi(2);
        assert!((r.energy_change - t).abs() < 1e-14 * t);
    }

    #[test]
    fn a_moment_about_the_rod_axis_is_rejected() {
        let body =
            RigidBody::from_mass_properties(&rod_along_x(1.0, 1.0), Vector3::zeros(), Vector3::zeros()).expect("ok");
        let err = body.apply_impulse(&Vector3::zeros(), &Vector3::new(1.0, 0.0, 0.0));
        assert!(
            matches!(err, Err(ImpulseError::ZeroInertiaAxisExcited { .. })),
            "{err:?}"
        );
        // An impulse off the axis at a point of the rod would also excite it.
        assert!(body.check_impulse_point("rod", &Vector3::new(0.0, 0.1, 0.0)).is_err());
        assert!(body.check_impulse_point("rod", &Vector3::new(0.4, 0.0, 0.0)).is_ok());
    }

    #[test]
    fn moment_about_any_point_follows_7_70() {
        // The same physical load described about C and about R gives the same response.
        let mut props = MassProperties::point(2.0, Vector3::new(0.1, -0.2, 0.3)).expect("ok");
        props.inertia_c = Matrix3::new(2.0, 0.1, 0.0, 0.1, 3.0, 0.2, 0.0, 0.2, 4.0);
        let body = RigidBody::from_mass_properties(&props, Vector3::new(0.3, 0.2, 0.1), Vector3::new(-1.0, 0.5, 2.0))
            .expect("ok");
        let s = Vector3::new(0.7, -0.4, 1.1);
        let r = Vector3::new(1.0, 2.0, -0.5);
        let m_r = Vector3::new(0.2, 0.3, -0.1);
        let a = body.apply_impulse_at(&s, &r, &m_r).expect("ok");
        let b = body.apply_impulse(&s, &(m_r + (r - props.p_oc).cross(&s))).expect("ok");
        assert!((a.w_w_after - b.w_w_after).norm() < 1e-14);
        // ΔD_R = M_RS (7.71): the angular momentum about R changes by exactly M_RS.
        let j = props.inertia_c;
        let d_r = |v: &Vector3<f64>, w: &Vector3<f64>| j * w + (props.p_oc - r).cross(&(props.mass * v));
        let change = d_r(&a.v_wc_after, &a.w_w_after) - d_r(&body.v_wc(), &body.w_w());
        assert!((change - m_r).norm() < 1e-13, "{change} vs {m_r}");
    }

    #[test]
    fn bad_bodies_are_rejected() {
        let bad = RigidBody::from_inverse(
            -1.0,
            &Matrix3::zeros(),
            Vector3::zeros(),
            Vector3::zeros(),
            Vector3::zeros(),
        );
        assert!(matches!(bad, Err(ImpulseError::NegativeInverseMass { .. })));
        let indefinite = Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, 1.0));
        let bad = RigidBody::from_inverse(1.0, &indefinite, Vector3::zeros(), Vector3::zeros(), Vector3::zeros());
        assert!(matches!(bad, Err(ImpulseError::InvalidInertia { .. })));
        let bad = RigidBody::from_inverse(
            1.0,
            &Matrix3::identity(),
            Vector3::zeros(),
            Vector3::new(f64::NAN, 0.0, 0.0),
            Vector3::zeros(),
        );
        assert!(matches!(bad, Err(ImpulseError::NonFinite { .. })));
        let body = RigidBody::fixed(Vector3::zeros()).expect("ok");
        assert!(matches!(
            body.hinged_on_axis(&Vector3::zeros(), &Vector3::new(0.0, 0.0, 2.0)),
            Err(ImpulseError::NotUnit { .. })
        ));
    }

    #[test]
    fn a_hinge_rejects_inconsistent_velocities_and_makes_the_body_a_pendulum() {
        let (m, l) = (2.0, 1.2);
        // Rod along x, centre at origin, hinged at its end (−L/2, 0, 0) about z; rotating at ω.
        let w = 0.8;
        let v = Vector3::new(0.0, w * l / 2.0, 0.0);
        let body = RigidBody::from_mass_properties(&rod_along_x(m, l), v, Vector3::new(0.0, 0.0, w)).expect("ok");
        let hinged = body
            .hinged_on_axis(&Vector3::new(-l / 2.0, 0.0, 0.0), &Vector3::z())
            .expect("consistent");
        // An impulse S ŷ at the free end: J_H ΔΩ = L S with J_H = mL²/3 → ΔΩ = 3S/(mL).
        let s = 0.9;
        let r = hinged
            .apply_impulse_at(
                &Vector3::new(0.0, s, 0.0),
                &Vector3::new(l / 2.0, 0.0, 0.0),
                &Vector3::zeros(),
            )
            .expect("ok");
        assert!((r.w_w_after.z - (w + 3.0 * s / (m * l))).abs() < 1e-13);
        assert!((r.v_wc_after.y - r.w_w_after.z * l / 2.0).abs() < 1e-13);
        // ΔT from the pendulum energy ½ J_H Ω².
        let jh = m * l * l / 3.0;
        let dt = 0.5 * jh * (r.w_w_after.z.powi(2) - w * w);
        assert!((r.energy_change - dt).abs() < 1e-13);
        // A moment about x (perpendicular to the hinge axis) is absorbed by the hinge.
        let r = hinged
            .apply_impulse(&Vector3::zeros(), &Vector3::new(0.0, 1.0, 0.0))
            .expect("ok");
        assert!((r.w_w_after - Vector3::new(0.0, 0.0, w)).norm() < 1e-13);
        // Moving the hinge point breaks the constraint.
        assert!(matches!(
            body.hinged_at_point(&Vector3::new(0.0, 0.3, 0.0)),
            Err(ImpulseError::ConstraintViolated { .. })
        ));
    }
}
