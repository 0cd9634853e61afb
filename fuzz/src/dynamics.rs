//! Dynamics handles for the `abi_dynamics` and `abi_motion` targets: a tree of any joint
//! types with bodies whose masses span many decades (and some massless, point-like, invalid
//! or non-finite ones), a mechanism with loads, and the dynamics made from it, plus the
//! output contract of those targets.

use crate::input::{Input, rotation_of};
use crate::oracle::{check_status, finite, last_error};
use crate::tree::{OwnedTree, build_tree, v3};
use mechanica::ffi::*;

/// A dynamics handle with its tree's sizes, destroyed on drop.
pub struct OwnedDynamics {
    pub handle: *mut mech_dynamics_t,
    pub bodies: usize,
    pub dof: usize,
    /// Whether the mechanism has a rotating frame (damped modes refuse some of its cases).
    pub rotating: bool,
}

impl Drop for OwnedDynamics {
    fn drop(&mut self) {
        // SAFETY: the handle came from mech_dynamics_create and is destroyed once.
        unsafe { mech_dynamics_destroy(self.handle) };
    }
}

/// The output contract of the dynamics and motion targets: a documented status; on success
/// every number written is finite; on failure nothing was written (`untouched`) and
/// mech_last_error says why.
pub fn check_call(call: &str, status: mech_status_t, untouched: bool, values: &[f64]) {
    check_status(call, status);
    if status == MECH_STATUS_OK {
        assert!(
            finite(values),
            "{call}: MECH_STATUS_OK but wrote a non-finite value: {values:?}"
        );
    } else {
        assert!(untouched, "{call}: failed with status {status} but wrote an output");
        assert!(
            !last_error().is_empty(),
            "{call}: failed with status {status} and an empty mech_last_error"
        );
    }
}

/// A non-NULL pointer misaligned for `T` (rejected before any dereference), into `storage`.
pub fn misaligned<T>(storage: &mut [u64; 4]) -> *mut T {
    storage.as_mut_ptr().cast::<u8>().wrapping_add(1).cast::<T>()
}

/// 10^e for e drawn in [−`decades`, `decades`].
pub fn decades(input: &mut Input, decades: i32) -> f64 {
    let span = 2 * decades + 1;
    10f64.powi(i32::from(input.u8()) % span - decades)
}

/// A positive value graded over many decades, or sometimes any double.
pub fn graded(input: &mut Input, decades_each_way: i32) -> f64 {
    if input.u8() < 232 {
        (0.1 + input.fraction()) * decades(input, decades_each_way)
    } else {
        input.any_f64()
    }
}

/// Mass properties whose masses span 1e-30 … 1e30 kg, with massless bodies, point masses
/// (zero inertia), values near 1e±308, invalid (negative) inertias and non-finite numbers.
pub fn graded_body(input: &mut Input) -> mech_mass_properties_t {
    let selector = input.u8();
    let (mass, scale) = match selector {
        0..=159 => {
            let m = (0.1 + input.fraction()) * decades(input, 30);
            (m, m)
        }
        160..=184 => (0.0, if input.bool() { 0.0 } else { input.fraction() }),
        185..=199 => (input.fraction() + 0.01, 0.0),
        200..=214 => {
            let big = [1e308, 1e-308, f64::MAX, 5e-324, 1e300, 1e-300][input.below(6)];
            (big, big)
        }
        215..=229 => (input.moderate(2.0), -(input.fraction() + 0.01)),
        _ => {
            return mech_mass_properties_t {
                mass: input.any_f64(),
                center_of_mass: v3(input.vec3_any()),
                inertia_about_com: mech_mat3_t {
                    m: std::array::from_fn(|_| input.any_f64()),
                },
            };
        }
    };
    let sigma = [input.fraction(), input.fraction(), input.fraction()].map(|s| s * scale);
    let moments = [sigma[1] + sigma[2], sigma[0] + sigma[2], sigma[0] + sigma[1]];
    let r = rotation_of(input.unit_quaternion());
    let mut inertia = [0.0; 9];
    for row in 0..3 {
        for col in 0..3 {
            inertia[row + 3 * col] = (0..3).map(|k| r[row + 3 * k] * moments[k] * r[col + 3 * k]).sum();
        }
    }
    mech_mass_properties_t {
        mass,
        center_of_mass: v3(input.vec3_moderate(1.0)),
        inertia_about_com: mech_mat3_t { m: inertia },
    }
}

/// A double of moderate size, or sometimes any double.
pub fn any_or(input: &mut Input, scale: f64) -> f64 {
    if input.u8() < 224 {
        input.moderate(scale)
    } else {
        input.any_f64()
    }
}

pub fn vec_or(input: &mut Input, scale: f64) -> mech_vec3_t {
    v3([any_or(input, scale), any_or(input, scale), any_or(input, scale)])
}

