//! Plain-data `#[repr(C)]` values shared by all capability modules.

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

#[cfg(feature = "kinematics")]
mod nalgebra_seam {
    //! Conversions between the C values and nalgebra, used only at the C boundary.
    use super::*;
    use mechanica_kinematics::nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

    impl From<mech_vec3_t> for Vector3<f64> {
        fn from(v: mech_vec3_t) -> Self {
            Vector3::new(v.x, v.y, v.z)
        }
    }
    impl From<Vector3<f64>> for mech_vec3_t {
        fn from(v: Vector3<f64>) -> Self {
            mech_vec3_t { x: v.x, y: v.y, z: v.z }
        }
    }
    impl From<mech_mat3_t> for Matrix3<f64> {
        fn from(m: mech_mat3_t) -> Self {
            Matrix3::from_column_slice(&m.m)
        }
    }
    impl From<Matrix3<f64>> for mech_mat3_t {
        fn from(m: Matrix3<f64>) -> Self {
            let mut out = mech_mat3_t::default();
            out.m.copy_from_slice(m.as_slice());
            out
        }
    }
    impl From<mech_quat_t> for Quaternion<f64> {
        fn from(q: mech_quat_t) -> Self {
            Quaternion::new(q.w, q.x, q.y, q.z)
        }
    }
    impl From<UnitQuaternion<f64>> for mech_quat_t {
        fn from(q: UnitQuaternion<f64>) -> Self {
            mech_quat_t {
                w: q.w,
                x: q.i,
                y: q.j,
                z: q.k,
            }
        }
    }
}
