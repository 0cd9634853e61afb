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
//!
//! The same elimination of B − sA with a diagonal A > 0 counts the pencil's eigenvalues below s
//! (its negative pivots, Sylvester's law of inertia) up to a margin ([`ForestPencil`]):
//! what orders and signs modes whose residual intervals cannot.

use faer::MatRef;

use crate::dd::Dd;
use crate::linalg::forest_order::leaves_first;
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
    let Some(scale) = forest.scale((0..n).map(|i| b[(i, i)].abs()).fold(0.0_f64, f64::max)) else {
        return false;
    };
    let scaled = |x: f64| times_power_of_two(x, -scale);
    let mut row_sums: Vec<f64> = (0..n).map(|i| scaled(b[(i, i)]).abs()).collect();
    for &(i, j, value) in &forest.edges {
        let v = scaled(value).abs();
        row_sums[i] += v;
        row_sums[j] += v;
    }
    let shift = 4.0 * elimination_rounding(n) * row_sums.iter().fold(0.0_f64, |m, &s| m.max(s));
    let rounding = times_power_of_two(1.0, -53);
    let pivots = (0..n)
        .map(|i| Dd::of(scaled(b[(i, i)])).minus(Dd::of(rounding * row_sums[i] + shift)))
        .collect();
    forest.negative_pivots(pivots, scaled) == Some(0)
}

/// γ = 16(n + 8)·2⁻¹⁰⁴: the relative perturbation of B's entries that accounts for the
/// double-double elimination of an order-n forest (module documentation).
fn elimination_rounding(n: usize) -> f64 {
    16.0 * (n as f64 + 8.0) * times_power_of_two(1.0, -104)
}

/// The number of eigenvalues of the pencil (B, A) below a shift s, for a diagonal A > 0 and a B
/// whose off-diagonal pattern is a forest: `below` negative pivots of B − sA eliminated from the
/// leaves in double-double arithmetic (Sylvester's law of inertia), with the `margin` m within
/// which that count is exact. By the argument of the module documentation the pivots are the
/// exact pivots of B + E − sA with |E_ij| ≤ γ|b_ij| off the diagonal and
/// |E_ii| ≤ 2γ(|b_ii| + |s|a_ii); E moves every eigenvalue of the pencil by at most
/// ‖A^{-1/2}EA^{-1/2}‖₂ ≤ m = max_i Σ_j |E_ij|/√(a_i a_j) (Weyl), so at least `below` eigenvalues
/// lie below s + m and at most `below` below s − m.
pub(crate) struct ForestCount {
    pub(crate) below: usize,
    pub(crate) margin: f64,
}

/// A pencil (B, A) with A diagonal and positive and B's off-diagonal pattern a forest, ready to
/// count its eigenvalues below any shift ([`ForestPencil::count_below`]).
pub(crate) struct ForestPencil<'a> {
    b: MatRef<'a, f64>,
    masses: Vec<f64>,
    forest: Forest,
}

impl<'a> ForestPencil<'a> {
    /// None when A is not diagonal with positive finite entries or B's pattern is not a forest.
    pub(crate) fn new(a: MatRef<'a, f64>, b: MatRef<'a, f64>) -> Option<Self> {
        let n = b.nrows();
        let masses: Vec<f64> = (0..n).map(|i| a[(i, i)]).collect();
        let diagonal = (0..n).all(|j| (0..n).all(|i| i == j || a[(i, j)] == 0.0));
        if !diagonal || !masses.iter().all(|&m| m > 0.0 && m.is_finite()) {
            return None;
        }
        let forest = Forest::of(b)?;
        Some(Self { b, masses, forest })
    }

