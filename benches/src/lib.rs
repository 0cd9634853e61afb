//! Shared reporting for the criterion benches: each bench writes its measured series to
//! `target/reports/<name>.csv`, and error-against-run-time series also to `<name>.svg`.

use plotters::prelude::*;
use std::io::Write as _;
use std::path::PathBuf;
use std::time::{Duration, Instant};

pub mod lapack;
pub mod modal;

/// Median wall time of `f` in seconds, and its last result. Runs `f` at least `min_runs` times
/// and keeps repeating (up to 1000 runs) until `budget` has elapsed: for report generators whose
/// problems are too slow for criterion's sampling (a run of several seconds is timed
/// `min_runs` times).
pub fn median_seconds<T>(min_runs: usize, budget: Duration, mut f: impl FnMut() -> T) -> (f64, T) {
    let start = Instant::now();
    let mut times = Vec::new();
    let mut last;
    loop {
        let t = Instant::now();
        last = std::hint::black_box(f());
        times.push(t.elapsed().as_secs_f64());
        if (times.len() >= min_runs.max(1) && start.elapsed() >= budget) || times.len() >= 1000 {
            break;
        }
    }
    times.sort_by(f64::total_cmp);
    (times[times.len() / 2], last)
}

/// `target/reports/` (honouring `CARGO_TARGET_DIR`), created if missing.
pub fn reports_dir() -> std::io::Result<PathBuf> {
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target"));
    let dir = target.join("reports");
    std::fs::create_dir_all(&dir)?;
    Ok(dir)
}

/// Writes `rows` under `header` to `target/reports/<name>.csv` and returns the path.
pub fn write_csv(name: &str, header: &[&str], rows: &[Vec<String>]) -> std::io::Result<PathBuf> {
    let path = reports_dir()?.join(format!("{name}.csv"));
    let mut file = std::fs::File::create(&path)?;
    writeln!(file, "{}", header.join(","))?;
    for row in rows {
        writeln!(file, "{}", row.join(","))?;
    }
    Ok(path)
}

/// One named series of (run time in seconds, error) points.
pub struct Series {
    /// Legend label.
    pub label: String,
    /// (seconds, error) points; both must be positive to appear on the log-log axes.
    pub points: Vec<(f64, f64)>,
}

/// Plots error against run time on log-log axes to `target/reports/<name>.svg`.
pub fn plot_error_vs_time(name: &str, title: &str, series: &[Series]) -> Result<PathBuf, Box<dyn std::error::Error>> {
    let path = reports_dir()?.join(format!("{name}.svg"));
    let points = || {
        series
            .iter()
            .flat_map(|s| s.points.iter().copied())
            .filter(|&(t, e)| t > 0.0 && e > 0.0)
    };
    let (t_min, t_max) = points().fold((f64::MAX, f64::MIN), |(lo, hi), (t, _)| (lo.min(t), hi.max(t)));
    let (e_min, e_max) = points().fold((f64::MAX, f64::MIN), |(lo, hi), (_, e)| (lo.min(e), hi.max(e)));
    if t_min > t_max || e_min > e_max {
        return Err("no positive points to plot".into());
    }
    draw_log_log(&path, title, series, (t_min, t_max), (e_min, e_max))?;
    Ok(path)
}

fn draw_log_log(
    path: &std::path::Path,
    title: &str,
    series: &[Series],
    (t_min, t_max): (f64, f64),
    (e_min, e_max): (f64, f64),
) -> Result<(), Box<dyn std::error::Error>> {
    let root = SVGBackend::new(path, (800, 520)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(
            (t_min * 0.8..t_max * 1.25).log_scale(),
            (e_min * 0.5..e_max * 2.0).log_scale(),
        )?;
    chart.configure_mesh().x_desc("run time [s]").y_desc("error").draw()?;
    for (i, s) in series.iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        let pts: Vec<(f64, f64)> = s.points.iter().copied().filter(|&(t, e)| t > 0.0 && e > 0.0).collect();
        chart
            .draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))?
            .label(s.label.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], color.stroke_width(2)));
        chart.draw_series(pts.into_iter().map(|p| Circle::new(p, 3, color.filled())))?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}
