//! The free response of A δ̈ + B δ = 0 from δ(0), δ̇(0) by modal superposition ((8.91), see
//! docs/theory.md).
//!
//! With A-orthonormal mode shapes x_k (x_jᵀ A x_k = δ_jk) the modal coordinates of the initial
//! state are q_k(0) = x_kᵀ A δ(0) and q̇_k(0) = x_kᵀ A δ̇(0), and each coordinate evolves alone:
//!
//! | mode                       | q_k(t)                                   |
//! |----------------------------|------------------------------------------|
//! | oscillatory, ω² > 0        | q cos ωt + (q̇/ω) sin ωt   (8.91)          |
//! | zero (rigid body), ω² ≈ 0  | q + q̇ t                                   |
//! | unstable, ω² = −γ² < 0     | q cosh γt + (q̇/γ) sinh γt                 |
//! | infinite (massless)        | none: see below                          |
//!
//! and δ(t) = Σ_k q_k(t) x_k. Repeated frequencies need no special care: the solver returns an
//! A-orthonormal basis of each eigenspace, so the projection is the same as for simple modes.
//!
//! **Massless coordinates** (A only semidefinite; infinite modes). A massless direction has no
//! dynamics of its own: the equations along the null space of A are static, B₀₁z + B₀₀w = 0
//! (condensed out by the dense solve), so those coordinates follow the massive ones
//! instantaneously. The finite
//! mode shapes already carry that static part, and the projection q_k = x_kᵀAδ(0) sees only
//! the massive part of δ(0) (A annihilates the null space). The response therefore keeps the
//! massive part of the initial state and replaces the massless part by its static value; the
//! difference is reported in [`InitialFit`] (it is zero exactly when δ(0), δ̇(0) are consistent).
//! Infinite modes get no coordinate.
//!
//! **Accuracy.** [`InitialFit`] reports how well Σ q_k(0) x_k reproduces δ(0) and δ̇(0); each
//! [`ModalCoordinate`] carries a bound on the error of its rate ω or γ derived from the mode's
//! ω² error bound, so the phase error after time t is at most that bound times |t| (to first
//! order). A zero mode is integrated as q + q̇t; its true ω² may be anything within its bound e,
//! which its rate bound √e expresses.

use crate::dense::{ModalSolution, SolveOptions, solve};
use crate::linalg::norms::euclidean_norm;
use crate::spectrum::ModeKind;
use crate::{ModalError, PencilProblem};
use faer::Mat;

/// How one modal coordinate evolves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CoordinateLaw {
    /// q(t) = q cos ωt + (q̇/ω) sin ωt.
    Oscillatory {
        /// Angular frequency ω (rad/s).
        omega: f64,
    },
    /// q(t) = q + q̇ t (rigid-body mode).
    Linear,
    /// q(t) = q cosh γt + (q̇/γ) sinh γt.
    Exponential {
        /// Growth rate γ (1/s).
        growth_rate: f64,
    },
}

/// One modal coordinate of the free response.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModalCoordinate {
    /// Index of the mode in [`ModalSolution::modes`].
    pub mode: usize,
    /// Its time law.
    pub law: CoordinateLaw,
    /// q_k(0) = x_kᵀ A δ(0).
    pub q0: f64,
    /// q̇_k(0) = x_kᵀ A δ̇(0).
    pub q_dot0: f64,
    /// Bound on the error of the rate (ω, γ, or 0 for a zero mode) from the mode's ω² bound e:
    /// e / (√|ω²| + √max(|ω²| − e, 0)), or √e for a zero mode.
    pub rate_error_bound: f64,
}

/// How well the modal coordinates reproduce the initial state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InitialFit {
    /// ‖δ(0) − Σ q_k(0) x_k‖₂ (m).
    pub displacement_residual: f64,
    /// ‖δ̇(0) − Σ q̇_k(0) x_k‖₂ (m/s).
    pub velocity_residual: f64,
    /// displacement_residual / ‖δ(0)‖₂ (0 when δ(0) = 0).
    pub relative_displacement_residual: f64,
    /// velocity_residual / ‖δ̇(0)‖₂ (0 when δ̇(0) = 0).
    pub relative_velocity_residual: f64,
    /// Number of massless directions whose coordinates follow statically (infinite modes). With
    /// massless directions the residuals above include the inconsistency of the initial state.
    pub massless: usize,
}

/// The free response δ(t) of A δ̈ + B δ = 0 (8.91), ready to evaluate at any time.
#[derive(Debug, Clone)]
pub struct FreeResponse {
    /// n × m shapes of the finite modes (A-orthonormal).
    shapes: Mat<f64>,
    coordinates: Vec<ModalCoordinate>,
    fit: InitialFit,
}

