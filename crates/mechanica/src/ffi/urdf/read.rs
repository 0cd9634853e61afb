//! Trees and mechanisms from URDF files and texts.

use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::handle::Handle;
use crate::ffi::kinematics::mech_tree_t;
use crate::ffi::mechanism::mech_mechanism_t;
use crate::ffi::status::*;
use crate::ffi::urdf::UrdfNames;
use crate::ffi::validate::*;
use mechanica_kinematics::nalgebra::Vector3;
use mechanica_kinematics::tree::TreeBuilder;
use mechanica_mechanism::Mechanism;
use mechanica_urdf::{UrdfDocument, UrdfError, UrdfOptions, UrdfTree};
use std::ffi::{CStr, c_char};
use std::path::Path;
use std::sync::Arc;

/// The longest URDF file or text the readers accept, in bytes (64 MiB); longer ones give
/// MECH_STATUS_BAD_DIMENSION before anything is parsed.
pub const MECH_URDF_MAX_BYTES: usize = 67108864;

/// How the URDF readers treat links that are not physical as written. Start from
/// mech_urdf_options_default().
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct mech_urdf_options_t {
    /// 1: replace an invalid `<inertia>` by the nearest physical tensor (the relative change is
    /// the Frobenius distance over the tensor's norm); 0 (default): refuse the robot.
    pub repair_inertia: i32,
    /// 1: a link without `<inertial>` whose mesh cannot be used (missing file, a format other
    /// than STL or OBJ, no volume) is massless; 0 (default): refuse the robot.
    pub allow_missing_mesh: i32,
}

/// Writes the default URDF options (both 0: strict) to `*options_out`.
///
/// Errors: none beyond the pointer checks.
///
/// # Safety
/// `options_out` must be writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_urdf_options_default(options_out: *mut mech_urdf_options_t) -> mech_status_t {
    boundary(|| {
        let out = Out::new(options_out, "options_out")?;
        // SAFETY: caller's contract.
        unsafe {
            out.write(mech_urdf_options_t {
                repair_inertia: 0,
                allow_missing_mesh: 0,
            })
        };
        Ok(())
    })
}

/// The options behind a pointer that may be NULL (the defaults), each flag 0 or 1.
///
/// # Safety
/// `options` must be NULL or readable.
unsafe fn read_options(options: *const mech_urdf_options_t) -> Result<UrdfOptions, FfiError> {
    if options.is_null() {
        return Ok(UrdfOptions::default());
    }
    // SAFETY: caller's contract.
    let o = unsafe { read(options, "options") }?;
    let flag = |value: i32, what: &str| match value {
        0 => Ok(false),
        1 => Ok(true),
        v => Err(FfiError::new(
            MECH_STATUS_INVALID_ARGUMENT,
            format!("options.{what} must be 0 or 1, got {v}"),
        )),
    };
    Ok(UrdfOptions {
        repair_inertia: flag(o.repair_inertia, "repair_inertia")?,
        allow_missing_mesh: flag(o.allow_missing_mesh, "allow_missing_mesh")?,
    })
}

/// A NUL-terminated UTF-8 path.
///
/// # Safety
/// A non-NULL `ptr` must point to a NUL-terminated string.
unsafe fn read_path<'a>(ptr: *const c_char, what: &str) -> Result<&'a Path, FfiError> {
    check_pointer(ptr, what)?;
    // SAFETY: non-NULL; NUL-terminated by the caller's contract.
    let text = unsafe { CStr::from_ptr(ptr) }
        .to_str()
        .map_err(|_| FfiError::new(MECH_STATUS_INVALID_ARGUMENT, format!("{what} is not valid UTF-8")))?;
    Ok(Path::new(text))
}

/// The status of a URDF error, with its message prefixed by `source` (the file, or "URDF text").
fn urdf_error(source: &str, error: UrdfError) -> FfiError {
    let status = match &error {
        UrdfError::Kinematics(e) => FfiError::from(e.clone()).status,
        UrdfError::Io { .. } | UrdfError::UnusableMeshes { .. } => MECH_STATUS_IO_ERROR,
        UrdfError::TooLarge { .. } => MECH_STATUS_BAD_DIMENSION,
        UrdfError::Parse { .. } => MECH_STATUS_PARSE_ERROR,
        UrdfError::NonFiniteOrigin { .. } => MECH_STATUS_NON_FINITE,
        _ => MECH_STATUS_INVALID_ARGUMENT,
    };
    FfiError::new(status, format!("{source}: {error}"))
}

/// Reads a URDF file (at `path`) or text (`text`, `length` bytes, meshes in `mesh_dir`) into a
/// tree with names.
enum Source<'a> {
    File(&'a Path),
    Text { text: &'a str, mesh_dir: &'a Path },
}

