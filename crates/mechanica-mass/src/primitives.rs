//! Closed-form mass properties of primitive bodies, by density or by total mass.
//!
//! Each primitive is given in its own body frame B; the doc of each function states where the
//! origin and axes of B lie. Rods, laminae and points have semidefinite (or planar) inertia
//! (remark after 3.14). Integrals are those of 3.17–3.18 evaluated in closed form, so the
//! results are exact up to rounding. Non-finite or non-positive dimensions, masses and densities
//! are refused with a [`MassError`] naming the input. Masses and moments are formed as
//! products with the exponents kept apart (m·L²·f with a shape factor f of order one), so a
//! result over- or underflows only when its exact value does: a mass that underflows is
//! [`MassError::MassUnderflow`], a mass or moment that overflows
//! [`MassError::NonFiniteResult`] naming it.

use crate::error::{check_dimension, check_finite, check_result};
use crate::{MassError, MassProperties};
use mechanica_kinematics::scaling;
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::PI;

/// How much material a body has: a total mass, or a density (kg/m for rods, kg/m² for
/// laminae and shells, kg/m³ for solids).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Amount {
    /// Total mass in kg.
    Mass(f64),
    /// Density per unit length, area or volume, by the dimension of the body.
    Density(f64),
}

impl Amount {
    /// The mass of a body of measure (length, area or volume) `measure`, checking that the
    /// mass or density is finite and positive, and that density × measure neither underflows
    /// to zero ([`MassError::MassUnderflow`]) nor overflows ([`MassError::NonFiniteResult`]).
    pub fn mass_for(&self, measure: f64) -> Result<f64, MassError> {
        self.mass_for_product(&[measure])
    }

    /// [`Amount::mass_for`] for the measure Π `factors` (a constant and the dimensions), the
    /// product ρ·Π factors formed with the exponents kept apart, so that it over- or underflows
    /// only when the mass itself does.
    pub(crate) fn mass_for_product(&self, factors: &[f64]) -> Result<f64, MassError> {
        match *self {
            Amount::Mass(m) => {
                check_finite(m, "mass")?;
                if m > 0.0 {
                    Ok(m)
                } else {
                    Err(MassError::NonPositiveMass(m))
                }
            }
            Amount::Density(rho) => {
                check_finite(rho, "density")?;
                if rho <= 0.0 {
                    return Err(MassError::NonPositiveDensity(rho));
                }
                let mut all = vec![rho];
                all.extend_from_slice(factors);
                let m = scaling::product(&all);
                if m == 0.0 {
                    return Err(MassError::MassUnderflow {
                        density: rho,
                        measure: factors.iter().product(),
                    });
                }
                check_result([m].iter(), "mass")?;
                Ok(m)
            }
        }
    }
}

/// m·L²·f, the product kept apart: a moment of inertia with length scale L and a
/// dimensionless shape factor f = O(1).
fn moment(m: f64, length: f64, f: f64) -> f64 {
    scaling::product(&[m, length, length, f])
}

/// Principal moments (I_xx, I_yy, I_zz) about the centre of mass, checked finite.
fn centred(mass: f64, moments: [f64; 3], quantity: &'static str) -> Result<MassProperties, MassError> {
    check_result(moments.iter(), quantity)?;
    Ok(MassProperties {
        mass,
        p_oc: Vector3::zeros(),
        inertia_c: Matrix3::from_diagonal(&Vector3::from(moments)),
    })
}

/// A point mass at the origin of B. `Amount::Density` is taken as the mass itself.
pub fn point(amount: Amount) -> Result<MassProperties, MassError> {
    let m = amount.mass_for(1.0)?;
    centred(m, [0.0; 3], "point moment of inertia")
}

/// A thin straight rod of length `length` along the z axis of B, centred at the origin;
/// density per metre. I_xx = I_yy = m L²/12, I_zz = 0 (semidefinite).
pub fn rod(length: f64, amount: Amount) -> Result<MassProperties, MassError> {
    let l = check_dimension(length, "rod length")?;
    let m = amount.mass_for_product(&[l])?;
    let i = moment(m, l, 1.0 / 12.0);
    centred(m, [i, i, 0.0], "rod moment of inertia")
}

