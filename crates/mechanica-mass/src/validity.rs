//! Physical validity of mass properties: what exactly is wrong with a tensor, the kind of body
//! a valid tensor describes (solid, lamina, rod, point; remark after 3.14), and a repair.

use crate::error::check_result;
use crate::{MassError, MassProperties};
use mechanica_kinematics::scaling::{self, power_of_two_above};
use nalgebra::{Matrix3, Vector3};
use std::fmt;

/// Relative tolerance of the validity check, measured against the scale s = Σ|J_ii| of the
/// tensor (the trace of a valid tensor, ≥ its largest moment).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ValidityTolerance {
    /// Allowed violation, relative to s, of symmetry (|J_ij − J_ji|), of semidefiniteness
    /// (−λ_min) and of the triangle inequality (I₃ − I₁ − I₂). It also decides when a moment
    /// counts as zero (rods, points) and when I₁ + I₂ = I₃ (laminae).
    pub relative: f64,
}

impl Default for ValidityTolerance {
    /// 1e-9: far above the rounding of tensors computed here (≈1e-15) or composed from a few
    /// hundred parts, far below anything a real body violates by. Hand-typed tensors rounded
    /// to a few digits may need [`repair`].
    fn default() -> Self {
        Self { relative: 1e-9 }
    }
}

/// One problem that makes an inertia tensor impossible for any distribution of mass.
#[derive(Debug, Clone, PartialEq)]
pub enum InertiaIssue {
    /// The mass, a centre coordinate or a tensor entry is NaN or ±∞.
    NonFinite {
        /// Which part held it.
        what: &'static str,
        /// The offending value.
        value: f64,
    },
    /// The mass is negative.
    NegativeMass(f64),
    /// The mass is zero but the inertia is not.
    ZeroMassWithInertia,
    /// J_row,col ≠ J_col,row beyond the tolerance (the largest such pair is reported).
    NotSymmetric {
        /// Row of the entry.
        row: usize,
        /// Column of the entry.
        col: usize,
        /// J_row,col − J_col,row.
        difference: f64,
    },
    /// The (symmetric part of the) tensor has a negative eigenvalue beyond the tolerance.
    NotPositiveSemidefinite {
        /// The smallest eigenvalue.
        min_eigenvalue: f64,
    },
    /// The principal moments violate I₁ + I₂ ≥ I₃ beyond the tolerance (3.18 implies it:
    /// I₁ + I₂ − I₃ = 2∫ρ y₃² dV ≥ 0).
    TriangleInequality {
        /// The principal moments, ascending.
        moments: [f64; 3],
        /// I₃ − I₁ − I₂ (> 0 here).
        excess: f64,
    },
}

impl fmt::Display for InertiaIssue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NonFinite { what, value } => write!(f, "{what} is not finite ({value})"),
            Self::NegativeMass(m) => write!(f, "negative mass {m}"),
            Self::ZeroMassWithInertia => write!(f, "zero mass with non-zero inertia"),
            Self::NotSymmetric { row, col, difference } => {
                write!(f, "not symmetric: J[{row}][{col}] - J[{col}][{row}] = {difference}")
            }
            Self::NotPositiveSemidefinite { min_eigenvalue } => {
                write!(f, "not positive semidefinite: smallest eigenvalue {min_eigenvalue}")
            }
            Self::TriangleInequality { moments, excess } => write!(
                f,
                "triangle inequality violated: I1 + I2 < I3 for moments {moments:?} (by {excess})"
            ),
        }
    }
}

/// The kind of body a valid tensor describes (remark after 3.14).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InertiaClass {
    /// Positive definite with I₁ + I₂ > I₃: a body with extent in three directions.
    Solid,
    /// I₁ + I₂ = I₃: all mass in one plane (a lamina, disc or flat shell).
    Planar,
    /// One zero moment and I₂ = I₃: all mass on one line (a rod).
    Linear,
    /// All moments zero: a point mass.
    Point,
}

