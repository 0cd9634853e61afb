//! `mode_shapes.svg`: each mode drawn on the mechanism, a stick figure at rest (grey) and
//! displaced along the mode (coloured by class): body origins (the joints) as rings, smaller
//! for fixed joints; links as lines from the parent's origin (the ground point for the root)
//! to the body's origin; dashed arms from a body's origin to its centre of mass, drawn as a
//! dot; and the ground marked by a hatched bar.
//!
//! Each panel is an orthographic view chosen for its mode: the plane spanned by the two
//! principal directions of the sum of the rest pose's spread about its mean and the second
//! moment of the mode's displacements (each normalised by its trace), so that a planar
//! mechanism is seen in its plane and a spatial one from where its motion shows most. One view
//! per mode keeps six modes legible where three views each (front, side, top) would not. The
//! picture is turned so that "up" (against gravity) points up when it lies near the plane, and
//! a triad shows the world axes. A motion too small to see at the mechanism's scale gets a
//! magnified detail, and a body whose turn limited the amplitude a mark ↻ (`detail`).

use crate::mode_record::ModeKindName;
use crate::mode_shape::{ModeFigure, ModeShapes, Pose, Skeleton};
use mechanica::kinematics::nalgebra::{Matrix3, Vector3};
use mechanica_svg::{Anchor, Color, Svg, fitted_size, tick_label, ticks};
use std::path::Path;

mod detail;

const WIDTH: f64 = 1000.0;
const HEADER: f64 = 56.0;
const PANEL_W: f64 = 500.0;
const PANEL_H: f64 = 440.0;
const TITLE_H: f64 = 50.0;
const CAPTION_H: f64 = 50.0;
const MARGIN: f64 = 24.0;
const REST: Color = Color(175, 175, 175);

/// The colour of a displaced figure of class `kind`.
pub fn color_of(kind: ModeKindName) -> Color {
    match kind {
        ModeKindName::Oscillatory => Color(31, 119, 180),
        ModeKindName::Unstable => Color(214, 39, 40),
        ModeKindName::Zero => Color(44, 160, 44),
        ModeKindName::Infinite | ModeKindName::Undecided => Color(255, 127, 14),
    }
}

/// An orthographic view: screen right and up as world unit vectors.
#[derive(Debug, Clone, Copy)]
struct View {
    right: Vector3<f64>,
    up: Vector3<f64>,
}

/// The second moment Σ v vᵀ of `vectors`, divided by its trace (zero for zero vectors).
fn normalised_moment(vectors: &[Vector3<f64>]) -> Matrix3<f64> {
    let moment: Matrix3<f64> = vectors.iter().map(|v| v * v.transpose()).sum();
    let trace = moment.trace();
    if trace > 0.0 && trace.is_finite() {
        moment / trace
    } else {
        Matrix3::zeros()
    }
}

/// The view of `figure` (see the module docs).
fn view_of(skeleton: &Skeleton, figure: &ModeFigure) -> View {
    let rest = &skeleton.rest;
    let mut points: Vec<Vector3<f64>> = rest.points().copied().chain([skeleton.base]).collect();
    let mean = points.iter().sum::<Vector3<f64>>() / points.len() as f64;
    points.iter_mut().for_each(|p| *p -= mean);
    let mut spread = normalised_moment(&points);
    if let Some(moved) = &figure.displaced {
        let displacements: Vec<Vector3<f64>> = moved.points().zip(rest.points()).map(|(a, b)| a - b).collect();
        spread += normalised_moment(&displacements);
    }
    let eigen = spread.symmetric_eigen();
    let order = |i: usize| eigen.eigenvalues[i];
    let smallest = (0..3).min_by(|&a, &b| order(a).total_cmp(&order(b))).unwrap_or(1);
    let largest = (0..3).max_by(|&a, &b| order(a).total_cmp(&order(b))).unwrap_or(2);
    let normal: Vector3<f64> = eigen.eigenvectors.column(smallest).into_owned();
    let in_plane = skeleton.up - normal * normal.dot(&skeleton.up);
    let up = if in_plane.norm() > 0.5 {
        in_plane.normalize()
    } else {
        eigen.eigenvectors.column(largest).into_owned()
    };
    let mut right = up.cross(&normal);
    let dominant = right
        .iter()
        .copied()
        .fold(0.0f64, |a, v| if v.abs() > a.abs() { v } else { a });
    if dominant < 0.0 {
        right = -right;
    }
    View { right, up }
}

