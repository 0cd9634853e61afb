//! The names of the links, joints and coordinates of trees and mechanisms read from URDF,
//! copied into caller buffers.

use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::handle::Handle;
use crate::ffi::kinematics::mech_tree_t;
use crate::ffi::mechanism::mech_mechanism_t;
use crate::ffi::status::*;
use crate::ffi::validate::*;
use mechanica_urdf::UrdfTree;
use std::ffi::c_char;

/// Per body: link and joint names; per coordinate: its name (see [`UrdfTree`]).
#[derive(Debug)]
pub(crate) struct UrdfNames {
    pub links: Vec<String>,
    pub joints: Vec<String>,
    pub coordinates: Vec<String>,
}

impl UrdfNames {
    pub(crate) fn of(tree: &UrdfTree) -> Self {
        Self {
            links: tree.link_names.clone(),
            joints: tree.joint_names.clone(),
            coordinates: tree.coordinate_names.clone(),
        }
    }
}

/// Entry `index` of `list` (the `what` of a handle read from URDF), or why there is none.
fn entry<'a>(list: Option<&'a [String]>, index: usize, what: &str) -> Result<&'a str, FfiError> {
    let list = list.ok_or_else(|| {
        FfiError::new(
            MECH_STATUS_INVALID_ARGUMENT,
            format!("{what} names exist only for handles read from URDF"),
        )
    })?;
    list.get(index).map(String::as_str).ok_or_else(|| {
        FfiError::new(
            MECH_STATUS_INVALID_ARGUMENT,
            format!("{what} index {index} is out of range (there are {})", list.len()),
        )
    })
}

/// Writes the length of `name` in bytes to `length_out` and, unless `buffer` is NULL with
/// `capacity` 0 (a length query), the name with a terminating NUL into `buffer`.
///
/// # Safety
/// `buffer` must be NULL or hold `capacity` writable bytes; `length_out` must be writable.
unsafe fn write_name(name: &str, buffer: *mut c_char, capacity: usize, length_out: *mut usize) -> Result<(), FfiError> {
    let length = Out::new(length_out, "length_out")?;
    let query = buffer.is_null() && capacity == 0;
    if !query {
        let mut bytes = Vec::with_capacity(name.len() + 1);
        bytes.extend_from_slice(name.as_bytes());
        bytes.push(0);
        let out = OutSlice::buffer(buffer.cast::<u8>(), capacity, bytes.len(), "buffer")?;
        // SAFETY: caller's contract.
        unsafe { out.write(&bytes) };
    }
    // SAFETY: caller's contract.
    unsafe { length.write(name.len()) };
    Ok(())
}

/// One name query on a tree: `pick` chooses the list.
///
/// # Safety
/// As the public functions below.
unsafe fn tree_name(
    tree: *mut mech_tree_t,
    pick: fn(&UrdfNames) -> &[String],
    what: &str,
    index: usize,
    buffer: *mut c_char,
    capacity: usize,
    length_out: *mut usize,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { mech_tree_t::borrow(tree, "tree") }?;
        let name = entry(t.names.as_deref().map(pick), index, what)?;
        // SAFETY: caller's contract.
        unsafe { write_name(name, buffer, capacity, length_out) }
    })
}

/// One name query on a mechanism: `pick` chooses the list.
///
/// # Safety
/// As the public functions below.
unsafe fn mechanism_name(
    mechanism: *const mech_mechanism_t,
    pick: fn(&UrdfNames) -> &[String],
    what: &str,
    index: usize,
    buffer: *mut c_char,
    capacity: usize,
    length_out: *mut usize,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let m = unsafe { mech_mechanism_t::borrow(mechanism, "mechanism") }?;
        let name = entry(m.names.as_deref().map(pick), index, what)?;
        // SAFETY: caller's contract.
        unsafe { write_name(name, buffer, capacity, length_out) }
    })
}

/// Copies the name of the link of body `body` of a tree read from URDF into `buffer` (UTF-8
/// with a terminating NUL) and writes its length in bytes (without the NUL) to `*length_out`.
/// With `buffer = NULL, capacity = 0` only the length is written: allocate length + 1 bytes.
///
/// Errors: MECH_STATUS_BUFFER_TOO_SMALL when `capacity` < length + 1 (nothing is written);
/// MECH_STATUS_INVALID_ARGUMENT for a body index out of range or a tree not read from URDF.
///
/// # Safety
/// `tree` must be a live handle, `buffer` NULL or `capacity` writable bytes, `length_out`
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_link_name(
    tree: *mut mech_tree_t,
    body: usize,
    buffer: *mut c_char,
    capacity: usize,
    length_out: *mut usize,
) -> mech_status_t {
    // SAFETY: caller's contract.
    unsafe { tree_name(tree, |n| &n.links, "link", body, buffer, capacity, length_out) }
}

/// As mech_tree_link_name, the name of the joint between body `body` and its parent (the empty
/// string for the root link, which hangs on the base frame by a fixed joint).
///
/// Errors: as mech_tree_link_name.
///
/// # Safety
/// As mech_tree_link_name.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_joint_name(
    tree: *mut mech_tree_t,
    body: usize,
    buffer: *mut c_char,
    capacity: usize,
    length_out: *mut usize,
) -> mech_status_t {
    // SAFETY: caller's contract.
    unsafe { tree_name(tree, |n| &n.joints, "joint", body, buffer, capacity, length_out) }
}

/// As mech_tree_link_name, the name of coordinate `k` (0 ≤ k < dof): its joint's name for a
/// one-coordinate joint, `joint[i]` (i = 0, 1, …) for the coordinates of spherical, planar and
/// free joints.
///
/// Errors: as mech_tree_link_name, for a coordinate index out of range.
///
/// # Safety
/// As mech_tree_link_name.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_coordinate_name(
    tree: *mut mech_tree_t,
    k: usize,
    buffer: *mut c_char,
    capacity: usize,
    length_out: *mut usize,
) -> mech_status_t {
    // SAFETY: caller's contract.
    unsafe { tree_name(tree, |n| &n.coordinates, "coordinate", k, buffer, capacity, length_out) }
}

/// As mech_tree_link_name, for a mechanism read from URDF (or created from a tree read from
/// URDF).
///
/// Errors: as mech_tree_link_name.
///
/// # Safety
/// `mechanism` must be a live handle, `buffer` NULL or `capacity` writable bytes,
/// `length_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_link_name(
    mechanism: *const mech_mechanism_t,
    body: usize,
    buffer: *mut c_char,
    capacity: usize,
    length_out: *mut usize,
) -> mech_status_t {
    // SAFETY: caller's contract.
    unsafe { mechanism_name(mechanism, |n| &n.links, "link", body, buffer, capacity, length_out) }
}

/// As mech_tree_coordinate_name, for a mechanism read from URDF (or created from a tree read
/// from URDF).
///
/// Errors: as mech_tree_link_name.
///
/// # Safety
/// As mech_mechanism_link_name.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_coordinate_name(
    mechanism: *const mech_mechanism_t,
    k: usize,
    buffer: *mut c_char,
    capacity: usize,
    length_out: *mut usize,
) -> mech_status_t {
    // SAFETY: caller's contract.
    unsafe {
        mechanism_name(
            mechanism,
            |n| &n.coordinates,
            "coordinate",
            k,
            buffer,
            capacity,
            length_out,
        )
    }
}