    /// [`ForestCount`] at `shift`; None when the shift or an entry is not finite, an entry is
    /// too small after scaling to be squared, or a pivot vanishes. O(n).
    pub(crate) fn count_below(&self, shift: f64) -> Option<ForestCount> {
        let (b, masses, forest) = (self.b, &self.masses, &self.forest);
        let n = b.nrows();
        if !shift.is_finite() {
            return None;
        }
        let diagonal_largest = (0..n)
            .map(|i| b[(i, i)].abs().max(shift.abs() * masses[i]))
            .fold(0.0_f64, f64::max);
        let scale = forest.scale(diagonal_largest)?;
        let scaled = |x: f64| times_power_of_two(x, -scale);
        let gamma = elimination_rounding(n);
        let mut spread: Vec<f64> = (0..n)
            .map(|i| 2.0 * gamma * (b[(i, i)].abs() + shift.abs() * masses[i]) / masses[i])
            .collect();
        for &(i, j, value) in &forest.edges {
            let term = gamma * value.abs() / (masses[i].sqrt() * masses[j].sqrt());
            spread[i] += term;
            spread[j] += term;
        }
        let margin = spread.iter().fold(0.0_f64, |m, &v| m.max(v));
        let pivots = (0..n)
            .map(|i| Dd::of(scaled(b[(i, i)])).minus(Dd::of(shift).times(Dd::of(scaled(masses[i])))))
            .collect();
        let below = forest.negative_pivots(pivots, scaled)?;
        margin.is_finite().then_some(ForestCount { below, margin })
    }

    /// A relative margin of the counts with respect to the shifted pencil (B + σA, A), whose
    /// eigenvalues are λ + σ, for σ ≥ 0 and B with a non-negative diagonal: a count c at a
    /// shift s ≥ 0 then proves λ_{c+1} ≥ s − (s + σ)ρ and λ_c < s + (s + σ)ρ (eigenvalues
    /// ascending, from 1). The elimination's perturbation of B is componentwise,
    /// |E_B| ≤ 2γ|B| ≤ 2γ|B + σA|, so with B + σA = DHD, D² = diag(B + σA), it is at most
    /// η = 2γ‖|H|‖∞/λ_min(H) relative to B + σA in the sense of quadratic forms; that of A is
    /// at most 2γs/(s + σ) ≤ 2γ relative, and ρ ≥ (η + 2γ)/(1 − η) (docs/theory.md, §6,
    /// item 5, "Inertia enclosures"). λ_min(H) ≥ t − m is proven by a count of zero for
    /// (B + σA) − t·diag(B + σA), diagonal formed in double-double, at the first t = 2⁻ʲ from
    /// `start` down that gives one. A shift σ near the mode makes H far better conditioned than
    /// diag(B)^{-1/2}B diag(B)^{-1/2} where B is singular up to rounding (free structures).
    /// None when σ or B's diagonal is negative or not finite, or no t gives η below 10⁻³.
    /// O(n) per trial t.
    pub(crate) fn relative_margin(&self, sigma: f64, start: f64) -> Option<ShiftedMargin> {
        let (b, forest) = (self.b, &self.forest);
        let n = b.nrows();
        if !(sigma >= 0.0 && sigma.is_finite() && (0..n).all(|i| b[(i, i)] >= 0.0)) {
            return None;
        }
        let shifted: Vec<Dd> = (0..n)
            .map(|i| Dd::of(b[(i, i)]).plus(Dd::of(sigma).times(Dd::of(self.masses[i]))))
            .collect();
        let diagonal: Vec<f64> = shifted.iter().map(|d| d.hi).collect();
        if !diagonal.iter().all(|&d| d > 0.0 && d.is_finite()) {
            return None;
        }
        let mut rows = vec![1.0_f64; n];
        for &(i, j, value) in &forest.edges {
            let h = value.abs() / (diagonal[i].sqrt() * diagonal[j].sqrt());
            rows[i] += h;
            rows[j] += h;
        }
        // Twice the computed ‖|H|‖∞, and a count margin 2γ(2 + that) in H's units (the
        // diagonal perturbed by 2γ·2d_i, each coupling by γ|h_ij| from both rows): room for
        // their own rounding.
        let coupling = 2.0 * rows.iter().fold(0.0_f64, |m, &r| m.max(r));
        let gamma = elimination_rounding(n);
        let count_margin = 2.0 * gamma * (2.0 + coupling);
        let scale = forest.scale(diagonal.iter().copied().fold(0.0_f64, f64::max))?;
        let scaled = |x: f64| times_power_of_two(x, -scale);
        let mut t = start.min(0.5);
        while 2.0 * gamma * coupling < 1e-3 * t {
            let one_minus_t = Dd::of(1.0).minus(Dd::of(t));
            let pivots = shifted
                .iter()
                .map(|d| Dd::of(scaled(d.hi)).plus(Dd::of(scaled(d.lo))).times(one_minus_t))
                .collect();
            // A vanishing pivot (t exactly an eigenvalue) only asks for another t.
            let smallest = t - count_margin;
            if forest.negative_pivots(pivots, scaled) == Some(0) && smallest > 0.0 {
                let eta = 2.0 * gamma * coupling / smallest;
                let rho = 2.0 * (eta + 2.0 * gamma) / (1.0 - eta);
                return Some(ShiftedMargin { sigma, rho, floor: t });
            }
            t *= 0.5;
        }
        None
    }