/// World points to pixels in a panel: the view, then a uniform scale and offset; drawing is
/// limited to `clip` (two corners) when set.
#[derive(Debug, Clone, Copy)]
struct Frame {
    view: View,
    scale: f64,
    origin: (f64, f64),
    centre: (f64, f64),
    clip: Option<((f64, f64), (f64, f64))>,
}

impl Frame {
    /// Fits `points` into the box at (`x`, `y`) of size `w` × `h`, one scale for both axes.
    fn fitted(view: View, points: &[Vector3<f64>], x: f64, y: f64, w: f64, h: f64) -> Frame {
        let projected = points.iter().map(|p| (p.dot(&view.right), p.dot(&view.up)));
        let (lo, hi) = projected.fold(((f64::MAX, f64::MAX), (f64::MIN, f64::MIN)), |(lo, hi), (a, b)| {
            ((lo.0.min(a), lo.1.min(b)), (hi.0.max(a), hi.1.max(b)))
        });
        let (dx, dy) = (hi.0 - lo.0, hi.1 - lo.1);
        let size = dx.max(dy);
        let scale = if size > 0.0 {
            (w / dx.max(1e-9 * size)).min(h / dy.max(1e-9 * size))
        } else {
            1.0
        };
        Frame {
            view,
            scale,
            origin: (0.5 * (lo.0 + hi.0), 0.5 * (lo.1 + hi.1)),
            centre: (x + 0.5 * w, y + 0.5 * h),
            clip: None,
        }
    }

    fn px(&self, p: &Vector3<f64>) -> (f64, f64) {
        let (a, b) = (p.dot(&self.view.right), p.dot(&self.view.up));
        (
            self.centre.0 + self.scale * (a - self.origin.0),
            self.centre.1 - self.scale * (b - self.origin.1),
        )
    }

    /// The pixel of `p` when it lies inside the clip box (always without one).
    fn shown(&self, p: &Vector3<f64>) -> Option<(f64, f64)> {
        let at = self.px(p);
        match self.clip {
            Some((lo, hi)) if !(lo.0..=hi.0).contains(&at.0) || !(lo.1..=hi.1).contains(&at.1) => None,
            _ => Some(at),
        }
    }

    /// The part of the segment from `a` to `b` inside the clip box (Liang–Barsky), in pixels.
    fn segment(&self, a: &Vector3<f64>, b: &Vector3<f64>) -> Option<((f64, f64), (f64, f64))> {
        let (p, q) = (self.px(a), self.px(b));
        let Some((lo, hi)) = self.clip else {
            return Some((p, q));
        };
        let (dx, dy) = (q.0 - p.0, q.1 - p.1);
        let (mut enter, mut leave) = (0.0f64, 1.0f64);
        for (step, room) in [(-dx, p.0 - lo.0), (dx, hi.0 - p.0), (-dy, p.1 - lo.1), (dy, hi.1 - p.1)] {
            if step == 0.0 {
                if room < 0.0 {
                    return None;
                }
            } else if step < 0.0 {
                enter = enter.max(room / step);
            } else {
                leave = leave.min(room / step);
            }
        }
        let inside = (
            (p.0 + enter * dx, p.1 + enter * dy),
            (p.0 + leave * dx, p.1 + leave * dy),
        );
        (enter <= leave).then_some(inside)
    }
}

