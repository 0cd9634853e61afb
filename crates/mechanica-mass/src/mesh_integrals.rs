//! The raw polynomial integrals over a triangle mesh, relative to a reference point r: for a
//! closed solid the signed tetrahedra (r, p₀, p₁, p₂), for a shell the triangles themselves.
//!
//! Triangles are processed [`LANES`] at a time in explicit lane arrays, with one partial sum per
//! lane, so the arithmetic vectorises (SSE2 everywhere, AVX2 when the CPU has it, chosen at run
//! time). Every lane operation is a plain IEEE operation (no fused multiply-add) and the lane
//! sums are reduced in a fixed order, so the result is bitwise the same on every x86-64 CPU,
//! with or without AVX2, and for any number of threads.

use crate::parallel::{map_in_parallel, worker_count};

/// Triangles per partial sum.
pub const BLOCK: usize = 4096;

/// Triangles evaluated together (one per lane).
const LANES: usize = 4;

type Lanes = [f64; LANES];

/// Which integrals to take.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Integrand {
    /// Volume integrals of 1, x, x xᵀ over the closed surface's interior (divergence theorem).
    Solid,
    /// Area integrals of 1, x, x xᵀ over the surface.
    Shell,
}

/// Raw integrals over some triangles, relative to the reference point.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Sums {
    /// Solid: Σ D, Σ D sₖ, Σ D (Σᵢ pᵢⱼpᵢₖ + sⱼsₖ) for jk = xx, yy, zz, xy, yz, zx (unscaled
    /// tetrahedron sums, see [`SOLID_DIVISORS`]).
    /// Shell: area, first moments, second moments (already scaled).
    pub v: [f64; 10],
    /// Σ |measure term|, for the error bound.
    pub abs_measure: f64,
    /// Degenerate (zero-area) triangles, left out of the sums.
    pub degenerate: usize,
    /// Index of the first degenerate triangle.
    pub first_degenerate: Option<usize>,
}

impl Sums {
    fn add(&mut self, o: &Sums) {
        for k in 0..10 {
            self.v[k] += o.v[k];
        }
        self.abs_measure += o.abs_measure;
        self.degenerate += o.degenerate;
        self.first_degenerate = self.first_degenerate.or(o.first_degenerate);
    }
}

/// The integrals of `integrand` over all triangles (indices already checked against
/// `vertices`), in blocks of [`BLOCK`] reduced in order, in parallel for large meshes.
pub(crate) fn integrate(vertices: &[[f64; 3]], triangles: &[[u32; 3]], r: &[f64; 3], integrand: Integrand) -> Sums {
    integrate_on(worker_count(triangles.len()), vertices, triangles, r, integrand)
}

/// [`integrate`] on `threads` threads.
pub(crate) fn integrate_on(
    threads: usize,
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    r: &[f64; 3],
    integrand: Integrand,
) -> Sums {
    let blocks = triangles.len().div_ceil(BLOCK);
    let per = blocks.div_ceil(threads.clamp(1, blocks.max(1))).max(1);
    let shares: Vec<usize> = (0..blocks).step_by(per).collect();
    let partials = map_in_parallel(shares, |first_block| {
        (first_block..(first_block + per).min(blocks))
            .map(|k| {
                let start = k * BLOCK;
                let end = (start + BLOCK).min(triangles.len());
                block_sums(vertices, &triangles[start..end], r, start, integrand)
            })
            .collect::<Vec<Sums>>()
    });
    let mut total = Sums::default();
    for p in partials.iter().flatten() {
        total.add(p);
    }
    total
}

/// The sums over one block, on the widest vector unit the CPU has.
fn block_sums(
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    r: &[f64; 3],
    offset: usize,
    integrand: Integrand,
) -> Sums {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the running CPU supports AVX2, checked just above; the function has no
            // other requirement.
            return unsafe { block_sums_avx2(vertices, triangles, r, offset, integrand) };
        }
    }
    block_sums_lanes(vertices, triangles, r, offset, integrand)
}

/// [`block_sums_lanes`] compiled for AVX2 (the same IEEE operations, four lanes per instruction).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn block_sums_avx2(
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    r: &[f64; 3],
    offset: usize,
    integrand: Integrand,
) -> Sums {
    block_sums_lanes(vertices, triangles, r, offset, integrand)
}