impl Source<'_> {
    fn label(&self) -> String {
        match self {
            Source::File(path) => path.display().to_string(),
            Source::Text { .. } => "URDF text".to_string(),
        }
    }

    fn tree(&self, options: UrdfOptions) -> Result<UrdfTree, FfiError> {
        let fail = |e| urdf_error(&self.label(), e);
        let robot = match self {
            Source::File(path) => mechanica_urdf::read_file(path, options),
            Source::Text { text, mesh_dir } => UrdfDocument::parse(text).and_then(|d| d.robot(mesh_dir, options)),
        }
        .map_err(fail)?;
        robot.tree().map_err(fail)
    }
}

/// The text argument of the string readers: `length` bytes of UTF-8 (no NUL needed), at most
/// MECH_URDF_MAX_BYTES.
///
/// # Safety
/// A non-NULL `text` must point to `length` readable bytes.
unsafe fn read_text<'a>(text: *const c_char, length: usize) -> Result<&'a str, FfiError> {
    if length > MECH_URDF_MAX_BYTES {
        return Err(FfiError::new(
            MECH_STATUS_BAD_DIMENSION,
            format!("length: {length} bytes, more than MECH_URDF_MAX_BYTES ({MECH_URDF_MAX_BYTES})"),
        ));
    }
    // SAFETY: caller's contract.
    let bytes = unsafe { read_slice(text.cast::<u8>(), length, "text") }?;
    std::str::from_utf8(bytes).map_err(|e| {
        FfiError::new(
            MECH_STATUS_PARSE_ERROR,
            format!("URDF text: not UTF-8 at byte {}", e.valid_up_to()),
        )
    })
}

/// The source of a string reader: the text and the mesh directory (NULL: the working
/// directory).
///
/// # Safety
/// As [`read_text`] and [`read_path`].
unsafe fn text_source<'a>(text: *const c_char, length: usize, mesh_dir: *const c_char) -> Result<Source<'a>, FfiError> {
    // SAFETY: caller's contract.
    let text = unsafe { read_text(text, length) }?;
    let mesh_dir = if mesh_dir.is_null() {
        Path::new(".")
    } else {
        // SAFETY: caller's contract.
        unsafe { read_path(mesh_dir, "mesh_dir") }?
    };
    Ok(Source::Text { text, mesh_dir })
}

/// A finalized tree handle holding `urdf`'s tree and names.
fn tree_handle(urdf: UrdfTree) -> mech_tree_t {
    let names = Arc::new(UrdfNames::of(&urdf));
    let workspace = urdf.tree.workspace();
    mech_tree_t {
        builder: TreeBuilder::new(),
        built: Some((urdf.tree, workspace)),
        mass_cache: None,
        names: Some(names),
    }
}

/// A mechanism handle of `urdf`: link masses, gravity −9.81 m/s² along the base z axis, and
/// the joint limits.
fn mechanism_handle(urdf: UrdfTree) -> Result<mech_mechanism_t, FfiError> {
    let names = Arc::new(UrdfNames::of(&urdf));
    let mut mechanism = Mechanism::new(urdf.tree, urdf.masses)?;
    mechanism.set_gravity(Vector3::new(0.0, 0.0, -9.81))?;
    for (k, limit) in urdf.limits.iter().enumerate() {
        if let Some([lower, upper]) = limit {
            mechanism.set_limits(k, *lower, *upper).map_err(|e| {
                let e = FfiError::from(e);
                FfiError::new(
                    e.status,
                    format!("coordinate \"{}\": {}", names.coordinates[k], e.message),
                )
            })?;
        }
    }
    Ok(mech_mechanism_t {
        mechanism,
        names: Some(names),
    })
}

/// Reads a robot from the URDF file at `path` (NUL-terminated, UTF-8) into a finalized tree
/// and writes its handle to `*tree_out` (freed with mech_tree_destroy). Body b is link b of
/// the file (file order); the root link hangs on the base frame by a fixed joint at the
/// identity, every other link on its parent by its joint: revolute and continuous → revolute,
/// prismatic, fixed, floating → free, spherical, planar (normal along the joint's z only);
/// the joint frame sits at `<origin xyz rpy>` (R = R_z(yaw) R_y(pitch) R_x(roll)) in the parent
/// link frame and is the child link's frame at q = 0. Mesh references (for links without
/// `<inertial>`) are resolved next to the file. mech_tree_link_name, mech_tree_joint_name and
/// mech_tree_coordinate_name give the names. `options` may be NULL (the defaults).
///
/// Errors (mech_last_error names the file, and the link or joint and field): MECH_STATUS_IO_ERROR
/// when the file or a needed mesh cannot be read; MECH_STATUS_BAD_DIMENSION for a file longer
/// than MECH_URDF_MAX_BYTES; MECH_STATUS_PARSE_ERROR when it is not a URDF robot;
/// MECH_STATUS_NON_FINITE for a NaN or infinite joint origin; MECH_STATUS_INVALID_ARGUMENT for
/// an invalid inertia, an unusable axis, a joint naming no link, not exactly one root link, a
/// cycle, a path that is not UTF-8 or an option flag other than 0 and 1.
///
/// # Safety
/// `path` must be a NUL-terminated string, `options` NULL or readable, `tree_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_from_urdf(
    path: *const c_char,
    options: *const mech_urdf_options_t,
    tree_out: *mut *mut mech_tree_t,
) -> mech_status_t {
    boundary(|| {
        let out = Out::new(tree_out, "tree_out")?;
        // SAFETY: caller's contract.
        let (path, options) = unsafe { (read_path(path, "path")?, read_options(options)?) };
        let handle = tree_handle(Source::File(path).tree(options)?);
        // SAFETY: caller's contract.
        unsafe { out.write(handle.into_raw()) };
        Ok(())
    })
}