/// Draws `pose` as a stick figure; classes are prefixed by `role` ("rest" or "mode").
fn draw_pose(svg: &mut Svg, skeleton: &Skeleton, pose: &Pose, frame: &Frame, color: Color, role: &str) {
    let width = if role.ends_with("rest") { 2.5 } else { 2.0 };
    for (i, origin) in pose.origins.iter().enumerate() {
        let from = skeleton.parents[i].map_or(&skeleton.base, |p| &pose.origins[p]);
        if let Some((a, b)) = frame.segment(from, origin) {
            svg.line(&format!("{role}-link"), a, b, color, width, false);
        }
    }
    for (origin, centre) in pose.origins.iter().zip(&pose.centres) {
        if let Some((a, b)) = centre.and_then(|c| frame.segment(origin, &c)) {
            svg.line(&format!("{role}-arm"), a, b, color, 1.0, true);
        }
    }
    for at in pose.centres.iter().flatten().filter_map(|c| frame.shown(c)) {
        svg.circle(&format!("{role}-com"), at, 3.0, color, Some(color));
    }
    // Rings over the dots, so that a joint at a centre of mass shows both.
    for (i, origin) in pose.origins.iter().enumerate() {
        let r = if skeleton.moving[i] { 5.5 } else { 3.0 };
        if let Some(at) = frame.shown(origin) {
            svg.circle(&format!("{role}-joint"), at, r, color, None);
        }
    }
}

/// The ground mark: a bar with hatches under the base point.
fn draw_ground(svg: &mut Svg, at: (f64, f64)) {
    let ink = Color(60, 60, 60);
    svg.line("ground", (at.0 - 14.0, at.1), (at.0 + 14.0, at.1), ink, 2.0, false);
    for k in 0..4 {
        let x = at.0 - 12.0 + 8.0 * k as f64;
        svg.line("ground", (x, at.1), (x - 5.0, at.1 + 6.0), ink, 1.0, false);
    }
}

/// The world axes as seen in the view, at `at`.
fn draw_triad(svg: &mut Svg, view: &View, at: (f64, f64)) {
    let ink = Color(90, 90, 90);
    for (name, axis) in [("x", Vector3::x()), ("y", Vector3::y()), ("z", Vector3::z())] {
        let (a, b) = (axis.dot(&view.right), axis.dot(&view.up));
        if a.hypot(b) < 0.2 {
            continue;
        }
        let tip = (at.0 + 22.0 * a, at.1 - 22.0 * b);
        svg.line("axis", at, tip, ink, 1.2, false);
        svg.text(
            "axis-label",
            (tip.0 + 6.0 * a, tip.1 - 6.0 * b + 4.0),
            name,
            11.0,
            Anchor::Middle,
        );
    }
}

/// A scale bar of a round length at most a quarter of the panel, ending at `right_end`.
fn draw_scale_bar(svg: &mut Svg, frame: &Frame, right_end: (f64, f64)) {
    let metres = 0.25 * PANEL_W / frame.scale;
    let (_, step) = ticks(0.0, metres, 1);
    let length = if step > metres { step / 2.0 } else { step };
    let pixels = length * frame.scale;
    let ink = Color(60, 60, 60);
    let left = (right_end.0 - pixels, right_end.1);
    svg.line("scale-bar", left, right_end, ink, 2.0, false);
    let label = format!("{} m", tick_label(length, length));
    svg.text(
        "scale-label",
        (right_end.0 - 0.5 * pixels, right_end.1 + 13.0),
        &label,
        11.0,
        Anchor::Middle,
    );
}

/// One panel at (`x`, `y`).
fn draw_panel(svg: &mut Svg, shapes: &ModeShapes, figure: &ModeFigure, x: f64, y: f64) {
    let skeleton = &shapes.skeleton;
    let view = view_of(skeleton, figure);
    let mut points: Vec<Vector3<f64>> = skeleton.rest.points().copied().collect();
    points.push(skeleton.base);
    points.extend(figure.displaced.iter().flat_map(|p| p.points().copied()));
    let (w, h) = (PANEL_W - 2.0 * MARGIN, PANEL_H - TITLE_H - CAPTION_H - 2.0 * MARGIN);
    let frame = Frame::fitted(view, &points, x + MARGIN, y + TITLE_H + MARGIN, w, h);
    svg.open_group("panel", &[("data-mode", &figure.number.to_string())]);
    let [first, second] = &figure.heading;
    let room = PANEL_W - 20.0;
    svg.text(
        "title",
        (x + 10.0, y + 20.0),
        first,
        fitted_size(first, room, 15.0),
        Anchor::Start,
    );
    svg.text(
        "subtitle",
        (x + 10.0, y + 40.0),
        second,
        fitted_size(second, room, 12.0),
        Anchor::Start,
    );
    draw_ground(svg, frame.px(&skeleton.base));
    draw_pose(svg, skeleton, &skeleton.rest, &frame, REST, "rest");
    if let Some(moved) = &figure.displaced {
        draw_pose(svg, skeleton, moved, &frame, color_of(figure.kind), "mode");
        detail::draw(svg, skeleton, figure, moved, &frame, (x, y));
    }
    let bottom = y + PANEL_H - CAPTION_H;
    draw_triad(svg, &view, (x + 36.0, bottom - 30.0));
    draw_scale_bar(svg, &frame, (x + PANEL_W - 16.0, bottom - 16.0));
    let lines = caption(skeleton, figure);
    let size = lines.iter().map(|l| fitted_size(l, room, 11.0)).fold(11.0, f64::min);
    for (k, line) in lines.iter().enumerate() {
        let at = (x + 10.0, bottom + 13.0 + 14.0 * k as f64);
        svg.text("caption", at, line, size, Anchor::Start);
    }
    svg.close_group();
}

