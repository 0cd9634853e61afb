//! `modes --plot DIR`: the mode shapes of a pencil read from Matrix Market files, which has no
//! mechanism to draw them on: each of the first six modes as its displacement x_i against the
//! coordinate index i = 1 … n (integer ticks), scaled so that the largest |x_i| is 1, with the
//! coordinate where it lies and the mode's ω² and bound in the caption.

use mechanica_svg::{Anchor, Color, INK, Svg, fitted_size, tick_label, ticks};
use std::path::Path;

/// The most modes drawn.
pub const MAX_MODES: usize = 6;
const PANEL_W: f64 = 500.0;
const PANEL_H: f64 = 300.0;
const HEADER: f64 = 40.0;
/// Plot box within a panel: left, top, right, bottom margins.
const MARGIN: (f64, f64, f64, f64) = (56.0, 34.0, 18.0, 64.0);
const LINE: Color = Color(31, 119, 180);

/// One mode to draw: its number (1-based), ω², bound and shape (one value per coordinate).
#[derive(Debug, Clone)]
pub struct PencilShape {
    /// The mode's number in the report, from 1.
    pub number: usize,
    /// ω² (None for an infinite mode).
    pub omega_sq: Option<f64>,
    /// |ω²_computed − ω²_exact| ≤ bound.
    pub bound: f64,
    /// x, one value per coordinate.
    pub shape: Vec<f64>,
}

/// Integer ticks 1 … n: a step 1, 2 or 5 × 10^k, never below 1.
fn index_ticks(n: usize) -> (Vec<f64>, f64) {
    let (values, step) = ticks(1.0, n.max(2) as f64, 8);
    if step >= 1.0 {
        let mut values: Vec<f64> = values.into_iter().filter(|v| *v >= 1.0).collect();
        if values.first() != Some(&1.0) {
            values.insert(0, 1.0);
        }
        (values, step)
    } else {
        ((1..=n.max(1)).map(|i| i as f64).collect(), 1.0)
    }
}

/// The pixel of (index i, scaled displacement v ∈ [−1, 1]) in the panel at (x0, y0).
fn pixel(n: usize, (x0, y0): (f64, f64), i: f64, v: f64) -> (f64, f64) {
    let (w, h) = (PANEL_W - MARGIN.0 - MARGIN.2, PANEL_H - MARGIN.1 - MARGIN.3);
    let u = if n > 1 { (i - 1.0) / (n - 1) as f64 } else { 0.5 };
    (x0 + MARGIN.0 + u * w, y0 + MARGIN.1 + (1.0 - (v + 1.1) / 2.2) * h)
}

/// One mode's panel.
fn draw_panel(svg: &mut Svg, mode: &PencilShape, at: (f64, f64)) {
    let n = mode.shape.len();
    let (largest_at, largest) =
        mode.shape.iter().enumerate().fold(
            (0, 0.0_f64),
            |(k, m), (i, v)| if v.abs() > m { (i, v.abs()) } else { (k, m) },
        );
    let scale = if largest > 0.0 { 1.0 / largest } else { 0.0 };
    svg.open_group("panel", &[("data-mode", &mode.number.to_string())]);
    let omega = match mode.omega_sq {
        Some(w) => format!(
            "ω² = {} ± {}",
            crate::report::text::number(w, 6),
            crate::report::text::bound(mode.bound)
        ),
        None => "infinite mode (no mass in its direction)".into(),
    };
    let title = format!("mode {}: {omega}", mode.number);
    svg.text(
        "title",
        (at.0 + 10.0, at.1 + 20.0),
        &title,
        fitted_size(&title, PANEL_W - 20.0, 14.0),
        Anchor::Start,
    );
    let (bottom, top) = (pixel(n, at, 1.0, -1.1).1, pixel(n, at, 1.0, 1.1).1);
    let (left, right) = (at.0 + MARGIN.0, at.0 + PANEL_W - MARGIN.2);
    let (values, step) = index_ticks(n);
    for &i in &values {
        let (x, _) = pixel(n, at, i, 0.0);
        svg.line("tick", (x, bottom), (x, bottom + 4.0), INK, 1.0, false);
        svg.text(
            "tick-label",
            (x, bottom + 16.0),
            &tick_label(i, step),
            11.0,
            Anchor::Middle,
        );
    }
    for v in [-1.0, -0.5, 0.0, 0.5, 1.0] {
        let (_, y) = pixel(n, at, 1.0, v);
        svg.line("grid", (left, y), (right, y), Color(225, 225, 225), 1.0, v != 0.0);
        svg.text(
            "tick-label",
            (left - 6.0, y + 4.0),
            &tick_label(v, 0.5),
            11.0,
            Anchor::End,
        );
    }
    svg.line("axis", (left, bottom), (right, bottom), INK, 1.0, false);
    svg.line("axis", (left, top), (left, bottom), INK, 1.0, false);
    svg.text(
        "axis-label",
        ((left + right) / 2.0, bottom + 32.0),
        "coordinate index i",
        12.0,
        Anchor::Middle,
    );
    svg.vertical_text("axis-label", (left - 40.0, (top + bottom) / 2.0), "x_i (scaled)", 12.0);
    let points: Vec<(f64, f64)> = mode
        .shape
        .iter()
        .enumerate()
        .map(|(i, v)| pixel(n, at, (i + 1) as f64, v * scale))
        .collect();
    for pair in points.windows(2) {
        svg.line("shape", pair[0], pair[1], LINE, 1.8, false);
    }
    if n <= 60 {
        for p in &points {
            svg.circle("shape-point", *p, 2.5, LINE, Some(LINE));
        }
    }
    let caption = format!(
        "scaled so that the largest |x_i| is 1: coordinate {} (|x| = {} in A-normalised units)",
        largest_at + 1,
        crate::report::text::number(largest, 4)
    );
    let size = fitted_size(&caption, PANEL_W - 20.0, 11.0);
    svg.text("caption", (at.0 + 10.0, bottom + 52.0), &caption, size, Anchor::Start);
    svg.close_group();
}

/// The SVG text of the first [`MAX_MODES`] modes of `modes`, two panels a row.
pub fn svg_text(modes: &[PencilShape]) -> String {
    let drawn = &modes[..modes.len().min(MAX_MODES)];
    let rows = drawn.len().div_ceil(2).max(1);
    let width = 2.0 * PANEL_W;
    let mut svg = Svg::new(width, HEADER + rows as f64 * PANEL_H);
    let title = "mode shapes of the pencil: displacement x_i against coordinate index i";
    svg.text(
        "figure-title",
        (12.0, 26.0),
        title,
        fitted_size(title, width - 24.0, 16.0),
        Anchor::Start,
    );
    for (k, mode) in drawn.iter().enumerate() {
        let at = (PANEL_W * (k % 2) as f64, HEADER + PANEL_H * (k / 2) as f64);
        draw_panel(&mut svg, mode, at);
    }
    svg.finish()
}

/// Writes [`svg_text`] to `path`.
pub fn write(modes: &[PencilShape], path: &Path) -> Result<(), String> {
    std::fs::write(path, svg_text(modes)).map_err(|e| format!("plot {}: {e}", path.display()))
}
