//! The C record of one mode: its eigenvalue, frequency or growth rate, error bound,
//! classification and group of equal frequencies.

use mechanica_modal::{Mode, ModeGroup, ModeKind};

/// Classification of a mode (int32_t; see MECH_MODAL_KIND_*).
pub type mech_modal_kind_t = i32;
/// λ < 0: oscillates at ω = √(−λ) rad/s.
pub const MECH_MODAL_KIND_OSCILLATORY: mech_modal_kind_t = 0;
/// |λ| within the data's resolution: rigid-body (zero-frequency) mode.
pub const MECH_MODAL_KIND_ZERO: mech_modal_kind_t = 1;
/// λ > 0: unstable equilibrium, growth rate √λ (1/s).
pub const MECH_MODAL_KIND_UNSTABLE: mech_modal_kind_t = 2;
/// Massless direction (A x = 0): infinite frequency.
pub const MECH_MODAL_KIND_INFINITE: mech_modal_kind_t = 3;
/// The interval omega_sq ± error_bound contains zero and is far wider than the data's
/// resolution: neither the sign nor the size of ω² is known (rate 0).
pub const MECH_MODAL_KIND_UNDECIDED: mech_modal_kind_t = 4;

/// Scalar data of one mode.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_modal_mode_t {
    /// λ of det(λA + B) = 0 (= −ω²); −HUGE_VAL for an infinite mode.
    pub lambda: f64,
    /// ω² = −λ (rad²/s²); +HUGE_VAL for an infinite mode.
    pub omega_sq: f64,
    /// ω (rad/s) for an oscillatory mode, the growth rate √λ (1/s) for an unstable one, 0 for a
    /// zero or undecided mode, +HUGE_VAL for an infinite one.
    pub rate: f64,
    /// Bound on |ω²_computed − ω²_exact|.
    pub error_bound: f64,
    /// Backward error η of the pair, or −1 when not available (values only, infinite mode).
    pub backward_error: f64,
    /// A MECH_MODAL_KIND_* value.
    pub kind: mech_modal_kind_t,
    /// Index of the mode's group of equal frequencies (modes of a group are consecutive).
    pub group: usize,
    /// Multiplicity of that group.
    pub multiplicity: usize,
}

/// The C kind of a mode and its rate (ω, growth rate, 0 or +∞).
pub(crate) fn kind_to_c(kind: ModeKind) -> (mech_modal_kind_t, f64) {
    match kind {
        ModeKind::Oscillatory { omega } => (MECH_MODAL_KIND_OSCILLATORY, omega),
        ModeKind::Zero => (MECH_MODAL_KIND_ZERO, 0.0),
        ModeKind::Unstable { growth_rate } => (MECH_MODAL_KIND_UNSTABLE, growth_rate),
        ModeKind::Infinite => (MECH_MODAL_KIND_INFINITE, f64::INFINITY),
        ModeKind::Undecided => (MECH_MODAL_KIND_UNDECIDED, 0.0),
    }
}

/// The C record of a mode, with its group's multiplicity from `groups`.
pub(super) fn mode_to_c(m: &Mode, groups: &[ModeGroup]) -> mech_modal_mode_t {
    let (kind, rate) = kind_to_c(m.kind);
    mech_modal_mode_t {
        lambda: m.lambda,
        omega_sq: m.omega_sq,
        rate,
        error_bound: m.error_bound,
        backward_error: m.backward_error.unwrap_or(-1.0),
        kind,
        group: m.group,
        multiplicity: groups.get(m.group).map_or(1, |g| g.multiplicity),
    }
}
