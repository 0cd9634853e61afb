//! Legendre's elliptic integrals of the first and third kind for real arguments, through
//! Carlson's symmetric integrals, and the modulus they share with Jacobi's functions
//! ([`super::jacobi`]).
//!
//! - K(k) = π / (2 M(1, k′)), M the arithmetic–geometric mean (DLMF 19.8.5), evaluated in
//!   double-double so that K carries ~106 bits for the argument reductions;
//! - F(φ, k) = sin φ R_F(cos²φ, Δ², 1) (DLMF 19.25.5), Δ² = 1 − k² sin²φ written as
//!   cos²φ + k′² sin²φ, which has no cancellation near k = 1 and φ = π/2;
//! - Π(n; φ, k) = F(φ, k) + (n/3) sin³φ R_J(cos²φ, Δ², 1, 1 − n sin²φ) (DLMF 19.25.14),
//!   Π(n; φ, k) = ∫₀^φ dθ / ((1 − n sin²θ) √(1 − k² sin²θ)), DLMF's Π(φ, n, k) (DLMF 19.2.7);
//! - |φ| > π/2 by F(φ + mπ) = F(φ) + 2mK and Π(n; φ + mπ) = Π(n; φ) + 2mΠ(n) (DLMF 19.2.10),
//!   with φ reduced by π in double-double.
//!
//! The modulus k is in [0, 1]; [`EllipticModulus::from_complementary_parameter`] takes
//! k′² = 1 − k² itself, which keeps full relative accuracy in k′ near k = 1 (the separatrix of
//! the torque-free body). Π is provided for n < 1, where the integrand has no pole.
//!
//! Measured against mpmath: K within 0 ulps (correctly rounded), F within 3 ulps, Π within
//! 9 ulps for n ≥ −5; for n ≪ −1 the two terms of DLMF 19.25.14 cancel and the error is a few
//! ulps of the larger term (34 ulps of Π itself at n = −100).

use super::carlson::{rf, rj};
use super::double_double::{DoubleDouble, PI};
use crate::error::{DynamicsError, check_input};

/// The largest number of descending Landen steps (DLMF 22.7.1); k′ ≥ 2⁻⁵³⁷ needs 12.
const MAX_LANDEN_LEVELS: usize = 16;
/// Landen's descent stops when kₙ² is below this: the first-order expansion (DLMF 22.10.4–6)
/// is then exact to O(kₙ⁴) < 1e-24.
const LANDEN_STOP: f64 = 1e-12;

/// A modulus k ∈ [0, 1] with the quantities that the elliptic integrals and Jacobi's functions
/// derive from it: k² , k′² = 1 − k², k′, the quarter period K(k) in double-double, and the
/// moduli of the descending Landen transformation.
#[derive(Debug, Clone, PartialEq)]
pub struct EllipticModulus {
    k: f64,
    parameter: f64,
    complementary_parameter: f64,
    complementary: f64,
    complementary_dd: DoubleDouble,
    quarter_period: Option<DoubleDouble>,
    landen: [LandenStep; MAX_LANDEN_LEVELS],
    levels: usize,
}

impl EllipticModulus {
    /// The modulus k, 0 ≤ k ≤ 1; k′² = (1 − k)(1 + k) is formed in double-double.
    pub fn new(k: f64) -> Result<Self, DynamicsError> {
        check_input(&[k], "elliptic modulus k")?;
        if !(0.0..=1.0).contains(&k) {
            return Err(DynamicsError::OutOfRange {
                what: "elliptic modulus k",
                requirement: "in [0, 1]",
                value: k,
            });
        }
        let complementary = DoubleDouble::sum(1.0, -k).mul(DoubleDouble::sum(1.0, k));
        Ok(Self::build(k, DoubleDouble::product(k, k), complementary))
    }

    /// The modulus with complementary parameter k′² = 1 − k² given, 0 ≤ k′² ≤ 1.
    pub fn from_complementary_parameter(complementary_parameter: f64) -> Result<Self, DynamicsError> {
        check_input(&[complementary_parameter], "complementary parameter k′²")?;
        if !(0.0..=1.0).contains(&complementary_parameter) {
            return Err(DynamicsError::OutOfRange {
                what: "complementary parameter k′²",
                requirement: "in [0, 1]",
                value: complementary_parameter,
            });
        }
        let parameter = DoubleDouble::sum(1.0, -complementary_parameter);
        Ok(Self::build(
            parameter.hi.sqrt(),
            parameter,
            DoubleDouble::from_f64(complementary_parameter),
        ))
    }