/// A few mechanism loads: gravity, a rotating frame, joint and point springs with stiffnesses
/// over many decades. Returns whether a rotating frame was set.
fn mechanism_loads(mechanism: *mut mech_mechanism_t, tree: &OwnedTree, input: &mut Input) -> bool {
    let mut rotating = false;
    for _ in 0..input.below(4) {
        let (call, status) = match input.u8() % 4 {
            0 => {
                let g = vec_or(input, 10.0);
                crate::trace!("set_gravity({g:?})");
                // SAFETY: the handle is live.
                ("mech_mechanism_set_gravity", unsafe {
                    mech_mechanism_set_gravity(mechanism, g)
                })
            }
            1 => {
                let axis = v3(input.unit_vec3());
                let rate = any_or(input, 3.0);
                crate::trace!("set_rotating_frame({axis:?}, {rate:e})");
                // SAFETY: the handle is live.
                let status = unsafe { mech_mechanism_set_rotating_frame(mechanism, axis, rate) };
                if status == MECH_STATUS_OK {
                    rotating = rate != 0.0; // rate 0 removes the rotation
                }
                ("mech_mechanism_set_rotating_frame", status)
            }
            2 => {
                let coordinate = input.below(tree.dof + 1);
                let (k, rest) = (graded(input, 20), any_or(input, 1.0));
                crate::trace!("add_joint_spring({coordinate}, {k:e}, {rest:e})");
                // SAFETY: the handle is live.
                ("mech_mechanism_add_joint_spring", unsafe {
                    mech_mechanism_add_joint_spring(mechanism, coordinate, k, rest)
                })
            }
            _ => {
                let (a, b) = (
                    input.below(tree.bodies + 1) as i64 - 1,
                    input.below(tree.bodies + 1) as i64 - 1,
                );
                let (pa, pb) = (vec_or(input, 1.0), vec_or(input, 1.0));
                let (k, rest) = (graded(input, 20), any_or(input, 1.0));
                crate::trace!("add_point_spring({a}, {pa:?}, {b}, {pb:?}, {k:e}, {rest:e})");
                // SAFETY: the handle is live.
                ("mech_mechanism_add_point_spring", unsafe {
                    mech_mechanism_add_point_spring(mechanism, a, pa, b, pb, k, rest)
                })
            }
        };
        check_status(call, status);
    }
    rotating
}

/// A dynamics handle on a tree from the input (every joint type), graded bodies and a few
/// loads; `None` when the input's tree or bodies were refused (each refusal checked).
pub fn build_dynamics(input: &mut Input) -> Option<OwnedDynamics> {
    let tree = build_tree(input)?;
    let bodies: Vec<mech_mass_properties_t> = (0..tree.bodies).map(|_| graded_body(input)).collect();
    crate::trace!(
        "tree: {} bodies, {} coordinates; bodies {bodies:?}",
        tree.bodies,
        tree.dof
    );
    let mut mechanism = std::ptr::null_mut();
    // SAFETY: the tree is live; `bodies` holds bodies.len() records.
    let status = unsafe { mech_mechanism_create(tree.handle, bodies.as_ptr(), bodies.len(), &mut mechanism) };
    check_status("mech_mechanism_create", status);
    if status != MECH_STATUS_OK {
        return None;
    }
    let rotating = mechanism_loads(mechanism, &tree, input);
    let mut handle = std::ptr::null_mut();
    if input.u8() >= 248 {
        // SAFETY: NULL arguments are rejected before any dereference.
        let status = unsafe { mech_dynamics_create(std::ptr::null(), &mut handle) };
        check_call("mech_dynamics_create(NULL)", status, handle.is_null(), &[]);
        assert_eq!(status, MECH_STATUS_NULL_POINTER, "mech_dynamics_create(NULL mechanism)");
        // SAFETY: as above.
        let status = unsafe { mech_dynamics_create(mechanism, std::ptr::null_mut()) };
        assert_eq!(status, MECH_STATUS_NULL_POINTER, "mech_dynamics_create(NULL out)");
    }
    // SAFETY: the mechanism is live and `handle` writable.
    let status = unsafe { mech_dynamics_create(mechanism, &mut handle) };
    // SAFETY: the dynamics copies the mechanism, which is no longer needed.
    unsafe { mech_mechanism_destroy(mechanism) };
    check_call("mech_dynamics_create", status, handle.is_null(), &[]);
    if status != MECH_STATUS_OK {
        return None;
    }
    let dynamics = OwnedDynamics {
        handle,
        bodies: tree.bodies,
        dof: tree.dof,
        rotating,
    };
    let (mut dof, mut count) = (0usize, 0usize);
    // SAFETY: the handle is live; the outputs are locals.
    unsafe {
        assert_eq!(mech_dynamics_dof(handle, &mut dof), MECH_STATUS_OK);
        assert_eq!(mech_dynamics_body_count(handle, &mut count), MECH_STATUS_OK);
    }
    assert_eq!(dof, tree.dof, "mech_dynamics_dof differs from the tree's dof");
    assert_eq!(count, tree.bodies, "mech_dynamics_body_count differs from the tree's");
    Some(dynamics)
}

/// Coordinates or velocities: moderate (|x| ≤ `scale`) or, sometimes, arbitrary doubles.
pub fn state_vector(input: &mut Input, n: usize, scale: f64) -> Vec<f64> {
    let wild = input.u8() >= 240;
    (0..n)
        .map(|_| if wild { input.any_f64() } else { input.moderate(scale) })
        .collect()
}

/// Forces or accelerations: moderate values times a power of ten over many decades, or
/// sometimes arbitrary doubles.
pub fn graded_vector(input: &mut Input, n: usize) -> Vec<f64> {
    let wild = input.u8() >= 240;
    let scale = decades(input, 20);
    (0..n)
        .map(|_| if wild { input.any_f64() } else { input.moderate(scale) })
        .collect()
}
