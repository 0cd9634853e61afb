//! The diagram read back from its SVG text: series joined in order of size or tolerance within
//! their own panel, zero errors on the marked floor, bounds dashed in their method's colour,
//! power-of-ten tick labels, titles that fit.

use super::*;
use mechanica_svg::text_width;

/// One element of the SVG text: its line, class, attributes and the panel and series holding it.
#[derive(Debug, Clone)]
struct Element {
    line: String,
    class: String,
    panel: Option<String>,
    series: Option<String>,
}

impl Element {
    fn attribute(&self, name: &str) -> Option<String> {
        let key = format!(" {name}=\"");
        let start = self.line.find(&key)? + key.len();
        let rest = &self.line[start..];
        Some(rest[..rest.find('"')?].to_string())
    }

    fn number(&self, name: &str) -> f64 {
        self.attribute(name)
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("{name} in {}", self.line))
    }

    fn text(&self) -> String {
        let start = self.line.find('>').map_or(0, |i| i + 1);
        let end = self.line.rfind("</").unwrap_or(self.line.len());
        self.line[start..end]
            .replace("&amp;", "&")
            .replace("&lt;", "<")
            .replace("&gt;", ">")
    }
}

/// The elements of `svg`, each with its enclosing panel and series.
fn elements(svg: &str) -> Vec<Element> {
    let mut stack: Vec<Element> = Vec::new();
    let mut out = Vec::new();
    for line in svg.lines() {
        let within = |class: &str| {
            stack
                .iter()
                .rev()
                .find(|g| g.class == class)
                .and_then(|g| g.attribute(if class == "panel" { "data-title" } else { "data-label" }))
        };
        let element = Element {
            line: line.to_string(),
            class: String::new(),
            panel: within("panel"),
            series: within("series"),
        };
        let class = element.attribute("class").unwrap_or_default();
        let element = Element { class, ..element };
        if line.starts_with("<g ") {
            stack.push(element);
        } else if line.starts_with("</g>") {
            stack.pop();
        } else {
            out.push(element);
        }
    }
    out
}

