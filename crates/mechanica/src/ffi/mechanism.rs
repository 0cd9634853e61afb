//! C entry points of the mechanism crate: a mechanism handle made from a finalized tree and
//! per-body mass properties, loads (gravity, rotating frame, springs, forces, limits), U* with
//! its exact gradient and Hessian, equilibrium search, stability and modes into caller buffers.

use super::boundary::{FfiError, boundary};
use super::c_enum::*;
use super::handle::Handle;
use super::kinematics::mech_tree_t;
use super::mass::mech_mass_properties_t;
use super::modal::{
    MECH_MODAL_KIND_INFINITE, MECH_MODAL_KIND_OSCILLATORY, MECH_MODAL_KIND_UNSTABLE, MECH_MODAL_KIND_ZERO,
    mech_modal_kind_t,
};
use super::status::*;
use super::types::mech_vec3_t;
use super::validate::*;
use mechanica_kinematics::nalgebra::{Unit, Vector3};
use mechanica_mass::MassProperties;
use mechanica_mechanism::potentials::{ConstantForce, JointSpring, PointSpring};
use mechanica_mechanism::{
    Anchor, EquilibriumOptions, Mechanism, MechanismError, RotatingFrame, Seek, Stability, find_equilibrium,
    mechanism_modes,
};
use mechanica_modal::{ModeKind, Selection, SolveOptions};

impl From<MechanismError> for FfiError {
    fn from(error: MechanismError) -> Self {
        let status = match &error {
            MechanismError::Kinematics(e) => return FfiError::from(e.clone()),
            MechanismError::Mass(e) => return FfiError::from(e.clone()),
            MechanismError::Modal(e) => return FfiError::from(e.clone()),
            MechanismError::NonFinite { .. } => MECH_STATUS_NON_FINITE,
            MechanismError::WrongLength { .. } => MECH_STATUS_BAD_DIMENSION,
            MechanismError::NoEquilibrium { .. } => MECH_STATUS_NOT_CONVERGED,
            MechanismError::Numerical(_) => MECH_STATUS_NOT_CONVERGED,
            MechanismError::ZeroLengthSpring { .. } => MECH_STATUS_SINGULAR,
            MechanismError::NoSuchBody { .. }
            | MechanismError::NoSuchCoordinate { .. }
            | MechanismError::OutOfRange { .. }
            | MechanismError::NotRebased { .. }
            | MechanismError::GravityNotAlongAxis { .. }
            | MechanismError::BadLimits { .. }
            | MechanismError::Potential { .. } => MECH_STATUS_INVALID_ARGUMENT,
        };
        FfiError::new(status, error.to_string())
    }
}

/// A mechanism (opaque): a copy of a finalized tree with body mass properties and loads.
/// Created by mech_mechanism_create, freed by mech_mechanism_destroy.
pub struct mech_mechanism_t {
    mechanism: Mechanism,
}

/// Borrows the mechanism behind a handle.
///
/// # Safety
/// `handle` must be NULL or a live handle from mech_mechanism_create.
unsafe fn mechanism_mut<'a>(handle: *mut mech_mechanism_t) -> Result<&'a mut Mechanism, FfiError> {
    if !handle.is_aligned() {
        return Err(FfiError::new(MECH_STATUS_MISALIGNED_POINTER, "mechanism is misaligned"));
    }
    // SAFETY: caller's contract.
    unsafe { handle.as_mut() }
        .map(|h| &mut h.mechanism)
        .ok_or_else(|| FfiError::new(MECH_STATUS_NULL_POINTER, "mechanism is NULL"))
}

/// Reads `n` coordinates, checked finite and of the mechanism's length.
///
/// # Safety
/// `q` must point to `n` readable doubles.
unsafe fn read_q<'a>(mechanism: &Mechanism, q: *const f64, n: usize, what: &str) -> Result<&'a [f64], FfiError> {
    if n != mechanism.dof() {
        return Err(FfiError::new(
            MECH_STATUS_BAD_DIMENSION,
            format!("{what}: the mechanism has {} coordinates, got {n}", mechanism.dof()),
        ));
    }
    // SAFETY: caller's contract.
    let q = unsafe { read_slice(q, n, what) }?;
    finite(q, what)?;
    Ok(q)
}

