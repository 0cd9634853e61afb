//! Random graded spring systems and their reference spectra.
//!
//! A *spring tree* is a set of lumped masses joined by springs along the edges of a tree, the
//! root optionally fixed to the ground by one more spring: A = diag(m) and
//! B = Σ_e k_e (e_i − e_p)(e_i − e_p)ᵀ (+ k_0 e_r e_rᵀ when fixed). Masses are 10^U(m_lo, m_hi),
//! stiffnesses 10^U(k_lo, k_hi), drawn independently (not monotone), and the coordinates are
//! numbered in a random order, so neither the grading nor the numbering favours a solver.
//!
//! The reference spectrum ([`tree_pencil_spectrum`]) is computed from the *stored* matrices by
//! bisection on Sylvester inertia counts of B − σA, each count an LDLᵀ elimination of the tree
//! from its leaves (no fill) in double-double arithmetic. The elimination is componentwise
//! backward stable, so the counts are those of a pencil whose entries differ from the stored ones
//! by a few units of 2⁻¹⁰⁴ relative; the values are independent of every solver in this crate.

use crate::dd::Dd;
use faer::Mat;

/// SplitMix64: a small deterministic generator for test families.
#[derive(Debug, Clone)]
pub struct SplitMix(u64);

impl SplitMix {
    /// The generator started from `seed`.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// Uniform integer in 0..n (n > 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n.max(1) as u64) as usize
    }
}

/// The shape of a random spring system.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// Mass i hangs on mass i − 1 (before renumbering).
    Chain,
    /// Mass i hangs on a uniformly random earlier mass.
    Tree,
}

/// What to draw.
#[derive(Debug, Clone, Copy)]
pub struct GradedFamily {
    /// Number of masses.
    pub n: usize,
    /// Chain or tree.
    pub shape: Shape,
    /// Root fixed to the ground (B positive definite) or free (one rigid-body mode).
    pub fixed: bool,
    /// Decimal exponent range of the masses.
    pub mass_decades: (f64, f64),
    /// Decimal exponent range of the stiffnesses.
    pub stiffness_decades: (f64, f64),
}

impl GradedFamily {
    /// Masses 10^U(−8, 0), stiffnesses 10^U(0, 12).
    pub fn new(n: usize, shape: Shape, fixed: bool) -> Self {
        Self {
            n,
            shape,
            fixed,
            mass_decades: (-8.0, 0.0),
            stiffness_decades: (0.0, 12.0),
        }
    }
}

/// A drawn spring system: the stored pencil and its tree.
#[derive(Debug, Clone)]
pub struct SpringTree {
    /// Mass matrix, diagonal.
    pub a: Mat<f64>,
    /// Stiffness matrix, with the sparsity of a tree.
    pub b: Mat<f64>,
    /// `parent[i]`: the coordinate that the spring of coordinate i joins it to (None: the root).
    pub parent: Vec<Option<usize>>,
    /// Number of rigid-body modes of the model the matrices were assembled from (0 or 1).
    pub rigid_modes: usize,
}

/// Draws a spring system from `family` with `seed`.
pub fn spring_tree(family: &GradedFamily, seed: u64) -> SpringTree {
    let n = family.n;
    let mut rng = SplitMix::new(seed);
    let mut label: Vec<usize> = (0..n).collect();
    for i in (1..n).rev() {
        label.swap(i, rng.below(i + 1));
    }
    let power = |rng: &mut SplitMix, (lo, hi): (f64, f64)| 10f64.powf(rng.uniform(lo, hi));
    let mut a = Mat::<f64>::zeros(n, n);
    let mut b = Mat::<f64>::zeros(n, n);
    let mut parent = vec![None; n];
    for i in 0..n {
        let me = label[i];
        a[(me, me)] = power(&mut rng, family.mass_decades);
        let k = power(&mut rng, family.stiffness_decades);
        let up = match (i, family.shape) {
            (0, _) => None,
            (_, Shape::Chain) => Some(label[i - 1]),
            (_, Shape::Tree) => Some(label[rng.below(i)]),
        };
        match up {
            Some(p) => {
                b[(me, me)] += k;
                b[(p, p)] += k;
                b[(me, p)] -= k;
                b[(p, me)] -= k;
                parent[me] = Some(p);
            }
            None if family.fixed => b[(me, me)] += k,
            None => {}
        }
    }
    SpringTree {
        a,
        b,
        parent,
        rigid_modes: usize::from(!family.fixed && n > 0),
    }
}

