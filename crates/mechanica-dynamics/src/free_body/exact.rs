//! The exact motion of a rigid body under no torque (Euler–Poinsot), EB1911 (7) and the text
//! after it: ω(t) in Jacobi's elliptic functions and the attitude R(t) with the precession angle
//! about the fixed angular momentum from Legendre's integral of the third kind.
//!
//! With the principal moments sorted, I₁ ≤ I₂ ≤ I₃, the energy 2T = Σ Iᵢωᵢ² and Γ² = Σ Iᵢ²ωᵢ²,
//! the body's angular velocity circles the axis of greatest moment when Γ² > 2TI₂
//! ([`Regime::MajorAxis`]) and the axis of least moment when Γ² < 2TI₂ ([`Regime::MinorAxis`]).
//! Call d that axis, c the other extreme axis, and Eᵢ = |Γ² − 2TIᵢ|. Then (EB1911 (7))
//!
//!   ω_c = a_c cn u,  ω₂ = a₂ sn u,  ω_d = a_d dn u,  u = σt + u₀,
//!
//!   σ² = |I_d − I₂| E_c / (I₁I₂I₃),  k² = |I₂ − I_c| E_d / (|I_d − I₂| E_c),
//!   k′² = |I_d − I_c| E₂ / (|I_d − I₂| E_c),
//!   a_c² = E_d / (I_c |I_d − I_c|),  a₂² = E_d / (I₂ |I_d − I₂|),  a_d² = E_c / (I_d |I_d − I_c|),
//!
//! with sign a₂ = sign(a_c a_d). At Γ² = 2TI₂ (k = 1, [`Regime::Separatrix`]) cn and dn become
//! sech and sn becomes tanh; at k = 0 (I₁ = I₂ or I₂ = I₃) they become cos, sin and 1. Each
//! Eᵢ is formed as a sum of terms Iⱼ(Iⱼ − Iᵢ)ωⱼ², so only E₂ can cancel (its two terms are
//! formed in double-double, so k′² stays accurate next to the separatrix); the regime is the
//! separatrix when |E₂| ≤ 8ε (I₃(I₃ − I₂)ω₃² + I₁(I₂ − I₁)ω₁²), ε = 2⁻⁵², i.e. when 2TI₂ − Γ² is
//! zero to the rounding of its two terms. A body turning about a principal axis (Euler's
//! right-hand side exactly zero, which includes the sphere) is [`Regime::Steady`].
//!
//! The attitude: in the invariable frame (z along the fixed angular momentum L), the body's
//! components of ẑ are L_body/Γ, which fixes the nutation and spin angles about the body axis c;
//! the precession ψ about L obeys (EB1911 (13) inverted)
//! ψ̇ = Γ(2T − I_cω_c²)/(Γ² − I_c²ω_c²) = Γ/I_c + Γ(1/I_d − 1/I_c) / (1 − n sn²u),
//! n = −I_c E_d / (I_d E_c) < 0, so ψ(t) = Γt/I_c + Γ(1/I_d − 1/I_c)(Π(n; am u, k) − Π(n; am u₀, k))/σ.
//! For large t, u is reduced by the half period 2K of ψ̇ and the increment of ψ per half period,
//! (2KΓ/I_c + 2Γ(1/I_d − 1/I_c)Π(n, k))/σ, is added m times, so the error does not grow with t
//! beyond the rounding of σ and of that increment.

use nalgebra::{Matrix3, Rotation3, Vector3};

use super::double_double::DoubleDouble;
use super::elliptic::EllipticModulus;
use crate::error::{DynamicsError, check_input, check_result};

/// Which motion the initial state starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Regime {
    /// ω along a principal axis (or any axis of a sphere, or any axis in the plane of two equal
    /// moments): ω and L are constant and the body spins steadily.
    Steady,
    /// Γ² > 2TI₂: ω circles the axis of the greatest moment I₃.
    MajorAxis,
    /// Γ² < 2TI₂: ω circles the axis of the least moment I₁.
    MinorAxis,
    /// Γ² = 2TI₂ to rounding: ω approaches the middle axis asymptotically (k = 1).
    Separatrix,
}