fn check_vector(what: &'static str, v: &[f64], n: usize) -> Result<(), ModalError> {
    if v.len() != n {
        return Err(ModalError::BadLength {
            what,
            len: v.len(),
            expected: n,
        });
    }
    match v.iter().position(|x| !x.is_finite()) {
        Some(index) => Err(ModalError::NonFiniteValue {
            what,
            index,
            value: v[index],
        }),
        None => Ok(()),
    }
}

/// The bound on |√|w'| − √|w|| over |w' − w| ≤ e with w' of the same sign as w.
fn rate_bound(omega_sq: f64, bound: f64) -> f64 {
    let w = omega_sq.abs();
    let denominator = w.sqrt() + (w - bound).max(0.0).sqrt();
    if denominator > 0.0 {
        bound / denominator
    } else {
        bound.sqrt()
    }
}

impl FreeResponse {
    /// Builds the free response from a solution of `problem` that holds every mode with its shape
    /// ([`crate::Selection::All`], vectors on; otherwise [`ModalError::IncompleteSolution`]).
    /// `delta0` = δ(0) and `delta_dot0` = δ̇(0) have length n and finite entries.
    pub fn new(
        problem: &PencilProblem,
        solution: &ModalSolution,
        delta0: &[f64],
        delta_dot0: &[f64],
    ) -> Result<Self, ModalError> {
        let n = problem.dim();
        let incomplete = || ModalError::IncompleteSolution {
            dim: n,
            modes: solution.modes.len(),
            shapes: solution.vectors.as_ref().map_or(0, |x| x.ncols()),
            shape_len: solution.vectors.as_ref().map_or(0, |x| x.nrows()),
        };
        let x = solution.vectors.as_ref().ok_or_else(incomplete)?;
        if solution.modes.len() != n || x.nrows() != n || x.ncols() != n {
            return Err(incomplete());
        }
        check_vector("delta0", delta0, n)?;
        check_vector("delta_dot0", delta_dot0, n)?;
        let finite: Vec<usize> = (0..n)
            .filter(|&k| solution.modes[k].kind != ModeKind::Infinite)
            .collect();
        let massless = n - finite.len();
        let shapes = Mat::from_fn(n, finite.len(), |i, c| x[(i, finite[c])]);
        // q = Xᵀ (A δ): one product with A, then m dot products.
        let a = problem.a();
        let a_times = |v: &[f64]| -> Vec<f64> {
            let mut w = vec![0.0; n];
            for (j, vj) in v.iter().enumerate() {
                for (i, wi) in w.iter_mut().enumerate() {
                    *wi += a[(i, j)] * vj;
                }
            }
            w
        };
        let (ad, av) = (a_times(delta0), a_times(delta_dot0));
        let dot_shape = |c: usize, w: &[f64]| (0..n).map(|i| shapes[(i, c)] * w[i]).sum::<f64>();
        let coordinates: Vec<ModalCoordinate> = finite
            .iter()
            .enumerate()
            .map(|(c, &k)| {
                let mode = &solution.modes[k];
                let law = match mode.kind {
                    ModeKind::Oscillatory { omega } => CoordinateLaw::Oscillatory { omega },
                    ModeKind::Unstable { growth_rate } => CoordinateLaw::Exponential { growth_rate },
                    ModeKind::Zero | ModeKind::Infinite => CoordinateLaw::Linear,
                    // Sign unknown: the motion of the computed value, whose rate error the
                    // coordinate's bound states.
                    ModeKind::Undecided if mode.omega_sq > 0.0 => CoordinateLaw::Oscillatory {
                        omega: mode.omega_sq.sqrt(),
                    },
                    ModeKind::Undecided if mode.omega_sq < 0.0 => CoordinateLaw::Exponential {
                        growth_rate: (-mode.omega_sq).sqrt(),
                    },
                    ModeKind::Undecided => CoordinateLaw::Linear,
                };
                ModalCoordinate {
                    mode: k,
                    law,
                    q0: dot_shape(c, &ad),
                    q_dot0: dot_shape(c, &av),
                    rate_error_bound: rate_bound(mode.omega_sq, mode.error_bound),
                }
            })
            .collect();
        let mut response = Self {
            shapes,
            coordinates,
            fit: InitialFit {
                displacement_residual: 0.0,
                velocity_residual: 0.0,
                relative_displacement_residual: 0.0,
                relative_velocity_residual: 0.0,
                massless,
            },
        };
        let mut rebuilt = vec![0.0; n];
        let residual = |rebuilt: &[f64], v: &[f64]| {
            let r: Vec<f64> = v.iter().zip(rebuilt).map(|(a, b)| a - b).collect();
            let (rn, vn) = (euclidean_norm(&r), euclidean_norm(v));
            (rn, if vn > 0.0 { rn / vn } else { 0.0 })
        };
        response.at(0.0, &mut rebuilt)?;
        let (abs, rel) = residual(&rebuilt, delta0);
        response.fit.displacement_residual = abs;
        response.fit.relative_displacement_residual = rel;
        response.velocity_at(0.0, &mut rebuilt)?;
        let (abs, rel) = residual(&rebuilt, delta_dot0);
        response.fit.velocity_residual = abs;
        response.fit.relative_velocity_residual = rel;
        Ok(response)
    }

