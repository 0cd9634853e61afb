//! Euler angles: the EB1911 convention (θ, φ, ψ) (see docs/theory.md) and the twelve intrinsic axis
//! sequences (aerospace ZYX, robotics XYZ and ZYZ among them), conversions from rotations that
//! stay accurate at and near gimbal lock, and the maps between Euler rates and the angular
//! velocity ω (EB1911 (13)), with a typed error where the rate map is singular.
//!
//! **Convention.** A sequence `ijk` is *intrinsic*: R = R_i(a) R_j(b) R_k(c), i.e. rotate by a
//! about the fixed axis i, then by b about the once-rotated axis j, then by c about the twice-
//! rotated axis k. `angles = [a, b, c]`. The same matrix is the *extrinsic* sequence k, j, i with
//! angles (c, b, a); e.g. ROS "roll-pitch-yaw" (extrinsic X-Y-Z, angles r, p, y) is intrinsic
//! [`EulerSequence::Zyx`] with angles [y, p, r].
//!
//! **Ranges.** a, c ∈ (−π, π]; b ∈ [−π/2, π/2] for Tait–Bryan sequences (i, j, k distinct) and
//! b ∈ [0, π] for proper Euler sequences (i = k).
//!
//! **Gimbal lock.** At |cos b| = 0 (Tait–Bryan) or |sin b| = 0 (proper) only a ± c is
//! determined. [`euler_from_rotation`] then sets c = 0, takes a from the rotation, and reports
//! the lock; away from the lock, a is refitted to R R_k(c)ᵀ R_j(b)ᵀ so that R is reproduced to
//! a few ulps even very close to the lock.

use crate::KinematicsError;
use crate::rotation::{check_finite, check_finite_vec, check_result};
use crate::scaling::power_of_two_above;
use nalgebra::{Matrix3, Rotation3, Vector3};

/// Below this value of |cos b| (Tait–Bryan) or |sin b| (proper Euler) a rotation is treated
/// as gimbal-locked, and Euler-rate inversion is refused.
pub const EULER_SINGULARITY_TOLERANCE: f64 = 1e-12;

/// An intrinsic Euler axis sequence: R = R_i(a) R_j(b) R_k(c) for the axes named in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum EulerSequence {
    /// Tait–Bryan x-y′-z″ ("Cardan" angles, the common robotics XYZ sequence).
    Xyz,
    /// Tait–Bryan x-z′-y″.
    Xzy,
    /// Tait–Bryan y-x′-z″.
    Yxz,
    /// Tait–Bryan y-z′-x″.
    Yzx,
    /// Tait–Bryan z-x′-y″.
    Zxy,
    /// Tait–Bryan z-y′-x″: aerospace yaw, pitch, roll (ψ, θ, φ); equals ROS extrinsic roll-pitch-yaw.
    Zyx,
    /// Proper Euler x-y′-x″.
    Xyx,
    /// Proper Euler x-z′-x″.
    Xzx,
    /// Proper Euler y-x′-y″.
    Yxy,
    /// Proper Euler y-z′-y″.
    Yzy,
    /// Proper Euler z-x′-z″ (the classical "x-convention" of Goldstein).
    Zxz,
    /// Proper Euler z-y′-z″ (robotics ZYZ wrist angles; the EB1911 convention, see [`Eb1911Angles`]).
    Zyz,
}

impl EulerSequence {
    /// Aerospace yaw–pitch–roll.
    pub const AEROSPACE_ZYX: EulerSequence = EulerSequence::Zyx;
    /// Robotics XYZ (Cardan) angles.
    pub const ROBOTICS_XYZ: EulerSequence = EulerSequence::Xyz;
    /// Robotics ZYZ angles.
    pub const ROBOTICS_ZYZ: EulerSequence = EulerSequence::Zyz;

    /// All twelve sequences.
    pub const ALL: [EulerSequence; 12] = [
        EulerSequence::Xyz,
        EulerSequence::Xzy,
        EulerSequence::Yxz,
        EulerSequence::Yzx,
        EulerSequence::Zxy,
        EulerSequence::Zyx,
        EulerSequence::Xyx,
        EulerSequence::Xzx,
        EulerSequence::Yxy,
        EulerSequence::Yzy,
        EulerSequence::Zxz,
        EulerSequence::Zyz,
    ];