/// The result of a successful validity check.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ValidityReport {
    /// What kind of body the tensor describes.
    pub class: InertiaClass,
    /// Principal moments of the symmetric part, ascending (3.20–3.21).
    pub moments: Vector3<f64>,
    /// The absolute tolerance applied, relative tolerance × Σ|J_ii|.
    pub absolute_tolerance: f64,
}

/// The smallest violation [`check`] reports: eight spacings of the subnormal grid (2⁻¹⁰⁷⁴),
/// the rounding that tensors of order 1e-320 cannot avoid.
pub const SUBNORMAL_ALLOWANCE: f64 = f64::from_bits(8);

/// Checks that `props` could be the mass properties of a real body and reports every problem
/// found (not only the first) in [`MassError::InvalidInertia`]. Semidefinite tensors of rods,
/// laminae and points are valid and reported through [`InertiaClass`]. The tests run on the
/// tensor scaled by the power of two above its largest entry (they are all relative), so that
/// any finite tensor is judged correctly; moments that exceed f64::MAX once scaled back are
/// [`MassError::NonFiniteResult`].
pub fn check(props: &MassProperties, tol: &ValidityTolerance) -> Result<ValidityReport, MassError> {
    let mut issues = non_finite_issues(props);
    if issues.iter().any(|i| {
        matches!(
            i,
            InertiaIssue::NonFinite {
                what: "inertia tensor",
                ..
            }
        )
    }) {
        return Err(MassError::InvalidInertia(issues));
    }
    if props.mass < 0.0 {
        issues.push(InertiaIssue::NegativeMass(props.mass));
    }
    let scale = power_of_two_above(props.inertia_c.amax());
    let j = props.inertia_c / scale;
    let trace_scale = (0..3).map(|i| j[(i, i)].abs()).sum::<f64>();
    // Entries on the subnormal grid carry an absolute rounding of half its spacing 2⁻¹⁰⁷⁴, which
    // moves each moment by up to three such halves: the tests allow eight spacings at least.
    let abs_tol = (tol.relative * trace_scale).max(SUBNORMAL_ALLOWANCE / scale);
    if props.mass == 0.0 && trace_scale > 0.0 {
        issues.push(InertiaIssue::ZeroMassWithInertia);
    }
    if let Some((row, col, difference)) = worst_asymmetry(&j, abs_tol) {
        issues.push(InertiaIssue::NotSymmetric {
            row,
            col,
            difference: difference * scale,
        });
    }
    let moments = sorted_eigenvalues(&symmetric_part(&j));
    if moments[0] < -abs_tol {
        issues.push(InertiaIssue::NotPositiveSemidefinite {
            min_eigenvalue: moments[0] * scale,
        });
    }
    let excess = moments[2] - moments[0] - moments[1];
    if excess > abs_tol {
        issues.push(InertiaIssue::TriangleInequality {
            moments: [moments[0] * scale, moments[1] * scale, moments[2] * scale],
            excess: excess * scale,
        });
    }
    if !issues.is_empty() {
        return Err(MassError::InvalidInertia(issues));
    }
    let class = if moments[2] <= abs_tol {
        InertiaClass::Point
    } else if moments[0] <= abs_tol {
        InertiaClass::Linear
    } else if -excess <= abs_tol {
        InertiaClass::Planar
    } else {
        InertiaClass::Solid
    };
    let report = ValidityReport {
        class,
        moments: moments * scale,
        absolute_tolerance: abs_tol * scale,
    };
    check_result(
        report.moments.iter().chain([report.absolute_tolerance].iter()),
        "principal moments",
    )?;
    Ok(report)
}

/// [`check`] for mass properties whose mass may be zero while the tensor is not: a part whose
/// mass is negligible but whose rotational inertia is not (a rotor, or a robot file's link
/// written with a zero mass and a tensor, which Pinocchio, Drake and MuJoCo keep as given).
/// Every other issue of [`check`] still fails; the tensor is judged as for a massive body.
pub fn check_allowing_zero_mass(props: &MassProperties, tol: &ValidityTolerance) -> Result<(), MassError> {
    match check(props, tol) {
        Ok(_) => Ok(()),
        Err(MassError::InvalidInertia(issues)) if issues == [InertiaIssue::ZeroMassWithInertia] => Ok(()),
        Err(other) => Err(other),
    }
}