/// A rectangular lamina with sides `size_x` × `size_y` in the xy plane of B, centred at the
/// origin; density per m². I_xx = m b²/12, I_yy = m a²/12, I_zz = m(a² + b²)/12.
pub fn rectangle_lamina(size_x: f64, size_y: f64, amount: Amount) -> Result<MassProperties, MassError> {
    let a = check_dimension(size_x, "rectangle size_x")?;
    let b = check_dimension(size_y, "rectangle size_y")?;
    let m = amount.mass_for_product(&[a, b])?;
    let l = a.max(b);
    let (a, b) = (a / l, b / l);
    let moments = [b * b, a * a, a * a + b * b].map(|f| moment(m, l, f / 12.0));
    centred(m, moments, "rectangle moment of inertia")
}

/// A disc lamina of radius `radius` in the xy plane of B, centred at the origin; density per
/// m². I_xx = I_yy = m r²/4, I_zz = m r²/2.
pub fn disc_lamina(radius: f64, amount: Amount) -> Result<MassProperties, MassError> {
    let r = check_dimension(radius, "disc radius")?;
    let m = amount.mass_for_product(&[PI, r, r])?;
    let (i, j) = (moment(m, r, 0.25), moment(m, r, 0.5));
    centred(m, [i, i, j], "disc moment of inertia")
}

/// A solid sphere of radius `radius` centred at the origin of B. I = 2/5 m r².
pub fn sphere(radius: f64, amount: Amount) -> Result<MassProperties, MassError> {
    let r = check_dimension(radius, "sphere radius")?;
    let m = amount.mass_for_product(&[4.0 / 3.0 * PI, r, r, r])?;
    let i = moment(m, r, 0.4);
    centred(m, [i, i, i], "sphere moment of inertia")
}

/// A solid ellipsoid with semi-axes `a`, `b`, `c` along x, y, z of B, centred at the origin.
/// I_xx = m(b² + c²)/5 and cyclically.
pub fn ellipsoid(a: f64, b: f64, c: f64, amount: Amount) -> Result<MassProperties, MassError> {
    let a = check_dimension(a, "ellipsoid semi-axis a")?;
    let b = check_dimension(b, "ellipsoid semi-axis b")?;
    let c = check_dimension(c, "ellipsoid semi-axis c")?;
    let m = amount.mass_for_product(&[4.0 / 3.0 * PI, a, b, c])?;
    let l = a.max(b).max(c);
    let (a, b, c) = (a / l, b / l, c / l);
    let moments = [b * b + c * c, a * a + c * c, a * a + b * b].map(|f| moment(m, l, f / 5.0));
    centred(m, moments, "ellipsoid moment of inertia")
}

/// A solid box with edge lengths `size_x`, `size_y`, `size_z` centred at the origin of B.
/// I_xx = m(b² + c²)/12 and cyclically.
pub fn solid_box(size_x: f64, size_y: f64, size_z: f64, amount: Amount) -> Result<MassProperties, MassError> {
    let a = check_dimension(size_x, "box size_x")?;
    let b = check_dimension(size_y, "box size_y")?;
    let c = check_dimension(size_z, "box size_z")?;
    let m = amount.mass_for_product(&[a, b, c])?;
    let l = a.max(b).max(c);
    let (a, b, c) = (a / l, b / l, c / l);
    let moments = [b * b + c * c, a * a + c * c, a * a + b * b].map(|f| moment(m, l, f / 12.0));
    centred(m, moments, "box moment of inertia")
}

/// A solid circular cylinder of radius `radius` and height `height` along z of B, centred at
/// the origin. I_xx = I_yy = m(3r² + h²)/12, I_zz = m r²/2.
pub fn cylinder(radius: f64, height: f64, amount: Amount) -> Result<MassProperties, MassError> {
    let r = check_dimension(radius, "cylinder radius")?;
    let h = check_dimension(height, "cylinder height")?;
    let m = amount.mass_for_product(&[PI, r, r, h])?;
    let l = r.max(h);
    let (rr, hh) = (r / l, h / l);
    let ixx = moment(m, l, (3.0 * rr * rr + hh * hh) / 12.0);
    centred(m, [ixx, ixx, moment(m, l, rr * rr / 2.0)], "cylinder moment of inertia")
}