/// The sums over one block, [`LANES`] triangles at a time.
#[inline(always)]
fn block_sums_lanes(
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    r: &[f64; 3],
    offset: usize,
    integrand: Integrand,
) -> Sums {
    let mut acc = [[0.0; LANES]; 11];
    let mut sums = Sums::default();
    let mut groups = triangles.chunks_exact(LANES);
    for (g, group) in groups.by_ref().enumerate() {
        let p = gather(vertices, group, r);
        add_group(&p, group.len(), offset + g * LANES, integrand, &mut acc, &mut sums);
    }
    let rest = groups.remainder();
    if !rest.is_empty() {
        let p = gather(vertices, rest, r);
        add_group(
            &p,
            rest.len(),
            offset + triangles.len() - rest.len(),
            integrand,
            &mut acc,
            &mut sums,
        );
    }
    let reduce = |a: &Lanes| (a[0] + a[1]) + (a[2] + a[3]);
    for k in 0..10 {
        sums.v[k] = reduce(&acc[k]);
    }
    sums.abs_measure = reduce(&acc[10]);
    sums
}

/// The corners of up to [`LANES`] triangles relative to r: `p[i][a][lane]` is axis a of corner
/// i; unused lanes stay at the origin (zero area).
#[inline(always)]
fn gather(vertices: &[[f64; 3]], group: &[[u32; 3]], r: &[f64; 3]) -> [[Lanes; 3]; 3] {
    let mut p = [[[0.0; LANES]; 3]; 3];
    let mut used = [0.0; LANES];
    for (lane, t) in group.iter().enumerate() {
        used[lane] = 1.0;
        for (i, &index) in t.iter().enumerate() {
            let v = &vertices[index as usize];
            for a in 0..3 {
                p[i][a][lane] = v[a];
            }
        }
    }
    // Relative to r, lane-parallel; an unused lane stays at zero.
    for corner in &mut p {
        for a in 0..3 {
            for l in 0..LANES {
                corner[a][l] = (corner[a][l] - r[a]) * used[l];
            }
        }
    }
    p
}

/// Adds the terms of one group of `used` triangles (the first at index `first`) to the lane
/// accumulators `acc` (measure, first moments, second moments, |measure|) and counts its
/// degenerate triangles in `sums`.
#[inline(always)]
fn add_group(
    p: &[[Lanes; 3]; 3],
    used: usize,
    first: usize,
    integrand: Integrand,
    acc: &mut [Lanes; 11],
    sums: &mut Sums,
) {
    // One loop over the lanes with no cross-lane dependence: the compiler turns it into
    // vector instructions of the lane width.
    let mut kept = [false; LANES];
    for l in 0..LANES {
        let c = |i: usize, a: usize| p[i][a][l];
        let e1 = [c(1, 0) - c(0, 0), c(1, 1) - c(0, 1), c(1, 2) - c(0, 2)];
        let e2 = [c(2, 0) - c(0, 0), c(2, 1) - c(0, 1), c(2, 2) - c(0, 2)];
        let n = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        let nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
        let l1 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
        let l2 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
        // Zero-area test: |n|² ≤ (8ε)²|e₁|²|e₂|² (the cross product is at rounding level); a
        // repeated index, or an unused lane, gives n = 0 exactly.
        const T: f64 = 64.0 * f64::EPSILON * f64::EPSILON;
        kept[l] = nn > T * l1 * l2;
        let s = [
            c(0, 0) + c(1, 0) + c(2, 0),
            c(0, 1) + c(1, 1) + c(2, 1),
            c(0, 2) + c(1, 2) + c(2, 2),
        ];
        // Weights of the measure, first-moment and second-moment terms.
        let (measure, first_weight, second_weight) = match integrand {
            Integrand::Solid => {
                let d = c(0, 0) * n[0] + c(0, 1) * n[1] + c(0, 2) * n[2];
                let d = if kept[l] { d } else { 0.0 };
                (d, d, d)
            }
            Integrand::Shell => {
                let area = if kept[l] { 0.5 * nn.sqrt() } else { 0.0 };
                (area, area / 3.0, area / 12.0)
            }
        };
        acc[0][l] += measure;
        acc[10][l] += measure.abs();
        for a in 0..3 {
            acc[1 + a][l] += first_weight * s[a];
        }
        // Σᵢ pᵢⱼpᵢₖ + sⱼsₖ for jk = xx, yy, zz, xy, yz, zx.
        for (k, (j, m)) in [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0)].into_iter().enumerate() {
            let second = c(0, j) * c(0, m) + c(1, j) * c(1, m) + c(2, j) * c(2, m) + s[j] * s[m];
            acc[4 + k][l] += second_weight * second;
        }
    }
    for (lane, &keep) in kept.iter().enumerate().take(used) {
        if !keep {
            sums.degenerate += 1;
            sums.first_degenerate.get_or_insert(first + lane);
        }
    }
}

