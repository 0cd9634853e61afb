//! Test and benchmark problem families with closed-form or independently known spectra:
//! unit spring chains (fixed, free, ring), their congruence by a random orthogonal matrix
//! (dense pencils with the same eigenvalues), and graded stiff chains.

pub mod graded;

/// x·2^e, exact unless the result is subnormal (the solver's own scaling, for tests that scale
/// pencils across the double range).
pub use crate::linalg::powers_of_two::times_power_of_two;

use faer::Mat;
use faer::sparse::Triplet;
use std::f64::consts::PI;

/// Chain of n unit masses joined by unit springs, both ends fixed to the ground:
/// A = I, B = tridiag(−1, 2, −1). Returns (A, B).
pub fn fixed_chain(n: usize) -> (Mat<f64>, Mat<f64>) {
    let a = Mat::identity(n, n);
    let b = Mat::from_fn(n, n, |i, j| {
        if i == j {
            2.0
        } else if i.abs_diff(j) == 1 {
            -1.0
        } else {
            0.0
        }
    });
    (a, b)
}

/// ω²_k = 4 sin²(kπ / (2(n+1))), k = 1..n, ascending: the spectrum of [`fixed_chain`].
pub fn fixed_chain_omega_sq(n: usize) -> Vec<f64> {
    (1..=n)
        .map(|k| {
            let s = (k as f64 * PI / (2.0 * (n as f64 + 1.0))).sin();
            4.0 * s * s
        })
        .collect()
}

/// Free–free chain of n unit masses and n − 1 unit springs: one rigid-body mode (ω² = 0).
pub fn free_chain(n: usize) -> (Mat<f64>, Mat<f64>) {
    let a = Mat::identity(n, n);
    let b = Mat::from_fn(n, n, |i, j| {
        if i == j {
            if n == 1 {
                0.0
            } else if i == 0 || i == n - 1 {
                1.0
            } else {
                2.0
            }
        } else if i.abs_diff(j) == 1 {
            -1.0
        } else {
            0.0
        }
    });
    (a, b)
}

/// ω²_k = 4 sin²(kπ / (2n)), k = 0..n−1: the spectrum of [`free_chain`].
pub fn free_chain_omega_sq(n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let s = (k as f64 * PI / (2.0 * n as f64)).sin();
            4.0 * s * s
        })
        .collect()
}

/// Ring of n ≥ 3 unit masses and n unit springs: ω²_k = 4 sin²(kπ/n), each k and n − k give a
/// double eigenvalue; one rigid-body mode.
pub fn ring(n: usize) -> (Mat<f64>, Mat<f64>) {
    let a = Mat::identity(n, n);
    let b = Mat::from_fn(n, n, |i, j| {
        let d = i.abs_diff(j);
        if i == j {
            2.0
        } else if d == 1 || d == n - 1 {
            -1.0
        } else {
            0.0
        }
    });
    (a, b)
}

/// The spectrum of [`ring`], ascending.
pub fn ring_omega_sq(n: usize) -> Vec<f64> {
    let mut w: Vec<f64> = (0..n)
        .map(|k| {
            let s = (k as f64 * PI / n as f64).sin();
            4.0 * s * s
        })
        .collect();
    w.sort_by(f64::total_cmp);
    w
}

/// A deterministic orthogonal n×n matrix (Q of the QR factorization of a pseudo-random
/// matrix from `seed`).
pub fn random_orthogonal(n: usize, seed: u64) -> Mat<f64> {
    let mut s = seed.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let g = Mat::from_fn(n, n, |_, _| {
        s = s
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    });
    g.qr().compute_Q()
}

/// The congruent pencil (Qᵀ A Q, Qᵀ B Q): the same eigenvalues, dense matrices. The results
/// are symmetrised exactly.
pub fn rotate(a: &Mat<f64>, b: &Mat<f64>, q: &Mat<f64>) -> (Mat<f64>, Mat<f64>) {
    let sym = |m: Mat<f64>| Mat::from_fn(m.nrows(), m.ncols(), |i, j| 0.5 * (m[(i, j)] + m[(j, i)]));
    (sym(q.transpose() * a * q), sym(q.transpose() * b * q))
}