/// The closed-form polhode and precession of a body that is not steady.
#[derive(Debug, Clone)]
struct Polhode {
    /// Index (0 or 2, sorted axes) of the axis with cn, the one ω does not circle.
    c: usize,
    /// Index of the axis with dn, the one ω circles.
    d: usize,
    /// a_c, a₂, a_d in sorted-axis positions.
    amplitude: Vector3<f64>,
    sigma: f64,
    modulus: EllipticModulus,
    u0: f64,
    /// Characteristic n < 0 of Π.
    n: f64,
    /// Γ/I_c.
    precession_base: f64,
    /// Γ(1/I_d − 1/I_c).
    precession_coupling: f64,
    /// Π(n; am u₀, k), or the separatrix's closed form at u₀.
    pi_at_u0: f64,
    /// ψ gained while u advances by 2K (None on the separatrix).
    precession_per_half_period: Option<f64>,
}

#[derive(Debug, Clone)]
enum Motion {
    Steady,
    Polhode(Box<Polhode>),
}

/// A rigid body moving under no torque about its centre of mass (or a fixed point), with its
/// exact state at any time.
///
/// Frames: the body frame has its axes along the principal axes, in the order of `moments`;
/// `omega0` and the ω returned are body-frame components (rad/s); the rotation maps body
/// components to space components (x_space = R x_body) and obeys Ṙ = R[ω]×.
#[derive(Debug, Clone)]
pub struct TorqueFreeBody {
    /// Principal moments sorted ascending.
    sorted_moments: Vector3<f64>,
    /// Signed permutation with determinant +1: sorted components = axes · body components.
    axes: Matrix3<f64>,
    omega0: Vector3<f64>,
    r0: Rotation3<f64>,
    energy: f64,
    momentum: Vector3<f64>,
    regime: Regime,
    motion: Motion,
    /// Q = R₀ Sᵀ M(0)ᵀ: the invariable frame's axes in space (elliptic motions only).
    invariable_frame: Matrix3<f64>,
}

impl TorqueFreeBody {
    /// The body with principal `moments` (> 0, any order), initial body-frame angular velocity
    /// `omega0` and initial attitude `r0`.
    ///
    /// Errors: [`DynamicsError::NonFiniteInput`] for a NaN or infinite entry,
    /// [`DynamicsError::OutOfRange`] for a moment ≤ 0, [`DynamicsError::NonFiniteResult`] when
    /// the energy or angular momentum overflows f64.
    pub fn new(moments: Vector3<f64>, omega0: Vector3<f64>, r0: Rotation3<f64>) -> Result<Self, DynamicsError> {
        check_input(moments.as_slice(), "principal moments")?;
        check_input(omega0.as_slice(), "initial angular velocity ω(0)")?;
        check_input(r0.matrix().as_slice(), "initial attitude R(0)")?;
        if let Some(&bad) = moments.iter().find(|m| **m <= 0.0) {
            return Err(DynamicsError::OutOfRange {
                what: "principal moment",
                requirement: "> 0",
                value: bad,
            });
        }
        let axes = sorting_rotation(&moments);
        let sorted_moments = Vector3::from_iterator((axes * moments).iter().map(|m| m.abs()));
        let w = axes * omega0;
        let energy = 0.5 * sorted_moments.dot(&w.component_mul(&w));
        let momentum = r0 * omega0.component_mul(&moments);
        check_result([energy].iter().chain(momentum.iter()), "energy and angular momentum")?;
        let (regime, motion) = classify(&sorted_moments, &w)?;
        let mut body = Self {
            sorted_moments,
            axes,
            omega0,
            r0,
            energy,
            momentum,
            regime,
            motion,
            invariable_frame: Matrix3::identity(),
        };
        if let Motion::Polhode(polhode) = &body.motion {
            let (w_start, _) = polhode.omega_and_precession(0.0);
            let r0_sorted = r0.matrix() * axes.transpose();
            body.invariable_frame = r0_sorted * body_to_node_frame(&sorted_moments, &w_start, polhode.c).transpose();
        }
        Ok(body)
    }

