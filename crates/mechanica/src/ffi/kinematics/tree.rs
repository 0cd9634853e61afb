//! The kinematic tree handle: creation, adding bodies with their joints, finalizing, sizes.

use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::c_enum::{c_enum, enum_value};
use crate::ffi::handle::Handle;
use crate::ffi::spatial::{read_rotation, read_vec3};
use crate::ffi::status::*;
use crate::ffi::types::*;
use crate::ffi::validate::*;
use mechanica_kinematics::nalgebra::{Isometry3, Translation3, UnitQuaternion};
use mechanica_kinematics::rotation;
use mechanica_kinematics::tree::{Joint, KinematicTree, TreeBuilder, Workspace};

/// The joint type of a tree body.
pub type mech_joint_type_t = i32;
/// One rotation about a unit axis (q: angle).
pub const MECH_JOINT_REVOLUTE: mech_joint_type_t = 0;
/// One translation along a unit axis (q: distance).
pub const MECH_JOINT_PRISMATIC: mech_joint_type_t = 1;
/// Three rotations about the joint origin (q: rotation vector about a reference orientation).
pub const MECH_JOINT_SPHERICAL: mech_joint_type_t = 2;
/// Six degrees of freedom (q: translation in the joint frame, then rotation vector).
pub const MECH_JOINT_FREE: mech_joint_type_t = 3;
/// Planar motion in the joint frame's xy plane (q: x, y, angle about z).
pub const MECH_JOINT_PLANAR: mech_joint_type_t = 4;
/// Rigid attachment (no coordinates).
pub const MECH_JOINT_FIXED: mech_joint_type_t = 5;

/// The joint kinds of [`mech_joint_type_t`]; the axis of the first two is read separately.
#[derive(Clone, Copy)]
enum JointKind {
    Revolute,
    Prismatic,
    Spherical,
    Free,
    Planar,
    Fixed,
}

c_enum!(JointKind,
    MECH_JOINT_REVOLUTE => JointKind::Revolute,
    MECH_JOINT_PRISMATIC => JointKind::Prismatic,
    MECH_JOINT_SPHERICAL => JointKind::Spherical,
    MECH_JOINT_FREE => JointKind::Free,
    MECH_JOINT_PLANAR => JointKind::Planar,
    MECH_JOINT_FIXED => JointKind::Fixed,
);

/// A kinematic tree (opaque). Created empty by mech_tree_create, filled with
/// mech_tree_add_body, validated by mech_tree_finalize, then queried; freed by mech_tree_destroy.
pub struct mech_tree_t {
    pub(crate) builder: TreeBuilder,
    pub(crate) built: Option<(KinematicTree, Workspace)>,
    /// The validated body mass properties of the last mass call, with their recursion's state.
    #[cfg(feature = "mass")]
    pub(crate) mass_cache: Option<crate::ffi::mass::TreeMassCache>,
    /// The link, joint and coordinate names of a tree read from URDF.
    #[cfg(feature = "urdf")]
    pub(crate) names: Option<std::sync::Arc<crate::ffi::urdf::UrdfNames>>,
}

impl Handle for mech_tree_t {}

impl mech_tree_t {
    /// The finalized tree and its workspace; INVALID_ARGUMENT before mech_tree_finalize.
    pub(crate) fn built(&mut self) -> Result<(&KinematicTree, &mut Workspace), FfiError> {
        match &mut self.built {
            Some((tree, ws)) => Ok((tree, ws)),
            None => Err(FfiError::new(
                MECH_STATUS_INVALID_ARGUMENT,
                "tree is not finalized (call mech_tree_finalize)",
            )),
        }
    }
}

/// Fails with BAD_DIMENSION, naming the argument `what`, unless the caller's count `given` is
/// the tree's number of coordinates.
pub(crate) fn check_dof(tree: &KinematicTree, given: usize, what: &str) -> Result<(), FfiError> {
    if given == tree.dof() {
        return Ok(());
    }
    Err(FfiError::new(
        MECH_STATUS_BAD_DIMENSION,
        format!("{what}: {given} given, but the tree has {} coordinates", tree.dof()),
    ))
}

/// Creates an empty kinematic tree and writes its handle to `*tree_out`. The caller owns the
/// handle and frees it with mech_tree_destroy.
///
/// Errors: none beyond the pointer checks.
///
/// # Safety
/// `tree_out` must point to a writable mech_tree_t pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_create(tree_out: *mut *mut mech_tree_t) -> mech_status_t {
    boundary(|| {
        let out = Out::new(tree_out, "tree_out")?;
        let tree = mech_tree_t {
            builder: TreeBuilder::new(),
            built: None,
            #[cfg(feature = "mass")]
            mass_cache: None,
            #[cfg(feature = "urdf")]
            names: None,
        };
        // SAFETY: caller's contract.
        unsafe { out.write(tree.into_raw()) };
        Ok(())
    })
}

/// Frees a tree and everything it holds. NULL is accepted and ignored. Mechanisms created from
/// the tree keep their own copy and stay valid.
///
/// # Safety
/// `tree` must be NULL or a handle from mech_tree_create not yet destroyed; it is invalid
/// afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_destroy(tree: *mut mech_tree_t) {
    // SAFETY: caller's contract.
    unsafe { mech_tree_t::destroy(tree) }
}