/// The panel's caption: the amplitude and how large the drawn motion is.
fn caption(skeleton: &Skeleton, figure: &ModeFigure) -> Vec<String> {
    let n = |v: f64| crate::report::text::number(v, 3);
    if figure.displaced.is_none() {
        let why = figure.note.as_deref().unwrap_or("no displaced shape");
        return vec![format!("rest pose only: {why}")];
    }
    let mut lines = vec![
        format!(
            "colour: the exact pose at q₀ + s·x with s = {} (x A-normalised)",
            n(figure.amplitude)
        ),
        format!(
            "largest displacement {} m{} = {} % of the mechanism's {} m extent",
            n(figure.largest),
            figure
                .moved_most
                .and_then(|b| skeleton.names.get(b))
                .map_or(String::new(), |name| format!(", of \"{name}\",")),
            n(100.0 * figure.largest / skeleton.extent),
            n(skeleton.extent)
        ),
    ];
    if let Some(body) = figure.turned_most.and_then(|b| skeleton.names.get(b)) {
        let limit = crate::mode_shape::MAX_ROTATION;
        lines.push(format!(
            "(s smaller: it keeps the turn of \"{body}\", marked ↻, to {limit} rad)"
        ));
    }
    lines
}

/// The header: what the colours and marks mean.
fn draw_header(svg: &mut Svg) {
    let title = "mode shapes: the mechanism at rest (grey) and displaced along each mode (coloured by class)";
    svg.text(
        "figure-title",
        (12.0, 22.0),
        title,
        fitted_size(title, WIDTH - 24.0, 16.0),
        Anchor::Start,
    );
    let y = 44.0;
    let mut x = 14.0;
    let ink = Color(80, 80, 80);
    svg.circle("legend", (x, y - 4.0), 5.5, ink, None);
    svg.text(
        "legend-label",
        (x + 10.0, y),
        "joint (body origin)",
        12.0,
        Anchor::Start,
    );
    x += 150.0;
    svg.circle("legend", (x, y - 4.0), 3.0, ink, Some(ink));
    svg.text("legend-label", (x + 10.0, y), "centre of mass", 12.0, Anchor::Start);
    x += 130.0;
    draw_ground(svg, (x + 12.0, y - 6.0));
    svg.text("legend-label", (x + 32.0, y), "ground", 12.0, Anchor::Start);
    x += 90.0;
    for kind in [
        ModeKindName::Oscillatory,
        ModeKindName::Zero,
        ModeKindName::Unstable,
        ModeKindName::Undecided,
    ] {
        svg.line("legend", (x, y - 4.0), (x + 18.0, y - 4.0), color_of(kind), 3.0, false);
        let name = if kind == ModeKindName::Undecided {
            "undecided / infinite"
        } else {
            kind.as_str()
        };
        svg.text("legend-label", (x + 24.0, y), name, 12.0, Anchor::Start);
        x += 34.0 + mechanica_svg::text_width(name, 12.0);
    }
}

/// The SVG text of the mode-shape pictures: two panels a row.
pub fn render(shapes: &ModeShapes) -> String {
    let rows = shapes.modes.len().div_ceil(2).max(1);
    let mut svg = Svg::new(WIDTH, HEADER + PANEL_H * rows as f64);
    draw_header(&mut svg);
    for (k, figure) in shapes.modes.iter().enumerate() {
        let (x, y) = (PANEL_W * (k % 2) as f64, HEADER + PANEL_H * (k / 2) as f64);
        draw_panel(&mut svg, shapes, figure, x, y);
    }
    svg.finish()
}