/// Creates a mechanism from a finalized tree (copied: later changes to the tree do not affect
/// it) and one mass-properties value per body (in the body's frame, in body order).
///
/// # Safety
/// `tree` must be a live tree handle, `bodies` must point to `n_bodies` readable values and
/// `mechanism_out` to a writable pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_create(
    tree: *mut mech_tree_t,
    bodies: *const mech_mass_properties_t,
    n_bodies: usize,
    mechanism_out: *mut *mut mech_mechanism_t,
) -> mech_status_t {
    boundary(|| {
        let out = Out::new(mechanism_out, "mechanism_out")?;
        // SAFETY: caller's contract.
        let tree = unsafe { mech_tree_t::borrow_mut(tree, "tree") }?;
        let (tree, _) = tree.built()?;
        // SAFETY: caller's contract.
        let raw = unsafe { read_slice(bodies, n_bodies, "bodies") }?;
        let mut masses = Vec::with_capacity(raw.len());
        for (i, m) in raw.iter().enumerate() {
            let properties =
                MassProperties::new(m.mass, m.center_of_mass.into(), m.inertia_about_com.into()).map_err(|e| {
                    FfiError::new(
                        FfiError::from(e).status,
                        format!("bodies[{i}]: invalid mass properties"),
                    )
                })?;
            masses.push(properties);
        }
        let mechanism = Mechanism::new(tree.clone(), masses)?;
        let handle = Box::new(mech_mechanism_t { mechanism });
        // SAFETY: caller's contract.
        unsafe { out.write(Box::into_raw(handle)) };
        Ok(())
    })
}

/// Frees a mechanism. NULL is accepted and ignored.
///
/// # Safety
/// `mechanism` must be NULL or a live handle, not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_destroy(mechanism: *mut mech_mechanism_t) {
    if !mechanism.is_null() {
        // SAFETY: caller's contract: a handle from mech_mechanism_create.
        drop(unsafe { Box::from_raw(mechanism) });
    }
}

/// Number of coordinates of the mechanism into `*dof_out`.
///
/// # Safety
/// `mechanism` must be a live handle and `dof_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_dof(mechanism: *mut mech_mechanism_t, dof_out: *mut usize) -> mech_status_t {
    boundary(|| {
        let out = Out::new(dof_out, "dof_out")?;
        // SAFETY: caller's contract.
        let m = unsafe { mechanism_mut(mechanism) }?;
        // SAFETY: caller's contract.
        unsafe { out.write(m.dof()) };
        Ok(())
    })
}

/// Sets uniform gravity g (m/s², base-frame components).
///
/// # Safety
/// `mechanism` must be a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_set_gravity(
    mechanism: *mut mech_mechanism_t,
    gravity: mech_vec3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let m = unsafe { mechanism_mut(mechanism) }?;
        m.set_gravity(gravity.into())?;
        Ok(())
    })
}

/// Makes the base frame turn at `rate` rad/s about the unit `axis` through its origin (§8e);
/// rate 0 removes the rotation. Gravity must be along the axis.
///
/// # Safety
/// `mechanism` must be a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_set_rotating_frame(
    mechanism: *mut mech_mechanism_t,
    axis: mech_vec3_t,
    rate: f64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let m = unsafe { mechanism_mut(mechanism) }?;
        let axis: Vector3<f64> = axis.into();
        finite(&rate, "rate")?;
        finite(axis.as_slice(), "axis")?;
        if (axis.norm() - 1.0).abs() > 1e-9 {
            return Err(FfiError::new(
                MECH_STATUS_INVALID_ARGUMENT,
                "axis must be a unit vector",
            ));
        }
        let frame = (rate != 0.0).then(|| RotatingFrame {
            axis: Unit::new_unchecked(axis),
            rate,
        });
        m.set_rotating_frame(frame)?;
        Ok(())
    })
}

/// Adds U = ½ k (q_i − rest)² on coordinate `coordinate` (not on spherical/free rotation vectors).
///
/// # Safety
/// `mechanism` must be a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_add_joint_spring(
    mechanism: *mut mech_mechanism_t,
    coordinate: usize,
    stiffness: f64,
    rest: f64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let m = unsafe { mechanism_mut(mechanism) }?;
        m.add_potential(JointSpring {
            coordinate,
            stiffness,
            rest,
        })?;
        Ok(())
    })
}

/// The ground, as a body index for mech_mechanism_add_point_spring.
pub const MECH_GROUND: i64 = -1;