    /// Solves `problem` for all modes ([`SolveOptions::default`]) and builds the free response.
    pub fn from_problem(problem: &PencilProblem, delta0: &[f64], delta_dot0: &[f64]) -> Result<Self, ModalError> {
        let solution = solve(problem, &SolveOptions::default())?;
        Self::new(problem, &solution, delta0, delta_dot0)
    }

    /// The order n of the pencil.
    pub fn dim(&self) -> usize {
        self.shapes.nrows()
    }

    /// The modal coordinates (finite modes only, ascending in ω²).
    pub fn coordinates(&self) -> &[ModalCoordinate] {
        &self.coordinates
    }

    /// The n × m shapes of the finite modes, column c belonging to `coordinates()[c]`.
    pub fn shapes(&self) -> faer::MatRef<'_, f64> {
        self.shapes.as_ref()
    }

    /// How well the coordinates reproduce δ(0) and δ̇(0).
    pub fn fit(&self) -> &InitialFit {
        &self.fit
    }

    /// Writes δ(t) (m) into `out` (length n). Errors: non-finite t, wrong length, overflow of an
    /// unstable mode.
    pub fn at(&self, t: f64, out: &mut [f64]) -> Result<(), ModalError> {
        self.evaluate(t, out, false)
    }

    /// Writes δ̇(t) (m/s) into `out` (length n). Errors as [`FreeResponse::at`].
    pub fn velocity_at(&self, t: f64, out: &mut [f64]) -> Result<(), ModalError> {
        self.evaluate(t, out, true)
    }

    /// δ(t) as a new vector.
    pub fn displacement(&self, t: f64) -> Result<Vec<f64>, ModalError> {
        let mut out = vec![0.0; self.dim()];
        self.at(t, &mut out)?;
        Ok(out)
    }

    /// δ̇(t) as a new vector.
    pub fn velocity(&self, t: f64) -> Result<Vec<f64>, ModalError> {
        let mut out = vec![0.0; self.dim()];
        self.velocity_at(t, &mut out)?;
        Ok(out)
    }

    /// A first-order bound on ‖δ(t) − δ_exact(t)‖₂ (m) from the rate errors of the modes:
    /// Σ_k |∂q_k(t)/∂rate_k| · rate_error_bound_k · ‖x_k‖₂ (for a zero mode the distance from
    /// q + q̇t to any motion with |ω²| ≤ e), plus the rounding n·u·Σ_k |q_k(t)|·‖x_k‖₂. It does not
    /// include the initial-state residuals of [`FreeResponse::fit`] or mode-shape errors.
    pub fn error_bound(&self, t: f64) -> Result<f64, ModalError> {
        if !t.is_finite() {
            return Err(ModalError::NonFiniteValue {
                what: "t",
                index: 0,
                value: t,
            });
        }
        let n = self.dim();
        let tau = t.abs();
        let mut bound = 0.0;
        for (c, coord) in self.coordinates.iter().enumerate() {
            let shape_norm = euclidean_norm(&(0..n).map(|i| self.shapes[(i, c)]).collect::<Vec<_>>());
            let (q, v, e) = (coord.q0.abs(), coord.q_dot0.abs(), coord.rate_error_bound);
            let sensitivity = match coord.law {
                CoordinateLaw::Oscillatory { omega } => {
                    let x = omega * tau;
                    tau * q + v * (x * x * x / 3.0).min(x + 1.0) / (omega * omega)
                }
                CoordinateLaw::Exponential { growth_rate: g } => {
                    let x = g * tau;
                    x.cosh() * (tau * q + v * (x * x * x / 3.0).min(x) / (g * g))
                }
                // |q cos ωt + q̇ sin(ωt)/ω − q − q̇t| ≤ (ωt)²(|q|/2 + |q̇|t/6)·cosh(ωt) with ω ≤ e
                // here (the cosh covers a true mode that is slightly unstable).
                CoordinateLaw::Linear => {
                    let x = e * tau;
                    x * x * (q / 2.0 + v * tau / 6.0) * x.cosh()
                }
            };
            let deviation = match coord.law {
                CoordinateLaw::Linear => sensitivity,
                _ => sensitivity * e,
            };
            let value = coordinate_at(coord, t, false).abs();
            bound += (deviation + n as f64 * f64::EPSILON * value) * shape_norm;
        }
        if bound.is_finite() {
            Ok(bound)
        } else {
            Err(ModalError::ResponseOverflow {
                t,
                mode: self.coordinates.last().map_or(0, |c| c.mode),
                exponent: f64::INFINITY,
            })
        }
    }

    fn evaluate(&self, t: f64, out: &mut [f64], derivative: bool) -> Result<(), ModalError> {
        if !t.is_finite() {
            return Err(ModalError::NonFiniteValue {
                what: "t",
                index: 0,
                value: t,
            });
        }
        let n = self.dim();
        if out.len() != n {
            return Err(ModalError::BadLength {
                what: "out",
                len: out.len(),
                expected: n,
            });
        }
        let q: Vec<f64> = self
            .coordinates
            .iter()
            .map(|coord| {
                let value = coordinate_at(coord, t, derivative);
                if value.is_finite() {
                    Ok(value)
                } else {
                    Err(overflow(coord, t))
                }
            })
            .collect::<Result<_, _>>()?;
        out.fill(0.0);
        for (c, qc) in q.iter().enumerate() {
            for (i, o) in out.iter_mut().enumerate() {
                *o += self.shapes[(i, c)] * qc;
            }
        }
        if out.iter().any(|v| !v.is_finite()) {
            // Finite coordinates whose combination overflows: blame the largest one.
            let c = (0..q.len())
                .max_by(|&i, &j| q[i].abs().total_cmp(&q[j].abs()))
                .unwrap_or(0);
            return Err(overflow(&self.coordinates[c], t));
        }
        Ok(())
    }
}