/// A solid right circular cone of base radius `radius` and height `height`: the origin of B
/// is the centre of the base, the apex lies at (0, 0, h). The centre of mass is at (0, 0, h/4);
/// about it I_xx = I_yy = m(3r²/20 + 3h²/80), I_zz = 3 m r²/10.
pub fn cone(radius: f64, height: f64, amount: Amount) -> Result<MassProperties, MassError> {
    let r = check_dimension(radius, "cone radius")?;
    let h = check_dimension(height, "cone height")?;
    let m = amount.mass_for_product(&[PI / 3.0, r, r, h])?;
    let l = r.max(h);
    let (rr, hh) = (r / l, h / l);
    let ixx = moment(m, l, 3.0 * rr * rr / 20.0 + 3.0 * hh * hh / 80.0);
    Ok(MassProperties {
        p_oc: Vector3::new(0.0, 0.0, h / 4.0),
        ..centred(m, [ixx, ixx, moment(m, l, 0.3 * rr * rr)], "cone moment of inertia")?
    })
}

/// A solid hemisphere of radius `radius`: the origin of B is the centre of the flat face, the
/// dome lies on +z. The centre of mass is at (0, 0, 3r/8); about it I_xx = I_yy = 83/320 m r²,
/// I_zz = 2/5 m r².
pub fn hemisphere(radius: f64, amount: Amount) -> Result<MassProperties, MassError> {
    let r = check_dimension(radius, "hemisphere radius")?;
    let m = amount.mass_for_product(&[2.0 / 3.0 * PI, r, r, r])?;
    let ixx = moment(m, r, 83.0 / 320.0);
    Ok(MassProperties {
        // r·(3/8), not 3r/8: 3r overflows for r above f64::MAX/3.
        p_oc: Vector3::new(0.0, 0.0, r * 0.375),
        ..centred(m, [ixx, ixx, moment(m, r, 0.4)], "hemisphere moment of inertia")?
    })
}

/// A solid capsule: a cylinder of radius `radius` and length `cylinder_length` along z with a
/// hemispherical cap of the same radius on each end, centred at the origin of B. Composed from
/// the cylinder and the two hemispheres by Steiner (3.27–3.29), in lengths relative to the
/// larger of r and l.
pub fn capsule(radius: f64, cylinder_length: f64, amount: Amount) -> Result<MassProperties, MassError> {
    let r = check_dimension(radius, "capsule radius")?;
    let l = check_dimension(cylinder_length, "capsule cylinder length")?;
    let scale = r.max(l);
    let (rr, ll) = (r / scale, l / scale);
    // Volume = π r² (l + 4r/3) = π scale³ r̂² (l̂ + 4r̂/3).
    let m = amount.mass_for_product(&[PI, scale, scale, scale, rr * rr * (ll + 4.0 * rr / 3.0)])?;
    // Mass fractions of the cylinder and of each cap.
    let f_cyl = ll / (ll + 4.0 * rr / 3.0);
    let f_cap = 0.5 * (1.0 - f_cyl);
    // Each cap's centre lies at l/2 + 3r/8 from the capsule centre.
    let d = ll / 2.0 + 3.0 * rr / 8.0;
    let fxx = f_cyl * (3.0 * rr * rr + ll * ll) / 12.0 + 2.0 * f_cap * (83.0 / 320.0 * rr * rr + d * d);
    let fzz = f_cyl * rr * rr / 2.0 + 2.0 * f_cap * 0.4 * rr * rr;
    let ixx = moment(m, scale, fxx);
    centred(m, [ixx, ixx, moment(m, scale, fzz)], "capsule moment of inertia")
}

