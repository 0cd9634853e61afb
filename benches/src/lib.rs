//! Shared reporting for the criterion benches: each bench writes its measured series to
//! `target/reports/<name>.csv`, and error-against-run-time series also to `<name>.svg` as a
//! work-precision diagram ([`work_precision`]).

use std::io::Write as _;
use std::path::PathBuf;
use std::time::{Duration, Instant};

pub mod lapack;
pub mod modal;
pub mod scipy;
pub mod work_precision;

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
