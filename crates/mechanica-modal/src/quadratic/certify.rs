//! Backward error, condition and error bound of every eigenvalue (Tisseur 2000), computed on
//! the scaled problem in homogeneous form so that nothing overflows near infinite eigenvalues.
//!
//! With (a, b) the normalized homogeneous coordinates of s̃ = a/b, P̃(a, b) = a²Ã + abC̃ + b²B̃,
//! H = |a|²‖Ã‖ + |a||b|‖C̃‖ + |b|²‖B̃‖ and D = y*(2aÃ + bC̃)x (= b·y*P̃′(s̃)x):
//!
//! - η = ‖P̃(a, b)x‖ / (H‖x‖), which for b ≠ 0 is the backward error of (s̃, x), plus
//!   2(n + 4)u for the rounding of the residual itself (‖|M||x|‖ ≤ ‖M‖_F‖x‖);
//! - the first-order bound |Δs̃| ≤ η H ‖y‖‖x‖ / (|b||D|) and κ = H‖y‖‖x‖ / (|a||D|);
//! - the eigenvalue is infinite within its bound when its chordal distance b to ∞ is at most
//!   the first-order chordal bound η H ‖y‖‖x‖ b / |D| (Dedieu & Tisseur), i.e. |D| ≤ η H ‖y‖‖x‖.

use super::linearize::Eigenpair;
use super::scaling::ScaledProblem;
use super::{QuadraticBoundKind, QuadraticEigenvalue};
use crate::error::ModalError;
use crate::linalg::norms::euclidean_norm;
use crate::linalg::powers_of_two::times_power_of_two;
use faer::{Mat, c64};

/// An eigenpair of the scaled problem with its certificate, the bound in stored units.
pub(super) struct Certified {
    pub pair: Eigenpair,
    pub value: QuadraticEigenvalue,
}

/// The products of Ã, C̃, B̃ with every right eigenvector, as real and imaginary parts.
struct Products {
    ax: (Mat<f64>, Mat<f64>),
    cx: (Mat<f64>, Mat<f64>),
    bx: (Mat<f64>, Mat<f64>),
}

/// Certifies every eigenpair, then widens the bounds of eigenvalues whose first-order disks
/// overlap into cluster bounds.
pub(super) fn certify(p: &ScaledProblem, pairs: Vec<Eigenpair>) -> Result<Vec<Certified>, ModalError> {
    let n = p.order();
    let xr = Mat::from_fn(n, pairs.len(), |i, k| pairs[k].x[i].re);
    let xi = Mat::from_fn(n, pairs.len(), |i, k| pairs[k].x[i].im);
    let times = |m: &Mat<f64>| (m * &xr, m * &xi);
    let products = Products {
        ax: times(&p.a),
        cx: times(&p.c),
        bx: times(&p.b),
    };
    let mut certified = Vec::with_capacity(pairs.len());
    for (k, pair) in pairs.into_iter().enumerate() {
        let value = first_order(p, &products, k, &pair)?;
        certified.push(Certified { pair, value });
    }
    widen_clusters(&mut certified);
    for c in &certified {
        if !c.value.error_bound.is_finite() {
            return Err(ModalError::OutOfRange {
                what: "the error bound of an eigenvalue".to_string(),
                detail: format!(
                    "it is {:e}: y*(2sA + C)x vanishes (a defective eigenvalue) or the bound exceeds the range of doubles",
                    c.value.error_bound
                ),
            });
        }
    }
    Ok(certified)
}

/// Column k of (re, im) as complex numbers.
fn column(m: &(Mat<f64>, Mat<f64>), k: usize) -> impl Iterator<Item = c64> + '_ {
    (0..m.0.nrows()).map(move |i| c64::new(m.0[(i, k)], m.1[(i, k)]))
}

fn norm(v: &[c64]) -> f64 {
    let parts: Vec<f64> = v.iter().flat_map(|z| [z.re, z.im]).collect();
    euclidean_norm(&parts)
}

/// y*(M x) for column k of a product M X.
fn left_product(y: &[c64], product: &(Mat<f64>, Mat<f64>), k: usize) -> c64 {
    column(product, k).zip(y).map(|(mx, y)| y.conj() * mx).sum()
}

/// The radius of the local model of a perturbed eigenvalue, min(2ρ/σ, √(ρ/κ)) for a residual ρ,
/// slope σ = |y*P′x| and curvature κ = |y*Ax| (x/0 = ∞): the distance from a computed root of
/// a scalar quadratic to the nearest exact root when ρ bounds its residual.
fn local_radius(residual: f64, slope: f64, curvature: f64) -> f64 {
    let first = if slope > 0.0 {
        2.0 * residual / slope
    } else {
        f64::INFINITY
    };
    let second = if curvature > 0.0 {
        (residual / curvature).sqrt()
    } else {
        f64::INFINITY
    };
    first.min(second)
}