/// A solid torus with ring (major) radius `ring_radius` and tube (minor) radius
/// `tube_radius` ≤ `ring_radius`, around the z axis of B, centred at the origin.
/// V = 2π² R r², I_zz = m(R² + 3r²/4), I_xx = I_yy = m(R²/2 + 5r²/8).
pub fn torus(ring_radius: f64, tube_radius: f64, amount: Amount) -> Result<MassProperties, MassError> {
    let big = check_dimension(ring_radius, "torus ring radius")?;
    let r = check_dimension(tube_radius, "torus tube radius")?;
    if r > big {
        return Err(MassError::InconsistentDimensions(
            "torus tube radius exceeds its ring radius (self-intersecting)",
        ));
    }
    let m = amount.mass_for_product(&[2.0 * PI * PI, big, r, r])?;
    let rr = r / big;
    let ixx = moment(m, big, 0.5 + 5.0 * rr * rr / 8.0);
    centred(
        m,
        [ixx, ixx, moment(m, big, 1.0 + 0.75 * rr * rr)],
        "torus moment of inertia",
    )
}

#[cfg(test)]
mod tests {
    //! Independent references: slice integrals along z evaluated by composite Simpson
    //! quadrature in the test (each slice an elliptic disc or annulus with its own textbook
    //! lamina inertia), 2-D quadrature for laminae, and the validity check for the class.
    use super::*;
    use crate::validity::{InertiaClass, ValidityTolerance, check};

    /// Mass properties of a solid of revolution-like body made of elliptic slices with
    /// semi-axes (a(t), b(t)) at height z(t), t ∈ [t0, t1], dz = z'(t) dt, density 1, minus an
    /// optional inner slice (for a torus). Returns (m, z_c, I_xx, I_yy, I_zz) about the centre.
    fn slices(
        t0: f64,
        t1: f64,
        f: impl Fn(f64) -> (f64, f64, f64, f64, f64, f64), // (z, dz/dt, a_out, b_out, a_in, b_in)
    ) -> (f64, f64, f64, f64, f64) {
        let n = 4000; // even; Simpson error ∝ h⁴ ≈ (1/4000)⁴ relative on smooth integrands
        let h = (t1 - t0) / n as f64;
        let mut acc = [0.0f64; 6]; // m, ∫z, ∫x², ∫y², ∫z²  (second moments), spare
        for k in 0..=n {
            let t = t0 + h * k as f64;
            let w = if k == 0 || k == n {
                1.0
            } else if k % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let (z, dz, a, b, ai, bi) = f(t);
            // Ellipse of semi-axes a, b: area π a b, ∫x² dA = π a³ b / 4, ∫y² dA = π a b³ / 4.
            let area = PI * (a * b - ai * bi);
            let x2 = PI * (a * a * a * b - ai * ai * ai * bi) / 4.0;
            let y2 = PI * (a * b * b * b - ai * bi * bi * bi) / 4.0;
            let c = w * dz * h / 3.0;
            acc[0] += c * area;
            acc[1] += c * area * z;
            acc[2] += c * x2;
            acc[3] += c * y2;
            acc[4] += c * area * z * z;
        }
        let m = acc[0];
        let zc = acc[1] / m;
        let z2c = acc[4] - m * zc * zc;
        (m, zc, acc[3] + z2c, acc[2] + z2c, acc[2] + acc[3])
    }

    fn assert_matches(p: &MassProperties, reference: (f64, f64, f64, f64, f64), tol: f64) {
        let (m, zc, ixx, iyy, izz) = reference;
        let scale = ixx.max(iyy).max(izz);
        assert!((p.mass - m).abs() <= tol * m, "mass {} vs {m}", p.mass);
        assert!(
            (p.p_oc.z - zc).abs() <= tol * m.cbrt().max(1.0),
            "z_c {} vs {zc}",
            p.p_oc.z
        );
        let j = &p.inertia_c;
        for (got, want) in [(j[(0, 0)], ixx), (j[(1, 1)], iyy), (j[(2, 2)], izz)] {
            assert!((got - want).abs() <= tol * scale, "{got} vs {want}");
        }
        assert_eq!(j[(0, 1)], 0.0);
        assert_eq!(j[(0, 2)], 0.0);
        assert_eq!(j[(1, 2)], 0.0);
    }

