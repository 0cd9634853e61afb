//! Carlson's symmetric elliptic integrals R_F, R_D, R_J and R_C for real arguments
//! (DLMF §19.16), by the duplication algorithm of B. C. Carlson, "Numerical computation of real
//! or complex elliptic integrals", Numer. Algorithms 10 (1995), with the fifth-order series of
//! that paper after the duplications. The stopping rule 4⁻ᵐQ < |Aₘ| with r = 2⁻⁵³ bounds the
//! truncation error by about one unit in the last place; the measured error against mpmath is
//! at most 3 ulps (docs/theory.md, "The torque-free rigid body (Euler–Poinsot)").

use crate::error::DynamicsError;

/// Carlson's relative error parameter r.
const TOLERANCE: f64 = f64::EPSILON / 2.0;
/// Guard on the duplication count: each step divides the spread by 4, so 60 steps shrink any
/// finite spread of positive arguments below the tolerance.
const MAX_STEPS: usize = 200;

fn domain_error(what: &'static str, requirement: &'static str, value: f64) -> DynamicsError {
    DynamicsError::OutOfRange {
        what,
        requirement,
        value,
    }
}

fn check_finite(values: &[f64], what: &'static str) -> Result<(), DynamicsError> {
    crate::error::check_input(values, what)
}

/// R_F(x, y, z) = ½∫₀^∞ dt/√((t+x)(t+y)(t+z)) (DLMF 19.16.1) for x, y, z ≥ 0 with at most one
/// of them zero.
pub fn carlson_rf(x: f64, y: f64, z: f64) -> Result<f64, DynamicsError> {
    check_finite(&[x, y, z], "carlson_rf arguments")?;
    let smallest = x.min(y).min(z);
    if smallest < 0.0 {
        return Err(domain_error("carlson_rf argument", "≥ 0", smallest));
    }
    if [x, y, z].iter().filter(|v| **v == 0.0).count() > 1 {
        return Err(domain_error("carlson_rf arguments", "at most one zero", 0.0));
    }
    Ok(rf(x, y, z))
}

/// R_F without the domain check (Carlson 1995, algorithm for R_F).
pub(crate) fn rf(x0: f64, y0: f64, z0: f64) -> f64 {
    let a0 = (x0 + y0 + z0) / 3.0;
    let spread = (a0 - x0).abs().max((a0 - y0).abs()).max((a0 - z0).abs());
    let q = (3.0 * TOLERANCE).powf(-1.0 / 6.0) * spread;
    let (mut x, mut y, mut z, mut a) = (x0, y0, z0, a0);
    let mut scale = 1.0; // 4⁻ᵐ
    for _ in 0..MAX_STEPS {
        if scale * q < a.abs() {
            break;
        }
        let (sx, sy, sz) = (x.sqrt(), y.sqrt(), z.sqrt());
        let lambda = sx * sy + sy * sz + sz * sx;
        x = (x + lambda) / 4.0;
        y = (y + lambda) / 4.0;
        z = (z + lambda) / 4.0;
        a = (a + lambda) / 4.0;
        scale /= 4.0;
    }
    let dx = (a0 - x0) * scale / a;
    let dy = (a0 - y0) * scale / a;
    let dz = -(dx + dy);
    let e2 = dx * dy - dz * dz;
    let e3 = dx * dy * dz;
    (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0) / a.sqrt()
}

/// The fifth-order series shared by R_D and R_J (Carlson 1995, eqs. for R_J and R_D).
fn rd_rj_series(e2: f64, e3: f64, e4: f64, e5: f64) -> f64 {
    1.0 - 3.0 * e2 / 14.0 + e3 / 6.0 + 9.0 * e2 * e2 / 88.0 - 3.0 * e4 / 22.0 - 9.0 * e2 * e3 / 52.0 + 3.0 * e5 / 26.0
}

/// R_D(x, y, z) = R_J(x, y, z, z) = (3/2)∫₀^∞ dt/((t+z)√((t+x)(t+y)(t+z))) (DLMF 19.16.5) for
/// x, y ≥ 0, x + y > 0, z > 0.
pub fn carlson_rd(x: f64, y: f64, z: f64) -> Result<f64, DynamicsError> {
    check_finite(&[x, y, z], "carlson_rd arguments")?;
    if x.min(y) < 0.0 {
        return Err(domain_error("carlson_rd x, y", "≥ 0", x.min(y)));
    }
    if x + y <= 0.0 {
        return Err(domain_error("carlson_rd x + y", "> 0", x + y));
    }
    if z <= 0.0 {
        return Err(domain_error("carlson_rd z", "> 0", z));
    }
    Ok(rd(x, y, z))
}

/// R_D without the domain check (Carlson 1995, algorithm for R_D).
pub(crate) fn rd(x0: f64, y0: f64, z0: f64) -> f64 {
    let a0 = (x0 + y0 + 3.0 * z0) / 5.0;
    let spread = (a0 - x0).abs().max((a0 - y0).abs()).max((a0 - z0).abs());
    let q = (TOLERANCE / 4.0).powf(-1.0 / 6.0) * spread;
    let (mut x, mut y, mut z, mut a) = (x0, y0, z0, a0);
    let (mut scale, mut sum) = (1.0, 0.0);
    for _ in 0..MAX_STEPS {
        if scale * q < a.abs() {
            break;
        }
        let (sx, sy, sz) = (x.sqrt(), y.sqrt(), z.sqrt());
        let lambda = sx * sy + sy * sz + sz * sx;
        sum += scale / (sz * (z + lambda));
        x = (x + lambda) / 4.0;
        y = (y + lambda) / 4.0;
        z = (z + lambda) / 4.0;
        a = (a + lambda) / 4.0;
        scale /= 4.0;
    }
    let dx = (a0 - x0) * scale / a;
    let dy = (a0 - y0) * scale / a;
    let dz = -(dx + dy) / 3.0;
    let xy = dx * dy;
    let e2 = xy - 6.0 * dz * dz;
    let e3 = (3.0 * xy - 8.0 * dz * dz) * dz;
    let e4 = 3.0 * (xy - dz * dz) * dz * dz;
    let e5 = xy * dz * dz * dz;
    scale * rd_rj_series(e2, e3, e4, e5) / (a * a.sqrt()) + 3.0 * sum
}