/// The NaN and infinities of `props`, one issue per part (mass, centre, tensor).
fn non_finite_issues(props: &MassProperties) -> Vec<InertiaIssue> {
    let mut issues = Vec::new();
    if !props.mass.is_finite() {
        issues.push(InertiaIssue::NonFinite {
            what: "mass",
            value: props.mass,
        });
    }
    if let Some(value) = props.p_oc.iter().copied().find(|v| !v.is_finite()) {
        issues.push(InertiaIssue::NonFinite {
            what: "centre of mass",
            value,
        });
    }
    if let Some(value) = props.inertia_c.iter().copied().find(|v| !v.is_finite()) {
        issues.push(InertiaIssue::NonFinite {
            what: "inertia tensor",
            value,
        });
    }
    issues
}

/// The largest asymmetry J_rc − J_cr above `abs_tol`, as (row, col, difference).
fn worst_asymmetry(j: &Matrix3<f64>, abs_tol: f64) -> Option<(usize, usize, f64)> {
    let mut worst: Option<(usize, usize, f64)> = None;
    for (row, col) in [(0, 1), (0, 2), (1, 2)] {
        let difference = j[(row, col)] - j[(col, row)];
        if difference.abs() > abs_tol && worst.is_none_or(|w| difference.abs() > w.2.abs()) {
            worst = Some((row, col, difference));
        }
    }
    worst
}

/// What [`repair`] changed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RepairReport {
    /// True when the tensor was modified.
    pub changed: bool,
    /// ‖J_repaired − J_given‖_F.
    pub change_norm: f64,
    /// ‖J_repaired − J_given‖_F / ‖J_given‖_F (0 for a zero tensor).
    pub relative_change: f64,
}

/// Repairs the inertia tensor of `props` when [`check`] rejects it, and returns the nearest
/// physical tensor in the following documented sense:
/// 1. J is replaced by its symmetric part (J + Jᵀ)/2;
/// 2. in its principal frame, the principal second moments σ_k = (I_i + I_j − I_k)/2
///    (= ∫ρ y_k² dV, from 3.18) are clamped to σ_k ≥ 0;
/// 3. the moments are rebuilt as I_k = σ_i + σ_j, which satisfies semidefiniteness and the
///    triangle inequality, and rotated back.
///
/// A tensor that already passes the check is returned bit-for-bit unchanged. The mass and
/// centre cannot be repaired: a non-finite value or a negative mass is still an error.
pub fn repair(props: &MassProperties, tol: &ValidityTolerance) -> Result<(MassProperties, RepairReport), MassError> {
    match check(props, tol) {
        Ok(_) => {
            return Ok((
                *props,
                RepairReport {
                    changed: false,
                    change_norm: 0.0,
                    relative_change: 0.0,
                },
            ));
        }
        Err(MassError::InvalidInertia(issues)) => {
            if let Some(bad) = issues
                .iter()
                .find(|i| matches!(i, InertiaIssue::NonFinite { .. } | InertiaIssue::NegativeMass(_)))
            {
                return Err(MassError::InvalidInertia(vec![bad.clone()]));
            }
        }
        Err(other) => return Err(other),
    }
    let scale = power_of_two_above(props.inertia_c.amax());
    let j = if props.mass == 0.0 {
        Matrix3::zeros()
    } else {
        physical_part(&(props.inertia_c / scale)) * scale
    };
    let change_norm = scaling::frobenius_norm(&(j - props.inertia_c));
    let given = scaling::frobenius_norm(&props.inertia_c);
    let report = RepairReport {
        changed: true,
        change_norm,
        relative_change: if given > 0.0 { change_norm / given } else { 0.0 },
    };
    check_result(
        j.iter().chain([change_norm, report.relative_change].iter()),
        "repaired inertia tensor",
    )?;
    Ok((MassProperties { inertia_c: j, ..*props }, report))
}