    /// (R(t), ω(t)): the attitude (body → space) and the body-frame angular velocity at time t.
    /// Errors: a non-finite t, or a t so far from 0 that the motion's phase is lost (the
    /// argument σt of its elliptic functions beyond 2⁵² quarter periods, where one ulp of σt is
    /// a quarter period; [`DynamicsError::OutOfRange`]).
    pub fn state_at(&self, t: f64) -> Result<(Rotation3<f64>, Vector3<f64>), DynamicsError> {
        check_input(&[t], "time t")?;
        if let Motion::Polhode(polhode) = &self.motion {
            let u = polhode.sigma.mul_add(t, polhode.u0);
            polhode
                .modulus
                .check_argument(u)
                .map_err(|_| DynamicsError::OutOfRange {
                    what: "time t",
                    requirement: "within 2⁵² quarter periods of the motion (beyond, its phase is lost)",
                    value: t,
                })?;
        }
        let (rotation, omega) = match &self.motion {
            Motion::Steady => (self.r0 * Rotation3::from_scaled_axis(self.omega0 * t), self.omega0),
            Motion::Polhode(polhode) => {
                let (w, psi) = polhode.omega_and_precession(t);
                let node = body_to_node_frame(&self.sorted_moments, &w, polhode.c);
                let sorted = self.invariable_frame * Rotation3::from_axis_angle(&Vector3::z_axis(), psi) * node;
                (
                    Rotation3::from_matrix_unchecked(sorted * self.axes),
                    self.axes.transpose() * w,
                )
            }
        };
        check_result(rotation.matrix().iter().chain(omega.iter()), "torque-free state")?;
        Ok((rotation, omega))
    }

    /// The kinetic energy T = ½ Σ Iᵢωᵢ², constant.
    pub fn energy(&self) -> f64 {
        self.energy
    }

    /// The angular momentum L = R(0) I ω(0) in space components, constant.
    pub fn angular_momentum(&self) -> Vector3<f64> {
        self.momentum
    }

    /// The regime of the motion.
    pub fn regime(&self) -> Regime {
        self.regime
    }

    /// The modulus k of the elliptic functions (None for a steady rotation).
    pub fn modulus(&self) -> Option<f64> {
        match &self.motion {
            Motion::Steady => None,
            Motion::Polhode(p) => Some(p.modulus.k()),
        }
    }

    /// The period 4K/σ after which ω(t) repeats in the body (None for a steady rotation and on
    /// the separatrix, where it is infinite).
    pub fn period(&self) -> Option<f64> {
        match &self.motion {
            Motion::Polhode(p) => p.modulus.complete_first_kind().map(|k| 4.0 * k / p.sigma),
            Motion::Steady => None,
        }
    }
}

/// The signed permutation S (det S = +1) with S·moments sorted ascending.
fn sorting_rotation(moments: &Vector3<f64>) -> Matrix3<f64> {
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| moments[a].total_cmp(&moments[b]));
    let mut s = Matrix3::zeros();
    for (row, &column) in order.iter().enumerate() {
        s[(row, column)] = 1.0;
    }
    if s.determinant() < 0.0 {
        s.row_mut(1).neg_mut();
    }
    s
}