fn anchor(body: i64, point: mech_vec3_t) -> Result<Anchor, FfiError> {
    let body = match body {
        MECH_GROUND => None,
        b if b >= 0 => Some(b as usize),
        b => {
            return Err(FfiError::new(
                MECH_STATUS_INVALID_ARGUMENT,
                format!("body index {b} is negative"),
            ));
        }
    };
    Ok(Anchor {
        body,
        point: point.into(),
    })
}

/// Adds a spring U = ½ k (|x_a − x_b| − rest_length)² between the point `point_a` of body
/// `body_a` and `point_b` of `body_b` (body coordinates; MECH_GROUND and world coordinates for
/// the ground).
///
/// # Safety
/// `mechanism` must be a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_add_point_spring(
    mechanism: *mut mech_mechanism_t,
    body_a: i64,
    point_a: mech_vec3_t,
    body_b: i64,
    point_b: mech_vec3_t,
    stiffness: f64,
    rest_length: f64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let m = unsafe { mechanism_mut(mechanism) }?;
        m.add_potential(PointSpring {
            a: anchor(body_a, point_a)?,
            b: anchor(body_b, point_b)?,
            stiffness,
            rest_length,
        })?;
        Ok(())
    })
}

/// Adds a constant world force `force` (N) at the point `point` of body `body` (U = −F·x).
///
/// # Safety
/// `mechanism` must be a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_add_force(
    mechanism: *mut mech_mechanism_t,
    body: usize,
    point: mech_vec3_t,
    force: mech_vec3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let m = unsafe { mechanism_mut(mechanism) }?;
        m.add_potential(ConstantForce {
            body,
            point: point.into(),
            force: force.into(),
        })?;
        Ok(())
    })
}

/// Limits coordinate `coordinate` to [lower, upper] in equilibrium searches.
///
/// # Safety
/// `mechanism` must be a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_set_limits(
    mechanism: *mut mech_mechanism_t,
    coordinate: usize,
    lower: f64,
    upper: f64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let m = unsafe { mechanism_mut(mechanism) }?;
        m.set_limits(coordinate, lower, upper)?;
        Ok(())
    })
}

/// U*(q) into `*potential_out`, its gradient into `gradient_out` (n values) and, unless
/// `hessian_out` is NULL, its Hessian B = ∂²(U*)/∂q∂q (n×n, column-major; spherical and free
/// joints need φ = 0, else MECH_STATUS_INVALID_ARGUMENT). All exact (8.79).
///
/// # Safety
/// `mechanism` must be a live handle; `q` and `gradient_out` must hold n doubles,
/// `hessian_out` n² (or be NULL).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_potential(
    mechanism: *mut mech_mechanism_t,
    q: *const f64,
    n: usize,
    potential_out: *mut f64,
    gradient_out: *mut f64,
    hessian_out: *mut f64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let m = unsafe { mechanism_mut(mechanism) }?;
        // SAFETY: caller's contract.
        let q = unsafe { read_q(m, q, n, "q") }?;
        let potential = Out::new(potential_out, "potential_out")?;
        let gradient = OutSlice::new(gradient_out, n, "gradient_out")?;
        let hessian = if hessian_out.is_null() {
            None
        } else {
            Some(OutSlice::new(
                hessian_out,
                square_len(n, "hessian_out")?,
                "hessian_out",
            )?)
        };
        let sum = m.potential(q, hessian.is_some())?;
        // SAFETY: caller's contract.
        unsafe {
            potential.write(sum.value);
            gradient.write(&sum.gradient);
            if let (Some(out), Some(h)) = (hessian, sum.hessian) {
                let values: Vec<f64> = (0..n)
                    .flat_map(|j| (0..n).map(move |i| (i, j)))
                    .map(|(i, j)| h[(i, j)])
                    .collect();
                out.write(&values);
            }
        }
        Ok(())
    })
}

/// What an equilibrium search heads for (int32_t; see MECH_SEEK_*).
pub type mech_seek_t = i32;
/// Any equilibrium, stable or not (Newton on grad U* = 0, line search on ‖grad U*‖).
pub const MECH_SEEK_STATIONARY: mech_seek_t = 0;
/// A local minimum of U* (a stable equilibrium).
pub const MECH_SEEK_MINIMUM: mech_seek_t = 1;

