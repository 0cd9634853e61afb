//! A minimal SVG writer for pictures that are drawings rather than charts: one element per
//! line, each carrying a `class` naming what it shows, coordinates in pixels with two decimals;
//! and the estimated width of sans-serif text.

use std::fmt::Write as _;

/// An RGB colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Color(pub u8, pub u8, pub u8);

impl Color {
    fn hex(self) -> String {
        format!("#{:02x}{:02x}{:02x}", self.0, self.1, self.2)
    }
}

/// Black, for axes and text.
pub const INK: Color = Color(30, 30, 30);

/// How text is anchored at its point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Anchor {
    /// The point is the text's left end.
    Start,
    /// The point is the text's middle.
    Middle,
    /// The point is the text's right end.
    End,
}

/// An SVG document under construction, `width` × `height` pixels.
#[derive(Debug)]
pub struct Svg {
    out: String,
}

/// `text` with the XML special characters escaped.
fn escaped(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The width in pixels a sans-serif `text` takes at `size` px: 0.64 em per character, the
/// width of a digit in DejaVu Sans and an upper estimate for the average of Latin letters,
/// digits and the mathematical signs used here.
pub fn text_width(text: &str, size: f64) -> f64 {
    0.64 * size * text.chars().count() as f64
}

/// The largest font size ≤ `size` in steps of 0.1 px (and ≥ 7 px) at which `text` fits into
/// `width` pixels.
pub fn fitted_size(text: &str, width: f64, size: f64) -> f64 {
    let needed = text_width(text, size);
    if needed <= width {
        size
    } else {
        // Rounded down to the 0.1 px the SVG text prints, so that the printed size still fits.
        ((10.0 * size * width / needed).floor() / 10.0).max(7.0)
    }
}

impl Svg {
    /// An empty white drawing of `width` × `height` pixels.
    pub fn new(width: f64, height: f64) -> Svg {
        let mut out = String::new();
        let _ = writeln!(
            out,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" viewBox="0 0 {width:.0} {height:.0}" font-family="sans-serif">"#
        );
        let _ = writeln!(
            out,
            r##"<rect class="background" x="0" y="0" width="{width:.0}" height="{height:.0}" fill="#ffffff"/>"##
        );
        Svg { out }
    }

    /// A straight line from `a` to `b`; `dashed` draws it dashed.
    pub fn line(&mut self, class: &str, a: (f64, f64), b: (f64, f64), color: Color, width: f64, dashed: bool) {
        let dash = if dashed { r#" stroke-dasharray="4 3""# } else { "" };
        let _ = writeln!(
            self.out,
            r#"<line class="{class}" x1="{:.2}" y1="{:.2}" x2="{:.2}" y2="{:.2}" stroke="{}" stroke-width="{width}"{dash}/>"#,
            a.0,
            a.1,
            b.0,
            b.1,
            color.hex()
        );
    }

    /// A circle of radius `r` at `c`, filled with `fill` (none when `None`), outlined in `stroke`.
    pub fn circle(&mut self, class: &str, c: (f64, f64), r: f64, stroke: Color, fill: Option<Color>) {
        let fill = fill.map_or_else(|| "none".to_string(), Color::hex);
        let _ = writeln!(
            self.out,
            r#"<circle class="{class}" cx="{:.2}" cy="{:.2}" r="{r}" stroke="{}" stroke-width="1.5" fill="{fill}"/>"#,
            c.0,
            c.1,
            stroke.hex()
        );
    }

    /// A filled rectangle with corners `a` and `b`.
    pub fn rect(&mut self, class: &str, a: (f64, f64), b: (f64, f64), fill: Color) {
        let _ = writeln!(
            self.out,
            r#"<rect class="{class}" x="{:.2}" y="{:.2}" width="{:.2}" height="{:.2}" fill="{}"/>"#,
            a.0.min(b.0),
            a.1.min(b.1),
            (a.0 - b.0).abs(),
            (a.1 - b.1).abs(),
            fill.hex()
        );
    }

    /// `text` at `at` (its baseline), `size` px high.
    pub fn text(&mut self, class: &str, at: (f64, f64), text: &str, size: f64, anchor: Anchor) {
        let anchor = match anchor {
            Anchor::Start => "start",
            Anchor::Middle => "middle",
            Anchor::End => "end",
        };
        let _ = writeln!(
            self.out,
            r#"<text class="{class}" x="{:.2}" y="{:.2}" font-size="{size:.1}" text-anchor="{anchor}" fill="{}">{}</text>"#,
            at.0,
            at.1,
            INK.hex(),
            escaped(text)
        );
    }

    /// `text` rotated a quarter turn anticlockwise about `at` (a vertical axis title).
    pub fn vertical_text(&mut self, class: &str, at: (f64, f64), text: &str, size: f64) {
        let _ = writeln!(
            self.out,
            r#"<text class="{class}" x="{:.2}" y="{:.2}" font-size="{size:.1}" text-anchor="middle" fill="{}" transform="rotate(-90 {:.2} {:.2})">{}</text>"#,
            at.0,
            at.1,
            INK.hex(),
            at.0,
            at.1,
            escaped(text)
        );
    }

    /// Opens a group `<g class=… name="value"…>` of the elements drawn until [`Svg::close_group`].
    pub fn open_group(&mut self, class: &str, attributes: &[(&str, &str)]) {
        let mut tag = format!(r#"<g class="{class}""#);
        for (name, value) in attributes {
            tag.push_str(&format!(r#" {name}="{}""#, escaped(value)));
        }
        let _ = writeln!(self.out, "{tag}>");
    }

    /// Closes the group opened last.
    pub fn close_group(&mut self) {
        self.out.push_str("</g>\n");
    }

    /// The finished document.
    pub fn finish(mut self) -> String {
        self.out.push_str("</svg>\n");
        self.out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_is_escaped_and_fitted() {
        let mut svg = Svg::new(100.0, 50.0);
        svg.text("t", (1.0, 2.0), "a < b & c", 12.0, Anchor::Start);
        let out = svg.finish();
        assert!(out.contains(">a &lt; b &amp; c</text>"), "{out}");
        let size = fitted_size(&"x".repeat(60), 300.0, 14.0);
        assert!(text_width(&"x".repeat(60), size) <= 300.0 + 1e-9 && size < 14.0);
        assert_eq!(fitted_size(&"x".repeat(100), 300.0, 14.0), 7.0, "no smaller than 7 px");
        assert_eq!(fitted_size("short", 300.0, 14.0), 14.0);
    }
}
