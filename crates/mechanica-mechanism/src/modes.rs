//! Stability and small oscillations of a mechanism about an equilibrium q₀ (§8f–g):
//! A(q₀) δ̈ + G(q₀) δ̇ + B(q₀) δ = 0 with A the mass matrix (8.28), B = ∂²U*/∂q∂q (8.85) and G
//! the gyroscopic matrix of a rotating frame (zero otherwise).
//!
//! - **Stability** comes from the modes of the pencil (A, B) solved by the modal crate: the
//!   number of unstable directions is the number of ω² < 0 beyond their error bounds, zero
//!   modes are those within their bounds (no magic threshold), and the modal crate's Sturm
//!   count certifies that none was missed.
//! - **Modes** (G = 0): ω_k, A-orthonormal shapes x_k in q, their body displacements (the
//!   centre-of-mass translation and rotation of every body per unit modal amplitude), and the
//!   effective modal masses m_eff,k(d) = (x_kᵀ L_d)² with L_d = M J_cᵀ d the generalized
//!   inertia of a unit base translation d; Σ_k m_eff,k(d) = M when all modes are kept and the
//!   mechanism can translate freely along d.
//! - **Gyroscopic coupling** (rotating frame): the quadratic problem det(s²A + sG + B) = 0 is
//!   solved by the modal crate's [`quadratic_modes`] (scaled companion linearization, QZ, no
//!   inversion of A, so massless coordinates give infinite eigenvalues, which are omitted),
//!   reported as s = σ ± iω with the backward error of each eigenvalue,
//!   ‖(s²A + sG + B)x‖ / ((|s|²‖A‖ + |s|‖G‖ + ‖B‖)‖x‖), and its error bound. Gyroscopic
//!   stabilisation (B indefinite, all Re s = 0 within their bounds) is reported as such.

use crate::assembly_error::AssemblyError;
use crate::{Mechanism, MechanismError};
use faer::c64;
use faer::{Mat, MatRef, Par};
use mechanica_modal::{
    ModalSolution, Mode, ModeKind, PencilProblem, QuadraticOptions, Selection, SolveOptions,
    proven_definite_with_margin, quadratic_modes, solve,
};
use nalgebra::Vector3;

/// The stability of an equilibrium from the inertia of B relative to A (Lyapunov, 8.79–8.83;
/// small oscillations, 8.84–8.90).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stability {
    /// B positive definite: every mode oscillates.
    Stable,
    /// B has negative directions: the equilibrium is unstable.
    Unstable {
        /// Number of unstable directions (negative eigenvalues of B relative to A).
        directions: usize,
        /// Largest growth rate √(−ω²) (1/s).
        max_growth_rate: f64,
    },
    /// No negative direction but zero modes within their error bounds: neutral (rigid-body or
    /// higher-order) behaviour decides.
    Marginal {
        /// Number of zero modes.
        zero_modes: usize,
    },
    /// No proven unstable direction, but modes whose sign is not decided (intervals ω² ± bound
    /// that contain zero, far wider than the data's resolution): the equilibrium may be stable,
    /// marginal or unstable.
    Undecided {
        /// Number of undecided modes.
        undecided_modes: usize,
        /// Number of zero modes.
        zero_modes: usize,
    },
}

/// One body's motion per unit modal amplitude (world/base components).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyDisplacement {
    /// Displacement of the body's centre of mass.
    pub translation: Vector3<f64>,
    /// Small rotation vector of the body.
    pub rotation: Vector3<f64>,
}

/// The quadratic eigenproblem of a rotating frame.
#[derive(Debug, Clone, PartialEq)]
pub struct GyroscopicModes {
    /// Eigenvalues s = σ + iω, ordered by |ω| then σ (2n values; infinite ones omitted).
    pub eigenvalues: Vec<(f64, f64)>,
    /// Backward error of each eigenvalue (see the module docs).
    pub backward_errors: Vec<f64>,
    /// Largest real part: > its error bound means unstable.
    pub max_real_part: f64,
    /// Bound on |Re s| that is indistinguishable from zero: the largest error bound of the
    /// eigenvalues (backward error times condition, [`mechanica_modal::QuadraticEigenvalue`]).
    pub real_part_bound: f64,
    /// True when no Re s exceeds its own error bound (so every Re s ≤ `real_part_bound`).
    pub stable: bool,
}

