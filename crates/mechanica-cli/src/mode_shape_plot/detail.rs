//! What a panel adds when its mode's motion is hard to see at the mechanism's scale: a mark ↻
//! on the body whose turn limited the amplitude (a light link spinning about its own axis
//! barely moves any drawn point), and, when the largest drawn motion is below
//! [`VISIBLE_PX`] pixels, a magnified detail of the neighbourhood of the point that moved most,
//! drawn in the panel's corner with its magnification.

use super::{Frame, MARGIN, PANEL_W, REST, TITLE_H, color_of, draw_pose};
use crate::mode_shape::{ModeFigure, Pose, Skeleton};
use mechanica::kinematics::nalgebra::Vector3;
use mechanica_svg::{Anchor, Color, Svg};

/// Below this many pixels of largest motion a panel gets a magnified detail.
pub(super) const VISIBLE_PX: f64 = 10.0;
/// The side of the detail box, px.
const SIDE: f64 = 150.0;
/// The largest motion as drawn in the detail, px.
const DETAIL_MOTION_PX: f64 = 30.0;
/// The radius of the turn mark, px.
const TURN_RADIUS: f64 = 12.0;

/// The turn mark and the magnified detail of `figure` (displaced pose `moved`) in the panel at
/// `panel` (its top-left corner) drawn with `frame`.
pub(super) fn draw(
    svg: &mut Svg,
    skeleton: &Skeleton,
    figure: &ModeFigure,
    moved: &Pose,
    frame: &Frame,
    panel: (f64, f64),
) {
    let color = color_of(figure.kind);
    if let Some(at) = figure.turned_most.and_then(|b| moved.origins.get(b)) {
        draw_turn_mark(svg, frame.px(at), color);
    }
    let Some((rest_point, moved_point)) = figure.moved_most.and_then(|b| moved_point(skeleton, moved, b)) else {
        return;
    };
    let drawn = figure.largest * frame.scale;
    if !(drawn > 0.0 && drawn < VISIBLE_PX) {
        return;
    }
    let magnification = DETAIL_MOTION_PX / drawn;
    let lo = (panel.0 + PANEL_W - MARGIN - SIDE, panel.1 + TITLE_H + 6.0);
    let hi = (lo.0 + SIDE, lo.1 + SIDE);
    let middle = (rest_point + moved_point) * 0.5;
    let detail = Frame {
        view: frame.view,
        scale: frame.scale * magnification,
        origin: (middle.dot(&frame.view.right), middle.dot(&frame.view.up)),
        centre: (0.5 * (lo.0 + hi.0), 0.5 * (lo.1 + hi.1) + 8.0),
        clip: Some((lo, hi)),
    };
    svg.open_group("detail", &[("data-magnification", &format!("{magnification:.6e}"))]);
    svg.rect("detail-background", lo, hi, Color(255, 255, 255));
    let ink = Color(120, 120, 120);
    for (a, b) in [
        (lo, (hi.0, lo.1)),
        ((hi.0, lo.1), hi),
        (hi, (lo.0, hi.1)),
        ((lo.0, hi.1), lo),
    ] {
        svg.line("detail-border", a, b, ink, 1.0, false);
    }
    draw_pose(svg, skeleton, &skeleton.rest, &detail, REST, "detail-rest");
    draw_pose(svg, skeleton, moved, &detail, color, "detail-mode");
    let label = format!("detail ×{}", crate::report::text::number(magnification, 2));
    svg.text("detail-label", (lo.0 + 6.0, lo.1 + 14.0), &label, 11.0, Anchor::Start);
    if let Some(name) = figure.moved_most.and_then(|b| skeleton.names.get(b)) {
        let size = mechanica_svg::fitted_size(name, SIDE - 12.0, 10.0);
        svg.text("detail-label", (lo.0 + 6.0, hi.1 - 6.0), name, size, Anchor::Start);
    }
    svg.close_group();
}

/// The rest and displaced positions of body `b`'s point that moved more: its origin or its
/// centre of mass.
fn moved_point(skeleton: &Skeleton, moved: &Pose, b: usize) -> Option<(Vector3<f64>, Vector3<f64>)> {
    let origin = (*skeleton.rest.origins.get(b)?, *moved.origins.get(b)?);
    let centre = skeleton
        .rest
        .centres
        .get(b)
        .copied()
        .flatten()
        .zip(moved.centres.get(b).copied().flatten());
    Some(match centre {
        Some(c) if (c.1 - c.0).norm() > (origin.1 - origin.0).norm() => c,
        _ => origin,
    })
}