/// Writes [`render`] to `path`.
pub fn write(shapes: &ModeShapes, path: &Path) -> Result<(), String> {
    std::fs::write(path, render(shapes)).map_err(|e| format!("plot {}: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A chain of bodies at `rest` (their origins and centres of mass the same points) hung from
    /// the ground, displaced by `shift` per body index.
    fn chain(rest: &[Vector3<f64>], shift: Vector3<f64>) -> (Skeleton, ModeFigure) {
        let pose = |d: Vector3<f64>| Pose {
            origins: rest.iter().enumerate().map(|(i, p)| p + d * i as f64).collect(),
            centres: rest.iter().enumerate().map(|(i, p)| Some(p + d * i as f64)).collect(),
        };
        let skeleton = Skeleton {
            names: (0..rest.len()).map(|i| format!("b{i}")).collect(),
            parents: (0..rest.len()).map(|i| i.checked_sub(1)).collect(),
            moving: vec![true; rest.len()],
            base: Vector3::zeros(),
            up: Vector3::z(),
            rest: pose(Vector3::zeros()),
            extent: 1.0,
        };
        let figure = ModeFigure {
            number: 1,
            kind: ModeKindName::Oscillatory,
            heading: [String::new(), String::new()],
            displaced: Some(pose(shift)),
            amplitude: 1.0,
            largest: shift.norm() * rest.len() as f64,
            turned_most: None,
            moved_most: None,
            note: None,
        };
        (skeleton, figure)
    }

    fn along(v: &Vector3<f64>, axis: Vector3<f64>) -> bool {
        (v.dot(&axis).abs() - 1.0).abs() < 1e-9
    }

    /// A chain hanging along −z and swinging along y is seen in the yz plane, up = z; a chain
    /// zigzagging along x that bends vertically (a horizontal beam) nearly in the xz plane,
    /// though its rest pose also spreads along y.
    #[test]
    fn the_view_shows_the_plane_of_the_motion_with_up_upwards() {
        let hanging: Vec<Vector3<f64>> = (1..5).map(|i| Vector3::new(0.0, 0.0, -0.3 * i as f64)).collect();
        let (skeleton, figure) = chain(&hanging, Vector3::new(0.0, 0.05, 0.0));
        let view = view_of(&skeleton, &figure);
        assert!(along(&view.up, Vector3::z()) && view.up.z > 0.0, "{view:?}");
        assert!(along(&view.right, Vector3::y()), "{view:?}");
        let beam: Vec<Vector3<f64>> = (1..6)
            .map(|i| Vector3::new(0.4 * i as f64, 0.1 * (i % 2) as f64, 0.0))
            .collect();
        let (skeleton, figure) = chain(&beam, Vector3::new(0.0, 0.0, -0.03));
        let view = view_of(&skeleton, &figure);
        assert!(along(&view.up, Vector3::z()) && view.up.z > 0.0, "{view:?}");
        // The zigzag's x–y correlation tilts the least-spread direction slightly off y.
        assert!(view.right.x.abs() > 0.999 && view.right.z == 0.0, "{view:?}");
    }

    /// Every drawn point lands inside the panel's box, whatever the scale of the mechanism.
    #[test]
    fn frames_fit_points_into_their_box() {
        for scale in [1e-6, 1.0, 1e5] {
            let points: Vec<Vector3<f64>> = (0..7)
                .map(|i| Vector3::new((i as f64).sin(), (i as f64).cos(), 0.1 * i as f64) * scale)
                .collect();
            let view = View {
                right: Vector3::x(),
                up: Vector3::z(),
            };
            let frame = Frame::fitted(view, &points, 10.0, 20.0, 300.0, 200.0);
            for p in &points {
                let (x, y) = frame.px(p);
                assert!((10.0 - 1e-9..=310.0 + 1e-9).contains(&x) && (20.0 - 1e-9..=220.0 + 1e-9).contains(&y));
            }
        }
    }
}
