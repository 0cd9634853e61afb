//! Plain-data `#[repr(C)]` 3-D values shared by all capability modules. Their conversions to
//! nalgebra live in `spatial`.

/// A 3-vector of doubles (x, y, z). Its frame is stated by each function that uses it.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_vec3_t {
    /// x component.
    pub x: f64,
    /// y component.
    pub y: f64,
    /// z component.
    pub z: f64,
}

/// A 3×3 matrix of doubles in column-major order: m[row + 3*col].
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_mat3_t {
    /// The nine entries, column-major.
    pub m: [f64; 9],
}

/// A unit quaternion w + x i + y j + z k (scalar first), representing a rotation.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_quat_t {
    /// Scalar part.
    pub w: f64,
    /// i component.
    pub x: f64,
    /// j component.
    pub y: f64,
    /// k component.
    pub z: f64,
}