/// The modes of a mechanism at q₀.
#[derive(Debug, Clone)]
pub struct MechanismModes {
    /// q₀ in charts re-centred at it: the rotation vectors of spherical and free joints are
    /// zero, the other coordinates as given. The matrices and shapes are in these charts; the
    /// mechanism the modes were asked of keeps its own.
    pub q: Vec<f64>,
    /// A(q₀).
    pub mass_matrix: Mat<f64>,
    /// B(q₀).
    pub stiffness_matrix: Mat<f64>,
    /// ‖grad U*(q₀)‖: how far q₀ is from an equilibrium (modes about a non-equilibrium point
    /// are those of the linearisation, not of small oscillations).
    pub gradient_norm: f64,
    /// The modal solution of (A, B): modes, shapes, groups, accuracy report.
    pub solution: ModalSolution,
    /// Stability from the inertia of (A, B).
    pub stability: Stability,
    /// Per mode, per body: displacement per unit modal amplitude (empty without vectors).
    pub body_displacements: Vec<Vec<BodyDisplacement>>,
    /// Per mode: effective modal masses for unit base translations along x, y, z (kg).
    pub effective_masses: Vec<[f64; 3]>,
    /// Total mass (kg), the upper bound of the effective-mass sums.
    pub total_mass: f64,
    /// The gyroscopic problem, in a rotating frame with G ≠ 0.
    pub gyroscopic: Option<GyroscopicModes>,
    /// Coordinates left out of the pencil because they move no mass and feel no force: their
    /// rows and columns of A, B and G and their gradient are exactly zero (a massless link
    /// without springs or applied forces), so
    /// the linearisation says nothing of their motion and (A, B) would be singular. Their rows
    /// of the shapes are zero, as for locked coordinates; the matrices above omit them.
    pub idle: Vec<usize>,
}

/// The verdict from the modes' classes: unstable if any mode is proven unstable, else
/// undecided if any mode's sign is open, else marginal with zero modes, else stable.
fn stability_of(modes: &[Mode]) -> Stability {
    let (mut unstable, mut zero, mut undecided) = (0, 0, 0);
    let mut growth: f64 = 0.0;
    for mode in modes {
        match mode.kind {
            ModeKind::Unstable { growth_rate } => {
                unstable += 1;
                growth = growth.max(growth_rate);
            }
            ModeKind::Zero => zero += 1,
            ModeKind::Undecided => undecided += 1,
            _ => {}
        }
    }
    if unstable > 0 {
        Stability::Unstable {
            directions: unstable,
            max_growth_rate: growth,
        }
    } else if undecided > 0 {
        Stability::Undecided {
            undecided_modes: undecided,
            zero_modes: zero,
        }
    } else if zero > 0 {
        Stability::Marginal { zero_modes: zero }
    } else {
        Stability::Stable
    }
}

/// The stability and modes of `mechanism` about q₀ (normally an equilibrium from
/// [`crate::find_equilibrium`]). `options` select the modes as in the modal crate; stability
/// needs the unstable and zero modes, which are the lowest, so `Selection::Lowest(k)` suffices.
/// Mode shapes are always computed (`options.vectors` is ignored). The Hessian needs the
/// rotation vectors of spherical and free joints at φ = 0, so with such joints the modes are
/// those of a copy whose charts are re-centred at q₀ (same poses, [`MechanismModes::q`]);
/// `mechanism` keeps its charts, so q₀ names the same configuration before and after the call
/// and identical calls give identical results.
pub fn mechanism_modes(
    mechanism: &mut Mechanism,
    q0: &[f64],
    options: &SolveOptions,
) -> Result<MechanismModes, MechanismError> {
    mechanism_modes_with_locks(mechanism, q0, &[], options)
}