/// Regime and closed-form data from sorted moments and sorted ω(0).
fn classify(moments: &Vector3<f64>, w: &Vector3<f64>) -> Result<(Regime, Motion), DynamicsError> {
    let [i1, i2, i3] = [moments.x, moments.y, moments.z];
    let rhs = [(i2 - i3) * w.y * w.z, (i3 - i1) * w.z * w.x, (i1 - i2) * w.x * w.y];
    if rhs.iter().all(|v| *v == 0.0) {
        return Ok((Regime::Steady, Motion::Steady));
    }
    let sq = w.component_mul(w);
    let (d21, d32, d31) = (i2 - i1, i3 - i2, i3 - i1);
    // E₂ = Γ² − 2TI₂ cancels near the separatrix: its two terms are formed in double-double, so
    // that k′² keeps its relative accuracy down to |E₂| ~ 1e-30 of the terms.
    let term = |i: f64, j: f64, k: f64, w: f64| DoubleDouble::sum(j, -k).scale(i).scale(w).scale(w);
    let (major_dd, minor_dd) = (term(i3, i3, i2, w.z), term(i1, i2, i1, w.x));
    let (major_side, minor_side) = (major_dd.hi, minor_dd.hi);
    let e2 = major_dd.sub(minor_dd).hi;
    let excess = [
        i2 * d21 * sq.y + i3 * d31 * sq.z,
        e2.abs(),
        i1 * d31 * sq.x + i2 * d32 * sq.y,
    ];
    check_result(excess.iter(), "Γ² − 2TIᵢ")?;
    let regime = if e2.abs() <= 8.0 * f64::EPSILON * (major_side + minor_side) {
        Regime::Separatrix
    } else if e2 > 0.0 {
        Regime::MajorAxis
    } else {
        Regime::MinorAxis
    };
    let (d, c) = if e2 >= 0.0 { (2, 0) } else { (0, 2) };
    match Polhode::new(moments, w, excess, regime, c, d) {
        Some(polhode) => Ok((regime, Motion::Polhode(Box::new(polhode)))),
        None => Ok((Regime::Steady, Motion::Steady)),
    }
}

impl Polhode {
    /// The closed form for sorted moments and ω(0), Eᵢ = `excess[i]`; None when the amplitudes
    /// or the rate underflow (a rotation indistinguishable from a steady one).
    fn new(
        moments: &Vector3<f64>,
        w: &Vector3<f64>,
        excess: [f64; 3],
        regime: Regime,
        c: usize,
        d: usize,
    ) -> Option<Self> {
        let (ic, i2, id) = (moments[c], moments[1], moments[d]);
        let (gap_dc, gap_d2, gap_2c) = ((id - ic).abs(), (id - i2).abs(), (i2 - ic).abs());
        let (ec, ed) = (excess[c], excess[d]);
        let sigma = (gap_d2 * ec / (moments.x * moments.y * moments.z)).sqrt();
        let separatrix = regime == Regime::Separatrix;
        // k² and k′² each from its own formula; the smaller one defines the modulus, so that
        // k = 0 (two equal moments) and k = 1 (the separatrix) come out exactly.
        let parameter = (gap_2c * ed / (gap_d2 * ec)).clamp(0.0, 1.0);
        let complementary = (gap_dc * excess[1] / (gap_d2 * ec)).clamp(0.0, 1.0);
        let modulus = if separatrix {
            EllipticModulus::from_complementary_parameter(0.0)
        } else if parameter <= complementary {
            EllipticModulus::new(parameter.sqrt())
        } else {
            EllipticModulus::from_complementary_parameter(complementary)
        };
        let a_c = (ed / (ic * gap_dc)).sqrt();
        let a_c = if separatrix { a_c.copysign(w[c]) } else { a_c };
        let a_d = (ec / (id * gap_dc)).sqrt().copysign(w[d]);
        let a_2 = (ed / (i2 * gap_d2)).sqrt().copysign(a_c * a_d);
        if !(sigma > 0.0 && a_c != 0.0 && a_2 != 0.0 && a_d != 0.0 && sigma.is_finite()) {
            return None;
        }
        let modulus = modulus.ok()?;
        let phi0 = (w.y / a_2).atan2(w[c] / a_c);
        let gamma = moments.component_mul(w).norm();
        let n = -(ic * ed) / (id * ec);
        let mut polhode = Self {
            c,
            d,
            amplitude: Vector3::zeros(),
            sigma,
            u0: modulus.first_kind_unchecked(phi0),
            n,
            precession_base: gamma / ic,
            precession_coupling: gamma * (1.0 / id - 1.0 / ic),
            pi_at_u0: 0.0,
            precession_per_half_period: None,
            modulus,
        };
        polhode.amplitude[c] = a_c;
        polhode.amplitude[1] = a_2;
        polhode.amplitude[d] = a_d;
        polhode.pi_at_u0 = polhode.third_kind_integral_at_start(phi0);
        polhode.precession_per_half_period = polhode.modulus.quarter_period_dd().map(|k| {
            let pi_complete = polhode.modulus.complete_third_kind_unchecked(n);
            2.0 * (polhode.precession_base * k.hi + polhode.precession_coupling * pi_complete) / sigma
        });
        Some(polhode)
    }