    fn build(k: f64, parameter: DoubleDouble, complementary_parameter: DoubleDouble) -> Self {
        let complementary_dd = complementary_parameter.sqrt();
        let complementary = complementary_dd.hi;
        let quarter_period = (complementary > 0.0).then(|| quarter_period(complementary_dd));
        let (landen, levels) = landen_moduli(parameter, complementary_dd);
        Self {
            k,
            parameter: parameter.hi,
            complementary_parameter: complementary_parameter.hi,
            complementary,
            complementary_dd,
            quarter_period,
            landen,
            levels,
        }
    }

    /// k.
    pub fn k(&self) -> f64 {
        self.k
    }

    /// The parameter m = k².
    pub fn parameter(&self) -> f64 {
        self.parameter
    }

    /// k′² = 1 − k².
    pub fn complementary_parameter(&self) -> f64 {
        self.complementary_parameter
    }

    /// k′ = √(1 − k²).
    pub fn complementary(&self) -> f64 {
        self.complementary
    }

    /// K(k), None at k = 1 where it is infinite.
    pub fn complete_first_kind(&self) -> Option<f64> {
        self.quarter_period.map(|k| k.hi)
    }

    pub(crate) fn quarter_period_dd(&self) -> Option<DoubleDouble> {
        self.quarter_period
    }

    pub(crate) fn complementary_dd(&self) -> DoubleDouble {
        self.complementary_dd
    }

    pub(crate) fn landen_moduli(&self) -> &[LandenStep] {
        &self.landen[..self.levels]
    }

    /// F(φ, k); an error where it is infinite (k = 1 and |φ| ≥ π/2) or not finite.
    pub fn first_kind(&self, phi: f64) -> Result<f64, DynamicsError> {
        check_input(&[phi], "amplitude φ")?;
        let value = self.first_kind_unchecked(phi);
        finite(value, "F(φ, k)")
    }

    pub(crate) fn first_kind_unchecked(&self, phi: f64) -> f64 {
        self.reduce_amplitude(phi, |s, c| s * rf(c * c, self.delta_squared(s, c), 1.0), |k| k.hi)
    }

    /// Π(n; φ, k) for n < 1; an error where it is infinite (k = 1 and |φ| ≥ π/2).
    pub fn third_kind(&self, n: f64, phi: f64) -> Result<f64, DynamicsError> {
        check_input(&[n, phi], "Π arguments (n, φ)")?;
        check_characteristic(n)?;
        finite(self.third_kind_unchecked(n, phi), "Π(n; φ, k)")
    }

    pub(crate) fn third_kind_unchecked(&self, n: f64, phi: f64) -> f64 {
        let complete = |_: DoubleDouble| self.complete_third_kind_unchecked(n);
        self.reduce_amplitude(phi, |s, c| self.third_kind_reduced(n, s, c), complete)
    }

    /// Π(n; φ, k) for |φ| ≤ π/2 given sin φ and cos φ (DLMF 19.25.14).
    pub(crate) fn third_kind_reduced(&self, n: f64, s: f64, c: f64) -> f64 {
        let c2 = c * c;
        let delta2 = self.delta_squared(s, c);
        let p = c2 + (1.0 - n) * s * s;
        s * rf(c2, delta2, 1.0) + n / 3.0 * s * s * s * rj(c2, delta2, 1.0, p)
    }

    /// Π(n, k) = Π(n; π/2, k) for n < 1 (DLMF 19.25.2); an error at k = 1.
    pub fn complete_third_kind(&self, n: f64) -> Result<f64, DynamicsError> {
        check_input(&[n], "characteristic n")?;
        check_characteristic(n)?;
        finite(self.complete_third_kind_unchecked(n), "Π(n, k)")
    }

    pub(crate) fn complete_third_kind_unchecked(&self, n: f64) -> f64 {
        match self.quarter_period {
            None => f64::INFINITY,
            Some(k) => {
                let mc = self.complementary_parameter;
                k.hi + n / 3.0 * rj(0.0, mc, 1.0, 1.0 - n)
            }
        }
    }

    /// Δ² = 1 − k² sin²φ = cos²φ + k′² sin²φ.
    fn delta_squared(&self, s: f64, c: f64) -> f64 {
        if self.complementary_parameter == 1.0 {
            1.0
        } else {
            c * c + self.complementary_parameter * s * s
        }
    }