/// Steps 1–3 of [`repair`] on a tensor with entries of order one.
fn physical_part(j: &Matrix3<f64>) -> Matrix3<f64> {
    let eig = symmetric_eigen(&symmetric_part(j));
    let l = eig.eigenvalues;
    let sigma = |k: usize| {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        (0.5 * (l[i] + l[j] - l[k])).max(0.0)
    };
    let s = [sigma(0), sigma(1), sigma(2)];
    let repaired_moments = Vector3::new(s[1] + s[2], s[0] + s[2], s[0] + s[1]);
    let v = eig.eigenvectors;
    symmetric_part(&(v * Matrix3::from_diagonal(&repaired_moments) * v.transpose()))
}

/// (J + Jᵀ)/2, halved before the sum so that it never overflows.
pub(crate) fn symmetric_part(j: &Matrix3<f64>) -> Matrix3<f64> {
    j * 0.5 + j.transpose() * 0.5
}

/// Entries below this fraction of a tensor's largest are dropped before its eigen-decomposition.
const NEGLIGIBLE_ENTRY: f64 = 1.0 / (1u128 << 110) as f64;

/// The eigen-decomposition of a symmetric 3×3 matrix with entries of order one (scaled by a
/// power of two). Entries below 2⁻¹¹⁰ of the largest are set to zero first: that moves the
/// matrix by far less than the decomposition's own backward error u·‖J‖, while such entries
/// (a tensor whose entries span 160 decades) have squares below the normal range, and
/// nalgebra's rotations built from them were not orthogonal (eigenvectors of norm 1.08 and a
/// repaired tensor whose moments broke the triangle inequality by 9 %).
pub(crate) fn symmetric_eigen(j: &Matrix3<f64>) -> nalgebra::SymmetricEigen<f64, nalgebra::U3> {
    let floor = j.amax() * NEGLIGIBLE_ENTRY;
    j.map(|x| if x.abs() < floor { 0.0 } else { x }).symmetric_eigen()
}