    /// The axis indices (i, j, k), 0 = x, 1 = y, 2 = z.
    pub fn axes(self) -> (usize, usize, usize) {
        match self {
            EulerSequence::Xyz => (0, 1, 2),
            EulerSequence::Xzy => (0, 2, 1),
            EulerSequence::Yxz => (1, 0, 2),
            EulerSequence::Yzx => (1, 2, 0),
            EulerSequence::Zxy => (2, 0, 1),
            EulerSequence::Zyx => (2, 1, 0),
            EulerSequence::Xyx => (0, 1, 0),
            EulerSequence::Xzx => (0, 2, 0),
            EulerSequence::Yxy => (1, 0, 1),
            EulerSequence::Yzy => (1, 2, 1),
            EulerSequence::Zxz => (2, 0, 2),
            EulerSequence::Zyz => (2, 1, 2),
        }
    }

    /// A short name, e.g. "ZYX".
    pub fn name(self) -> &'static str {
        match self {
            EulerSequence::Xyz => "XYZ",
            EulerSequence::Xzy => "XZY",
            EulerSequence::Yxz => "YXZ",
            EulerSequence::Yzx => "YZX",
            EulerSequence::Zxy => "ZXY",
            EulerSequence::Zyx => "ZYX",
            EulerSequence::Xyx => "XYX",
            EulerSequence::Xzx => "XZX",
            EulerSequence::Yxy => "YXY",
            EulerSequence::Yzy => "YZY",
            EulerSequence::Zxz => "ZXZ",
            EulerSequence::Zyz => "ZYZ",
        }
    }

    /// True for proper Euler sequences (first axis = last axis).
    pub fn is_proper(self) -> bool {
        let (i, _, k) = self.axes();
        i == k
    }

    /// (i, j, k′, ε): the axes, the third axis k′ ∉ {i, j}, and the sign ε = ε_{i j k′}.
    fn frame(self) -> (usize, usize, usize, usize, f64) {
        let (i, j, k) = self.axes();
        let kp = 3 - i - j;
        let eps = if (j + 3 - i) % 3 == 1 { 1.0 } else { -1.0 };
        (i, j, k, kp, eps)
    }

    /// The quantity that vanishes at gimbal lock: |cos b| (Tait–Bryan) or |sin b| (proper).
    pub fn singularity_distance(self, b: f64) -> f64 {
        if self.is_proper() { b.sin().abs() } else { b.cos().abs() }
    }

    fn measure_name(self) -> &'static str {
        if self.is_proper() {
            "sin(second angle)"
        } else {
            "cos(second angle)"
        }
    }
}

/// The elementary rotation by `angle` (rad) about coordinate axis `axis` (0 = x, 1 = y, any
/// other value = z), in the right-handed sense. Exact to rounding of `sin_cos`.
pub fn elementary_rotation(axis: usize, angle: f64) -> Matrix3<f64> {
    let (s, c) = angle.sin_cos();
    match axis {
        0 => Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c),
        1 => Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c),
        _ => Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0),
    }
}

fn check_angles(angles: &[f64; 3], what: &'static str) -> Result<(), KinematicsError> {
    for (index, &value) in angles.iter().enumerate() {
        if !value.is_finite() {
            return Err(KinematicsError::NonFiniteEntry { what, index, value });
        }
    }
    Ok(())
}

/// The rotation R = R_i(a) R_j(b) R_k(c) (body → fixed, `R_WB`) of the intrinsic sequence
/// `seq`, angles = [a, b, c] in radians. Fails on a non-finite angle.
pub fn rotation_from_euler(seq: EulerSequence, angles: &[f64; 3]) -> Result<Rotation3<f64>, KinematicsError> {
    check_angles(angles, "Euler angles")?;
    let (i, j, k) = seq.axes();
    Ok(Rotation3::from_matrix_unchecked(
        elementary_rotation(i, angles[0]) * elementary_rotation(j, angles[1]) * elementary_rotation(k, angles[2]),
    ))
}