/// η, κ and the bound of eigenpair k (see the module docs).
fn first_order(
    p: &ScaledProblem,
    products: &Products,
    k: usize,
    pair: &Eigenpair,
) -> Result<QuadraticEigenvalue, ModalError> {
    let (a, b) = (pair.a, pair.b);
    let residual: Vec<c64> = column(&products.ax, k)
        .zip(column(&products.cx, k))
        .zip(column(&products.bx, k))
        .map(|((ax, cx), bx)| a * a * ax + a * b * cx + bx * (b * b))
        .collect();
    let y = &pair.y;
    let (yax, ycx, ybx) = (
        left_product(y, &products.ax, k),
        left_product(y, &products.cx, k),
        left_product(y, &products.bx, k),
    );
    let (x_norm, y_norm) = (norm(&pair.x), norm(y));
    let h = a.norm_sqr() * p.norm_a + a.norm() * b * p.norm_c + b * b * p.norm_b;
    let unit_roundoff = f64::EPSILON / 2.0;
    let rounding = 2.0 * (p.order() as f64 + 4.0) * unit_roundoff;
    let eta = if h * x_norm > 0.0 {
        norm(&residual) / (h * x_norm) + rounding
    } else {
        1.0
    };
    let numerator = eta * h * x_norm * y_norm;
    let forward = (yax * a * 2.0 + ycx * b).norm();
    if a.norm() > b {
        // μ̃ = b/a of the reversed polynomial μ²B̃ + μC̃ + Ã.
        let reverse = (ycx * a + ybx * (2.0 * b)).norm();
        let radius = local_radius(numerator / a.norm_sqr(), reverse / a.norm(), ybx.norm());
        if b / a.norm() <= radius {
            return Ok(QuadraticEigenvalue {
                s: None,
                backward_error: eta,
                condition: None,
                error_bound: times_power_of_two(2.0 * radius, -p.gamma_exponent),
                bound_kind: QuadraticBoundKind::FirstOrder,
            });
        }
    }
    let s = c64::new(
        times_power_of_two(a.re / b, p.gamma_exponent),
        times_power_of_two(a.im / b, p.gamma_exponent),
    );
    if !(s.re.is_finite() && s.im.is_finite()) {
        return Err(ModalError::OutOfRange {
            what: "an eigenvalue s".to_string(),
            detail: format!(
                "|s| exceeds the range of doubles once scaled back by 2^{}",
                p.gamma_exponent
            ),
        });
    }
    let radius = local_radius(numerator / (b * b), forward / b, yax.norm());
    Ok(QuadraticEigenvalue {
        s: Some(s),
        backward_error: eta,
        condition: (a.norm() * forward > 0.0).then(|| h * x_norm * y_norm / (a.norm() * forward)),
        error_bound: times_power_of_two(radius, p.gamma_exponent),
        bound_kind: QuadraticBoundKind::FirstOrder,
    })
}

/// The finite eigenvalues (both members of each conjugate pair) as points with their bounds;
/// where disks overlap, every member of the connected cluster gets the distance to the
/// farthest member plus the cluster's largest bound, until no disk overlaps a new one.
fn widen_clusters(certified: &mut [Certified]) {
    let mut points = Vec::new();
    for (k, c) in certified.iter().enumerate() {
        if let Some(s) = c.value.s {
            points.push((k, s, c.value.error_bound));
            if c.pair.conjugate_pair {
                points.push((k, s.conj(), c.value.error_bound));
            }
        }
    }
    let mut radius: Vec<f64> = points.iter().map(|p| p.2).collect();
    let mut clustered = vec![false; points.len()];
    for _ in 0..points.len() {
        let label = components(&points.iter().map(|p| p.1).collect::<Vec<_>>(), &radius);
        let mut changed = false;
        for members in groups(&label).iter().filter(|g| g.len() > 1) {
            let largest = members.iter().map(|&j| radius[j]).fold(0.0, f64::max);
            for &i in members {
                let farthest = members
                    .iter()
                    .map(|&j| (points[i].1 - points[j].1).norm())
                    .fold(0.0, f64::max);
                clustered[i] = true;
                if farthest + largest > radius[i] {
                    radius[i] = farthest + largest;
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    for (i, point) in points.iter().enumerate() {
        let value = &mut certified[point.0].value;
        if clustered[i] {
            value.bound_kind = QuadraticBoundKind::Cluster;
            value.error_bound = value.error_bound.max(radius[i]);
        }
    }
}

/// Labels of the connected components of the graph joining points whose disks overlap.
fn components(points: &[c64], radius: &[f64]) -> Vec<usize> {
    let m = points.len();
    let mut label: Vec<usize> = (0..m).collect();
    fn root(label: &mut [usize], mut i: usize) -> usize {
        while label[i] != i {
            label[i] = label[label[i]];
            i = label[i];
        }
        i
    }
    for i in 0..m {
        for j in i + 1..m {
            if (points[i] - points[j]).norm() <= radius[i] + radius[j] {
                let (ri, rj) = (root(&mut label, i), root(&mut label, j));
                label[ri.max(rj)] = ri.min(rj);
            }
        }
    }
    (0..m).map(|i| root(&mut label, i)).collect()
}

/// The members of each component, from the labels of [`components`].
fn groups(label: &[usize]) -> Vec<Vec<usize>> {
    let mut members = vec![Vec::new(); label.len()];
    for (i, &l) in label.iter().enumerate() {
        members[l].push(i);
    }
    members
}
