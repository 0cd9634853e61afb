//! A proof that a stiffness matrix whose off-diagonal nonzeros form a forest (spring chains and
//! spring trees, numbered in any order) stays positive definite when each entry is moved by its
//! own rounding, |Δb_ij| ≤ u|b_ij|: for the case double precision cannot decide, B's smallest
//! eigenvalue below the rounding 4n·u·max b_kk of a Cholesky factorization
//! ([`super::inertia::stiffness_is_definite`]), as in a chain whose springs span twelve
//! decades. docs/theory.md, §6 "Numerical eigenproblem and certified accuracy", item 5
//! (Classification), gives the argument.
//!
//! Any symmetric ΔB obeys ΔB ⪰ −diag(Σ_j |Δb_ij|) (the difference is diagonally dominant with
//! a non-negative diagonal), so B + ΔB ⪰ B − D with D = diag(u Σ_j |b_ij|), and it suffices to
//! prove B − D ≻ 0. A free structure whose assembly happened to round its stiffness to a
//! positive definite matrix fails that test (its smallest eigenvalue is of the size of D), so
//! its rigid-body mode stays within the data's resolution; a structure held by a spring well
//! above the rounding passes it.
//!
//! The elimination of a forest from its leaves makes no fill: the pivot of a coordinate i is
//! d_i = b_ii − D_ii − s − Σ_c b_ic²/d_c over its children c, here in double-double arithmetic
//! on B scaled by a power of two. Each operation errs by at most a few units of 2⁻¹⁰⁴ relative
//! (products of doubles exactly, quotients relatively, sums absolutely in their operands), so
//! the computed pivots are the exact pivots of a B̃ − D − sI with |b̃_ic − b_ic| ≤ γ|b_ic| and
//! |b̃_ii − b_ii| ≤ 2γ|b_ii| wherever they come out positive, γ = 16(n + 8)·2⁻¹⁰⁴. With every
//! pivot positive, B̃ − D − sI ≻ 0 (Sylvester), and ‖B − B̃‖₂ ≤ ‖B − B̃‖∞ ≤ 2γ·max_i Σ_j |b_ij|
//! < s for the shift s = 4γ·max_i Σ_j |b_ij| used, so B − D ≻ 0.
//!
//! The answer "not proven" is returned when the pattern is not a forest, an entry is so small
//! after scaling that its square would leave the normal range, or a pivot is not positive.

use faer::MatRef;

use crate::dd::Dd;
use crate::linalg::powers_of_two::{exponent, times_power_of_two};

/// Scaled entries below this magnitude are not squared (their squares would be subnormal).
const SMALLEST_SCALED_ENTRY: f64 = 1e-150;

/// Whether B (lower triangle read) is proven positive definite, with room for the rounding of
/// each entry, by the forest elimination.
pub(crate) fn forest_is_positive_definite(b: MatRef<'_, f64>) -> bool {
    let n = b.nrows();
    let Some(forest) = Forest::of(b) else {
        return false;
    };
    let largest = forest
        .edges
        .iter()
        .map(|e| e.2.abs())
        .chain((0..n).map(|i| b[(i, i)].abs()))
        .fold(0.0_f64, f64::max);
    if largest == 0.0 || !largest.is_finite() {
        return false;
    }
    let scale = exponent(largest);
    let scaled = |x: f64| times_power_of_two(x, -scale);
    let mut row_sums: Vec<f64> = (0..n).map(|i| scaled(b[(i, i)]).abs()).collect();
    for &(i, j, value) in &forest.edges {
        let v = scaled(value).abs();
        if v < SMALLEST_SCALED_ENTRY {
            return false;
        }
        row_sums[i] += v;
        row_sums[j] += v;
    }
    let gamma = 16.0 * (n as f64 + 8.0) * times_power_of_two(1.0, -104);
    let shift = 4.0 * gamma * row_sums.iter().fold(0.0_f64, |m, &s| m.max(s));
    let rounding = times_power_of_two(1.0, -53);
    let mut pivot: Vec<Dd> = (0..n)
        .map(|i| Dd::of(scaled(b[(i, i)])).minus(Dd::of(rounding * row_sums[i] + shift)))
        .collect();
    for &node in forest.leaves_first.iter() {
        let d = pivot[node];
        if !(d.hi > 0.0 && d.hi.is_finite()) {
            return false;
        }
        if let Some((parent, coupling)) = forest.parent[node] {
            let c = Dd::of(scaled(coupling));
            pivot[parent] = pivot[parent].minus(c.times(c).over(d));
        }
    }
    true
}