/// Euler angles recovered from a rotation, with the gimbal-lock report.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EulerDecomposition {
    /// [a, b, c] with R = R_i(a) R_j(b) R_k(c); exactly at a lock (distance ≤ eps), c = 0.
    pub angles: [f64; 3],
    /// True when |cos b| (Tait–Bryan) or |sin b| (proper) ≤ [`EULER_SINGULARITY_TOLERANCE`]:
    /// only a ± c is well determined (each of a, c alone only to about eps / distance).
    pub gimbal_lock: bool,
    /// |cos b| or |sin b| as measured from R: the distance to the lock. The angles a and c are
    /// individually determined to about eps / distance (their reconstruction of R is always
    /// accurate to a few ulps).
    pub singularity_distance: f64,
}

/// The Euler angles (rad) of `r` in the sequence `seq` (see the module docs for ranges and
/// locks). The angles reproduce `r` to a few ulps; [`EulerDecomposition::singularity_distance`]
/// says how well a and c are determined individually.
pub fn euler_from_rotation(seq: EulerSequence, r: &Rotation3<f64>) -> EulerDecomposition {
    let m = r.matrix();
    let (i, j, k, kp, eps) = seq.frame();
    let (b, distance) = if seq.is_proper() {
        let s = m[(i, j)].hypot(m[(i, kp)]);
        (s.atan2(m[(i, i)]), s)
    } else {
        let cb = m[(i, i)].hypot(m[(i, j)]);
        ((eps * m[(i, k)]).atan2(cb), cb)
    };
    let gimbal_lock = distance <= EULER_SINGULARITY_TOLERANCE;
    // The representative c = 0 is used only where it changes R by less than an ulp
    // (|cos b| or |sin b| ≤ eps); in between, c from the formula is inaccurate on its own but
    // the refit of a below absorbs its error, so R is still reproduced to a few ulps.
    let c = if distance <= f64::EPSILON {
        0.0
    } else if seq.is_proper() {
        m[(i, j)].atan2(eps * m[(i, kp)])
    } else {
        (-eps * m[(i, j)]).atan2(m[(i, i)])
    };
    // Refit a to M = R R_k(c)ᵀ R_j(b)ᵀ = R_i(a): M e_j = cos a e_j + ε sin a e_k′.
    let mm = m * elementary_rotation(k, -c) * elementary_rotation(j, -b);
    let a = (eps * mm[(kp, j)]).atan2(mm[(j, j)]);
    EulerDecomposition {
        angles: [a, b, c],
        gimbal_lock,
        singularity_distance: distance,
    }
}

/// In which frame an angular velocity is expressed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AngularVelocityFrame {
    /// Fixed-frame (world) components ω_W.
    Fixed,
    /// Body-frame components ω_B = Rᵀ ω_W (EB1911's p, q, r).
    Body,
}

/// The 3×3 matrix E with ω = E [ȧ, ḃ, ċ]ᵀ for the intrinsic sequence `seq` at `angles`.
///
/// Body frame: columns R_k(c)ᵀ R_j(b)ᵀ e_i, R_k(c)ᵀ e_j, e_k. Fixed frame: e_i, R_i(a) e_j,
/// R_i(a) R_j(b) e_k. (Differentiating R = R_i R_j R_k and applying Ω = Ṙ Rᵀ, (2.7–2.12).)
pub fn euler_rate_matrix(seq: EulerSequence, angles: &[f64; 3], frame: AngularVelocityFrame) -> Matrix3<f64> {
    let (i, j, k) = seq.axes();
    let ri = elementary_rotation(i, angles[0]);
    let rj = elementary_rotation(j, angles[1]);
    let rk = elementary_rotation(k, angles[2]);
    let e = |n: usize| Vector3::ith(n, 1.0);
    match frame {
        AngularVelocityFrame::Fixed => Matrix3::from_columns(&[e(i), ri * e(j), ri * rj * e(k)]),
        AngularVelocityFrame::Body => {
            Matrix3::from_columns(&[rk.transpose() * (rj.transpose() * e(i)), rk.transpose() * e(j), e(k)])
        }
    }
}