impl CEnum for Seek {
    fn from_c(raw: i32) -> Option<Self> {
        match raw {
            MECH_SEEK_STATIONARY => Some(Seek::Stationary),
            MECH_SEEK_MINIMUM => Some(Seek::Minimum),
            _ => None,
        }
    }
}

/// The report of an equilibrium search.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_equilibrium_report_t {
    /// U* at the equilibrium (J).
    pub potential: f64,
    /// ‖grad U*‖ at the equilibrium.
    pub gradient_norm: f64,
    /// The tolerance used.
    pub tolerance: f64,
    /// Newton iterations.
    pub iterations: usize,
    /// Length of the last Newton step (an estimate of the distance to the exact equilibrium).
    pub last_step: f64,
    /// Number of coordinates resting on a joint limit.
    pub at_limit: usize,
}

/// Searches an equilibrium from `q0` (n values) and writes it to `q_out` (n values) with its
/// report. `max_iterations` 0 means the default (100); `tolerance` ≤ 0 means the default
/// derived from rounding. Spherical and free joints are re-centred during the search: the
/// result is in the mechanism's new chart (bodies do not move). When the search fails
/// (MECH_STATUS_NOT_CONVERGED), `q_out` still receives the best point found and
/// `report_out` its gradient norm, so the caller can inspect it.
///
/// # Safety
/// `mechanism` must be a live handle; `q0` and `q_out` must hold n doubles; `report_out`
/// must be writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_equilibrium(
    mechanism: *mut mech_mechanism_t,
    q0: *const f64,
    n: usize,
    seek: mech_seek_t,
    max_iterations: usize,
    tolerance: f64,
    q_out: *mut f64,
    report_out: *mut mech_equilibrium_report_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let m = unsafe { mechanism_mut(mechanism) }?;
        // SAFETY: caller's contract.
        let q0 = unsafe { read_q(m, q0, n, "q0") }?.to_vec();
        let seek: Seek = enum_value(seek, "seek")?;
        finite(&tolerance, "tolerance")?;
        let q_out = OutSlice::new(q_out, n, "q_out")?;
        let report_out = Out::new(report_out, "report_out")?;
        let options = EquilibriumOptions {
            max_iterations: if max_iterations == 0 { 100 } else { max_iterations },
            tolerance: (tolerance > 0.0).then_some(tolerance),
            seek,
            ..EquilibriumOptions::default()
        };
        match find_equilibrium(m, &q0, &options) {
            Ok(eq) => {
                let report = mech_equilibrium_report_t {
                    potential: eq.potential,
                    gradient_norm: eq.gradient_norm,
                    tolerance: eq.tolerance,
                    iterations: eq.iterations,
                    last_step: eq.last_step,
                    at_limit: eq.at_limit.len(),
                };
                // SAFETY: caller's contract.
                unsafe {
                    q_out.write(&eq.q);
                    report_out.write(report);
                }
                Ok(())
            }
            Err(MechanismError::NoEquilibrium {
                iterations,
                gradient_norm,
                tolerance,
                best_q,
            }) => {
                let report = mech_equilibrium_report_t {
                    potential: f64::NAN,
                    gradient_norm,
                    tolerance,
                    iterations,
                    last_step: f64::NAN,
                    at_limit: 0,
                };
                // SAFETY: caller's contract.
                unsafe {
                    q_out.write(&best_q);
                    report_out.write(report);
                }
                Err(FfiError::new(
                    MECH_STATUS_NOT_CONVERGED,
                    format!(
                        "equilibrium search did not converge: best |grad U*| = {gradient_norm:.3e} (tolerance {tolerance:.3e}); the best point was written to q_out"
                    ),
                ))
            }
            Err(other) => Err(other.into()),
        }
    })
}

/// The stability verdict of mech_mechanism_modes.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_stability_t {
    /// Number of unstable directions (0 for a stable or marginal equilibrium).
    pub unstable_directions: usize,
    /// Largest growth rate of the unstable directions (1/s; 0 when none).
    pub max_growth_rate: f64,
    /// Number of zero modes within their error bounds.
    pub zero_modes: usize,
    /// ‖grad U*‖ at q (should be ~0: modes are about an equilibrium).
    pub gradient_norm: f64,
    /// In a rotating frame with Coriolis coupling: 1 when every Re s of det(s²A + sG + B) = 0 is
    /// within its bound, 0 when some mode grows, −1 when there is no gyroscopic coupling.
    pub gyroscopic_stable: i32,
}

