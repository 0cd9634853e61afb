//! Work-precision diagrams: error against run time on log-log axes, one panel per problem
//! family, one series per method whose points are joined in the order of the problem size or
//! tolerance (never across families), and the error bound a method reports drawn dashed, in the
//! same colour, beside its true error. An error of exactly zero has no place on a log axis: it is
//! drawn as a hollow square on a marked floor at u/2 = 2⁻⁵³, and the legend says so. Ticks are
//! powers of ten labelled 10⁻¹², 10⁻⁸, … ([`mechanica_svg::log_ticks`]).

use mechanica_svg::{Anchor, Color, INK, Svg, fitted_size, log_ticks, power_of_ten};
use std::path::PathBuf;

/// Where an error of exactly zero is drawn: u/2, half the unit roundoff of double precision.
pub const ZERO_FLOOR: f64 = f64::EPSILON / 2.0;

/// One measurement: the problem's size or tolerance (the order the series follows), the run
/// time in seconds, and the error (≥ 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorkPoint {
    /// Problem size or tolerance: the points of a series are joined in increasing order of it.
    pub order: f64,
    /// Run time, s (> 0 to be drawn).
    pub seconds: f64,
    /// The error; exactly 0 is drawn at [`ZERO_FLOOR`].
    pub error: f64,
}

/// One method within one family.
#[derive(Debug, Clone, Default)]
pub struct Series {
    /// The method (legend label; the same label has the same colour in every panel).
    pub label: String,
    /// Its true errors.
    pub points: Vec<WorkPoint>,
    /// The error bounds it reported for the same runs (empty when it reports none).
    pub bound: Vec<WorkPoint>,
}

/// One problem family.
#[derive(Debug, Clone, Default)]
pub struct Panel {
    /// The family.
    pub title: String,
    /// One series per method.
    pub series: Vec<Series>,
}

const PANEL_WIDTH: f64 = 560.0;
const PANEL_HEIGHT: f64 = 380.0;
const HEADER: f64 = 44.0;
const LEGEND_ROW: f64 = 18.0;
/// Plot box within a panel: left, top, right, bottom margins.
const MARGIN: (f64, f64, f64, f64) = (70.0, 34.0, 16.0, 46.0);
const PALETTE: [Color; 10] = [
    Color(31, 119, 180),
    Color(214, 39, 40),
    Color(44, 160, 44),
    Color(255, 127, 14),
    Color(148, 103, 189),
    Color(140, 86, 75),
    Color(227, 119, 194),
    Color(23, 190, 207),
    Color(188, 189, 34),
    Color(127, 127, 127),
];

/// The error as drawn: exactly zero is lifted to the floor.
fn drawn_error(error: f64) -> f64 {
    if error == 0.0 { ZERO_FLOOR } else { error }
}

/// The points that can be drawn (positive time, finite non-negative error), in increasing
/// order of their size or tolerance.
fn ordered(points: &[WorkPoint]) -> Vec<WorkPoint> {
    let mut kept: Vec<WorkPoint> = points
        .iter()
        .copied()
        .filter(|p| p.seconds > 0.0 && p.seconds.is_finite() && p.error >= 0.0 && p.error.is_finite())
        .collect();
    kept.sort_by(|a, b| a.order.total_cmp(&b.order));
    kept
}

/// A log-log frame: the axes' decades and the plot box in pixels.
struct Frame {
    x: (f64, f64),
    y: (f64, f64),
    x_ticks: Vec<i32>,
    y_ticks: Vec<i32>,
    left: f64,
    top: f64,
    width: f64,
    height: f64,
}

impl Frame {
    /// The frame of a panel at (`x0`, `y0`) holding every drawable point of `panel`.
    fn new(panel: &Panel, x0: f64, y0: f64) -> Option<Frame> {
        let points: Vec<WorkPoint> = panel
            .series
            .iter()
            .flat_map(|s| ordered(&s.points).into_iter().chain(ordered(&s.bound)))
            .collect();
        let span = |values: Vec<f64>| {
            let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = values.iter().copied().fold(0.0, f64::max);
            (lo <= hi).then_some((lo, hi))
        };
        let (t_lo, t_hi) = span(points.iter().map(|p| p.seconds).collect())?;
        let (e_lo, e_hi) = span(points.iter().map(|p| drawn_error(p.error)).collect())?;
        let axis = |lo: f64, hi: f64| {
            let ticks = log_ticks(lo, hi, 7);
            let first = ticks.first().map_or(lo.log10(), |&e| f64::from(e));
            let last = ticks.last().map_or(hi.log10(), |&e| f64::from(e));
            let range = (lo.log10().min(first) - 0.15, hi.log10().max(last) + 0.15);
            (range, ticks)
        };
        let (x, x_ticks) = axis(t_lo, t_hi);
        let (y, y_ticks) = axis(e_lo, e_hi);
        Some(Frame {
            x,
            y,
            x_ticks,
            y_ticks,
            left: x0 + MARGIN.0,
            top: y0 + MARGIN.1,
            width: PANEL_WIDTH - MARGIN.0 - MARGIN.2,
            height: PANEL_HEIGHT - MARGIN.1 - MARGIN.3,
        })
    }