/// The parent index of mech_tree_add_body: −1 for the root, else a body index.
fn parent_index(parent: i64) -> Result<Option<usize>, FfiError> {
    match parent {
        -1 => Ok(None),
        p if p >= 0 => usize::try_from(p)
            .map(Some)
            .map_err(|_| FfiError::new(MECH_STATUS_INVALID_ARGUMENT, format!("parent {p} is out of range"))),
        p => Err(FfiError::new(
            MECH_STATUS_INVALID_ARGUMENT,
            format!("parent must be −1 (root) or a body index, got {p}"),
        )),
    }
}

/// Adds a body to a tree that is not finalized yet and writes its index (0, 1, … in the order
/// of the calls) to `body_out`. `parent` is the parent's body index, or −1 for the root
/// (attached to the base frame); it may name a body added later. `joint_type` is a
/// mech_joint_type_t; `axis` (joint-frame components, unit length) is required for revolute and
/// prismatic joints and ignored (may be NULL) otherwise. The joint frame sits at rotation
/// `placement_rotation` (a rotation matrix, column-major) and translation
/// `placement_translation` (m) in the parent's body frame. Structural checks (one root, no
/// cycles, parents in range) happen in mech_tree_finalize.
///
/// Errors: MECH_STATUS_BAD_ENUM for an unknown `joint_type`; MECH_STATUS_NON_FINITE for a NaN or
/// infinite entry; MECH_STATUS_INVALID_ARGUMENT for a finalized tree, a parent below −1, a
/// placement that is not a rotation within ‖RᵀR − I‖_F ≤ 1e-12 or a zero or non-unit axis
/// (|‖a‖ − 1| > 1e-12). The tree is unchanged on error.
///
/// # Safety
/// `tree` must be a live handle; `axis` NULL or readable; `placement_rotation` and
/// `placement_translation` readable; `body_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_add_body(
    tree: *mut mech_tree_t,
    parent: i64,
    joint_type: mech_joint_type_t,
    axis: *const mech_vec3_t,
    placement_rotation: *const mech_mat3_t,
    placement_translation: *const mech_vec3_t,
    body_out: *mut usize,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { mech_tree_t::borrow_mut(tree, "tree") }?;
        let kind: JointKind = enum_value(joint_type, "joint_type")?;
        // SAFETY: caller's contract.
        let (r, p) = unsafe {
            (
                read_rotation(placement_rotation, "placement_rotation")?,
                read_vec3(placement_translation, "placement_translation")?,
            )
        };
        let out = Out::new(body_out, "body_out")?;
        if t.built.is_some() {
            return Err(FfiError::new(
                MECH_STATUS_INVALID_ARGUMENT,
                "tree is already finalized; bodies can no longer be added",
            ));
        }
        let parent = parent_index(parent)?;
        let joint = match kind {
            JointKind::Revolute | JointKind::Prismatic => {
                // SAFETY: caller's contract.
                let a = unsafe { read_vec3(axis, "axis") }?;
                rotation::unit_axis(&a, "joint axis")?;
                if matches!(kind, JointKind::Revolute) {
                    Joint::Revolute { axis: a }
                } else {
                    Joint::Prismatic { axis: a }
                }
            }
            JointKind::Spherical => Joint::Spherical,
            JointKind::Free => Joint::Free,
            JointKind::Planar => Joint::Planar,
            JointKind::Fixed => Joint::Fixed,
        };
        let placement = Isometry3::from_parts(Translation3::from(p), UnitQuaternion::from_rotation_matrix(&r));
        let index = t.builder.add_body(parent, joint, placement);
        // SAFETY: caller's contract.
        unsafe { out.write(index) };
        Ok(())
    })
}

/// Validates the tree (at least one body, exactly one root, parents in range, no cycles) and
/// makes it ready for state updates and queries; bodies can no longer be added.
///
/// Errors: MECH_STATUS_INVALID_ARGUMENT for a structural error (the message in mech_last_error
/// names the offending body) or when the tree is already finalized.
///
/// # Safety
/// `tree` must be a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_finalize(tree: *mut mech_tree_t) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { mech_tree_t::borrow_mut(tree, "tree") }?;
        if t.built.is_some() {
            return Err(FfiError::new(MECH_STATUS_INVALID_ARGUMENT, "tree is already finalized"));
        }
        let kt = t.builder.clone().build()?;
        let ws = kt.workspace();
        t.built = Some((kt, ws));
        #[cfg(feature = "mass")]
        {
            t.mass_cache = None;
        }
        Ok(())
    })
}

/// The number of bodies (`body_count_out`) and of coordinates, which equals the number of
/// velocities (`dof_out`), of a finalized tree.
///
/// Errors: MECH_STATUS_INVALID_ARGUMENT when the tree is not finalized.
///
/// # Safety
/// `tree` must be a live handle; `body_count_out` and `dof_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_size(
    tree: *mut mech_tree_t,
    body_count_out: *mut usize,
    dof_out: *mut usize,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { mech_tree_t::borrow_mut(tree, "tree") }?;
        let bodies = Out::new(body_count_out, "body_count_out")?;
        let dof = Out::new(dof_out, "dof_out")?;
        let (kt, _) = t.built()?;
        // SAFETY: caller's contract.
        unsafe {
            bodies.write(kt.body_count());
            dof.write(kt.dof());
        }
        Ok(())
    })
}
