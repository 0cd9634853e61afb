//! The eigenvalues grouped into modes and classified by their bounds.
//!
//! A conjugate pair is one mode; real roots are paired when their eigenvectors are parallel
//! (|x₁*x₂| ≥ ‖x₁‖‖x₂‖/√2, most parallel first: the two roots −ζω ± ω√(ζ² − 1) of an overdamped
//! proportionally damped mode share their shape); every other real root and every infinite
//! eigenvalue is a mode of its own. With r the bound of s:
//!
//! | kind | condition |
//! |---|---|
//! | Rigid | \|s\| ≤ r (for any eigenvalue of the mode) |
//! | Unstable | Re s > r (for any eigenvalue of the mode) |
//! | Neutral | \|Re s\| ≤ r < Im s |
//! | Underdamped | Re s < −r, Im s > r |
//! | Critical | Re s < −r, Im s ≤ r; or two real roots whose disks meet |
//! | Overdamped | two real roots < −r, disks apart |
//! | Relaxation | one real root < −r |
//! | Undecided | \|Re s\| ≤ r, Im s ≤ r < \|s\| |

use super::certify::Certified;
use super::scaling::ScaledProblem;
use super::{QuadraticEigenvalue, QuadraticMode, QuadraticModeKind, QuadraticModes, QuadraticOptions};
use crate::error::ModalError;
use faer::{Mat, c64};
use std::f64::consts::FRAC_1_SQRT_2;

/// One eigenvalue with its right eigenvector.
struct Entry {
    value: QuadraticEigenvalue,
    x: Vec<c64>,
}

/// The modes (with their eigenvalues in mode order) of the certified eigenpairs.
pub(super) fn assemble(
    p: &ScaledProblem,
    certified: Vec<Certified>,
    options: &QuadraticOptions,
) -> Result<QuadraticModes, ModalError> {
    let mut entries = Vec::with_capacity(2 * certified.len());
    let mut groups: Vec<Vec<usize>> = Vec::new();
    let mut real_roots = Vec::new();
    for c in certified {
        let first = entries.len();
        if c.pair.conjugate_pair {
            let conjugate = QuadraticEigenvalue {
                s: c.value.s.map(|s| s.conj()),
                ..c.value
            };
            let x_conj = c.pair.x.iter().map(|z| z.conj()).collect();
            entries.push(Entry {
                value: c.value,
                x: c.pair.x,
            });
            entries.push(Entry {
                value: conjugate,
                x: x_conj,
            });
            if c.value.s.is_some() {
                groups.push(vec![first, first + 1]);
            } else {
                groups.extend([vec![first], vec![first + 1]]);
            }
        } else {
            if c.value.s.is_some() {
                real_roots.push(first);
            } else {
                groups.push(vec![first]);
            }
            entries.push(Entry {
                value: c.value,
                x: c.pair.x,
            });
        }
    }
    groups.extend(pair_real_roots(&entries, &real_roots));
    let mut modes: Vec<QuadraticMode> = groups.into_iter().map(|g| mode_of(&entries, g)).collect();
    modes.sort_by(|m1, m2| {
        let key = |m: &QuadraticMode| (m.natural_frequency.is_none(), m.natural_frequency.unwrap_or(0.0));
        key(m1).partial_cmp(&key(m2)).unwrap_or(std::cmp::Ordering::Equal)
    });
    Ok(ordered(p, entries, modes, options))
}

/// Real roots paired by the parallelism of their eigenvectors (most parallel first); the rest
/// alone.
fn pair_real_roots(entries: &[Entry], roots: &[usize]) -> Vec<Vec<usize>> {
    let cosine = |i: usize, j: usize| {
        let (x, y) = (&entries[i].x, &entries[j].x);
        let dot: c64 = x.iter().zip(y).map(|(a, b)| a.conj() * b).sum();
        let norms =
            x.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt() * y.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt();
        if norms > 0.0 { dot.norm() / norms } else { 0.0 }
    };
    let mut candidates = Vec::new();
    for (k, &i) in roots.iter().enumerate() {
        for &j in &roots[k + 1..] {
            let c = cosine(i, j);
            if c >= FRAC_1_SQRT_2 {
                candidates.push((c, i, j));
            }
        }
    }
    candidates.sort_by(|p, q| q.0.partial_cmp(&p.0).unwrap_or(std::cmp::Ordering::Equal));
    let mut used = vec![false; entries.len()];
    let mut groups = Vec::new();
    for (_, i, j) in candidates {
        if !used[i] && !used[j] {
            used[i] = true;
            used[j] = true;
            groups.push(vec![i, j]);
        }
    }
    groups.extend(roots.iter().filter(|&&i| !used[i]).map(|&i| vec![i]));
    groups
}