/// R_J(x, y, z, p) = (3/2)∫₀^∞ dt/((t+p)√((t+x)(t+y)(t+z))) (DLMF 19.16.2) for x, y, z ≥ 0 with
/// at most one zero and p > 0 (the principal value for p < 0 is not provided).
pub fn carlson_rj(x: f64, y: f64, z: f64, p: f64) -> Result<f64, DynamicsError> {
    check_finite(&[x, y, z, p], "carlson_rj arguments")?;
    let smallest = x.min(y).min(z);
    if smallest < 0.0 {
        return Err(domain_error("carlson_rj x, y, z", "≥ 0", smallest));
    }
    if [x, y, z].iter().filter(|v| **v == 0.0).count() > 1 {
        return Err(domain_error("carlson_rj x, y, z", "at most one zero", 0.0));
    }
    if p <= 0.0 {
        return Err(domain_error("carlson_rj p", "> 0", p));
    }
    Ok(rj(x, y, z, p))
}

/// R_J without the domain check (Carlson 1995, algorithm for R_J, with the sum of
/// R_C(1, 1 + eₘ)/dₘ; 1 + eₘ is formed without cancellation, which keeps the accuracy when
/// p ≪ x, y, z).
pub(crate) fn rj(x0: f64, y0: f64, z0: f64, p0: f64) -> f64 {
    let a0 = (x0 + y0 + z0 + 2.0 * p0) / 5.0;
    let spread = [x0, y0, z0, p0].iter().fold(0.0_f64, |m, v| m.max((a0 - v).abs()));
    let q = (TOLERANCE / 4.0).powf(-1.0 / 6.0) * spread;
    let (mut x, mut y, mut z, mut p, mut a) = (x0, y0, z0, p0, a0);
    let (mut scale, mut sum) = (1.0, 0.0);
    for _ in 0..MAX_STEPS {
        if scale * q < a.abs() {
            break;
        }
        let (sx, sy, sz, sp) = (x.sqrt(), y.sqrt(), z.sqrt(), p.sqrt());
        let lambda = sx * sy + sy * sz + sz * sx;
        let d = (sp + sx) * (sp + sy) * (sp + sz);
        // 1 + eₘ with eₘ = 4⁻³ᵐδ/dₘ² = Π(√p − √x)/Π(√p + √x), written without cancellation:
        // Π(√p + √x) + Π(√p − √x) = 2√p (p + λ).
        let one_plus_e = 2.0 * sp * (p + lambda) / d;
        sum += scale * rc(1.0, one_plus_e) / d;
        x = (x + lambda) / 4.0;
        y = (y + lambda) / 4.0;
        z = (z + lambda) / 4.0;
        p = (p + lambda) / 4.0;
        a = (a + lambda) / 4.0;
        scale /= 4.0;
    }
    let dx = (a0 - x0) * scale / a;
    let dy = (a0 - y0) * scale / a;
    let dz = (a0 - z0) * scale / a;
    let dp = -(dx + dy + dz) / 2.0;
    let xyz = dx * dy * dz;
    let e2 = dx * dy + dx * dz + dy * dz - 3.0 * dp * dp;
    let e3 = xyz + 2.0 * e2 * dp + 4.0 * dp * dp * dp;
    let e4 = (2.0 * xyz + e2 * dp + 3.0 * dp * dp * dp) * dp;
    let e5 = xyz * dp * dp;
    scale * rd_rj_series(e2, e3, e4, e5) / (a * a.sqrt()) + 6.0 * sum
}

/// R_C(x, y) = ½∫₀^∞ dt/((t+y)√(t+x)) (DLMF 19.2.17) for x ≥ 0, y > 0.
pub fn carlson_rc(x: f64, y: f64) -> Result<f64, DynamicsError> {
    check_finite(&[x, y], "carlson_rc arguments")?;
    if x < 0.0 {
        return Err(domain_error("carlson_rc x", "≥ 0", x));
    }
    if y <= 0.0 {
        return Err(domain_error(
            "carlson_rc y",
            "> 0 (the principal value is not provided)",
            y,
        ));
    }
    Ok(rc(x, y))
}

/// R_C without the domain check (Carlson 1995, algorithm for R_C, seventh-order series).
pub(crate) fn rc(x0: f64, y0: f64) -> f64 {
    let a0 = (x0 + 2.0 * y0) / 3.0;
    let q = (3.0 * TOLERANCE).powf(-1.0 / 8.0) * (a0 - x0).abs();
    let (mut x, mut y, mut a) = (x0, y0, a0);
    let mut scale = 1.0;
    for _ in 0..MAX_STEPS {
        if scale * q < a.abs() {
            break;
        }
        let lambda = 2.0 * x.sqrt() * y.sqrt() + y;
        x = (x + lambda) / 4.0;
        y = (y + lambda) / 4.0;
        a = (a + lambda) / 4.0;
        scale /= 4.0;
    }
    let s = (y0 - a0) * scale / a;
    let series = 1.0
        + s * s
            * (3.0 / 10.0 + s * (1.0 / 7.0 + s * (3.0 / 8.0 + s * (9.0 / 22.0 + s * (159.0 / 208.0 + s * 9.0 / 8.0)))));
    series / a.sqrt()
}