    const RHO: Amount = Amount::Density(1.0);
    // Simpson with n = 4000 on integrands that are smooth after the substitutions below.
    const QUAD_TOL: f64 = 1e-11;

    #[test]
    fn sphere_ellipsoid_and_hemisphere_match_slice_quadrature() {
        let r = 1.3;
        // z = r sin t keeps the slice radius r cos t smooth in t.
        let sphere_ref = slices(-PI / 2.0, PI / 2.0, |t| {
            let s = r * t.cos();
            (r * t.sin(), r * t.cos(), s, s, 0.0, 0.0)
        });
        assert_matches(&sphere(r, RHO).expect("ok"), sphere_ref, QUAD_TOL);
        let (a, b, c) = (0.5, 1.2, 2.0);
        let ell_ref = slices(-PI / 2.0, PI / 2.0, |t| {
            (c * t.sin(), c * t.cos(), a * t.cos(), b * t.cos(), 0.0, 0.0)
        });
        assert_matches(&ellipsoid(a, b, c, RHO).expect("ok"), ell_ref, QUAD_TOL);
        let hemi_ref = slices(0.0, PI / 2.0, |t| {
            let s = r * t.cos();
            (r * t.sin(), r * t.cos(), s, s, 0.0, 0.0)
        });
        assert_matches(&hemisphere(r, RHO).expect("ok"), hemi_ref, QUAD_TOL);
    }

    #[test]
    fn cylinder_cone_capsule_and_torus_match_slice_quadrature() {
        let (r, h) = (0.7, 2.5);
        let cyl_ref = slices(-h / 2.0, h / 2.0, |z| (z, 1.0, r, r, 0.0, 0.0));
        assert_matches(&cylinder(r, h, RHO).expect("ok"), cyl_ref, QUAD_TOL);
        let cone_ref = slices(0.0, h, |z| {
            let s = r * (1.0 - z / h);
            (z, 1.0, s, s, 0.0, 0.0)
        });
        assert_matches(&cone(r, h, RHO).expect("ok"), cone_ref, QUAD_TOL);
        // Capsule: lower cap, cylinder and upper cap, each a smooth piece of its own.
        let l = 1.1;
        let lower = |t: f64| (-l / 2.0 + r * t.sin(), r * t.cos(), r * t.cos(), r * t.cos(), 0.0, 0.0);
        let middle = |z: f64| (z, 1.0, r, r, 0.0, 0.0);
        let upper = |t: f64| (l / 2.0 + r * t.sin(), r * t.cos(), r * t.cos(), r * t.cos(), 0.0, 0.0);
        // Integrate the three smooth pieces separately and combine (Simpson needs smoothness).
        let parts = [
            slices(-PI / 2.0, 0.0, lower),
            slices(-l / 2.0, l / 2.0, middle),
            slices(0.0, PI / 2.0, upper),
        ];
        let m: f64 = parts.iter().map(|p| p.0).sum();
        let zc = parts.iter().map(|p| p.0 * p.1).sum::<f64>() / m;
        let shift = |p: &(f64, f64, f64, f64, f64)| p.0 * (p.1 - zc) * (p.1 - zc);
        let ixx: f64 = parts.iter().map(|p| p.2 + shift(p)).sum();
        let iyy: f64 = parts.iter().map(|p| p.3 + shift(p)).sum();
        let izz: f64 = parts.iter().map(|p| p.4).sum();
        assert_matches(&capsule(r, l, RHO).expect("ok"), (m, zc, ixx, iyy, izz), QUAD_TOL);
        // Torus: annulus slices with radii R ± r cos t at z = r sin t.
        let (big, small) = (2.0, 0.6);
        let torus_ref = slices(-PI / 2.0, PI / 2.0, |t| {
            let s = small * t.cos();
            (small * t.sin(), small * t.cos(), big + s, big + s, big - s, big - s)
        });
        assert_matches(&torus(big, small, RHO).expect("ok"), torus_ref, QUAD_TOL);
    }

