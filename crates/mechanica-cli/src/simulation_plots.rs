//! `--plot DIR` for a simulation: the coordinates over time (`motion.svg`), the drift of the
//! conserved quantity (`energy_drift.svg`) and the estimated global error of q and q̇
//! (`error_estimate.svg`), the last two on logarithmic axes.

use crate::plots::SimulationSeries;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

fn failed(e: impl std::fmt::Display) -> String {
    format!("plot: {e}")
}

/// Writes the three plots into `dir`; returns the files written.
pub fn write(series: &SimulationSeries, dir: &Path) -> Result<Vec<PathBuf>, String> {
    let t_end = series.times.last().copied().filter(|t| *t > 0.0).unwrap_or(1.0);
    let motion = dir.join("motion.svg");
    let lines: Vec<(String, &[f64])> = series
        .names
        .iter()
        .cloned()
        .zip(series.coordinates.iter().map(Vec::as_slice))
        .collect();
    linear_plot(
        &motion,
        "motion: coordinates q(t)",
        "q (rad | m)",
        t_end,
        &series.times,
        &lines,
    )?;
    let drift = dir.join("energy_drift.svg");
    let drift_lines = [("|H − H(0)| / energy scale".to_string(), series.drift.as_slice())];
    log_plot(
        &drift,
        "drift of the conserved quantity H",
        t_end,
        &series.times,
        &drift_lines,
    )?;
    let mut written = vec![motion, drift];
    if series.error_q.iter().any(|e| e.is_finite()) {
        let error = dir.join("error_estimate.svg");
        let error_lines = [
            ("estimated error of q".to_string(), series.error_q.as_slice()),
            ("estimated error of q̇".to_string(), series.error_q_dot.as_slice()),
        ];
        log_plot(
            &error,
            "estimated global error (companion run)",
            t_end,
            &series.times,
            &error_lines,
        )?;
        written.push(error);
    }
    Ok(written)
}

fn linear_plot(
    path: &Path,
    title: &str,
    y_label: &str,
    t_end: f64,
    times: &[f64],
    lines: &[(String, &[f64])],
) -> Result<(), String> {
    let (lo, hi) = lines
        .iter()
        .flat_map(|(_, v)| v.iter().copied())
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    let (lo, hi) = if lo < hi {
        (lo, hi)
    } else {
        (lo.min(0.0) - 1.0, hi.max(0.0) + 1.0)
    };
    let pad = 0.05 * (hi - lo);
    let root = SVGBackend::new(path, (900, 500)).into_drawing_area();
    root.fill(&WHITE).map_err(failed)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(0f64..t_end, (lo - pad)..(hi + pad))
        .map_err(failed)?;
    chart
        .configure_mesh()
        .x_desc("t (s)")
        .y_desc(y_label)
        .draw()
        .map_err(failed)?;
    draw_lines(&mut chart, times, lines, |v| v)?;
    root.present().map_err(failed)
}

fn log_plot(path: &Path, title: &str, t_end: f64, times: &[f64], lines: &[(String, &[f64])]) -> Result<(), String> {
    // Zeros (exact values) are drawn at a floor of u/2 below the smallest positive value.
    let positive = lines
        .iter()
        .flat_map(|(_, v)| v.iter().copied())
        .filter(|v| v.is_finite() && *v > 0.0);
    let (lo, hi) = positive.fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    let floor = if lo.is_finite() {
        (lo * 0.5).min(f64::EPSILON / 2.0)
    } else {
        f64::EPSILON / 2.0
    };
    let top = if hi > floor { hi * 2.0 } else { floor * 10.0 };
    let root = SVGBackend::new(path, (900, 500)).into_drawing_area();
    root.fill(&WHITE).map_err(failed)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d(0f64..t_end, (floor..top).log_scale())
        .map_err(failed)?;
    chart
        .configure_mesh()
        .x_desc("t (s)")
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(failed)?;
    draw_lines(&mut chart, times, lines, |v| v.max(floor))?;
    root.present().map_err(failed)
}

fn draw_lines<'a, X, Y>(
    chart: &mut ChartContext<'a, SVGBackend<'a>, Cartesian2d<X, Y>>,
    times: &[f64],
    lines: &[(String, &[f64])],
    shown: impl Fn(f64) -> f64,
) -> Result<(), String>
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    for (k, (name, values)) in lines.iter().enumerate() {
        let color = Palette99::pick(k);
        let points: Vec<(f64, f64)> = times
            .iter()
            .zip(values.iter())
            .filter(|(_, v)| v.is_finite())
            .map(|(t, v)| (*t, shown(*v)))
            .collect();
        chart
            .draw_series(LineSeries::new(points, &color))
            .map_err(failed)?
            .label(name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], Palette99::pick(k)));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(failed)
}
