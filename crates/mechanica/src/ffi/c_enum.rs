//! Enums that C passes as plain `int32_t` values: the [`CEnum`] conversion into a Rust enum,
//! [`enum_value`] that turns an unknown value into MECH_STATUS_BAD_ENUM, and the
//! [`c_enum!`](crate::ffi::c_enum::c_enum) macro that writes the conversion from a table of
//! `MECH_*` constants.

use super::boundary::FfiError;
use super::status::MECH_STATUS_BAD_ENUM;

/// A Rust enum that C passes as a plain integer (never as the Rust enum itself).
pub(crate) trait CEnum: Sized {
    /// The enum value of a C integer, or None for an integer that names no value.
    fn from_c(raw: i32) -> Option<Self>;
}

/// Converts a C enum integer into its Rust enum, failing with BAD_ENUM for unknown values.
pub(crate) fn enum_value<E: CEnum>(raw: i32, what: &str) -> Result<E, FfiError> {
    E::from_c(raw).ok_or_else(|| FfiError::new(MECH_STATUS_BAD_ENUM, format!("{what}: unknown value {raw}")))
}

/// Implements [`CEnum`] for a Rust enum from a table `MECH_CONSTANT => RustEnum::Variant, ...`;
/// every other integer names no value. The constants stay written out in the source, where
/// cbindgen reads them into the header.
macro_rules! c_enum {
    ($rust:ty, $($c:ident => $v:expr),+ $(,)?) => {
        impl $crate::ffi::c_enum::CEnum for $rust {
            fn from_c(raw: i32) -> Option<Self> {
                match raw {
                    $($c => Some($v),)+
                    _ => None,
                }
            }
        }
    };
}
pub(crate) use c_enum;

#[cfg(test)]
mod tests {
    use super::*;

    const ONLY_SEVEN: i32 = 7;
    #[derive(Debug)]
    struct Only7;
    c_enum!(Only7, ONLY_SEVEN => Only7);

    #[test]
    fn known_values_convert_and_unknown_ones_are_bad_enums() {
        assert!(enum_value::<Only7>(7, "mode").is_ok());
        assert_eq!(
            enum_value::<Only7>(-3, "mode").map(|_| ()).map_err(|e| e.status),
            Err(MECH_STATUS_BAD_ENUM)
        );
    }
}