fn overflow(coord: &ModalCoordinate, t: f64) -> ModalError {
    let rate = match coord.law {
        CoordinateLaw::Oscillatory { omega } => omega,
        CoordinateLaw::Linear => 0.0,
        CoordinateLaw::Exponential { growth_rate } => growth_rate,
    };
    ModalError::ResponseOverflow {
        t,
        mode: coord.mode,
        exponent: rate * t.abs(),
    }
}

/// q(t) or q̇(t) of one coordinate.
fn coordinate_at(coord: &ModalCoordinate, t: f64, derivative: bool) -> f64 {
    let (q, v) = (coord.q0, coord.q_dot0);
    match (coord.law, derivative) {
        (CoordinateLaw::Oscillatory { omega }, false) => {
            let (s, c) = (omega * t).sin_cos();
            q * c + v * s / omega
        }
        (CoordinateLaw::Oscillatory { omega }, true) => {
            let (s, c) = (omega * t).sin_cos();
            -q * omega * s + v * c
        }
        (CoordinateLaw::Linear, false) => q + v * t,
        (CoordinateLaw::Linear, true) => v,
        (CoordinateLaw::Exponential { growth_rate: g }, false) => {
            let x = g * t;
            // Terms with a zero coefficient contribute nothing (avoids 0·∞ = NaN).
            scaled(q, x.cosh()) + scaled(v / g, x.sinh())
        }
        (CoordinateLaw::Exponential { growth_rate: g }, true) => {
            let x = g * t;
            scaled(q * g, x.sinh()) + scaled(v, x.cosh())
        }
    }
}

/// a·f, with 0·f = 0 even for an infinite f.
fn scaled(a: f64, f: f64) -> f64 {
    if a == 0.0 { 0.0 } else { a * f }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rate_bound_brackets_the_square_root() {
        // √(w ± e) − √w for w = 4, e = 0.01.
        let b = rate_bound(4.0, 0.01);
        assert!(b >= 4.01_f64.sqrt() - 2.0);
        assert!(b >= 2.0 - 3.99_f64.sqrt());
        assert!(b <= 0.01 / 3.0);
        assert_eq!(rate_bound(0.0, 1e-16), 1e-8);
    }

    #[test]
    fn zero_coefficient_never_meets_infinity() {
        let coord = ModalCoordinate {
            mode: 0,
            law: CoordinateLaw::Exponential { growth_rate: 1.0 },
            q0: 0.0,
            q_dot0: 0.0,
            rate_error_bound: 0.0,
        };
        assert_eq!(coordinate_at(&coord, 1e4, false), 0.0);
    }
}
