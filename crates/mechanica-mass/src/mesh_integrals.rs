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

/// A lane array from its per-lane values.
#[inline(always)]
fn lanes(f: impl FnMut(usize) -> f64) -> Lanes {
    std::array::from_fn(f)
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
    for (lane, t) in group.iter().enumerate() {
        for (i, &index) in t.iter().enumerate() {
            let v = &vertices[index as usize];
            for a in 0..3 {
                p[i][a][lane] = v[a] - r[a];
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
    let e1: [Lanes; 3] = std::array::from_fn(|a| lanes(|l| p[1][a][l] - p[0][a][l]));
    let e2: [Lanes; 3] = std::array::from_fn(|a| lanes(|l| p[2][a][l] - p[0][a][l]));
    let n: [Lanes; 3] = std::array::from_fn(|a| {
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        lanes(|l| e1[b][l] * e2[c][l] - e1[c][l] * e2[b][l])
    });
    let nn = lanes(|l| n[0][l] * n[0][l] + n[1][l] * n[1][l] + n[2][l] * n[2][l]);
    let l1 = lanes(|l| e1[0][l] * e1[0][l] + e1[1][l] * e1[1][l] + e1[2][l] * e1[2][l]);
    let l2 = lanes(|l| e2[0][l] * e2[0][l] + e2[1][l] * e2[1][l] + e2[2][l] * e2[2][l]);
    // Zero-area test: |n|² ≤ (8ε)²|e₁|²|e₂|² (the cross product is at rounding level); a
    // repeated index, or an unused lane, gives n = 0 exactly.
    const T: f64 = 64.0 * f64::EPSILON * f64::EPSILON;
    let kept: [bool; LANES] = std::array::from_fn(|l| nn[l] > T * l1[l] * l2[l]);
    for (lane, &keep) in kept.iter().enumerate().take(used) {
        if !keep {
            sums.degenerate += 1;
            sums.first_degenerate.get_or_insert(first + lane);
        }
    }
    let s: [Lanes; 3] = std::array::from_fn(|a| lanes(|l| p[0][a][l] + p[1][a][l] + p[2][a][l]));
    // Weight of the measure term and of the moment terms per lane.
    let (measure, moment_weight, first_scale) = match integrand {
        Integrand::Solid => {
            let d = lanes(|l| p[0][0][l] * n[0][l] + p[0][1][l] * n[1][l] + p[0][2][l] * n[2][l]);
            let d = lanes(|l| if kept[l] { d[l] } else { 0.0 });
            (d, d, d)
        }
        Integrand::Shell => {
            let area = lanes(|l| if kept[l] { 0.5 * nn[l].sqrt() } else { 0.0 });
            (area, lanes(|l| area[l] / 12.0), lanes(|l| area[l] / 3.0))
        }
    };
    for l in 0..LANES {
        acc[0][l] += measure[l];
        acc[10][l] += measure[l].abs();
    }
    for a in 0..3 {
        for l in 0..LANES {
            acc[1 + a][l] += first_scale[l] * s[a][l];
        }
    }
    // Σᵢ pᵢⱼpᵢₖ + sⱼsₖ for jk = xx, yy, zz, xy, yz, zx.
    for (k, (j, m)) in [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0)].into_iter().enumerate() {
        for l in 0..LANES {
            let second =
                p[0][j][l] * p[0][m][l] + p[1][j][l] * p[1][m][l] + p[2][j][l] * p[2][m][l] + s[j][l] * s[m][l];
            acc[4 + k][l] += moment_weight[l] * second;
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
