//! The spectrum as the modal crate certifies it: each mode's frequency as a point on a
//! logarithmic axis, with the error bar its certified bound allows, coloured by its class, and
//! mode numbers as integer categories.

use plotters::prelude::*;
use std::path::Path;

/// One mode of the spectrum plot.
#[derive(Debug, Clone)]
pub struct SpectrumPoint {
    /// ω² (rad²/s²); negative for an unstable mode.
    pub omega_sq: f64,
    /// The certified bound on |ω² − ω²_exact|.
    pub bound: f64,
    /// The class, as the report names it ("oscillatory", "zero", "unstable", "undecided", …).
    pub kind: String,
}

/// The frequency |ω|/2π (Hz) of an ω², and its interval from ω² ± bound (the lower end 0 when
/// the interval reaches zero).
fn frequency_interval(p: &SpectrumPoint) -> (f64, f64, f64) {
    let hz = |w2: f64| w2.abs().sqrt() / std::f64::consts::TAU;
    let (lo, hi) = (p.omega_sq.abs() - p.bound, p.omega_sq.abs() + p.bound);
    (hz(p.omega_sq), hz(lo.max(0.0)), hz(hi))
}

fn color_of(kind: &str) -> RGBColor {
    match kind {
        "oscillatory" => RGBColor(31, 119, 180),
        "unstable" => RGBColor(214, 39, 40),
        "zero" => RGBColor(127, 127, 127),
        _ => RGBColor(255, 127, 14),
    }
}

fn failed(e: impl std::fmt::Display) -> String {
    format!("plot: {e}")
}

/// Writes the spectrum plot of `points` to `path`. Frequencies of zero (rigid-body modes, and
/// the lower ends of intervals that reach zero) are drawn at a floor a decade below the
/// smallest positive frequency, marked on the plot.
pub fn write(points: &[SpectrumPoint], path: &Path) -> Result<(), String> {
    let intervals: Vec<(f64, f64, f64)> = points.iter().map(frequency_interval).collect();
    let positive = intervals
        .iter()
        .flat_map(|&(f, lo, hi)| [f, lo, hi])
        .filter(|v| v.is_finite() && *v > 0.0);
    let (smallest, largest) = positive.fold((f64::INFINITY, 0.0f64), |(a, b), v| (a.min(v), b.max(v)));
    let floor = if smallest.is_finite() { smallest / 10.0 } else { 1e-3 };
    let top = if largest > floor { largest * 3.0 } else { floor * 100.0 };
    let root = SVGBackend::new(path, (900, 500)).into_drawing_area();
    root.fill(&WHITE).map_err(failed)?;
    let n = points.len();
    let mut chart = ChartBuilder::on(&root)
        .caption("spectrum: f = |ω|/2π with its certified interval", ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d((1..n.max(1)).into_segmented(), (floor..top).log_scale())
        .map_err(failed)?;
    chart
        .configure_mesh()
        .x_desc("mode")
        .y_desc("Hz")
        .x_label_formatter(&|v| match v {
            SegmentValue::CenterOf(k) | SegmentValue::Exact(k) => k.to_string(),
            SegmentValue::Last => String::new(),
        })
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(failed)?;
    let shown = |v: f64| if v.is_finite() { v.max(floor) } else { top };
    for kind in ["oscillatory", "unstable", "zero", "undecided", "infinite"] {
        let color = color_of(kind);
        let members: Vec<(usize, (f64, f64, f64))> = (0..n)
            .filter(|&k| points[k].kind == kind)
            .map(|k| (k + 1, intervals[k]))
            .collect();
        if members.is_empty() {
            continue;
        }
        chart
            .draw_series(members.iter().map(|&(k, (_, lo, hi))| {
                let x = SegmentValue::CenterOf(k);
                PathElement::new(vec![(x.clone(), shown(lo)), (x, shown(hi))], color.stroke_width(2))
            }))
            .map_err(failed)?
            .label(kind)
            .legend(move |(x, y)| Circle::new((x + 8, y), 4, color.filled()));
        chart
            .draw_series(
                members
                    .iter()
                    .map(|&(k, (f, _, _))| Circle::new((SegmentValue::CenterOf(k), shown(f)), 4, color.filled())),
            )
            .map_err(failed)?;
    }
    chart
        .draw_series(std::iter::once(Text::new(
            "floor: frequency 0",
            (SegmentValue::CenterOf(1), floor * 1.3),
            ("sans-serif", 11),
        )))
        .map_err(failed)?;
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(failed)?;
    root.present().map_err(failed)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The interval of a mode: ω² = 4π² (1 Hz) with bound 4π²·0.21 spans √0.79 … √1.21 Hz; an
    /// interval reaching zero starts at 0.
    #[test]
    fn frequency_intervals_follow_the_bounds() {
        let w2 = std::f64::consts::TAU.powi(2);
        let p = SpectrumPoint {
            omega_sq: w2,
            bound: 0.21 * w2,
            kind: "oscillatory".into(),
        };
        let (f, lo, hi) = frequency_interval(&p);
        assert!((f - 1.0).abs() < 1e-15 && (lo - 0.79f64.sqrt()).abs() < 1e-15 && (hi - 1.1).abs() < 1e-15);
        let wide = SpectrumPoint { bound: 2.0 * w2, ..p };
        assert_eq!(frequency_interval(&wide).1, 0.0);
    }
}
