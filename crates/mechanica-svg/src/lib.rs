//! Drawing for mechanica's pictures: a minimal SVG writer ([`Svg`]), axis ticks for linear and
//! logarithmic axes with clean labels ([`ticks`], [`log_ticks`]), and the number formatting
//! they share with the CLI's text report ([`number`]). The CLI's `--plot` pictures and the
//! benches' work-precision diagrams both draw with it; it depends on nothing.

mod document;
mod number;
mod ticks;

pub use document::{Anchor, Color, INK, Svg, fitted_size, text_width};
pub use number::{MAX_DIGITS, number};
pub use ticks::{log_ticks, power_of_ten, tick_label, ticks};
