//! Valid-looking trees and bodies for the C-ABI targets that need them (mass, impulse,
//! mechanism): mostly well-formed, so that the calls get past validation, with arbitrary
//! numbers mixed in where the fuzzer asks for them.

use crate::input::{Input, rotation_of};
use mechanica::ffi::*;

/// A finalized tree handle, destroyed on drop.
pub struct OwnedTree {
    pub handle: *mut mech_tree_t,
    pub bodies: usize,
    pub dof: usize,
    /// The coordinates that are rotation vectors (of spherical and free joints).
    pub rotation_coordinates: Vec<usize>,
}

impl Drop for OwnedTree {
    fn drop(&mut self) {
        // SAFETY: the handle came from mech_tree_create and is destroyed once.
        unsafe { mech_tree_destroy(self.handle) };
    }
}

pub fn v3(a: [f64; 3]) -> mech_vec3_t {
    mech_vec3_t {
        x: a[0],
        y: a[1],
        z: a[2],
    }
}

/// A chain or branching tree of 1–4 bodies on valid joints with placements from the input;
/// `None` when the input picked an invalid joint and finalizing refused it.
/// Where a joint's coordinates sit: how many, which form a rotation vector and which are
/// translations (offsets from the joint's first coordinate).
pub struct JointLayout {
    pub dof: usize,
    pub rotation_vector: std::ops::Range<usize>,
    pub translation: std::ops::Range<usize>,
}

impl JointLayout {
    /// The layout of a (valid) MECH_JOINT_* kind: revolute θ; prismatic s; spherical φ;
    /// free (p, φ); planar (x, y, θ); fixed none.
    pub fn of(joint: i32) -> Self {
        let (dof, rotation_vector, translation) = match joint {
            MECH_JOINT_PRISMATIC => (1, 0..0, 0..1),
            MECH_JOINT_SPHERICAL => (3, 0..3, 0..0),
            MECH_JOINT_FREE => (6, 3..6, 0..3),
            MECH_JOINT_PLANAR => (3, 0..0, 0..2),
            MECH_JOINT_FIXED => (0, 0..0, 0..0),
            _ => (1, 0..0, 0..0),
        };
        JointLayout {
            dof,
            rotation_vector,
            translation,
        }
    }
}

pub fn build_tree(input: &mut Input) -> Option<OwnedTree> {
    let mut handle = std::ptr::null_mut();
    // SAFETY: `handle` is a writable pointer.
    let status = unsafe { mech_tree_create(&mut handle) };
    assert_eq!(status, MECH_STATUS_OK);
    let mut tree = OwnedTree {
        handle,
        bodies: 0,
        dof: 0,
        rotation_coordinates: Vec::new(),
    };
    let mut offset = 0;
    let count = 1 + input.below(4);
    for i in 0..count {
        let parent = if i == 0 { -1 } else { input.below(i) as i64 };
        let joint = input.enum_i32(6);
        let axis = v3(input.unit_vec3());
        let rotation = mech_mat3_t {
            m: rotation_of(input.unit_quaternion()),
        };
        let translation = v3(input.vec3_moderate(1.0));
        crate::trace!(
            "add_body(parent {parent}, joint {joint}, axis {axis:?}, R {:?}, t {translation:?})",
            rotation.m
        );
        let mut body = 0usize;
        // SAFETY: all pointers are to live locals; the handle is live.
        let status = unsafe { mech_tree_add_body(handle, parent, joint, &axis, &rotation, &translation, &mut body) };
        if status != MECH_STATUS_OK {
            return None;
        }
        tree.bodies += 1;
        let layout = JointLayout::of(joint);
        tree.rotation_coordinates
            .extend(layout.rotation_vector.map(|k| offset + k));
        let dof = layout.dof;
        offset += dof;
    }
    // SAFETY: the handle is live.
    if unsafe { mech_tree_finalize(handle) } != MECH_STATUS_OK {
        return None;
    }
    let (mut bodies, mut dof) = (0usize, 0usize);
    // SAFETY: the handle is live and finalized.
    let status = unsafe { mech_tree_size(handle, &mut bodies, &mut dof) };
    assert_eq!(status, MECH_STATUS_OK);
    assert_eq!(bodies, tree.bodies);
    assert_eq!(dof, offset, "the tree's dof differs from its joints'");
    tree.dof = dof;
    Some(tree)
}

/// Sets a state with moderate coordinates and velocities (or arbitrary ones when asked).
pub fn set_state(tree: &OwnedTree, input: &mut Input) -> mech_status_t {
    let wild = input.u8() >= 240;
    let value = |input: &mut Input| if wild { input.any_f64() } else { input.moderate(3.0) };
    let q: Vec<f64> = (0..tree.dof).map(|_| value(input)).collect();
    let q_dot: Vec<f64> = (0..tree.dof).map(|_| value(input)).collect();
    // SAFETY: both arrays hold dof doubles; the handle is live.
    unsafe { mech_tree_set_state(tree.handle, q.as_ptr(), q_dot.as_ptr(), tree.dof) }
}

/// Mass properties: usually a valid body (positive mass, a tensor built from non-negative
/// principal second moments in a random frame), sometimes arbitrary numbers.
pub fn body_properties(input: &mut Input) -> mech_mass_properties_t {
    if input.u8() >= 224 {
        return mech_mass_properties_t {
            mass: input.any_f64(),
            center_of_mass: v3(input.vec3_any()),
            inertia_about_com: mech_mat3_t {
                m: std::array::from_fn(|_| input.any_f64()),
            },
        };
    }
    let mass = 0.01 + input.fraction() * 10.0;
    let sigma = [input.fraction(), input.fraction(), input.fraction()].map(|s| s * mass);
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
