//! Stability and small-oscillation modes of a mechanism about an equilibrium.

use super::{mech_mechanism_t, mechanism_mut, read_q};
use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::modal::{MECH_MODAL_KIND_INFINITE, column_major, kind_to_c, mech_modal_kind_t};
use crate::ffi::status::*;
use crate::ffi::validate::*;
use mechanica_mechanism::{MechanismModes, Stability, mechanism_modes};
use mechanica_modal::{Selection, SolveOptions};

/// The stability verdict of mech_mechanism_modes. Modes whose sign is not decided (kinds_out
/// MECH_MODAL_KIND_UNDECIDED) are counted in neither field: an equilibrium is stable only when
/// both counts are zero and no mode is undecided.
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

/// The C verdict of a modes computation.
fn stability_to_c(modes: &MechanismModes) -> mech_stability_t {
    let verdict = match modes.stability {
        Stability::Stable => mech_stability_t::default(),
        Stability::Unstable {
            directions,
            max_growth_rate,
        } => mech_stability_t {
            unstable_directions: directions,
            max_growth_rate,
            ..Default::default()
        },
        // The struct has no count of undecided modes (kinds_out marks them
        // MECH_MODAL_KIND_UNDECIDED); its zero modes are reported.
        Stability::Marginal { zero_modes } | Stability::Undecided { zero_modes, .. } => mech_stability_t {
            zero_modes,
            ..Default::default()
        },
    };
    mech_stability_t {
        gradient_norm: modes.gradient_norm,
        gyroscopic_stable: modes.gyroscopic.as_ref().map_or(-1, |g| i32::from(g.stable)),
        ..verdict
    }
}

/// The stability and the lowest `count` modes (count 0: all n) of det(λA + B) = 0 for the
/// mechanism about q (n values, normally an equilibrium), A the mass matrix and B the Hessian
/// of U*: ω² (rad²/s²) into `omega_sq_out`, their error bounds into `error_bounds_out`, their
/// kinds (MECH_MODAL_KIND_*) into `kinds_out` (each `count` long, or n for all; entries past
/// the modes found are 0, 0 and MECH_MODAL_KIND_INFINITE), the A-normalised shapes into
/// `shapes_out` (n × count column-major, may be NULL) and the verdict into `stability_out`.
/// The number of modes written goes to `*modes_out`: fewer than n when some coordinates move no
/// mass and feel no force (massless links without springs; their rows of A and B are zero and
/// they are left out, with zero rows in the shapes). The rows of a spherical or free joint's
/// rotation vector are in charts re-centred at q (rotation increments about the body frame at
/// q); the handle keeps its own charts, so identical calls give identical results.
///
/// Errors: MECH_STATUS_BAD_DIMENSION when n is not the dof or count > n;
/// MECH_STATUS_NON_FINITE for a NaN or infinite coordinate; the modal solve's errors
/// (mech_modal_solve), e.g. MECH_STATUS_NOT_POSITIVE_DEFINITE for an indefinite mass matrix.
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
        let shapes = OutSlice::optional(shapes_out, product(n, k, "n·count")?, "shapes_out")?;
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
            kinds[i] = kind_to_c(mode.kind).0;
        }
        let stability = stability_to_c(&modes);
        let shape_values = modes.solution.vectors.as_ref().map(|x| column_major(x.as_ref(), k));
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