    /// P(u₀) = ∫₀^u₀ du / (1 − n sn²u) = Π(n; am u₀, k).
    fn third_kind_integral_at_start(&self, phi0: f64) -> f64 {
        if self.modulus.quarter_period_dd().is_none() {
            separatrix_integral(self.u0, -self.n)
        } else {
            self.modulus.third_kind_unchecked(self.n, phi0)
        }
    }

    /// Sorted-axis ω(t) and the precession angle ψ(t) about L, ψ(0) = 0.
    fn omega_and_precession(&self, t: f64) -> (Vector3<f64>, f64) {
        let u = self.sigma.mul_add(t, self.u0);
        let Some(quarter) = self.modulus.quarter_period_dd() else {
            let sech = 1.0 / u.cosh();
            let w = self.polhode_point(u.tanh(), sech, sech);
            let integral = separatrix_integral(u, -self.n) - self.pi_at_u0;
            let psi = self.precession_base * t + self.precession_coupling * integral / self.sigma;
            return (w, psi);
        };
        let half = quarter.scale(2.0);
        let m = (u / half.hi).round();
        let r = m.mul_add(-half.hi, u) - m * half.lo;
        let v = self.modulus.jacobi_unchecked(r);
        let sign = if m.rem_euclid(2.0) == 0.0 { 1.0 } else { -1.0 };
        let w = self.polhode_point(sign * v.sn, sign * v.cn, v.dn);
        let norm = v.sn.hypot(v.cn);
        let pi_r = self.modulus.third_kind_reduced(self.n, v.sn / norm, v.cn / norm);
        let within = self.precession_base * (r - self.u0) + self.precession_coupling * (pi_r - self.pi_at_u0);
        let per_half = self.precession_per_half_period.unwrap_or(0.0);
        (w, m.mul_add(per_half, within / self.sigma))
    }

    fn polhode_point(&self, sn: f64, cn: f64, dn: f64) -> Vector3<f64> {
        let mut w = Vector3::zeros();
        w[self.c] = self.amplitude[self.c] * cn;
        w[1] = self.amplitude[1] * sn;
        w[self.d] = self.amplitude[self.d] * dn;
        w
    }
}

/// ∫₀^u du / (1 + ν tanh²u) = (u + √ν atan(√ν tanh u)) / (1 + ν): Π(−ν; am u, 1).
fn separatrix_integral(u: f64, nu: f64) -> f64 {
    let root = nu.sqrt();
    (u + root * (root * u.tanh()).atan()) / (1.0 + nu)
}

/// M: sorted body components → the frame (n̂ × ẑ, n̂, ẑ) with ẑ = L/Γ and n̂ = ẑ × e_c / |ẑ × e_c|
/// (in Euler angles about the body axis c, M = R_y(θ) R_z(φ)); |ẑ × e_c| is bounded below
/// because ω never reaches the plane normal to the axis d it circles.
fn body_to_node_frame(moments: &Vector3<f64>, w: &Vector3<f64>, c: usize) -> Matrix3<f64> {
    let z = moments.component_mul(w).normalize();
    let node = z.cross(&Vector3::ith(c, 1.0)).normalize();
    let x = node.cross(&z);
    Matrix3::from_rows(&[x.transpose(), node.transpose(), z.transpose()])
}