    /// A proven bound e with the eigenvalue of ascending rank `rank` (from 0) in
    /// [value − e, value + e]: counts below value·(1 ∓ r) of at most `rank` and at least
    /// `rank` + 1, for the first r of 2⁻⁴⁸, 2⁻³⁶, 2⁻²⁴, 2⁻¹² that gives them, widened by the
    /// counts' margins (each count's absolute margin, and for non-negative shifts the relative
    /// one of `relative`, from [`ForestPencil::relative_margin`]; the tighter end is kept) and
    /// by the rounding of the interval's ends. None for a zero or non-finite value, or when no
    /// r separates. At most eight counts.
    pub(crate) fn enclose(&self, rank: usize, value: f64, relative: Option<ShiftedMargin>) -> Option<f64> {
        if value == 0.0 || !value.is_finite() {
            return None;
        }
        for exponent in [-48, -36, -24, -12] {
            let r = times_power_of_two(1.0, exponent);
            let (low_shift, high_shift) = (value - r * value.abs(), value + r * value.abs());
            let Some(low) = self.count_below(low_shift).filter(|c| c.below <= rank) else {
                continue;
            };
            let Some(high) = self.count_below(high_shift).filter(|c| c.below > rank) else {
                continue;
            };
            let mut low_end = low_shift - low.margin;
            let mut high_end = high_shift + high.margin;
            if let Some(m) = relative {
                if low_shift >= 0.0 {
                    low_end = low_end.max(low_shift - (low_shift + m.sigma) * m.rho);
                }
                if high_shift >= 0.0 {
                    high_end = high_end.min(high_shift + (high_shift + m.sigma) * m.rho);
                }
            }
            let reach = (value - low_end).max(high_end - value);
            let rounding = 2.0 * f64::EPSILON * (value.abs() + relative.map_or(0.0, |m| m.sigma * m.rho));
            return Some((reach + rounding) * (1.0 + 2.0 * f64::EPSILON));
        }
        None
    }
}