    /// The pixel of (seconds, error).
    fn pixel(&self, seconds: f64, error: f64) -> (f64, f64) {
        let u = (seconds.log10() - self.x.0) / (self.x.1 - self.x.0);
        let v = (drawn_error(error).log10() - self.y.0) / (self.y.1 - self.y.0);
        (self.left + u * self.width, self.top + (1.0 - v) * self.height)
    }

    fn draw_axes(&self, svg: &mut Svg, y_label: &str) {
        let grid = Color(225, 225, 225);
        let (right, bottom) = (self.left + self.width, self.top + self.height);
        for &e in &self.x_ticks {
            let (x, _) = self.pixel(10f64.powi(e), 1.0);
            svg.line("grid", (x, self.top), (x, bottom), grid, 1.0, false);
            svg.text("tick-label", (x, bottom + 16.0), &power_of_ten(e), 11.0, Anchor::Middle);
        }
        for &e in &self.y_ticks {
            let (_, y) = self.pixel(1.0, 10f64.powi(e));
            svg.line("grid", (self.left, y), (right, y), grid, 1.0, false);
            svg.text(
                "tick-label",
                (self.left - 6.0, y + 4.0),
                &power_of_ten(e),
                11.0,
                Anchor::End,
            );
        }
        svg.line("axis", (self.left, bottom), (right, bottom), INK, 1.0, false);
        svg.line("axis", (self.left, self.top), (self.left, bottom), INK, 1.0, false);
        let x_title = "run time (s)";
        svg.text(
            "axis-label",
            (self.left + self.width / 2.0, bottom + 36.0),
            x_title,
            12.0,
            Anchor::Middle,
        );
        svg.vertical_text(
            "axis-label",
            (self.left - 52.0, self.top + self.height / 2.0),
            y_label,
            12.0,
        );
    }
}

/// The colour of `label`: by its first appearance over all panels.
fn colour_of(labels: &[String], label: &str) -> Color {
    let k = labels.iter().position(|l| l == label).unwrap_or(0);
    PALETTE[k % PALETTE.len()]
}

/// One series (or its bound, `dashed`) joined in order, with its markers.
fn draw_series(svg: &mut Svg, frame: &Frame, points: &[WorkPoint], colour: Color, dashed: bool) {
    let points = ordered(points);
    for pair in points.windows(2) {
        let (a, b) = (
            frame.pixel(pair[0].seconds, pair[0].error),
            frame.pixel(pair[1].seconds, pair[1].error),
        );
        svg.line(if dashed { "bound" } else { "error" }, a, b, colour, 1.8, dashed);
    }
    for p in &points {
        let at = frame.pixel(p.seconds, p.error);
        if p.error == 0.0 {
            svg.open_group("zero", &[]);
            for (a, b) in [
                ((-4.0, -4.0), (4.0, -4.0)),
                ((4.0, -4.0), (4.0, 4.0)),
                ((4.0, 4.0), (-4.0, 4.0)),
                ((-4.0, 4.0), (-4.0, -4.0)),
            ] {
                svg.line(
                    "zero-marker",
                    (at.0 + a.0, at.1 + a.1),
                    (at.0 + b.0, at.1 + b.1),
                    colour,
                    1.5,
                    false,
                );
            }
            svg.close_group();
        } else if dashed {
            svg.circle("bound-marker", at, 2.5, colour, None);
        } else {
            svg.circle("error-marker", at, 3.0, colour, Some(colour));
        }
    }
}