/// The angular velocity ω (rad/s) from Euler angles (rad) and their rates (rad/s),
/// ω = E(angles) rates (see [`euler_rate_matrix`]), in the components chosen by `frame`.
/// Fails on a non-finite input, and with [`KinematicsError::NonFiniteResult`] when ω
/// overflows (the product is formed on the rates scaled by a power of two).
pub fn angular_velocity_from_euler_rates(
    seq: EulerSequence,
    angles: &[f64; 3],
    rates: &[f64; 3],
    frame: AngularVelocityFrame,
) -> Result<Vector3<f64>, KinematicsError> {
    check_angles(angles, "Euler angles")?;
    check_angles(rates, "Euler rates")?;
    let rates = Vector3::from(*rates);
    let scale = power_of_two_above(rates.amax());
    let omega = euler_rate_matrix(seq, angles, frame) * (rates / scale) * scale;
    check_result(omega.iter(), "angular velocity")?;
    Ok(omega)
}

/// Euler rates recovered from ω, with the conditioning of the inversion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EulerRates {
    /// [ȧ, ḃ, ċ].
    pub rates: [f64; 3],
    /// |cos b| or |sin b|; the rates carry a relative error of about eps / distance.
    pub singularity_distance: f64,
}

/// The Euler rates [ȧ, ḃ, ċ] that produce the angular velocity ω at `angles` (inverse of
/// [`angular_velocity_from_euler_rates`]). Fails with [`KinematicsError::EulerRateSingular`]
/// when |cos b| (Tait–Bryan) or |sin b| (proper) ≤ [`EULER_SINGULARITY_TOLERANCE`], and with
/// [`KinematicsError::NonFiniteResult`] when a rate overflows (up to about |ω|/distance).
pub fn euler_rates_from_angular_velocity(
    seq: EulerSequence,
    angles: &[f64; 3],
    omega: &Vector3<f64>,
    frame: AngularVelocityFrame,
) -> Result<EulerRates, KinematicsError> {
    check_angles(angles, "Euler angles")?;
    check_finite_vec(omega, "angular velocity component")?;
    let distance = seq.singularity_distance(angles[1]);
    let singular = KinematicsError::EulerRateSingular {
        sequence: seq.name(),
        measure: seq.measure_name(),
        distance,
        tolerance: EULER_SINGULARITY_TOLERANCE,
    };
    if distance <= EULER_SINGULARITY_TOLERANCE {
        return Err(singular);
    }
    // A solve by LU with partial pivoting, not an explicit inverse: its residual ω − E ṙ stays
    // at rounding of |E||ṙ| near the singularity, where E⁻¹ω loses digits.
    let e = euler_rate_matrix(seq, angles, frame);
    let scale = power_of_two_above(omega.amax());
    let r = e.lu().solve(&(omega / scale)).ok_or(singular)? * scale;
    check_result(r.iter(), "Euler rates")?;
    Ok(EulerRates {
        rates: [r.x, r.y, r.z],
        singularity_distance: distance,
    })
}

/// Euler's angles as the EB1911 article uses them (§21, see docs/theory.md): θ the nutation (angle
/// between the fixed z axis and the body axis OC), φ the spin about OC, ψ the precession
/// about the fixed z axis. The rotation is R = R_z(ψ) R_y(θ) R_z(φ), i.e. [`EulerSequence::Zyz`]
/// with angles [ψ, θ, φ]; with this R the body components of ω are exactly (13).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Eb1911Angles {
    /// Nutation θ ∈ [0, π].
    pub theta: f64,
    /// Spin φ.
    pub phi: f64,
    /// Precession ψ.
    pub psi: f64,
}

impl Eb1911Angles {
    /// The ZYZ angle triple [ψ, θ, φ].
    pub fn to_zyz(self) -> [f64; 3] {
        [self.psi, self.theta, self.phi]
    }

    /// From a ZYZ angle triple [ψ, θ, φ].
    pub fn from_zyz(angles: [f64; 3]) -> Self {
        Eb1911Angles {
            psi: angles[0],
            theta: angles[1],
            phi: angles[2],
        }
    }