    #[test]
    fn box_laminae_rod_and_point_match_direct_quadrature() {
        // Midpoint rule on polynomials of degree 2 has error h²/12·f'' — exact after Richardson;
        // instead use Simpson (exact for cubics) in each direction.
        fn simpson(a: f64, b: f64, f: impl Fn(f64) -> f64) -> f64 {
            let n = 2;
            let h = (b - a) / n as f64;
            (f(a) + 4.0 * f(a + h) + f(b)) * h / 3.0
        }
        let (a, b, c) = (0.3, 1.7, 0.9);
        let bx = solid_box(a, b, c, Amount::Density(2.0)).expect("ok");
        let m = 2.0 * a * b * c;
        let ixx = 2.0 * a * simpson(-b / 2.0, b / 2.0, |y| simpson(-c / 2.0, c / 2.0, |z| y * y + z * z));
        assert!((bx.mass - m).abs() <= 1e-15 * m);
        assert!((bx.inertia_c[(0, 0)] - ixx).abs() <= 1e-15 * ixx);
        let rect = rectangle_lamina(a, b, Amount::Mass(3.0)).expect("ok");
        let izz = 3.0 / (a * b) * simpson(-a / 2.0, a / 2.0, |x| simpson(-b / 2.0, b / 2.0, |y| x * x + y * y));
        assert!((rect.inertia_c[(2, 2)] - izz).abs() <= 1e-15 * izz);
        assert_eq!(
            check(&rect, &ValidityTolerance::default()).map(|r| r.class),
            Ok(InertiaClass::Planar)
        );
        let disc = disc_lamina(0.5, Amount::Mass(2.0)).expect("ok");
        assert_eq!(
            check(&disc, &ValidityTolerance::default()).map(|r| r.class),
            Ok(InertiaClass::Planar)
        );
        // Disc: ∫ r² dA = π R⁴ / 2 by Simpson in the radius (exact for the cubic 2π r³).
        let polar = 2.0 / (PI * 0.25) * simpson(0.0, 0.5, |s| 2.0 * PI * s * s * s);
        assert!((disc.inertia_c[(2, 2)] - polar).abs() <= 1e-15 * polar);
        let rod = rod(2.0, Amount::Density(0.5)).expect("ok");
        let ixx = 0.5 * simpson(-1.0, 1.0, |z| z * z);
        assert!((rod.mass - 1.0).abs() <= 1e-15 && (rod.inertia_c[(0, 0)] - ixx).abs() <= 1e-15);
        assert_eq!(
            check(&rod, &ValidityTolerance::default()).map(|r| r.class),
            Ok(InertiaClass::Linear)
        );
        let p = point(Amount::Mass(4.0)).expect("ok");
        assert_eq!(
            check(&p, &ValidityTolerance::default()).map(|r| r.class),
            Ok(InertiaClass::Point)
        );
    }

    #[test]
    fn by_mass_and_by_density_agree_and_bad_amounts_are_named() {
        let by_density = cone(0.5, 1.0, Amount::Density(1000.0)).expect("ok");
        let by_mass = cone(0.5, 1.0, Amount::Mass(by_density.mass)).expect("ok");
        assert!((by_density.inertia_c - by_mass.inertia_c).norm() <= 1e-15 * by_mass.inertia_c.norm());
        assert_eq!(
            sphere(1.0, Amount::Density(0.0)),
            Err(MassError::NonPositiveDensity(0.0))
        );
        assert_eq!(sphere(1.0, Amount::Mass(-1.0)), Err(MassError::NonPositiveMass(-1.0)));
        assert!(matches!(sphere(f64::NAN, RHO), Err(MassError::NonFinite { .. })));
        assert!(matches!(
            cylinder(1.0, -2.0, RHO),
            Err(MassError::NonPositiveDimension { value: -2.0, .. })
        ));
        assert!(matches!(
            torus(1.0, 2.0, RHO),
            Err(MassError::InconsistentDimensions(_))
        ));
        assert_eq!(
            sphere(1e200, Amount::Density(1e200)),
            Err(MassError::NonFiniteResult { quantity: "mass" })
        );
    }
}