/// As mech_tree_from_urdf, from the URDF text `text` of `length` bytes (UTF-8, no NUL needed,
/// at most MECH_URDF_MAX_BYTES). Mesh file names, with `package://` and `file://` stripped,
/// are looked for in the directory `mesh_dir` (NUL-terminated; NULL: the working directory),
/// then relative to the working directory, and a `package://PKG/…` name also under the
/// package's directory among the ancestors of `mesh_dir` and in `ROS_PACKAGE_PATH`
/// (docs/c-abi.md, "Mesh paths").
///
/// Errors: as mech_tree_from_urdf; MECH_STATUS_PARSE_ERROR also for a text that is not UTF-8.
///
/// # Safety
/// `text` must point to `length` readable bytes, `mesh_dir` be NULL or a NUL-terminated
/// string, `options` NULL or readable, `tree_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_from_urdf_string(
    text: *const c_char,
    length: usize,
    mesh_dir: *const c_char,
    options: *const mech_urdf_options_t,
    tree_out: *mut *mut mech_tree_t,
) -> mech_status_t {
    boundary(|| {
        let out = Out::new(tree_out, "tree_out")?;
        // SAFETY: caller's contract.
        let (source, options) = unsafe { (text_source(text, length, mesh_dir)?, read_options(options)?) };
        let handle = tree_handle(source.tree(options)?);
        // SAFETY: caller's contract.
        unsafe { out.write(handle.into_raw()) };
        Ok(())
    })
}

/// Reads a robot from the URDF file at `path` into a mechanism and writes its handle to
/// `*mechanism_out` (freed with mech_mechanism_destroy): the tree of mech_tree_from_urdf, each
/// body with its link's mass properties (`<inertial>`: centre of mass at the inertial origin,
/// the tensor rotated by its rpy into the link frame; a link without one takes its collision
/// (else visual) STL or OBJ mesh at 1000 kg/m³, or is a massless frame when it has no mesh),
/// gravity −9.81 m/s² along the base frame's z axis, and the finite limits (lower < upper) of
/// revolute and prismatic joints as coordinate limits. Every link's tensor is checked for
/// symmetry, semidefiniteness and the triangle inequality; all invalid links are named in one
/// message. `options` may be NULL (the defaults). mech_mechanism_link_name and
/// mech_mechanism_coordinate_name give the names.
///
/// Errors: as mech_tree_from_urdf.
///
/// # Safety
/// `path` must be a NUL-terminated string, `options` NULL or readable, `mechanism_out`
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_from_urdf(
    path: *const c_char,
    options: *const mech_urdf_options_t,
    mechanism_out: *mut *mut mech_mechanism_t,
) -> mech_status_t {
    boundary(|| {
        let out = Out::new(mechanism_out, "mechanism_out")?;
        // SAFETY: caller's contract.
        let (path, options) = unsafe { (read_path(path, "path")?, read_options(options)?) };
        let handle = mechanism_handle(Source::File(path).tree(options)?)?;
        // SAFETY: caller's contract.
        unsafe { out.write(handle.into_raw()) };
        Ok(())
    })
}

/// As mech_mechanism_from_urdf, from the URDF text `text` of `length` bytes with meshes looked
/// for in `mesh_dir` (see mech_tree_from_urdf_string).
///
/// Errors: as mech_tree_from_urdf_string.
///
/// # Safety
/// `text` must point to `length` readable bytes, `mesh_dir` be NULL or a NUL-terminated
/// string, `options` NULL or readable, `mechanism_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_from_urdf_string(
    text: *const c_char,
    length: usize,
    mesh_dir: *const c_char,
    options: *const mech_urdf_options_t,
    mechanism_out: *mut *mut mech_mechanism_t,
) -> mech_status_t {
    boundary(|| {
        let out = Out::new(mechanism_out, "mechanism_out")?;
        // SAFETY: caller's contract.
        let (source, options) = unsafe { (text_source(text, length, mesh_dir)?, read_options(options)?) };
        let handle = mechanism_handle(source.tree(options)?)?;
        // SAFETY: caller's contract.
        unsafe { out.write(handle.into_raw()) };
        Ok(())
    })
}