    /// The rotation R = R_z(ψ) R_y(θ) R_z(φ) (body → fixed).
    pub fn rotation(self) -> Result<Rotation3<f64>, KinematicsError> {
        rotation_from_euler(EulerSequence::Zyz, &self.to_zyz())
    }

    /// The EB1911 angles of a rotation, with gimbal-lock report (lock at sin θ = 0).
    pub fn from_rotation(r: &Rotation3<f64>) -> (Self, EulerDecomposition) {
        let d = euler_from_rotation(EulerSequence::Zyz, r);
        (Self::from_zyz(d.angles), d)
    }
}

/// The body-axis angular velocity (p, q, r) from EB1911 (13):
/// p = θ̇ sin φ − sin θ cos φ ψ̇, q = θ̇ cos φ + sin θ sin φ ψ̇, r = φ̇ + cos θ ψ̇.
/// `rates` holds (θ̇, φ̇, ψ̇). Fails on a non-finite input and with
/// [`KinematicsError::NonFiniteResult`] when the result overflows.
pub fn eb1911_body_angular_velocity(
    angles: &Eb1911Angles,
    rates: &Eb1911Angles,
) -> Result<Vector3<f64>, KinematicsError> {
    for (what, v) in [
        ("θ", angles.theta),
        ("φ", angles.phi),
        ("ψ", angles.psi),
        ("θ̇", rates.theta),
        ("φ̇", rates.phi),
        ("ψ̇", rates.psi),
    ] {
        check_finite(v, what)?;
    }
    let (st, ct) = angles.theta.sin_cos();
    let (sp, cp) = angles.phi.sin_cos();
    let scale = power_of_two_above(rates.theta.abs().max(rates.phi.abs()).max(rates.psi.abs()));
    let (theta_dot, phi_dot, psi_dot) = (rates.theta / scale, rates.phi / scale, rates.psi / scale);
    let omega = Vector3::new(
        theta_dot * sp - st * cp * psi_dot,
        theta_dot * cp + st * sp * psi_dot,
        phi_dot + ct * psi_dot,
    ) * scale;
    check_result(omega.iter(), "angular velocity")?;
    Ok(omega)
}