/// The forest of B's off-diagonal pattern: its edges (i > j, b_ij ≠ 0), each coordinate's
/// parent with the coupling b_ip, and an order with every child before its parent.
struct Forest {
    edges: Vec<(usize, usize, f64)>,
    parent: Vec<Option<(usize, f64)>>,
    leaves_first: Vec<usize>,
}

impl Forest {
    /// None when the pattern has a cycle (more than n − components edges).
    fn of(b: MatRef<'_, f64>) -> Option<Self> {
        let n = b.nrows();
        let mut edges = Vec::new();
        for j in 0..n {
            for i in j + 1..n {
                let value = b[(i, j)];
                if value != 0.0 {
                    if edges.len() + 1 >= n.max(1) {
                        return None;
                    }
                    edges.push((i, j, value));
                }
            }
        }
        let mut neighbours: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        for &(i, j, value) in &edges {
            neighbours[i].push((j, value));
            neighbours[j].push((i, value));
        }
        let mut parent: Vec<Option<(usize, f64)>> = vec![None; n];
        let mut seen = vec![false; n];
        let mut order = Vec::with_capacity(n);
        for root in 0..n {
            if seen[root] {
                continue;
            }
            seen[root] = true;
            let start = order.len();
            order.push(root);
            let mut next = start;
            while next < order.len() {
                let node = order[next];
                next += 1;
                for &(other, value) in &neighbours[node] {
                    if parent[node].is_some_and(|(p, _)| p == other) {
                        continue;
                    }
                    if seen[other] {
                        return None; // a second path to `other`: a cycle
                    }
                    seen[other] = true;
                    parent[other] = Some((node, value));
                    order.push(other);
                }
            }
        }
        order.reverse();
        Some(Self {
            edges,
            parent,
            leaves_first: order,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;

    /// The stiffness of springs `k` on the edges (i, parent) of a forest, ground springs
    /// `ground` on the diagonal.
    fn assemble(n: usize, springs: &[(usize, usize, f64)], ground: &[(usize, f64)]) -> Mat<f64> {
        let mut b = Mat::<f64>::zeros(n, n);
        for &(i, j, k) in springs {
            b[(i, i)] += k;
            b[(j, j)] += k;
            b[(i, j)] -= k;
            b[(j, i)] -= k;
        }
        for &(i, k) in ground {
            b[(i, i)] += k;
        }
        b
    }

    #[test]
    fn a_grounded_chain_is_definite_and_a_free_one_is_not() {
        let springs = [(1, 0, 1e12), (2, 1, 1.0), (3, 2, 1e6), (4, 3, 1e-3)];
        assert!(forest_is_positive_definite(assemble(5, &springs, &[(0, 1.0)]).as_ref()));
        assert!(!forest_is_positive_definite(assemble(5, &springs, &[]).as_ref()));
        // A ground spring below the rounding of the stiff entries does not count; one above does.
        assert!(!forest_is_positive_definite(
            assemble(5, &springs, &[(4, 1e-9)]).as_ref()
        ));
        assert!(forest_is_positive_definite(
            assemble(5, &springs, &[(4, 1e-2)]).as_ref()
        ));
    }

    #[test]
    fn a_cycle_or_a_negative_stiffness_is_not_proven() {
        let ring = [(1, 0, 1.0), (2, 1, 1.0), (2, 0, 1.0)];
        assert!(!forest_is_positive_definite(assemble(3, &ring, &[(0, 1.0)]).as_ref()));
        let negative = [(1, 0, 1.0), (2, 1, -0.5)];
        assert!(!forest_is_positive_definite(
            assemble(3, &negative, &[(0, 1.0)]).as_ref()
        ));
    }

    #[test]
    fn scale_does_not_matter_within_the_range() {
        let springs = [(1, 0, 1e12), (2, 0, 1.0), (3, 2, 1e6)];
        for e in [-900, -300, 0, 300, 900] {
            let b = assemble(4, &springs, &[(3, 1.0)]);
            let b = Mat::from_fn(4, 4, |i, j| times_power_of_two(b[(i, j)], e));
            assert!(forest_is_positive_definite(b.as_ref()), "scaled by 2^{e}");
        }
    }
}