/// The divisors that turn the raw solid [`Sums::v`] into ∫dV, ∫x dV and ∫x xᵀ dV: the
/// closed surface bounds the signed union of the tetrahedra (r, p₀, p₁, p₂), each with
/// D = p₀·((p₁ − p₀) × (p₂ − p₀)) = 6·volume, ∫x dV = D s/24 and ∫x xᵀ dV = D (Σᵢ pᵢpᵢᵀ + s sᵀ)/120
/// with s = p₀ + p₁ + p₂ (coordinates relative to r; the second moment of a simplex with
/// vertices vᵢ is V/20 (Σ vᵢvᵢᵀ + (Σ vᵢ)(Σ vᵢ)ᵀ), here with one vertex at r). These are the
/// same polynomial integrals as in Mirtich's and Eberly's forms, in fewer operations. Shell
/// sums are already scaled: ∫dA = |n|/2, ∫x dA = A s/3, ∫x xᵀ dA = A/12 (Σᵢ pᵢpᵢᵀ + s sᵀ).
pub(crate) const SOLID_DIVISORS: [f64; 10] = [6.0, 24.0, 24.0, 24.0, 120.0, 120.0, 120.0, 120.0, 120.0, 120.0];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tessellation::torus_mesh;

    /// One triangle at a time, in the plain scalar form of the doc formulas.
    fn scalar_reference(
        vertices: &[[f64; 3]],
        triangles: &[[u32; 3]],
        r: &[f64; 3],
        integrand: Integrand,
    ) -> [f64; 10] {
        let mut v = [0.0; 10];
        for t in triangles {
            let p: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|a| vertices[t[i] as usize][a] - r[a]));
            let e1: [f64; 3] = std::array::from_fn(|a| p[1][a] - p[0][a]);
            let e2: [f64; 3] = std::array::from_fn(|a| p[2][a] - p[0][a]);
            let n = [
                e1[1] * e2[2] - e1[2] * e2[1],
                e1[2] * e2[0] - e1[0] * e2[2],
                e1[0] * e2[1] - e1[1] * e2[0],
            ];
            let s: [f64; 3] = std::array::from_fn(|a| p[0][a] + p[1][a] + p[2][a]);
            let second = |j: usize, k: usize| p[0][j] * p[0][k] + p[1][j] * p[1][k] + p[2][j] * p[2][k] + s[j] * s[k];
            let (w0, w1, w2) = match integrand {
                Integrand::Solid => {
                    let d = p[0][0] * n[0] + p[0][1] * n[1] + p[0][2] * n[2];
                    (d, d, d)
                }
                Integrand::Shell => {
                    let area = 0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                    (area, area / 3.0, area / 12.0)
                }
            };
            v[0] += w0;
            for a in 0..3 {
                v[1 + a] += w1 * s[a];
            }
            for (k, (j, m)) in [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0)].into_iter().enumerate() {
                v[4 + k] += w2 * second(j, m);
            }
        }
        v
    }

    #[test]
    fn lane_sums_equal_the_scalar_formulas_and_do_not_depend_on_threads_or_vector_width() {
        let mesh = torus_mesh(2.0, 0.5, 200, 101);
        let r = [0.1, -0.2, 0.05];
        for integrand in [Integrand::Solid, Integrand::Shell] {
            let reference = scalar_reference(&mesh.vertices, &mesh.triangles, &r, integrand);
            let one = integrate_on(1, &mesh.vertices, &mesh.triangles, &r, integrand);
            for k in 0..10 {
                let scale = reference[k].abs().max(reference[0].abs());
                assert!((one.v[k] - reference[k]).abs() <= 1e-12 * scale, "{integrand:?} {k}");
            }
            for threads in [2, 3, 7] {
                let many = integrate_on(threads, &mesh.vertices, &mesh.triangles, &r, integrand);
                assert_eq!(one.v, many.v);
                assert_eq!(one.abs_measure, many.abs_measure);
            }
            // The portable lanes give the same bits as the dispatched (AVX2 where present) path.
            let portable = block_sums_lanes(&mesh.vertices, &mesh.triangles[..BLOCK], &r, 0, integrand);
            let dispatched = block_sums(&mesh.vertices, &mesh.triangles[..BLOCK], &r, 0, integrand);
            assert_eq!(portable.v, dispatched.v);
        }
    }

    #[test]
    fn degenerate_triangles_are_counted_once_and_the_first_is_named() {
        let vertices = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [2.0, 0.0, 0.0]];
        // Triangles 2 (repeated index) and 5 (collinear) are degenerate; 6 triangles fill one
        // group of four lanes and half of the next.
        let triangles = [[0, 1, 2], [0, 2, 1], [0, 0, 1], [1, 2, 0], [2, 1, 0], [0, 1, 3]];
        let sums = integrate_on(1, &vertices, &triangles, &[0.0; 3], Integrand::Shell);
        assert_eq!(sums.degenerate, 2);
        assert_eq!(sums.first_degenerate, Some(2));
        assert_eq!(sums.v[0], 4.0 * 0.5);
    }
}