/// The mode of the eigenvalues `group` (see the module docs for the kinds).
fn mode_of(entries: &[Entry], eigenvalues: Vec<usize>) -> QuadraticMode {
    let values: Vec<(c64, f64)> = eigenvalues
        .iter()
        .filter_map(|&i| entries[i].value.s.map(|s| (s, entries[i].value.error_bound)))
        .collect();
    let (kind, natural_frequency, damping_ratio) = match values.as_slice() {
        [(s, r)] => (single_kind(*s, *r), Some(s.norm()), ratio(s.re, s.re, s.norm())),
        [(s1, r1), (s2, r2)] => {
            let omega_n = s1.norm().sqrt() * s2.norm().sqrt();
            let kind = if s1.im != 0.0 {
                pair_kind(*s1, *r1)
            } else {
                real_pair_kind((s1.re, *r1), (s2.re, *r2))
            };
            (kind, Some(omega_n), ratio(s1.re, s2.re, omega_n))
        }
        _ => (QuadraticModeKind::Infinite, None, None),
    };
    let damped_frequency = values.first().map_or(0.0, |v| v.0.im.abs());
    QuadraticMode {
        kind,
        eigenvalues,
        natural_frequency,
        damped_frequency,
        damping_ratio,
    }
}

/// ζ = −(s₁ + s₂)/(2ω_n), None for ω_n = 0.
fn ratio(re1: f64, re2: f64, omega_n: f64) -> Option<f64> {
    (omega_n > 0.0).then(|| -(re1 / omega_n + re2 / omega_n) / 2.0)
}

/// A single real root.
fn single_kind(s: c64, r: f64) -> QuadraticModeKind {
    if s.norm() <= r {
        QuadraticModeKind::Rigid
    } else if s.re > r {
        QuadraticModeKind::Unstable
    } else {
        QuadraticModeKind::Relaxation
    }
}

/// A conjugate pair, s its member with Im s > 0.
fn pair_kind(s: c64, r: f64) -> QuadraticModeKind {
    let oscillates = s.im.abs() > r;
    if s.norm() <= r {
        QuadraticModeKind::Rigid
    } else if s.re > r {
        QuadraticModeKind::Unstable
    } else if s.re >= -r {
        if oscillates {
            QuadraticModeKind::Neutral
        } else {
            QuadraticModeKind::Undecided
        }
    } else if oscillates {
        QuadraticModeKind::Underdamped
    } else {
        QuadraticModeKind::Critical
    }
}

/// Two real roots (value, bound).
fn real_pair_kind((s1, r1): (f64, f64), (s2, r2): (f64, f64)) -> QuadraticModeKind {
    if s1 > r1 || s2 > r2 {
        QuadraticModeKind::Unstable
    } else if s1.abs() <= r1 || s2.abs() <= r2 {
        QuadraticModeKind::Rigid
    } else if (s1 - s2).abs() <= r1 + r2 {
        QuadraticModeKind::Critical
    } else {
        QuadraticModeKind::Overdamped
    }
}

/// The result with the eigenvalues (and vectors) renumbered in mode order.
fn ordered(
    p: &ScaledProblem,
    entries: Vec<Entry>,
    mut modes: Vec<QuadraticMode>,
    options: &QuadraticOptions,
) -> QuadraticModes {
    let n = p.order();
    let mut order = Vec::with_capacity(entries.len());
    for mode in &mut modes {
        for index in &mut mode.eigenvalues {
            order.push(*index);
            *index = order.len() - 1;
        }
    }
    let eigenvalues: Vec<QuadraticEigenvalue> = order.iter().map(|&i| entries[i].value).collect();
    let vectors = options.vectors.then(|| {
        Mat::from_fn(n, order.len(), |r, k| {
            let x = &entries[order[k]].x;
            let norm = x.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt();
            if norm > 0.0 { x[r] / norm } else { x[r] }
        })
    });
    QuadraticModes {
        max_backward_error: eigenvalues.iter().map(|e| e.backward_error).fold(0.0, f64::max),
        eigenvalues,
        modes,
        vectors,
        frequency_scale_exponent: p.gamma_exponent,
        coefficient_scale_exponent: p.delta_exponent,
    }
}