/// As [`mechanism_modes`], with the coordinates in `locked` held fixed (e.g. those resting on a
/// joint limit at the equilibrium, [`crate::Equilibrium::at_limit`]): A and B are restricted to
/// the free coordinates, the gradient norm counts only those, and the shapes carry zeros in the
/// locked rows. Matrices in the result are the restricted ones.
pub fn mechanism_modes_with_locks(
    mechanism: &mut Mechanism,
    q0: &[f64],
    locked: &[usize],
    options: &SolveOptions,
) -> Result<MechanismModes, MechanismError> {
    let mut q = q0.to_vec();
    if mechanism.has_rotation_vectors() {
        let mut recentred = mechanism.clone();
        recentred.rebase(&mut q)?;
        return modes_at(&mut recentred, q, locked, options);
    }
    modes_at(mechanism, q, locked, options)
}

/// [`mechanism_modes_with_locks`] about `q`, whose rotation vectors (if any) are zero.
fn modes_at(
    mechanism: &mut Mechanism,
    q: Vec<f64>,
    locked: &[usize],
    options: &SolveOptions,
) -> Result<MechanismModes, MechanismError> {
    let n_all = mechanism.dof();
    if let Some(&k) = locked.iter().find(|&&k| k >= n_all) {
        return Err(MechanismError::NoSuchCoordinate {
            what: "locked coordinate",
            index: k,
            dof: n_all,
        });
    }
    let evaluation = mechanism.potential(&q, true)?;
    let b_all = evaluation.hessian.ok_or(MechanismError::Numerical("Hessian missing"))?;
    let a_all = mechanism.mass_matrix(&q)?;
    let g_all = mechanism.gyroscopic_matrix(&q)?;
    let unlocked: Vec<usize> = (0..n_all).filter(|k| !locked.contains(k)).collect();
    let (free, idle): (Vec<usize>, Vec<usize>) = unlocked.iter().partition(|&&k| {
        evaluation.gradient[k] != 0.0
            || [&a_all, &b_all, &g_all]
                .iter()
                .any(|m| (0..n_all).any(|j| m[(k, j)] != 0.0))
    });
    let restrict = |m: &Mat<f64>| Mat::from_fn(free.len(), free.len(), |i, j| m[(free[i], free[j])]);
    let (a, b) = (restrict(&a_all), restrict(&b_all));
    let problem = PencilProblem::new(a.as_ref(), b.as_ref())?;
    // Shapes are always computed: they carry the propagation of B's rounding (below) and the
    // body displacements; for mechanisms (n in the hundreds at most) they cost little.
    // A count within the coordinates but beyond those kept (some locked or idle) asks for all
    // of the kept ones.
    let selection = match options.selection {
        Selection::Lowest(k) if k >= free.len() && k <= n_all => Selection::All,
        other => other,
    };
    let options = SolveOptions {
        vectors: true,
        selection,
        ..*options
    };
    let mut solution = solve(&problem, &options)?;
    let assembly = AssemblyError::of(mechanism, &q, &free)?;
    propagate_assembly_error(&mut solution, &assembly, b.as_ref());
    let stability = stability_of(&solution.modes);
    let gradient_norm = free.iter().map(|&k| evaluation.gradient[k].powi(2)).sum::<f64>().sqrt();
    if let Some(x) = solution.vectors.take() {
        let mut row_of = vec![None; n_all];
        for (i, &k) in free.iter().enumerate() {
            row_of[k] = Some(i);
        }
        solution.vectors = Some(Mat::from_fn(n_all, x.ncols(), |r, c| {
            row_of[r].map_or(0.0, |i| x[(i, c)])
        }));
    }
    let (body_displacements, effective_masses, total_mass) = shapes_in_space(mechanism, &q, &solution)?;
    let g = restrict(&g_all);
    let gyroscopic = if g.norm_l2() > 0.0 {
        Some(gyroscopic_modes(&a, &g, &b)?)
    } else {
        None
    };
    Ok(MechanismModes {
        q,
        mass_matrix: a,
        stiffness_matrix: b,
        gradient_norm,
        solution,
        stability,
        body_displacements,
        effective_masses,
        total_mass,
        gyroscopic,
        idle,
    })
}