/// The relative margin ρ of [`ForestPencil::relative_margin`] for the shift σ, and the t at
/// which λ_min(H) was proven (a start for the next, larger σ: λ_min(H) does not fall as σ
/// grows while it is below 1).
#[derive(Debug, Clone, Copy)]
pub(crate) struct ShiftedMargin {
    pub(crate) sigma: f64,
    pub(crate) rho: f64,
    pub(crate) floor: f64,
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
        let (leaves_first, parent) = leaves_first(n, std::iter::empty(), |v| &neighbours[v])?;
        Some(Self {
            edges,
            parent,
            leaves_first,
        })
    }

    /// The power-of-two exponent that brings the largest magnitude of an elimination, the
    /// larger of `diagonal_largest` and the largest coupling, near one; None when that is zero
    /// or not finite, or when a coupling so scaled is too small to be squared.
    fn scale(&self, diagonal_largest: f64) -> Option<i32> {
        let largest = self.edges.iter().map(|e| e.2.abs()).fold(diagonal_largest, f64::max);
        if largest == 0.0 || !largest.is_finite() {
            return None;
        }
        let scale = exponent(largest);
        let tiny = |value: f64| times_power_of_two(value, -scale).abs() < SMALLEST_SCALED_ENTRY;
        (!self.edges.iter().any(|e| tiny(e.2))).then_some(scale)
    }

    /// The number of negative pivots of the symmetric matrix with diagonal `pivots` and this
    /// forest's couplings (each mapped by `scaled`), eliminated from the leaves in double-double
    /// arithmetic without fill; None when a pivot is zero or not finite.
    fn negative_pivots(&self, mut pivots: Vec<Dd>, scaled: impl Fn(f64) -> f64) -> Option<usize> {
        let mut negative = 0;
        for &node in &self.leaves_first {
            let d = pivots[node];
            if d.hi == 0.0 || !d.hi.is_finite() {
                return None;
            }
            negative += usize::from(d.hi < 0.0);
            if let Some((parent, coupling)) = self.parent[node] {
                let c = Dd::of(scaled(coupling));
                pivots[parent] = pivots[parent].minus(c.times(c).over(d));
            }
        }
        Some(negative)
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

    /// B = S T S and A = S² with T the fixed chain (−1, 2, −1) of order n and S diagonal,
    /// graded at random over eight decades in either direction: the pencil's eigenvalues are
    /// T's, 2 − 2cos(kπ/(n + 1)), up to 4u from rounding the stored entries. A count inside
    /// every gap (off its midpoint, where B − sA has exactly zero pivots), in any coordinate
    /// order (the chain renumbered at random), is exact, and its margin is far inside the gap.
    #[test]
    fn counts_on_graded_chains_match_the_closed_form() {
        let mut rng = crate::testing::graded::SplitMix::new(0x2545_f491_4f6c_dd1d);
        let mut uniform = move || rng.unit();
        for trial in 0..20 {
            let n = 8 + trial * 3;
            let scale: Vec<f64> = (0..n).map(|_| 10f64.powf(8.0 * uniform() - 4.0)).collect();
            let mut order: Vec<usize> = (0..n).collect();
            for i in (1..n).rev() {
                order.swap(i, (uniform() * (i + 1) as f64) as usize % (i + 1));
            }
            let mut b = Mat::<f64>::zeros(n, n);
            let mut a = Mat::<f64>::zeros(n, n);
            for i in 0..n {
                let (p, sp) = (order[i], scale[i]);
                a[(p, p)] = sp * sp;
                b[(p, p)] = 2.0 * sp * sp;
                if i + 1 < n {
                    let (q, sq) = (order[i + 1], scale[i + 1]);
                    b[(p, q)] = -sp * sq;
                    b[(q, p)] = -sp * sq;
                }
            }
            let exact: Vec<f64> = (1..=n)
                .map(|k| 2.0 - 2.0 * (k as f64 * std::f64::consts::PI / (n + 1) as f64).cos())
                .collect();
            for k in 0..=n {
                let (lo, hi) = (
                    if k == 0 { 0.0 } else { exact[k - 1] },
                    exact.get(k).copied().unwrap_or(4.0),
                );
                let shift = lo + 0.45 * (hi - lo);
                let count = ForestPencil::new(a.as_ref(), b.as_ref())
                    .and_then(|p| p.count_below(shift))
                    .expect("a forest with positive masses");
                assert_eq!(count.below, k, "trial {trial}: count at {shift}");
                assert!(
                    count.margin < 1e-20 * (hi - lo),
                    "trial {trial}: margin {:e}",
                    count.margin
                );
            }
        }
    }

    /// A = S², B = S T S for the chain T of order n (−1 beside the diagonal; 2 on it when
    /// `fixed`, else the number of neighbours), S diagonal powers of two over eight decades
    /// either way, coordinates renumbered at random: stored exactly.
    fn power_of_two_chain(rng: &mut crate::testing::graded::SplitMix, n: usize, fixed: bool) -> (Mat<f64>, Mat<f64>) {
        let scale: Vec<f64> = (0..n)
            .map(|_| times_power_of_two(1.0, rng.uniform(-26.5, 26.5).round() as i32))
            .collect();
        let mut order: Vec<usize> = (0..n).collect();
        for i in (1..n).rev() {
            order.swap(i, rng.below(i + 1));
        }
        let (mut a, mut b) = (Mat::<f64>::zeros(n, n), Mat::<f64>::zeros(n, n));
        for i in 0..n {
            let p = order[i];
            let neighbours = usize::from(i > 0) + usize::from(i + 1 < n);
            a[(p, p)] = scale[i] * scale[i];
            b[(p, p)] = if fixed { 2.0 } else { neighbours as f64 } * scale[i] * scale[i];
            if i + 1 < n {
                let q = order[i + 1];
                b[(p, q)] = -scale[i] * scale[i + 1];
                b[(q, p)] = b[(p, q)];
            }
        }
        (a, b)
    }

    /// B = S T S and A = S² with T the fixed chain (−1, 2, −1) of order n and S diagonal powers
    /// of two over eight decades either way, renumbered at random: the stored pencil is exact
    /// and its eigenvalues are 4 sin²(kπ/(2n + 2)), computed here to a few ulps. Each, offered
    /// 1e-14 relative off with its rank, is enclosed within 1e-10 relative; offered with the
    /// rank of a neighbour, any enclosure given still holds that neighbour's eigenvalue.
    #[test]
    fn enclosures_hold_the_eigenvalue_of_their_rank() {
        let mut rng = crate::testing::graded::SplitMix::new(0x0e4c_1057);
        for trial in 0..16 {
            let n = 2 + rng.below(70);
            let (a, b) = power_of_two_chain(&mut rng, n, true);
            let exact: Vec<f64> = (1..=n)
                .map(|k| 4.0 * (k as f64 * std::f64::consts::PI / (2 * n + 2) as f64).sin().powi(2))
                .collect();
            let pencil = ForestPencil::new(a.as_ref(), b.as_ref()).expect("a forest with positive masses");
            let relative = pencil.relative_margin(0.0, 0.5);
            assert!(relative.is_some_and(|m| m.rho < 1e-16), "trial {trial}: {relative:?}");
            for (k, &w) in exact.iter().enumerate() {
                let value = w * (1.0 + rng.uniform(-1e-14, 1e-14));
                let bound = pencil.enclose(k, value, relative).expect("an enclosure");
                assert!(
                    (value - w).abs() <= bound + 8.0 * f64::EPSILON * w,
                    "trial {trial} rank {k}"
                );
                assert!(bound <= 1e-10 * w, "trial {trial} rank {k}: bound {bound:e} on {w:e}");
                for other in [k.wrapping_sub(1), k + 1].into_iter().filter(|&o| o < n) {
                    if let Some(bound) = pencil.enclose(other, value, relative) {
                        assert!(
                            (value - exact[other]).abs() <= bound,
                            "trial {trial}: rank {other} at {value:e}"
                        );
                    }
                }
            }
        }
    }

    /// The free chain (B singular: diagonal 1, 2, …, 2, 1 and −1 beside it) scaled by powers
    /// of two over eight decades either way and renumbered at random, stored exactly, has the
    /// eigenvalues 4 sin²(kπ/(2n)), k = 0 … n − 1. Unshifted, no relative margin exists (the
    /// rigid-body mode makes H singular); shifted by each nonzero eigenvalue, the enclosures
    /// of that eigenvalue are within 1e-9 relative and hold it.
    #[test]
    fn shifted_margins_enclose_the_modes_of_a_free_chain() {
        let mut rng = crate::testing::graded::SplitMix::new(0xf4ee_c4a1);
        for trial in 0..12 {
            let n = 3 + rng.below(60);
            let (a, b) = power_of_two_chain(&mut rng, n, false);
            let exact: Vec<f64> = (0..n)
                .map(|k| 4.0 * (k as f64 * std::f64::consts::PI / (2 * n) as f64).sin().powi(2))
                .collect();
            let pencil = ForestPencil::new(a.as_ref(), b.as_ref()).expect("a forest with positive masses");
            assert!(pencil.relative_margin(0.0, 0.5).is_none(), "trial {trial}");
            for (k, &w) in exact.iter().enumerate().skip(1) {
                let relative = pencil.relative_margin(w, 0.5);
                assert!(relative.is_some(), "trial {trial} rank {k}");
                let value = w * (1.0 + rng.uniform(-1e-14, 1e-14));
                let bound = pencil.enclose(k, value, relative).expect("an enclosure");
                assert!(
                    (value - w).abs() <= bound + 8.0 * f64::EPSILON * w,
                    "trial {trial} rank {k}"
                );
                assert!(bound <= 1e-9 * w, "trial {trial} rank {k}: bound {bound:e} on {w:e}");
            }
        }
    }

    #[test]
    fn a_count_needs_a_positive_diagonal_mass_and_a_forest() {
        let springs = [(1, 0, 1.0), (2, 1, 1.0)];
        let b = assemble(3, &springs, &[(0, 1.0)]);
        let mut a = Mat::<f64>::identity(3, 3);
        assert!(ForestPencil::new(a.as_ref(), b.as_ref()).is_some());
        a[(1, 1)] = 0.0;
        assert!(ForestPencil::new(a.as_ref(), b.as_ref()).is_none());
        a[(1, 1)] = 1.0;
        a[(0, 1)] = 0.1;
        a[(1, 0)] = 0.1;
        assert!(ForestPencil::new(a.as_ref(), b.as_ref()).is_none());
        let ring = assemble(3, &[(1, 0, 1.0), (2, 1, 1.0), (2, 0, 1.0)], &[]);
        assert!(ForestPencil::new(Mat::<f64>::identity(3, 3).as_ref(), ring.as_ref()).is_none());
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