/// The stability and the lowest `count` modes (count 0: all) of the mechanism about q (n
/// values): ω² into `omega_sq_out`, their error bounds into `error_bounds_out`, their kinds
/// (MECH_MODAL_KIND_*) into `kinds_out` (each `count` long, or n for all), the A-normalised
/// shapes into `shapes_out` (n × count column-major, may be NULL) and the verdict into
/// `stability_out`. The number of modes written goes to `*modes_out`.
///
/// # Safety
/// `mechanism` must be a live handle; the buffers must have the lengths above.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_modes(
    mechanism: *mut mech_mechanism_t,
    q: *const f64,
    n: usize,
    count: usize,
    omega_sq_out: *mut f64,
    error_bounds_out: *mut f64,
    kinds_out: *mut mech_modal_kind_t,
    shapes_out: *mut f64,
    modes_out: *mut usize,
    stability_out: *mut mech_stability_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let m = unsafe { mechanism_mut(mechanism) }?;
        // SAFETY: caller's contract.
        let q = unsafe { read_q(m, q, n, "q") }?.to_vec();
        let k = if count == 0 { n } else { count };
        if k > n {
            return Err(FfiError::new(
                MECH_STATUS_BAD_DIMENSION,
                format!("count {count} exceeds the {n} coordinates"),
            ));
        }
        let omega_out = OutSlice::new(omega_sq_out, k, "omega_sq_out")?;
        let bounds_out = OutSlice::new(error_bounds_out, k, "error_bounds_out")?;
        let kinds_out = OutSlice::new(kinds_out, k, "kinds_out")?;
        let shapes = if shapes_out.is_null() {
            None
        } else {
            let len = n
                .checked_mul(k)
                .ok_or_else(|| FfiError::new(MECH_STATUS_BAD_DIMENSION, "n·count overflows"))?;
            Some(OutSlice::new(shapes_out, len, "shapes_out")?)
        };
        let modes_out = Out::new(modes_out, "modes_out")?;
        let stability_out = Out::new(stability_out, "stability_out")?;
        let options = SolveOptions {
            selection: if count == 0 {
                Selection::All
            } else {
                Selection::Lowest(count)
            },
            ..SolveOptions::default()
        };
        let modes = mechanism_modes(m, &q, &options)?;
        let found = modes.solution.modes.len();
        let mut omega = vec![0.0; k];
        let mut bounds = vec![0.0; k];
        let mut kinds = vec![MECH_MODAL_KIND_INFINITE; k];
        for (i, mode) in modes.solution.modes.iter().enumerate().take(k) {
            omega[i] = mode.omega_sq;
            bounds[i] = mode.error_bound;
            kinds[i] = match mode.kind {
                ModeKind::Oscillatory { .. } => MECH_MODAL_KIND_OSCILLATORY,
                ModeKind::Zero => MECH_MODAL_KIND_ZERO,
                ModeKind::Unstable { .. } => MECH_MODAL_KIND_UNSTABLE,
                ModeKind::Infinite => MECH_MODAL_KIND_INFINITE,
            };
        }
        let stability = match modes.stability {
            Stability::Stable => mech_stability_t::default(),
            Stability::Unstable {
                directions,
                max_growth_rate,
            } => mech_stability_t {
                unstable_directions: directions,
                max_growth_rate,
                ..Default::default()
            },
            Stability::Marginal { zero_modes } => mech_stability_t {
                zero_modes,
                ..Default::default()
            },
        };
        let stability = mech_stability_t {
            gradient_norm: modes.gradient_norm,
            gyroscopic_stable: modes.gyroscopic.as_ref().map_or(-1, |g| i32::from(g.stable)),
            ..stability
        };
        let shape_values: Option<Vec<f64>> = modes.solution.vectors.as_ref().map(|x| {
            (0..k)
                .flat_map(|j| (0..n).map(move |i| (i, j)))
                .map(|(i, j)| if j < x.ncols() { x[(i, j)] } else { 0.0 })
                .collect()
        });
        // SAFETY: caller's contract.
        unsafe {
            omega_out.write(&omega);
            bounds_out.write(&bounds);
            kinds_out.write(&kinds);
            if let (Some(out), Some(values)) = (shapes, shape_values) {
                out.write(&values);
            }
            modes_out.write(found.min(k));
            stability_out.write(stability);
        }
        Ok(())
    })
}