/// The modal solver certifies each ω² for the B it was given; B itself carries the rounding
/// of its assembly, bounded mode by mode in [`AssemblyError`], which is added to every bound,
/// and the modes are reclassified with it: a ω² of 1e-29 from a B of size 40 is a zero mode,
/// not an instability. Where that leaves a finite mode short of oscillatory, the exact Hessian
/// is tested for definiteness with the assembly's rounding as margin
/// ([`AssemblyError::stiffness_margin`], [`proven_definite_with_margin`]): when it is proven,
/// every finite ω² of the exact linearisation is positive (Sylvester's law), whatever the
/// bounds, and every finite mode is oscillatory.
fn propagate_assembly_error(solution: &mut ModalSolution, assembly: &AssemblyError, b: MatRef<'_, f64>) {
    let Some(x) = &solution.vectors else { return };
    for (k, mode) in solution.modes.iter_mut().enumerate() {
        if matches!(mode.kind, ModeKind::Infinite) {
            continue;
        }
        let shape = |r: usize| x[(r, k)];
        let stiffness_share = assembly.stiffness_share(shape);
        let sign_bound = mode.error_bound + stiffness_share;
        // The assembly error is the model's own resolution: within B's share, a mode is zero.
        // When the solve's own bound is what reaches zero, the size is unknown, not zero.
        let kind = mechanica_modal::classify(mode.omega_sq, sign_bound, sign_bound);
        let solve_limited = stiffness_share < mode.error_bound && mode.kind != ModeKind::Zero;
        mode.kind = match kind {
            ModeKind::Zero if solve_limited => ModeKind::Undecided,
            other => other,
        };
        mode.error_bound = sign_bound + assembly.inertia_share(mode.omega_sq, shape);
        if let Some(bound) = solution.accuracy.error_bounds.get_mut(k) {
            *bound = mode.error_bound;
        }
    }
    let doubtful = |m: &Mode| !matches!(m.kind, ModeKind::Infinite | ModeKind::Oscillatory { .. });
    if !solution.modes.iter().any(doubtful) {
        return;
    }
    let definite = assembly
        .stiffness_margin(b)
        .is_some_and(|margin| proven_definite_with_margin(b, margin, Par::Seq));
    if definite {
        solution
            .modes
            .iter_mut()
            .filter(|m| doubtful(m))
            .for_each(Mode::set_proven_oscillatory);
    }
}

type Shapes = (Vec<Vec<BodyDisplacement>>, Vec<[f64; 3]>, f64);

