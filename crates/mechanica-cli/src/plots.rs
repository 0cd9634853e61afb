//! `--plot DIR`: SVG plots of what a scene computed — the spectrum
//! ([`crate::spectrum_plot`]), the mode shapes drawn on the mechanism
//! ([`crate::mode_shape_plot`]), the free response over time, an impact's energy balance
//! ([`crate::impact_plot`]), and a simulation ([`crate::simulation_plots`]).

use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// Sampled free response: one series per coordinate.
#[derive(Debug, Clone)]
pub struct ResponseSeries {
    /// The coordinates' names.
    pub names: Vec<String>,
    /// Sample times, s.
    pub times: Vec<f64>,
    /// `values[k][i]` = δ_k(t_i).
    pub values: Vec<Vec<f64>>,
}

/// Kinetic energy before and after an impact, per restitution law.
#[derive(Debug, Clone)]
pub struct EnergyBalance {
    /// The body that strikes the ground.
    pub body: String,
    /// The scene's restitution law.
    pub chosen: String,
    /// (law, T before, T after), J.
    pub laws: Vec<(String, f64, f64)>,
}

/// A simulated trajectory: the coordinates, the drift of H and the estimated errors per sample.
#[derive(Debug, Clone)]
pub struct SimulationSeries {
    /// Sample times, s.
    pub times: Vec<f64>,
    /// The coordinates' names.
    pub names: Vec<String>,
    /// `coordinates[k][i]` = q_k(t_i).
    pub coordinates: Vec<Vec<f64>>,
    /// |H(t_i) − H(0)| / the energy scale.
    pub drift: Vec<f64>,
    /// The estimated global error of q (NaN without the companion run).
    pub error_q: Vec<f64>,
    /// The estimated global error of q̇.
    pub error_q_dot: Vec<f64>,
}

/// Everything the scene computed that can be plotted.
#[derive(Debug, Clone, Default)]
pub struct PlotData {
    /// Every mode with its bound and class.
    pub spectrum: Vec<crate::spectrum_plot::SpectrumPoint>,
    /// The first modes drawn on the mechanism.
    pub shapes: Option<crate::mode_shape::ModeShapes>,
    /// The free response.
    pub response: Option<ResponseSeries>,
    /// The impact energy balance.
    pub impact: Option<EnergyBalance>,
    /// A simulated trajectory.
    pub simulation: Option<SimulationSeries>,
}

fn failed(e: impl std::fmt::Display) -> String {
    format!("plot: {e}")
}

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((0.0_f64, 0.0_f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    let pad = 0.05 * (hi - lo).max(1e-12);
    (lo - pad, hi + pad)
}

impl PlotData {
    /// Writes the SVGs of whatever was computed into `dir` (created if needed); returns the
    /// files written.
    pub fn write_all(&self, dir: &Path) -> Result<Vec<PathBuf>, String> {
        std::fs::create_dir_all(dir).map_err(|e| format!("plot directory {}: {e}", dir.display()))?;
        let mut written = Vec::new();
        if !self.spectrum.is_empty() {
            let path = dir.join("spectrum.svg");
            crate::spectrum_plot::write(&self.spectrum, &path)?;
            written.push(path);
        }
        if let Some(shapes) = &self.shapes {
            let path = dir.join("mode_shapes.svg");
            crate::mode_shape_plot::write(shapes, &path)?;
            written.push(path);
        }
        if let Some(response) = &self.response {
            let path = dir.join("response.svg");
            let root = SVGBackend::new(&path, (900, 500)).into_drawing_area();
            root.fill(&WHITE).map_err(failed)?;
            let t_end = response.times.last().copied().unwrap_or(1.0);
            let (lo, hi) = range(response.values.iter().flatten().copied());
            let mut chart = ChartBuilder::on(&root)
                .caption("free response δ(t) (8.91)", ("sans-serif", 18))
                .margin(10)
                .x_label_area_size(35)
                .y_label_area_size(60)
                .build_cartesian_2d(0f64..t_end, lo..hi)
                .map_err(failed)?;
            chart
                .configure_mesh()
                .x_desc("t (s)")
                .y_desc("δ (rad | m)")
                .draw()
                .map_err(failed)?;
            for (k, series) in response.values.iter().enumerate() {
                let color = Palette99::pick(k);
                chart
                    .draw_series(LineSeries::new(
                        response.times.iter().copied().zip(series.iter().copied()),
                        &color,
                    ))
                    .map_err(failed)?
                    .label(response.names.get(k).cloned().unwrap_or_else(|| format!("q[{k}]")))
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], Palette99::pick(k)));
            }
            chart
                .configure_series_labels()
                .border_style(BLACK)
                .draw()
                .map_err(failed)?;
            root.present().map_err(failed)?;
            written.push(path.clone());
        }
        if let Some(impact) = &self.impact {
            let path = dir.join("impact_energy.svg");
            crate::impact_plot::write(impact, &path)?;
            written.push(path);
        }
        if let Some(simulation) = &self.simulation {
            written.extend(crate::simulation_plots::write(simulation, dir)?);
        }
        Ok(written)
    }
}