    /// reduced(sin φᵣ, cos φᵣ) + 2m·complete(K) for φ = mπ + φᵣ, |φᵣ| ≤ π/2. φᵣ is formed in
    /// double-double and its low part corrects sin and cos, so that cos φᵣ keeps its absolute
    /// accuracy near ±π/2 (where F and Π are most sensitive to φ).
    fn reduce_amplitude(
        &self,
        phi: f64,
        reduced: impl Fn(f64, f64) -> f64,
        complete: impl Fn(DoubleDouble) -> f64,
    ) -> f64 {
        let m = if phi.abs() <= 0.5 * PI.hi {
            0.0
        } else {
            (phi / PI.hi).round()
        };
        if m == 0.0 {
            let (s, c) = phi.sin_cos();
            return reduced(s, c);
        }
        let rest = DoubleDouble::from_f64(phi).sub(PI.scale(m));
        let (s, c) = rest.hi.sin_cos();
        let (s, c) = (s + c * rest.lo, c - s * rest.lo);
        match self.quarter_period {
            None => f64::INFINITY.copysign(phi),
            Some(k) => 2.0 * m * complete(k) + reduced(s, c),
        }
    }
}

fn check_characteristic(n: f64) -> Result<(), DynamicsError> {
    if n < 1.0 {
        Ok(())
    } else {
        Err(DynamicsError::OutOfRange {
            what: "characteristic n of Π",
            requirement: "< 1",
            value: n,
        })
    }
}

fn finite(value: f64, what: &'static str) -> Result<f64, DynamicsError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(DynamicsError::NonFiniteResult { what })
    }
}

/// K = π / (2 M(1, k′)) in double-double (DLMF 19.8.5), for k′ > 0.
fn quarter_period(complementary: DoubleDouble) -> DoubleDouble {
    let mut a = DoubleDouble::from_f64(1.0);
    let mut b = complementary;
    for _ in 0..64 {
        let difference = a.sub(b);
        if difference.hi.abs() <= 1e-33 * a.hi {
            break;
        }
        let next_a = a.add(b).scale(0.5);
        b = a.mul(b).sqrt();
        a = next_a;
    }
    PI.div(a.add(b)) // π / (2 · (a + b)/2)
}

/// One step of the descending Landen transformation: the next modulus kₙ₊₁ and 1 − kₙ₊₁, in
/// double-double.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LandenStep {
    pub k: DoubleDouble,
    pub one_minus_k: DoubleDouble,
}

/// The moduli k₁, k₂, … of the descending Landen transformation kₙ₊₁ = kₙ² / (1 + kₙ′)²
/// (DLMF 22.7.1, kₙ₊₁ = (1 − kₙ′)/(1 + kₙ′) without the cancellation), with
/// 1 − kₙ₊₁ = 2kₙ′ / (1 + kₙ′) and kₙ₊₁′ = 2√kₙ′ / (1 + kₙ′), in double-double, until
/// kₙ² < [`LANDEN_STOP`].
fn landen_moduli(parameter: DoubleDouble, complementary: DoubleDouble) -> ([LandenStep; MAX_LANDEN_LEVELS], usize) {
    let zero = DoubleDouble::from_f64(0.0);
    let mut steps = [LandenStep {
        k: zero,
        one_minus_k: zero,
    }; MAX_LANDEN_LEVELS];
    let (mut m, mut kc) = (parameter, complementary);
    let mut levels = 0;
    while m.hi >= LANDEN_STOP && kc.hi > 0.0 && levels < MAX_LANDEN_LEVELS {
        let one_plus_kc = kc.add(DoubleDouble::from_f64(1.0));
        let next = m.div(one_plus_kc.mul(one_plus_kc));
        steps[levels] = LandenStep {
            k: next,
            one_minus_k: kc.scale(2.0).div(one_plus_kc),
        };
        levels += 1;
        kc = kc.sqrt().scale(2.0).div(one_plus_kc);
        m = next.mul(next);
    }
    (steps, levels)
}

/// K(k) for 0 ≤ k < 1.
pub fn elliptic_k(k: f64) -> Result<f64, DynamicsError> {
    let modulus = EllipticModulus::new(k)?;
    modulus.complete_first_kind().ok_or(DynamicsError::OutOfRange {
        what: "modulus k of K(k)",
        requirement: "< 1",
        value: k,
    })
}

/// F(φ, k) for 0 ≤ k ≤ 1.
pub fn elliptic_f(phi: f64, k: f64) -> Result<f64, DynamicsError> {
    EllipticModulus::new(k)?.first_kind(phi)
}

/// Π(n; φ, k) for n < 1, 0 ≤ k ≤ 1.
pub fn elliptic_pi(n: f64, phi: f64, k: f64) -> Result<f64, DynamicsError> {
    EllipticModulus::new(k)?.third_kind(n, phi)
}

/// Π(n, k) for n < 1, 0 ≤ k < 1.
pub fn elliptic_pi_complete(n: f64, k: f64) -> Result<f64, DynamicsError> {
    EllipticModulus::new(k)?.complete_third_kind(n)
}