/// Lumped masses with a dense stiffness: A = D = diag(`masses`) and B = D^½ Qᵀ T Q D^½ with T the
/// fixed–fixed unit chain ([`fixed_chain`]) and Q = [`random_orthogonal`]`(n, seed)`. With
/// z = Q D^½ x, B x = ω² A x becomes T z = ω² z, so ω² = [`fixed_chain_omega_sq`] up to the
/// rounding of the products (about u·n in ω², absolute), while A stays diagonal.
pub fn lumped_chain(masses: &[f64], seed: u64) -> (Mat<f64>, Mat<f64>) {
    let n = masses.len();
    let a = Mat::from_fn(n, n, |i, j| if i == j { masses[i] } else { 0.0 });
    let (_, t) = fixed_chain(n);
    let q = random_orthogonal(n, seed);
    let similar = q.transpose() * &t * &q;
    let b = Mat::from_fn(n, n, |i, j| {
        (masses[i] * masses[j]).sqrt() * 0.5 * (similar[(i, j)] + similar[(j, i)])
    });
    (a, b)
}

/// 10^e as the correctly rounded double (the same value Python's `float(f"1e{e}")` gives).
pub fn power_of_ten(e: i32) -> f64 {
    format!("1e{e}").parse().unwrap_or(f64::NAN)
}

/// Chain fixed at its left end: mass i is m_i = `10^mass_exponents[i]`, spring i (joining mass
/// i − 1, or the ground for i = 0, to mass i) is k_i = `10^stiffness_exponents[i]`.
/// Returns (A, B) with A = diag(m), B = Σ_i k_i (e_i − e_{i−1})(e_i − e_{i−1})ᵀ, assembled in
/// the order i = 0, 1, … (tools/modal_reference.py repeats exactly these roundings).
pub fn spring_chain(stiffness_exponents: &[i32], mass_exponents: &[i32]) -> (Mat<f64>, Mat<f64>) {
    let n = stiffness_exponents.len().min(mass_exponents.len());
    let k: Vec<f64> = stiffness_exponents[..n].iter().map(|&e| power_of_ten(e)).collect();
    let a = Mat::from_fn(n, n, |i, j| if i == j { power_of_ten(mass_exponents[i]) } else { 0.0 });
    let mut b = Mat::<f64>::zeros(n, n);
    for i in 0..n {
        b[(i, i)] += k[i];
        if i > 0 {
            b[(i - 1, i - 1)] += k[i];
            b[(i, i - 1)] -= k[i];
            b[(i - 1, i)] -= k[i];
        }
    }
    (a, b)
}

/// Stiffness exponents round(decades · i / (n − 1)), i = 0..n: a chain graded from k = 1 at the
/// ground to k = 10^decades at the free end.
pub fn graded_exponents(n: usize, decades: i32) -> Vec<i32> {
    (0..n)
        .map(|i| {
            if n > 1 {
                (decades as f64 * i as f64 / (n - 1) as f64).round() as i32
            } else {
                0
            }
        })
        .collect()
}

/// Sparse entries (row, col, value) of a matrix, both triangles.
pub type Triplets = Vec<Triplet<usize, usize, f64>>;

/// The 5-point Dirichlet Laplacian of an nx × ny grid of unit spacing (node (i, j) is unknown
/// i + nx·j) as B, with the identity mass matrix A. Its spectrum is
/// ω²_pq = 4 sin²(pπ/(2(nx+1))) + 4 sin²(qπ/(2(ny+1))), p = 1..nx, q = 1..ny (double on a
/// square grid for p ≠ q). Returns (A, B) triplets, both triangles.
pub fn grid_laplacian(nx: usize, ny: usize) -> (Triplets, Triplets) {
    let n = nx * ny;
    let a = (0..n).map(|i| Triplet::new(i, i, 1.0)).collect();
    let mut b = Vec::with_capacity(5 * n);
    for j in 0..ny {
        for i in 0..nx {
            let r = i + nx * j;
            b.push(Triplet::new(r, r, 4.0));
            if i > 0 {
                b.push(Triplet::new(r, r - 1, -1.0));
            }
            if i + 1 < nx {
                b.push(Triplet::new(r, r + 1, -1.0));
            }
            if j > 0 {
                b.push(Triplet::new(r, r - nx, -1.0));
            }
            if j + 1 < ny {
                b.push(Triplet::new(r, r + nx, -1.0));
            }
        }
    }
    (a, b)
}

/// The `k` lowest ω² of [`grid_laplacian`], ascending, with multiplicity.
pub fn grid_omega_sq(nx: usize, ny: usize, k: usize) -> Vec<f64> {
    let one = |p: usize, m: usize| {
        let s = (p as f64 * PI / (2.0 * (m as f64 + 1.0))).sin();
        4.0 * s * s
    };
    let mut w: Vec<f64> = (1..=nx.min(k + 1))
        .flat_map(|p| (1..=ny.min(k + 1)).map(move |q| one(p, nx) + one(q, ny)))
        .collect();
    w.sort_by(f64::total_cmp);
    w.truncate(k);
    w
}