/// Per mode, the displacement of every body and the effective masses (see the module docs).
/// A mode x moves the points of body i by δx = Ω_i × (x − r) + V_i, with the sums Ω_i = Σ w_k x_k
/// and V_i = Σ ā_k x_k over the coordinates k on i's root path of the columns referred to the
/// root's origin r (ā_k = v_k + w_k × (r − o_k)); both sums grow from parent to child, so every
/// mode costs O(n) operations.
fn shapes_in_space(mechanism: &Mechanism, q: &[f64], solution: &ModalSolution) -> Result<Shapes, MechanismError> {
    let bodies = mechanism.bodies();
    let total_mass: f64 = bodies.iter().map(|b| b.mass).sum();
    let Some(x) = &solution.vectors else {
        return Ok((Vec::new(), Vec::new(), total_mass));
    };
    let tree = mechanism.tree();
    let mut ws = tree.workspace();
    tree.update_positions(&mut ws, q)?;
    let order = tree.topological_order();
    let root = ws.position(order.first().copied().unwrap_or(0))?;
    let mut columns = Vec::with_capacity(tree.dof());
    for k in 0..tree.dof() {
        let (w, v) = ws.motion_column(k)?;
        let origin = ws.position(tree.dof_body(k).unwrap_or(0))?;
        columns.push((w, v + w.cross(&(root - origin))));
    }
    let mut centres = Vec::with_capacity(bodies.len());
    for (i, body) in bodies.iter().enumerate() {
        centres.push(ws.point_position(i, &body.p_oc)? - root);
    }
    let mut displacements = Vec::with_capacity(x.ncols());
    let mut effective = Vec::with_capacity(x.ncols());
    let mut sums = vec![(Vector3::zeros(), Vector3::zeros()); bodies.len()];
    for m in 0..x.ncols() {
        for &i in order {
            let (mut spin, mut shift) = tree.parent(i).map_or((Vector3::zeros(), Vector3::zeros()), |p| sums[p]);
            for k in tree.dof_range(i) {
                spin += columns[k].0 * x[(k, m)];
                shift += columns[k].1 * x[(k, m)];
            }
            sums[i] = (spin, shift);
        }
        let moved: Vec<BodyDisplacement> = sums
            .iter()
            .zip(&centres)
            .map(|((spin, shift), c)| BodyDisplacement {
                translation: spin.cross(c) + shift,
                rotation: *spin,
            })
            .collect();
        // Γ_d = x_kᵀ L_d with L_d = Σ m_i J_iᵀ d = (M J_c)ᵀ d; x_k is A-normalised.
        let participation: Vector3<f64> = moved.iter().zip(bodies).map(|(d, b)| d.translation * b.mass).sum();
        effective.push(if matches!(solution.modes[m].kind, ModeKind::Infinite) {
            [0.0; 3]
        } else {
            [
                participation.x.powi(2),
                participation.y.powi(2),
                participation.z.powi(2),
            ]
        });
        displacements.push(moved);
    }
    Ok((displacements, effective, total_mass))
}

/// Solves det(s²A + sG + B) = 0 with the modal crate's quadratic solver (see the module docs).
fn gyroscopic_modes(a: &Mat<f64>, g: &Mat<f64>, b: &Mat<f64>) -> Result<GyroscopicModes, MechanismError> {
    let solution = quadratic_modes(a.as_ref(), g.as_ref(), b.as_ref(), &QuadraticOptions::default())?;
    let mut finite: Vec<(c64, f64, f64)> = solution
        .eigenvalues
        .iter()
        .filter_map(|e| e.s.map(|s| (s, e.backward_error, e.error_bound)))
        .collect();
    finite.sort_by(|p, q| {
        (p.0.im.abs(), p.0.re)
            .partial_cmp(&(q.0.im.abs(), q.0.re))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    let max_real_part = finite.iter().map(|p| p.0.re).fold(f64::NEG_INFINITY, f64::max);
    Ok(GyroscopicModes {
        eigenvalues: finite.iter().map(|p| (p.0.re, p.0.im)).collect(),
        backward_errors: finite.iter().map(|p| p.1).collect(),
        max_real_part,
        real_part_bound: finite.iter().map(|p| p.2).fold(0.0, f64::max),
        stable: finite.iter().all(|p| p.0.re <= p.2),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mode(omega_sq: f64, error_bound: f64, kind: ModeKind) -> Mode {
        Mode {
            lambda: -omega_sq,
            omega_sq,
            kind,
            error_bound,
            backward_error: None,
            group: 0,
        }
    }

    #[test]
    fn an_undecided_mode_keeps_the_verdict_open() {
        let oscillatory = mode(4.0, 1e-12, ModeKind::Oscillatory { omega: 2.0 });
        let zero = mode(1e-15, 1e-14, ModeKind::Zero);
        let undecided = mode(1e-3, 1.0, ModeKind::Undecided);
        let unstable = mode(-4.0, 1e-12, ModeKind::Unstable { growth_rate: 2.0 });
        assert_eq!(stability_of(&[oscillatory]), Stability::Stable);
        assert_eq!(
            stability_of(&[zero, oscillatory]),
            Stability::Marginal { zero_modes: 1 }
        );
        assert_eq!(
            stability_of(&[zero, undecided, oscillatory]),
            Stability::Undecided {
                undecided_modes: 1,
                zero_modes: 1
            }
        );
        assert_eq!(
            stability_of(&[unstable, undecided]),
            Stability::Unstable {
                directions: 1,
                max_growth_rate: 2.0
            }
        );
    }
}