/// The inverse of (13): (θ̇, φ̇, ψ̇) from the body components (p, q, r). Singular at sin θ = 0
/// (the spin and precession axes coincide); fails there with
/// [`KinematicsError::EulerRateSingular`] when |sin θ| ≤ [`EULER_SINGULARITY_TOLERANCE`], and
/// with [`KinematicsError::NonFiniteResult`] when a rate overflows.
///
/// From (13): θ̇ = p sin φ + q cos φ, ψ̇ = (q sin φ − p cos φ)/sin θ, φ̇ = r − cos θ ψ̇.
pub fn eb1911_rates_from_body_angular_velocity(
    angles: &Eb1911Angles,
    omega_b: &Vector3<f64>,
) -> Result<Eb1911Angles, KinematicsError> {
    check_finite_vec(omega_b, "angular velocity component")?;
    for (what, v) in [("θ", angles.theta), ("φ", angles.phi), ("ψ", angles.psi)] {
        check_finite(v, what)?;
    }
    let (st, ct) = angles.theta.sin_cos();
    if st.abs() <= EULER_SINGULARITY_TOLERANCE {
        return Err(KinematicsError::EulerRateSingular {
            sequence: "EB1911 (θ, φ, ψ)",
            measure: "sin θ",
            distance: st.abs(),
            tolerance: EULER_SINGULARITY_TOLERANCE,
        });
    }
    let (sp, cp) = angles.phi.sin_cos();
    let scale = power_of_two_above(omega_b.amax());
    let (p, q, r) = (omega_b.x / scale, omega_b.y / scale, omega_b.z / scale);
    let psi_dot = (q * sp - p * cp) / st;
    let rates = Eb1911Angles {
        theta: (p * sp + q * cp) * scale,
        phi: (r - ct * psi_dot) * scale,
        psi: psi_dot * scale,
    };
    check_result([rates.theta, rates.phi, rates.psi].iter(), "Euler rates")?;
    Ok(rates)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::{angular_velocity_from_rate, body_angular_velocity_from_rate, exp_unchecked};
    use proptest::prelude::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    const EPS: f64 = f64::EPSILON;

    fn reconstruct_err(seq: EulerSequence, r: &Rotation3<f64>, d: &EulerDecomposition) -> f64 {
        let back = rotation_from_euler(seq, &d.angles).expect("finite");
        (back.matrix() - r.matrix()).norm()
    }

    #[test]
    fn named_sequences_match_their_textbook_matrices() {
        // Aerospace: R = Rz(ψ) Ry(θ) Rx(φ); entry (2,0) = −sin θ (pitch).
        let (yaw, pitch, roll) = (0.3, -0.4, 1.2);
        let r = rotation_from_euler(EulerSequence::AEROSPACE_ZYX, &[yaw, pitch, roll]).expect("finite");
        let expected = Rotation3::from_euler_angles(roll, pitch, yaw); // nalgebra: extrinsic roll-pitch-yaw
        assert!((r.matrix() - expected.matrix()).norm() < 4.0 * EPS);
        assert!((r.matrix()[(2, 0)] + pitch.sin()).abs() < EPS);
        let d = euler_from_rotation(EulerSequence::Zyx, &r);
        assert!((d.angles[0] - yaw).abs() < 4.0 * EPS);
        assert!((d.angles[1] - pitch).abs() < 4.0 * EPS);
        assert!((d.angles[2] - roll).abs() < 4.0 * EPS);
    }

    #[test]
    fn round_trips_for_all_sequences_at_random_and_locked_inputs() {
        let bs_tb = [-FRAC_PI_2, FRAC_PI_2, FRAC_PI_2 - 1e-9, -FRAC_PI_2 + 1e-13, 0.7, 1e-300];
        let bs_pr = [0.0, PI, 1e-9, PI - 1e-13, 1.3, 5e-324];
        for seq in EulerSequence::ALL {
            let bs = if seq.is_proper() { bs_pr } else { bs_tb };
            for &b in &bs {
                for &(a, c) in &[(0.4, -2.1), (-3.0, 0.0), (1.0, 3.1)] {
                    let r = rotation_from_euler(seq, &[a, b, c]).expect("finite");
                    let d = euler_from_rotation(seq, &r);
                    let err = reconstruct_err(seq, &r, &d);
                    assert!(err < 16.0 * EPS, "{seq:?} a={a} b={b} c={c}: {err}");
                    if seq.singularity_distance(b) <= 0.5 * EULER_SINGULARITY_TOLERANCE {
                        assert!(d.gimbal_lock, "{seq:?} b={b}");
                    }
                    if seq.singularity_distance(b) <= 0.5 * EPS {
                        assert_eq!(d.angles[2], 0.0);
                    }
                    if seq.singularity_distance(b) > 1e-6 {
                        assert!(!d.gimbal_lock);
                        for (got, want) in d.angles.iter().zip([a, b, c]) {
                            let diff = (got - want + PI).rem_euclid(2.0 * PI) - PI;
                            assert!(diff.abs() < 1e-9, "{seq:?} {:?} vs {:?}", d.angles, [a, b, c]);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn eb1911_13_matches_omega_from_rdot() {
        // ω_B from (13) against vee(Rᵀ Ṙ) with Ṙ by central differences along a path.
        let angles = Eb1911Angles {
            theta: 0.8,
            phi: -1.3,
            psi: 2.2,
        };
        let rates = Eb1911Angles {
            theta: 0.5,
            phi: 3.0,
            psi: -1.1,
        };
        let at = |t: f64| {
            Eb1911Angles {
                theta: angles.theta + t * rates.theta,
                phi: angles.phi + t * rates.phi,
                psi: angles.psi + t * rates.psi,
            }
            .rotation()
            .expect("finite")
        };
        let h = 1e-5;
        let r_dot = (at(h).matrix() - at(-h).matrix()) / (2.0 * h);
        let fd = body_angular_velocity_from_rate(&at(0.0), &r_dot).expect("finite");
        let w = eb1911_body_angular_velocity(&angles, &rates).expect("finite");
        let tol = 10.0 * 9.0 * (h * h + EPS / h);
        assert!((w - fd).norm() < tol, "{w} vs {fd}");
        // Same as the generic ZYZ body-rate matrix.
        let generic = angular_velocity_from_euler_rates(
            EulerSequence::Zyz,
            &angles.to_zyz(),
            &rates.to_zyz(),
            AngularVelocityFrame::Body,
        )
        .expect("finite");
        assert!((w - generic).norm() < 8.0 * EPS * 10.0);
        let back = eb1911_rates_from_body_angular_velocity(&angles, &w).expect("regular");
        assert!((back.theta - rates.theta).abs() < 1e-14);
        assert!((back.phi - rates.phi).abs() < 1e-14);
        assert!((back.psi - rates.psi).abs() < 1e-14);
    }

    #[test]
    fn rate_inversion_at_the_singularity_is_a_typed_error() {
        let locked = Eb1911Angles {
            theta: 0.0,
            phi: 0.3,
            psi: 0.1,
        };
        let err = eb1911_rates_from_body_angular_velocity(&locked, &Vector3::new(0.1, 0.2, 0.3));
        assert!(matches!(err, Err(KinematicsError::EulerRateSingular { distance, .. }) if distance == 0.0));
        let err = euler_rates_from_angular_velocity(
            EulerSequence::Zyx,
            &[0.2, FRAC_PI_2, -0.4],
            &Vector3::new(1.0, 0.0, 0.0),
            AngularVelocityFrame::Fixed,
        );
        assert!(matches!(
            err,
            Err(KinematicsError::EulerRateSingular { sequence: "ZYX", .. })
        ));
        let err = euler_rates_from_angular_velocity(
            EulerSequence::Xyz,
            &[f64::NAN, 0.0, 0.0],
            &Vector3::zeros(),
            AngularVelocityFrame::Fixed,
        );
        assert!(matches!(err, Err(KinematicsError::NonFiniteEntry { index: 0, .. })));
    }

    /// Cases found by fuzzing the C ABI (sequence, frame, angles, ω): rates from an explicit
    /// inverse of E left residuals of 1e-11…1e-8 of ‖E‖‖ṙ‖ + ‖ω‖ (ω → rates → ω off by that).
    #[test]
    fn reported_rates_have_a_rounding_residual() {
        let body = AngularVelocityFrame::Body;
        let cases = [
            (
                6,
                body,
                [-4.9726562499999996e-39, 1.28662109375e-12, 1.0],
                [-3.36328125e-13, -9.085943073308605e-14, 1.4150517928105477e-13],
            ),
            (
                11,
                body,
                [3.0154296874999998e25, -8.333984374999999e-7, 1.32880859375e19],
                [24.5846312972039, 8.675084888818022, 1.5709960937494542e-39],
            ),
            (
                9,
                body,
                [-20483.3984375, 2.6201171875e-9, 14898437.5],
                [1.6405982296031048e-18, 1.5689111328125001e-21, 9.389982997207915e-18],
            ),
        ];
        for (index, frame, angles, omega) in cases {
            let seq = EulerSequence::ALL[index];
            let omega = Vector3::from(omega);
            let rates = euler_rates_from_angular_velocity(seq, &angles, &omega, frame).expect("regular");
            let r = Vector3::from(rates.rates);
            let e = euler_rate_matrix(seq, &angles, frame);
            let scale = e.abs().row_sum().amax() * r.amax() + omega.amax();
            let residual = (omega - e * r).amax();
            assert!(
                residual <= 16.0 * EPS * scale,
                "{}: residual {residual:e} of {scale:e}",
                seq.name()
            );
        }
    }

    proptest! {
        #[test]
        fn generic_rate_matrices_match_finite_differences(
            seq_index in 0usize..12, a in -3.0f64..3.0, b in -3.0f64..3.0, c in -3.0f64..3.0,
            da in -2.0f64..2.0, db in -2.0f64..2.0, dc in -2.0f64..2.0,
        ) {
            let seq = EulerSequence::ALL[seq_index];
            let at = |t: f64| rotation_from_euler(seq, &[a + t * da, b + t * db, c + t * dc]).expect("finite");
            let h = 1e-5;
            let r_dot = (at(h).matrix() - at(-h).matrix()) / (2.0 * h);
            let rates_norm = (da * da + db * db + dc * dc).sqrt();
            let tol = 10.0 * (rates_norm.powi(3) * h * h + EPS / h);
            let fixed = angular_velocity_from_rate(&at(0.0), &r_dot).expect("finite");
            let body = body_angular_velocity_from_rate(&at(0.0), &r_dot).expect("finite");
            let wf = angular_velocity_from_euler_rates(seq, &[a, b, c], &[da, db, dc], AngularVelocityFrame::Fixed).expect("finite");
            let wb = angular_velocity_from_euler_rates(seq, &[a, b, c], &[da, db, dc], AngularVelocityFrame::Body).expect("finite");
            prop_assert!((wf - fixed).norm() < tol);
            prop_assert!((wb - body).norm() < tol);
            // Inversion, when regular: relative error ~ eps / distance.
            let dist = seq.singularity_distance(b);
            if dist > 1e-6 {
                let back = euler_rates_from_angular_velocity(seq, &[a, b, c], &wf, AngularVelocityFrame::Fixed).expect("regular");
                for (got, want) in back.rates.iter().zip([da, db, dc]) {
                    prop_assert!((got - want).abs() < 64.0 * EPS * (1.0 + rates_norm) / dist);
                }
            }
        }

        /// Near the singularity (distance 1e-11…1e-1) the rates solve E ṙ = ω with a residual at
        /// the rounding of ‖E‖‖ṙ‖ + ‖ω‖ (∞-norms), for either frame, any sequence and components
        /// of ω from 1e-200 to 1e200 each: what a backward-stable solve gives (an explicit
        /// inverse left residuals up to 1e-7 of that scale).
        #[test]
        fn rates_near_the_singularity_have_a_rounding_residual(
            seq_index in 0usize..12, a in -3.0f64..3.0, c in -3.0f64..3.0, log_distance in -11.0f64..-1.0,
            side in prop::bool::ANY, body in prop::bool::ANY, w in proptest::array::uniform3(-1.0f64..1.0),
            exponents in proptest::array::uniform3(-200.0f64..200.0),
        ) {
            let seq = EulerSequence::ALL[seq_index];
            let offset = 10f64.powf(log_distance) * if side { 1.0 } else { -1.0 };
            let b = if seq.is_proper() { offset.abs() } else { FRAC_PI_2 + offset };
            prop_assume!(seq.singularity_distance(b) > EULER_SINGULARITY_TOLERANCE);
            let frame = if body { AngularVelocityFrame::Body } else { AngularVelocityFrame::Fixed };
            let omega = Vector3::from(w).component_mul(&Vector3::from(exponents.map(|e| 10f64.powf(e))));
            let rates = euler_rates_from_angular_velocity(seq, &[a, b, c], &omega, frame).expect("regular");
            let e = euler_rate_matrix(seq, &[a, b, c], frame);
            let r = Vector3::from(rates.rates);
            let scale = e.abs().row_sum().amax() * r.amax() + omega.amax();
            let residual = (omega - e * r).amax();
            prop_assert!(residual <= 16.0 * EPS * scale, "residual {:e} of {:e}", residual, scale);
        }

        #[test]
        fn decomposition_reproduces_random_rotations(seq_index in 0usize..12, x in -3.0f64..3.0, y in -3.0f64..3.0, z in -3.0f64..3.0) {
            let seq = EulerSequence::ALL[seq_index];
            let r = exp_unchecked(&Vector3::new(x, y, z));
            let d = euler_from_rotation(seq, &r);
            prop_assert!(reconstruct_err(seq, &r, &d) < 16.0 * EPS);
            let b = d.angles[1];
            if seq.is_proper() { prop_assert!((0.0..=PI).contains(&b)); } else { prop_assert!(b.abs() <= FRAC_PI_2); }
        }
    }
}