/// One panel at (`x0`, `y0`).
fn draw_panel(svg: &mut Svg, panel: &Panel, labels: &[String], y_label: &str, (x0, y0): (f64, f64)) {
    svg.open_group("panel", &[("data-title", &panel.title)]);
    let size = fitted_size(&panel.title, PANEL_WIDTH - 20.0, 14.0);
    svg.text("panel-title", (x0 + 10.0, y0 + 20.0), &panel.title, size, Anchor::Start);
    let Some(frame) = Frame::new(panel, x0, y0) else {
        svg.text(
            "empty",
            (x0 + PANEL_WIDTH / 2.0, y0 + PANEL_HEIGHT / 2.0),
            "no point to draw",
            12.0,
            Anchor::Middle,
        );
        svg.close_group();
        return;
    };
    frame.draw_axes(svg, y_label);
    let has_zero = panel
        .series
        .iter()
        .any(|s| s.points.iter().chain(&s.bound).any(|p| p.error == 0.0));
    if has_zero {
        let (_, y) = frame.pixel(1.0, ZERO_FLOOR);
        let right = frame.left + frame.width;
        svg.line(
            "zero-floor",
            (frame.left, y),
            (right, y),
            Color(120, 120, 120),
            1.0,
            true,
        );
        svg.text(
            "zero-floor-label",
            (right - 4.0, y - 4.0),
            "u/2: error 0",
            10.0,
            Anchor::End,
        );
    }
    for series in &panel.series {
        svg.open_group("series", &[("data-label", &series.label)]);
        let colour = colour_of(labels, &series.label);
        draw_series(svg, &frame, &series.points, colour, false);
        draw_series(svg, &frame, &series.bound, colour, true);
        svg.close_group();
    }
    svg.close_group();
}

/// The legend entries: each method, its bound when it reports one, and the zero note.
fn legend_entries(panels: &[Panel], labels: &[String]) -> Vec<(String, Option<(Color, bool)>)> {
    let mut entries = Vec::new();
    for label in labels {
        let colour = colour_of(labels, label);
        entries.push((label.clone(), Some((colour, false))));
        let bounded = panels
            .iter()
            .flat_map(|p| &p.series)
            .any(|s| &s.label == label && !s.bound.is_empty());
        if bounded {
            entries.push((format!("{label}: reported bound"), Some((colour, true))));
        }
    }
    let zero = panels
        .iter()
        .flat_map(|p| &p.series)
        .any(|s| s.points.iter().chain(&s.bound).any(|p| p.error == 0.0));
    if zero {
        entries.push((
            format!("□ hollow square: error exactly 0, drawn at u/2 = {ZERO_FLOOR:.1e} (dashed grey line)"),
            None,
        ));
    }
    entries
}

/// The SVG text of a work-precision diagram: `title` above, the panels two a row, the legend
/// below; `y_label` names the error.
pub fn work_precision_svg(title: &str, y_label: &str, panels: &[Panel]) -> String {
    let mut labels: Vec<String> = Vec::new();
    for s in panels.iter().flat_map(|p| &p.series) {
        if !labels.contains(&s.label) {
            labels.push(s.label.clone());
        }
    }
    let columns = panels.len().clamp(1, 2);
    let rows = panels.len().div_ceil(2).max(1);
    let width = PANEL_WIDTH * columns as f64;
    let entries = legend_entries(panels, &labels);
    let legend_columns = if columns == 2 { 2 } else { 1 };
    let legend_rows = entries.len().div_ceil(legend_columns);
    let height = HEADER + PANEL_HEIGHT * rows as f64 + LEGEND_ROW * legend_rows as f64 + 16.0;
    let mut svg = Svg::new(width, height);
    let size = fitted_size(title, width - 24.0, 16.0);
    svg.text("figure-title", (12.0, 28.0), title, size, Anchor::Start);
    for (k, panel) in panels.iter().enumerate() {
        let at = (PANEL_WIDTH * (k % 2) as f64, HEADER + PANEL_HEIGHT * (k / 2) as f64);
        draw_panel(&mut svg, panel, &labels, y_label, at);
    }
    let column_width = width / legend_columns as f64;
    for (k, (text, sample)) in entries.iter().enumerate() {
        let x = 12.0 + column_width * (k % legend_columns) as f64;
        let y = HEADER + PANEL_HEIGHT * rows as f64 + LEGEND_ROW * (k / legend_columns) as f64 + 10.0;
        let text_x = if let Some((colour, dashed)) = sample {
            svg.line("legend", (x, y - 4.0), (x + 22.0, y - 4.0), *colour, 1.8, *dashed);
            x + 28.0
        } else {
            x
        };
        let room = column_width - (text_x - x) - 16.0;
        svg.text(
            "legend-label",
            (text_x, y),
            text,
            fitted_size(text, room, 11.0),
            Anchor::Start,
        );
    }
    svg.finish()
}

/// Writes [`work_precision_svg`] to `target/reports/<name>.svg` and returns the path.
pub fn write_work_precision(name: &str, title: &str, y_label: &str, panels: &[Panel]) -> std::io::Result<PathBuf> {
    let path = crate::reports_dir()?.join(format!("{name}.svg"));
    std::fs::write(&path, work_precision_svg(title, y_label, panels))?;
    Ok(path)
}

#[cfg(test)]
mod tests;