/// The number of eigenvalues ω² of B x = ω² A x (A diagonal positive, B with the sparsity of
/// the forest `parent`) strictly below `sigma`: the negative pivots of B − σA eliminated from
/// the leaves, in double-double. A zero pivot is replaced by a tiny positive one (the count of a
/// pencil perturbed by far less than the arithmetic's own rounding).
pub(crate) fn tree_count_below(
    a: &Mat<f64>,
    b: &Mat<f64>,
    parent: &[Option<usize>],
    order: &[usize],
    sigma: Dd,
) -> usize {
    let n = parent.len();
    let mut pivot: Vec<Dd> = (0..n)
        .map(|i| Dd::of(b[(i, i)]).minus(sigma.times(Dd::of(a[(i, i)]))))
        .collect();
    let mut negatives = 0;
    for &i in order {
        let mut d = pivot[i];
        if d.hi == 0.0 {
            d = Dd::of(f64::MIN_POSITIVE);
        }
        if d.hi < 0.0 {
            negatives += 1;
        }
        if let Some(p) = parent[i] {
            let coupling = Dd::of(b[(i, p)]);
            pivot[p] = pivot[p].minus(coupling.times(coupling).over(d));
        }
    }
    negatives
}

/// Coordinates ordered so that every child comes before its parent.
fn leaves_first(parent: &[Option<usize>]) -> Vec<usize> {
    let n = parent.len();
    let mut children = vec![Vec::new(); n];
    let mut roots = Vec::new();
    for (i, p) in parent.iter().enumerate() {
        match p {
            Some(p) => children[*p].push(i),
            None => roots.push(i),
        }
    }
    let mut pre = Vec::with_capacity(n);
    let mut stack = roots;
    while let Some(i) = stack.pop() {
        pre.push(i);
        stack.extend(children[i].iter().copied());
    }
    pre.reverse();
    pre
}

fn midpoint(lo: Dd, hi: Dd) -> Dd {
    Dd {
        hi: 0.5 * lo.hi,
        lo: 0.5 * lo.lo,
    }
    .plus(Dd {
        hi: 0.5 * hi.hi,
        lo: 0.5 * hi.lo,
    })
}

/// Every ω² of the spring tree's stored pencil, ascending, each to about 1e-24 relative (or
/// 1e-300 absolute near zero), by bisection on the inertia counts of B − σA.
pub fn tree_pencil_spectrum(system: &SpringTree) -> Vec<f64> {
    tree_pencil_lowest(system, system.parent.len())
}

/// The `k` lowest ω² of [`tree_pencil_spectrum`].
pub fn tree_pencil_lowest(system: &SpringTree, k: usize) -> Vec<f64> {
    let (a, b, parent) = (&system.a, &system.b, &system.parent[..]);
    let n = parent.len();
    let order = leaves_first(parent);
    // Gershgorin: every ω² lies in ±max_i Σ_j |b_ij| / a_ii.
    let reach = (0..n)
        .map(|i| (0..n).map(|j| b[(i, j)].abs()).sum::<f64>() / a[(i, i)])
        .fold(0.0, f64::max)
        * 2.0
        + 1.0;
    let count = |s: Dd| tree_count_below(a, b, parent, &order, s);
    (0..k.min(n))
        .map(|k| {
            // The k-th value (from 0) is where the count first exceeds k.
            let (mut lo, mut hi) = (Dd::of(-reach), Dd::of(reach));
            for _ in 0..2200 {
                let mid = midpoint(lo, hi);
                if count(mid) > k {
                    hi = mid;
                } else {
                    lo = mid;
                }
                let width = hi.minus(lo).to_f64();
                if width <= 1e-24 * hi.to_f64().abs().max(lo.to_f64().abs()) || width <= 1e-300 {
                    break;
                }
            }
            midpoint(lo, hi).to_f64()
        })
        .collect()
}