/// Eigenvalues of a symmetric 3×3 matrix, ascending.
pub(crate) fn sorted_eigenvalues(j: &Matrix3<f64>) -> Vector3<f64> {
    let mut l = symmetric_eigen(j).eigenvalues;
    l.as_mut_slice().sort_by(f64::total_cmp);
    l
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On the subnormal grid a tensor is judged within a few of its spacings: the rounding of
    /// a repaired tensor there is accepted, a violation of many spacings is not.
    #[test]
    fn subnormal_tensors_are_judged_on_their_grid() {
        let tiny = f64::from_bits(1);
        let rounded = Matrix3::new(2.0, 1.0, 1.0, 1.0, 2.0, 1.0, 1.0, 1.0, 2.0) * tiny;
        assert!(check(&props(1.0, rounded), &ValidityTolerance::default()).is_ok());
        let rod_too_far = Matrix3::from_diagonal(&Vector3::new(0.0, 0.0, 100.0)) * tiny;
        assert!(matches!(
            check(&props(1.0, rod_too_far), &ValidityTolerance::default()),
            Err(MassError::InvalidInertia(ref issues))
                if issues.iter().any(|i| matches!(i, InertiaIssue::TriangleInequality { .. }))
        ));
    }

    fn props(mass: f64, j: Matrix3<f64>) -> MassProperties {
        MassProperties {
            mass,
            p_oc: Vector3::zeros(),
            inertia_c: j,
        }
    }

    fn diag(a: f64, b: f64, c: f64) -> Matrix3<f64> {
        Matrix3::from_diagonal(&Vector3::new(a, b, c))
    }

    fn issues(p: &MassProperties) -> Vec<InertiaIssue> {
        match check(p, &ValidityTolerance::default()) {
            Err(MassError::InvalidInertia(i)) => i,
            other => panic!("expected invalid, got {other:?}"),
        }
    }

    #[test]
    fn semidefinite_bodies_are_valid_and_classified() {
        let tol = ValidityTolerance::default();
        let class = |p: MassProperties| check(&p, &tol).map(|r| r.class);
        assert_eq!(class(props(1.0, diag(1.0, 2.0, 2.5))), Ok(InertiaClass::Solid));
        // Disc lamina m r²/4, m r²/4, m r²/2: I1 + I2 = I3 exactly.
        assert_eq!(class(props(1.0, diag(0.25, 0.25, 0.5))), Ok(InertiaClass::Planar));
        // Rod along z with length 1: 1/12, 1/12, 0, and a rounding-level negative moment.
        assert_eq!(
            class(props(1.0, diag(1.0 / 12.0, 1.0 / 12.0, -1e-18))),
            Ok(InertiaClass::Linear)
        );
        assert_eq!(class(props(1.0, Matrix3::zeros())), Ok(InertiaClass::Point));
    }

    #[test]
    fn every_problem_is_named() {
        let mut j = diag(1.0, 1.0, 1.0);
        j[(0, 1)] = 0.1;
        assert_eq!(
            issues(&props(1.0, j)),
            vec![InertiaIssue::NotSymmetric {
                row: 0,
                col: 1,
                difference: 0.1
            }]
        );
        assert_eq!(
            issues(&props(-2.0, diag(1.0, 1.0, 1.0))),
            vec![InertiaIssue::NegativeMass(-2.0)]
        );
        let bad = issues(&props(1.0, diag(-1.0, 2.0, 3.0)));
        assert!(matches!(bad[0], InertiaIssue::NotPositiveSemidefinite { min_eigenvalue } if min_eigenvalue == -1.0));
        assert!(matches!(bad[1], InertiaIssue::TriangleInequality { excess, .. } if excess == 2.0));
        let tri = issues(&props(1.0, diag(1.0, 1.0, 3.0)));
        assert_eq!(
            tri,
            vec![InertiaIssue::TriangleInequality {
                moments: [1.0, 1.0, 3.0],
                excess: 1.0
            }]
        );
        assert!(matches!(
            issues(&props(1.0, diag(f64::NAN, 1.0, 1.0)))[0],
            InertiaIssue::NonFinite {
                what: "inertia tensor",
                ..
            }
        ));
        assert_eq!(
            issues(&props(0.0, diag(1.0, 1.0, 1.0))),
            vec![InertiaIssue::ZeroMassWithInertia]
        );
    }

    #[test]
    fn repair_fixes_what_it_can_and_leaves_valid_tensors_alone() {
        let tol = ValidityTolerance::default();
        let good = props(1.0, diag(1.0, 2.0, 2.5));
        let (same, report) = repair(&good, &tol).expect("valid");
        assert_eq!(same, good);
        assert!(!report.changed);
        // A disc lamina typed with 4 digits violates the triangle inequality by 1e-4.
        let typed = props(1.0, diag(0.25, 0.25, 0.5001));
        assert!(check(&typed, &tol).is_err());
        let (fixed, report) = repair(&typed, &tol).expect("repairable");
        assert!(check(&fixed, &tol).is_ok());
        assert!(report.changed && report.relative_change < 1e-3);
        // σ = (0.25+0.5001−0.25)/2 … clamped: σ₃ = 0 → I₃ = I₁ + I₂ after the repair.
        let m = sorted_eigenvalues(&fixed.inertia_c);
        assert!((m[0] + m[1] - m[2]).abs() <= 1e-15);
        // Asymmetric and indefinite input.
        let mut j = diag(-0.1, 1.0, 1.0);
        j[(1, 2)] = 0.2;
        let (fixed, _) = repair(&props(1.0, j), &tol).expect("repairable");
        assert!(check(&fixed, &tol).is_ok());
        assert!(repair(&props(-1.0, diag(1.0, 1.0, 1.0)), &tol).is_err());
    }
}
