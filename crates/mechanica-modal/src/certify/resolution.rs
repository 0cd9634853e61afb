//! The resolution of the data: how far rounding the stored A and B can move ω², below which a
//! mode cannot be told from a rigid-body mode (the zero classification of [`crate::classify`]).

use faer::{Mat, MatRef, Par};

/// The change of ω² that rounding A and B entrywise can cause for an A-normalised mode shape x:
/// |xᵀδBx| + |ω²|·|xᵀδAx| ≤ u(|x|ᵀ|B||x| + |ω²|·|x|ᵀ|A||x|) for |δA| ≤ u|A|, |δB| ≤ u|B| (u
/// taken as f64::EPSILON, one rounding of each entry with margin). Below it neither the sign
/// nor the size of ω² is determined by the data: a rigid-body mode of a stiffness matrix that is
/// singular only up to rounding (an assembled or rotated one) has a computed ω² of that order,
/// of either sign, however tight its error bound for the stored matrices. Componentwise, so a
/// soft spring beside stiff ones, or a small negative stiffness on a decoupled coordinate,
/// stays resolved. O(n²); [`normwise_resolution`] bounds it from above in O(n).
pub fn data_resolution(a: MatRef<'_, f64>, b: MatRef<'_, f64>, x: &[f64], omega_sq: f64) -> f64 {
    f64::EPSILON * (abs_quadratic(b, x) + omega_sq.abs() * abs_quadratic(a, x))
}

/// An upper bound of [`data_resolution`] from norms: |x|ᵀ|M||x| ≤ ‖M‖_F‖x‖₂².
pub fn normwise_resolution(omega_sq: f64, norm_a: f64, norm_b: f64, shape_norm_sq: f64) -> f64 {
    f64::EPSILON * (norm_b + omega_sq.abs() * norm_a) * shape_norm_sq
}

/// |x|ᵀ|M||x| of a dense M.
fn abs_quadratic(m: MatRef<'_, f64>, x: &[f64]) -> f64 {
    (0..m.ncols())
        .map(|j| {
            let column: f64 = m.col(j).iter().zip(x).map(|(mij, xi)| (mij * xi).abs()).sum();
            column * x[j].abs()
        })
        .sum()
}

/// The resolution the zero classification compares |ω²| with: [`data_resolution`] where
/// |ω²| is within the cheap [`normwise_resolution`] (only there can it decide), the normwise
/// value elsewhere.
pub(crate) fn zero_resolution(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    x: &[f64],
    omega_sq: f64,
    (norm_a, norm_b): (f64, f64),
) -> f64 {
    let shape_norm_sq = x.iter().map(|v| v * v).sum::<f64>();
    let normwise = normwise_resolution(omega_sq, norm_a, norm_b, shape_norm_sq);
    if omega_sq.abs() <= normwise {
        data_resolution(a, b, x, omega_sq)
    } else {
        normwise
    }
}

/// [`data_resolution`] of the columns `columns` of `x` (A-normalised shapes) with their ω², at
/// once: |B||X| and |A||X| as two matrix products (gemm speed) instead of n² scalar steps per
/// mode.
pub(crate) fn data_resolutions(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    x: MatRef<'_, f64>,
    columns: &[usize],
    omega_sq: &[f64],
    par: Par,
) -> Vec<f64> {
    if columns.is_empty() {
        return Vec::new();
    }
    let n = x.nrows();
    let abs_x = Mat::from_fn(n, columns.len(), |i, c| x[(i, columns[c])].abs());
    let quadratic = |m: MatRef<'_, f64>| -> Vec<f64> {
        let abs_m = Mat::from_fn(n, n, |i, j| m[(i, j)].abs());
        let mut product = Mat::<f64>::zeros(n, columns.len());
        faer::linalg::matmul::matmul(
            product.as_mut(),
            faer::Accum::Replace,
            abs_m.as_ref(),
            abs_x.as_ref(),
            1.0,
            par,
        );
        (0..columns.len())
            .map(|c| abs_x.col(c).iter().zip(product.col(c).iter()).map(|(u, v)| u * v).sum())
            .collect()
    };
    let (stiffness, mass) = (quadratic(b), quadratic(a));
    (0..columns.len())
        .map(|c| f64::EPSILON * (stiffness[c] + omega_sq[c].abs() * mass[c]))
        .collect()
}

/// The rounding of the double-double residual and Rayleigh quotient of the A-normalised shapes
/// `columns` of `x`: each of their n-term sums errs by at most about n·u²(|x|ᵀ|B||x| + |ω²|·|x|ᵀ|A||x|), a
/// term that matters only where ω² is cancelled far below the entries (a near-zero mode of a
/// stiff structure). It is 4n·u times the data resolution ([`data_resolutions`]), which has the same sums.
pub(crate) fn extended_roundings(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    x: MatRef<'_, f64>,
    columns: &[usize],
    omega_sq: &[f64],
    par: Par,
) -> Vec<f64> {
    let scale = 4.0 * x.nrows() as f64 * f64::EPSILON;
    data_resolutions(a, b, x, columns, omega_sq, par)
        .into_iter()
        .map(|r| scale * r)
        .collect()
}