/// A circular arrow ↻ of radius [`TURN_RADIUS`] around `at`: three quarters of a circle and a
/// head.
fn draw_turn_mark(svg: &mut Svg, at: (f64, f64), color: Color) {
    let point = |angle: f64| (at.0 + TURN_RADIUS * angle.cos(), at.1 - TURN_RADIUS * angle.sin());
    let segments = 18;
    let sweep = 1.5 * std::f64::consts::PI;
    for k in 0..segments {
        let (a, b) = (
            sweep * k as f64 / segments as f64,
            sweep * (k + 1) as f64 / segments as f64,
        );
        svg.line("turn-mark", point(a), point(b), color, 1.5, false);
    }
    let tip = point(sweep);
    for spread in [0.45f64, -0.45] {
        // The head's two strokes point back along the arc's tangent at its end.
        let back = sweep - 0.5 * std::f64::consts::PI + spread;
        let end = (tip.0 + 6.0 * back.cos(), tip.1 - 6.0 * back.sin());
        svg.line("turn-mark", tip, end, color, 1.5, false);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mode_record::ModeKindName;
    use crate::mode_shape::ModeFigure;

    fn figure(largest: f64, shift: Vector3<f64>) -> (Skeleton, ModeFigure, Pose) {
        let rest = Pose {
            origins: vec![Vector3::new(0.0, 0.0, -1.0), Vector3::new(0.0, 0.0, -2.0)],
            centres: vec![None, Some(Vector3::new(0.0, 0.0, -2.5))],
        };
        let mut moved = rest.clone();
        moved.centres[1] = Some(Vector3::new(0.0, 0.0, -2.5) + shift);
        let skeleton = Skeleton {
            names: vec!["upper".into(), "wrist".into()],
            parents: vec![None, Some(0)],
            moving: vec![true, true],
            base: Vector3::zeros(),
            up: Vector3::z(),
            rest,
            extent: 2.5,
        };
        let figure = ModeFigure {
            number: 1,
            kind: ModeKindName::Oscillatory,
            heading: [String::new(), String::new()],
            displaced: Some(moved.clone()),
            amplitude: 1.0,
            largest,
            turned_most: Some(1),
            moved_most: Some(1),
            note: None,
        };
        (skeleton, figure, moved)
    }

    fn frame(scale: f64) -> Frame {
        Frame {
            view: super::super::View {
                right: Vector3::y(),
                up: Vector3::z(),
            },
            scale,
            origin: (0.0, -1.25),
            centre: (250.0, 200.0),
            clip: None,
        }
    }

    /// The x or y of every `<circle class="CLASS"` in `svg`, in order.
    fn centres(svg: &str, class: &str) -> Vec<(f64, f64)> {
        let attribute = |tag: &str, name: &str| -> f64 {
            let start = tag.find(&format!(" {name}=\"")).expect("attribute") + name.len() + 3;
            tag[start..].split('"').next().expect("value").parse().expect("number")
        };
        svg.lines()
            .filter(|l| l.contains(&format!("class=\"{class}\"")) && l.starts_with("<circle"))
            .map(|l| (attribute(l, "cx"), attribute(l, "cy")))
            .collect()
    }

    /// A wrist whose centre moves 1e-4 m in a panel of 100 px/m (0.01 px) is magnified so that
    /// its motion spans 30 px inside the detail box, with every detail mark inside the box; a
    /// visible motion gets no detail; the turn mark is drawn either way.
    #[test]
    fn small_motions_get_a_magnified_detail_inside_its_box() {
        let shift = Vector3::new(0.0, 1e-4, 0.0);
        let (skeleton, figure, moved) = figure(1e-4, shift);
        let mut svg = Svg::new(500.0, 440.0);
        draw(&mut svg, &skeleton, &figure, &moved, &frame(100.0), (0.0, 0.0));
        let text = svg.finish();
        assert!(text.contains("detail ×"), "{text}");
        assert!(text.contains("class=\"turn-mark\""));
        let rest = centres(&text, "detail-rest-com");
        let mode = centres(&text, "detail-mode-com");
        assert_eq!((rest.len(), mode.len()), (1, 1), "{text}");
        let apart = (mode[0].0 - rest[0].0).hypot(mode[0].1 - rest[0].1);
        assert!((apart - DETAIL_MOTION_PX).abs() < 1e-6, "{apart}");
        let (lo, hi) = (
            (PANEL_W - MARGIN - SIDE, TITLE_H + 6.0),
            (PANEL_W - MARGIN, TITLE_H + 6.0 + SIDE),
        );
        for (x, y) in centres(&text, "detail-rest-joint").into_iter().chain(rest).chain(mode) {
            assert!(
                (lo.0..=hi.0).contains(&x) && (lo.1..=hi.1).contains(&y),
                "({x}, {y}) outside the box"
            );
        }
        let (skeleton, figure, moved) = super::tests::figure(0.2, Vector3::new(0.0, 0.2, 0.0));
        let mut svg = Svg::new(500.0, 440.0);
        draw(&mut svg, &skeleton, &figure, &moved, &frame(100.0), (0.0, 0.0));
        let text = svg.finish();
        assert!(!text.contains("class=\"detail\"") && text.contains("class=\"turn-mark\""));
    }

    /// Segments are cut at the clip box: a link crossing the box keeps only its inside part.
    #[test]
    fn segments_are_clipped_to_the_box() {
        let mut clipped = frame(100.0);
        clipped.clip = Some(((200.0, 150.0), (300.0, 250.0)));
        let (a, b) = (Vector3::new(0.0, -10.0, -1.25), Vector3::new(0.0, 10.0, -1.25));
        let (p, q) = clipped.segment(&a, &b).expect("crosses the box");
        assert!((p.0 - 200.0).abs() < 1e-9 && (q.0 - 300.0).abs() < 1e-9 && (p.1 - 200.0).abs() < 1e-9);
        let outside = (Vector3::new(0.0, -10.0, 5.0), Vector3::new(0.0, 10.0, 5.0));
        assert!(clipped.segment(&outside.0, &outside.1).is_none());
    }
}