/// A deterministic stream in [0, 1).
fn stream(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Two families of three methods, sizes given in a random order, a few exact zeros, bounds for
/// the first method.
fn random_panels(seed: u64) -> Vec<Panel> {
    let mut uniform = stream(seed);
    let mut panels = Vec::new();
    for family in [
        "fixed chain",
        "graded chain with a title long enough to need a smaller font size",
    ] {
        let mut series = Vec::new();
        for (m, method) in ["all pairs", "values only", "LAPACK"].iter().enumerate() {
            let mut sizes = [100.0, 400.0, 1000.0, 2000.0, 4000.0];
            for k in (1..sizes.len()).rev() {
                sizes.swap(k, (uniform() * (k + 1) as f64) as usize % (k + 1));
            }
            let point = |n: f64, u: f64, v: f64| WorkPoint {
                order: n,
                seconds: 1e-6 * n.powf(2.5) * (0.5 + u),
                error: if v < 0.2 { 0.0 } else { 10f64.powf(-16.0 + 6.0 * v) },
            };
            let points: Vec<WorkPoint> = sizes.iter().map(|&n| point(n, uniform(), uniform())).collect();
            let bound = if m == 0 {
                points
                    .iter()
                    .map(|p| WorkPoint {
                        error: 1e3 * p.error.max(1e-16),
                        ..*p
                    })
                    .collect()
            } else {
                Vec::new()
            };
            series.push(Series {
                label: method.to_string(),
                points,
                bound,
            });
        }
        panels.push(Panel {
            title: family.to_string(),
            series,
        });
    }
    panels
}

#[test]
fn series_are_joined_in_order_within_their_panel() {
    for seed in 1..20u64 {
        let panels = random_panels(0x9e37_79b9_7f4a_7c15 ^ seed);
        let svg = work_precision_svg("modal solvers: error against run time", "max relative error", &panels);
        let drawn = elements(&svg);
        for (p, panel) in panels.iter().enumerate() {
            let frame = Frame::new(panel, PANEL_WIDTH * (p % 2) as f64, HEADER).expect("frame");
            for series in &panel.series {
                for (class, points) in [("error", &series.points), ("bound", &series.bound)] {
                    let segments: Vec<&Element> = drawn
                        .iter()
                        .filter(|e| e.class == class && e.series.as_deref() == Some(series.label.as_str()))
                        .filter(|e| e.panel.as_deref() == Some(panel.title.as_str()))
                        .collect();
                    let sorted = ordered(points);
                    assert_eq!(
                        segments.len(),
                        sorted.len().saturating_sub(1),
                        "{class} of {}",
                        series.label
                    );
                    for (segment, pair) in segments.iter().zip(sorted.windows(2)) {
                        let a = frame.pixel(pair[0].seconds, pair[0].error);
                        let b = frame.pixel(pair[1].seconds, pair[1].error);
                        let got = [
                            segment.number("x1"),
                            segment.number("y1"),
                            segment.number("x2"),
                            segment.number("y2"),
                        ];
                        for (g, w) in got.iter().zip([a.0, a.1, b.0, b.1]) {
                            assert!((g - w).abs() <= 0.006, "{}: {got:?} vs {a:?} → {b:?}", series.label);
                        }
                        let dashed = segment.line.contains("stroke-dasharray");
                        assert_eq!(dashed, class == "bound", "{}", segment.line);
                    }
                }
            }
        }
        // Every element lies inside its panel's box.
        for e in drawn.iter().filter(|e| e.class == "error" || e.class == "bound") {
            let p = panels
                .iter()
                .position(|p| Some(p.title.as_str()) == e.panel.as_deref())
                .expect("in a panel");
            let x0 = PANEL_WIDTH * (p % 2) as f64;
            for x in [e.number("x1"), e.number("x2")] {
                assert!(
                    x >= x0 + MARGIN.0 - 0.01 && x <= x0 + PANEL_WIDTH - MARGIN.2 + 0.01,
                    "{}",
                    e.line
                );
            }
        }
    }
}

#[test]
fn zero_errors_sit_on_the_marked_floor_and_the_legend_says_so() {
    let panels = random_panels(7);
    let zeros = panels
        .iter()
        .flat_map(|p| &p.series)
        .flat_map(|s| &s.points)
        .filter(|p| p.error == 0.0)
        .count();
    assert!(zeros > 0, "the family has exact zeros");
    let svg = work_precision_svg("t", "error", &panels);
    let drawn = elements(&svg);
    let floors: Vec<&Element> = drawn.iter().filter(|e| e.class == "zero-floor").collect();
    assert!(!floors.is_empty());
    let markers: Vec<&Element> = drawn.iter().filter(|e| e.class == "zero-marker").collect();
    assert_eq!(markers.len(), 4 * zeros, "four sides of a square per zero");
    for square in markers.chunks(4) {
        let floor = floors
            .iter()
            .find(|f| f.panel == square[0].panel)
            .expect("a floor in the panel");
        let centre = (square[0].number("y1") + square[2].number("y1")) / 2.0;
        assert!((centre - floor.number("y1")).abs() < 0.01, "{centre} vs {}", floor.line);
    }
    let note = drawn
        .iter()
        .find(|e| e.class == "legend-label" && e.text().contains("exactly 0"))
        .expect("a legend note");
    assert!(note.text().contains("u/2 = 1.1e-16"), "{}", note.text());
}

#[test]
fn ticks_are_powers_of_ten_and_titles_fit() {
    let panels = random_panels(11);
    let title = "Graded stiff chains, single and doubled (mpmath references): max relative error of the lowest 10 ω² against run time";
    let svg = work_precision_svg(title, "max relative error", &panels);
    let drawn = elements(&svg);
    let labels: Vec<String> = drawn
        .iter()
        .filter(|e| e.class == "tick-label")
        .map(Element::text)
        .collect();
    assert!(labels.len() >= 8, "{labels:?}");
    for label in &labels {
        let exponent = label.strip_prefix("10").expect("a power of ten");
        assert!(
            exponent.chars().all(|c| "⁻⁰¹²³⁴⁵⁶⁷⁸⁹".contains(c)) && !exponent.is_empty(),
            "{label}"
        );
    }
    let width = PANEL_WIDTH * 2.0;
    for e in drawn
        .iter()
        .filter(|e| e.class.ends_with("title") || e.class == "legend-label")
    {
        let room = match e.class.as_str() {
            "figure-title" => width - 24.0,
            "panel-title" => PANEL_WIDTH - 20.0,
            _ => width / 2.0 - 16.0,
        };
        let size = e.number("font-size");
        assert!(
            size >= 7.0 && text_width(&e.text(), size) <= room + 0.5,
            "{}: {size}",
            e.text()
        );
    }
    let svg_width = elements(&svg)[0].number("width");
    assert_eq!(svg_width, width);
}
