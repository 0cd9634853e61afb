//! `impact_energy.svg`: the kinetic energy of the mechanism just before and just after the
//! impact, T⁻ and T⁺ = T⁻ + ΔT (J), as a pair of bars per restitution law, each law named under
//! its pair and the change ΔT/T⁻ in per cent over it; a gain (ΔT > 0, Kane's paradox under
//! Newton's law) is drawn in red.

use crate::plots::EnergyBalance;
use mechanica_svg::{Anchor, Color, INK, Svg, fitted_size, text_width, tick_label, ticks};
use std::path::Path;

const WIDTH: f64 = 800.0;
const HEIGHT: f64 = 480.0;
const LEFT: f64 = 90.0;
const RIGHT: f64 = 20.0;
const TOP: f64 = 90.0;
const BOTTOM: f64 = 70.0;
const BEFORE: Color = Color(31, 119, 180);
const AFTER: Color = Color(255, 127, 14);
const GAIN: Color = Color(214, 39, 40);

/// The plot area's vertical pixel of energy `t` on an axis from 0 to `top`.
fn y_of(t: f64, top: f64) -> f64 {
    HEIGHT - BOTTOM - (HEIGHT - TOP - BOTTOM) * t / top
}

/// The energy axis: ticks, grid lines and the axis title; returns the axis top (J).
fn draw_axis(svg: &mut Svg, largest: f64) -> f64 {
    let largest = if largest > 0.0 && largest.is_finite() {
        largest
    } else {
        1.0
    };
    let (values, step) = ticks(0.0, 1.12 * largest, 5);
    let top = values
        .last()
        .copied()
        .filter(|t| *t >= largest)
        .unwrap_or(1.12 * largest)
        .max(1.12 * largest);
    for v in &values {
        let y = y_of(*v, top);
        svg.line("grid", (LEFT, y), (WIDTH - RIGHT, y), Color(225, 225, 225), 1.0, false);
        svg.text(
            "tick-label",
            (LEFT - 8.0, y + 4.0),
            &tick_label(*v, step),
            12.0,
            Anchor::End,
        );
    }
    svg.line("axis", (LEFT, TOP), (LEFT, HEIGHT - BOTTOM), INK, 1.0, false);
    svg.line(
        "axis",
        (LEFT, HEIGHT - BOTTOM),
        (WIDTH - RIGHT, HEIGHT - BOTTOM),
        INK,
        1.0,
        false,
    );
    let middle = 0.5 * (TOP + HEIGHT - BOTTOM);
    svg.vertical_text("axis-title", (22.0, middle), "kinetic energy T (J)", 13.0);
    svg.text(
        "axis-title",
        (0.5 * (LEFT + WIDTH - RIGHT), HEIGHT - 14.0),
        "restitution law",
        13.0,
        Anchor::Middle,
    );
    top
}

/// The change of one law in per cent of T⁻, or "no change" labels.
fn change_label(before: f64, after: f64) -> String {
    if before > 0.0 {
        let percent = 100.0 * (after - before) / before;
        let sign = if percent > 0.0 { "+" } else { "−" };
        let gain = if percent > 0.0 { " (gain)" } else { "" };
        format!("ΔT = {sign}{} %{gain}", crate::report::text::number(percent.abs(), 3))
    } else {
        format!("ΔT = {} J", crate::report::text::number(after - before, 3))
    }
}

/// One law's pair of bars, its name and change, in the group starting at `x` of width `w`.
fn draw_law(svg: &mut Svg, law: &(String, f64, f64), chosen: bool, x: f64, w: f64, top: f64) {
    let (name, before, after) = (law.0.as_str(), law.1.max(0.0), law.2.max(0.0));
    let bar = 0.3 * w;
    let base = HEIGHT - BOTTOM;
    let x_before = x + 0.5 * w - bar - 3.0;
    let x_after = x + 0.5 * w + 3.0;
    svg.rect(
        "bar-before",
        (x_before, y_of(before, top)),
        (x_before + bar, base),
        BEFORE,
    );
    let color = if after > before { GAIN } else { AFTER };
    svg.rect("bar-after", (x_after, y_of(after, top)), (x_after + bar, base), color);
    let change = change_label(before, after);
    let y = y_of(after.max(before), top) - 8.0;
    svg.text(
        "change-label",
        (x + 0.5 * w, y),
        &change,
        fitted_size(&change, w, 12.0),
        Anchor::Middle,
    );
    let label = if chosen {
        format!("{name} (the scene's law)")
    } else {
        name.to_string()
    };
    svg.text(
        "law-label",
        (x + 0.5 * w, base + 20.0),
        &label,
        fitted_size(&label, w, 13.0),
        Anchor::Middle,
    );
}

/// The legend: which bar is which.
fn draw_legend(svg: &mut Svg, any_gain: bool) {
    let mut entries = vec![(BEFORE, "T⁻ just before the impact"), (AFTER, "T⁺ just after")];
    if any_gain {
        entries.push((GAIN, "T⁺ > T⁻: energy gained"));
    }
    let mut x = LEFT;
    let y = 58.0;
    for (color, text) in entries {
        svg.rect("legend", (x, y - 10.0), (x + 14.0, y + 2.0), color);
        svg.text("legend-label", (x + 20.0, y), text, 12.0, Anchor::Start);
        x += 40.0 + text_width(text, 12.0);
    }
}

/// The SVG text of the energy balance.
pub fn render(balance: &EnergyBalance) -> String {
    let mut svg = Svg::new(WIDTH, HEIGHT);
    let title = format!(
        "impact of body \"{}\" on the ground: kinetic energy before and after, per restitution law",
        balance.body
    );
    svg.text(
        "title",
        (12.0, 26.0),
        &title,
        fitted_size(&title, WIDTH - 24.0, 16.0),
        Anchor::Start,
    );
    let largest = balance.laws.iter().flat_map(|l| [l.1, l.2]).fold(0.0, f64::max);
    let top = draw_axis(&mut svg, largest);
    let n = balance.laws.len().max(1) as f64;
    let w = (WIDTH - LEFT - RIGHT) / n;
    for (k, law) in balance.laws.iter().enumerate() {
        draw_law(&mut svg, law, law.0 == balance.chosen, LEFT + w * k as f64, w, top);
    }
    draw_legend(&mut svg, balance.laws.iter().any(|l| l.2 > l.1));
    svg.finish()
}

/// Writes [`render`] to `path`.
pub fn write(balance: &EnergyBalance, path: &Path) -> Result<(), String> {
    std::fs::write(path, render(balance)).map_err(|e| format!("plot {}: {e}", path.display()))
}
