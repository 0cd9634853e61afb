//! The pictures of `run --plot`, read back as XML: the mode shapes of a double pendulum against
//! its closed-form modes, the impact energy bars against the JSON report, and pictures of
//! unstable, massless and spatial mechanisms that must still be drawn inside their canvas.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use xml::reader::{EventReader, XmlEvent};
mod common;
use common::{mechanica, step};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mechanica-plots-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// One drawn element: its tag, attributes, text and the mode panel holding it.
#[derive(Debug, Clone)]
struct Element {
    name: String,
    attributes: HashMap<String, String>,
    panel: Option<usize>,
    text: String,
}

impl Element {
    fn class(&self) -> &str {
        self.attributes.get("class").map_or("", String::as_str)
    }

    fn number(&self, key: &str) -> f64 {
        let value = self
            .attributes
            .get(key)
            .unwrap_or_else(|| panic!("{key} missing: {self:?}"));
        value
            .parse()
            .unwrap_or_else(|_| panic!("{key} = {value} is not a number"))
    }

    /// The element's centre (circle) or first point (line, text, rect).
    fn at(&self) -> (f64, f64) {
        match self.name.as_str() {
            "circle" => (self.number("cx"), self.number("cy")),
            "line" => (self.number("x1"), self.number("y1")),
            _ => (self.number("x"), self.number("y")),
        }
    }

    /// Every point the element reaches.
    fn points(&self) -> Vec<(f64, f64)> {
        match self.name.as_str() {
            "line" => vec![self.at(), (self.number("x2"), self.number("y2"))],
            "rect" => {
                let (x, y) = self.at();
                vec![(x, y), (x + self.number("width"), y + self.number("height"))]
            }
            "circle" | "text" => vec![self.at()],
            _ => Vec::new(),
        }
    }
}

/// An SVG file parsed as XML (a malformed file fails the test), with its size.
struct Drawing {
    width: f64,
    height: f64,
    elements: Vec<Element>,
}

impl Drawing {
    fn read(path: &Path) -> Drawing {
        let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let mut elements: Vec<Element> = Vec::new();
        let (mut panels, mut open): (Vec<Option<usize>>, Vec<usize>) = (vec![None], Vec::new());
        for event in EventReader::new(std::io::BufReader::new(file)) {
            match event.unwrap_or_else(|e| panic!("{}: not XML: {e}", path.display())) {
                XmlEvent::StartElement { name, attributes, .. } => {
                    let attributes: HashMap<String, String> =
                        attributes.into_iter().map(|a| (a.name.local_name, a.value)).collect();
                    let panel = match attributes.get("data-mode") {
                        Some(mode) => Some(mode.parse().expect("panel number")),
                        None => *panels.last().expect("panel stack"),
                    };
                    panels.push(panel);
                    open.push(elements.len());
                    elements.push(Element {
                        name: name.local_name,
                        attributes,
                        panel,
                        text: String::new(),
                    });
                }
                XmlEvent::Characters(text) => {
                    let last = *open.last().expect("text inside an element");
                    elements[last].text.push_str(&text);
                }
                XmlEvent::EndElement { .. } => {
                    panels.pop();
                    open.pop();
                }
                _ => {}
            }
        }
        let root = elements.first().expect("an svg element");
        assert_eq!(root.name, "svg");
        let view: Vec<f64> = root.attributes["viewBox"]
            .split(' ')
            .map(|v| v.parse().expect("viewBox"))
            .collect();
        assert_eq!(view[..2], [0.0, 0.0]);
        Drawing {
            width: view[2],
            height: view[3],
            elements,
        }
    }

    fn of_class(&self, class: &str, panel: Option<usize>) -> Vec<&Element> {
        self.elements
            .iter()
            .filter(|e| e.class() == class && (panel.is_none() || e.panel == panel))
            .collect()
    }

    fn texts(&self, class: &str, panel: Option<usize>) -> Vec<String> {
        self.of_class(class, panel).iter().map(|e| e.text.clone()).collect()
    }

    /// Every coordinate is finite and inside the view box.
    fn assert_inside(&self) {
        for element in &self.elements {
            for (x, y) in element.points() {
                assert!(
                    (0.0..=self.width).contains(&x) && (0.0..=self.height).contains(&y),
                    "outside the {}×{} canvas: {element:?}",
                    self.width,
                    self.height
                );
            }
        }
    }
}

fn distance(a: (f64, f64), b: (f64, f64)) -> f64 {
    (a.0 - b.0).hypot(a.1 - b.1)
}

/// The numbers in `text` (a minus sign written − included).
fn numbers_in(text: &str) -> Vec<f64> {
    text.replace('−', "-")
        .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == 'e'))
        .filter_map(|t| t.trim_matches('.').parse().ok())
        .collect()
}

/// A double pendulum of two equal point masses m on massless links of length l, hinged about y.
fn double_pendulum(m: f64, l: f64) -> String {
    format!(
        r#"title = "double pendulum"
gravity = [0.0, 0.0, -9.81]
[[body]]
name = "upper"
primitive = {{ shape = "point", mass = {m} }}
offset = [0.0, 0.0, -{l}]
[[body]]
name = "lower"
primitive = {{ shape = "point", mass = {m} }}
offset = [0.0, 0.0, -{l}]
[[joint]]
name = "shoulder"
type = "revolute"
parent = "ground"
child = "upper"
axis = [0.0, 1.0, 0.0]
[[joint]]
name = "elbow"
type = "revolute"
parent = "upper"
child = "lower"
axis = [0.0, 1.0, 0.0]
origin = [0.0, 0.0, -{l}]
[analyses]
equilibrium = {{}}
modes = {{}}
"#
    )
}

/// Checks panel `mode` of a double pendulum with links l against the closed form: the absolute
/// link angles of the modes ω² = (2 ∓ √2) g/l stand in the ratio θ₂/θ₁ = ±√2, so the drawn
/// tip follows from the drawn elbow by exact kinematics, to the drawing's rounding.
fn check_pendulum_panel(drawing: &Drawing, mode: usize, l: f64) {
    let panel = Some(mode);
    let (sign, ratio) = if mode == 1 {
        (-1.0, 2f64.sqrt())
    } else {
        (1.0, -(2f64.sqrt()))
    };
    for class in [
        "rest-link",
        "mode-link",
        "rest-com",
        "mode-com",
        "rest-joint",
        "mode-joint",
    ] {
        assert_eq!(drawing.of_class(class, panel).len(), 2, "{class} in panel {mode}");
    }
    let rest = drawing.of_class("rest-com", panel);
    let moved = drawing.of_class("mode-com", panel);
    let base = drawing.of_class("rest-link", panel)[0].at();
    let (elbow, tip) = (rest[0].at(), rest[1].at());
    let l_px = distance(elbow, base);
    assert!(
        l_px > 20.0 && (distance(tip, elbow) - l_px).abs() < 0.02,
        "rest links {l_px}"
    );
    let d = ((elbow.0 - base.0) / l_px, (elbow.1 - base.1) / l_px);
    let p = (-d.1, d.0);
    let u = (moved[0].at().0 - base.0, moved[0].at().1 - base.1);
    assert!((u.0.hypot(u.1) - l_px).abs() < 0.02, "the upper link keeps its length");
    let theta = (u.0 * p.0 + u.1 * p.1).atan2(u.0 * d.0 + u.1 * d.1);
    assert!(theta.abs() > 0.03, "mode {mode} barely moves: θ₁ = {theta}");
    let (s, c) = (ratio * theta).sin_cos();
    let predicted = (
        moved[0].at().0 + l_px * (c * d.0 + s * p.0),
        moved[0].at().1 + l_px * (c * d.1 + s * p.1),
    );
    assert!(
        distance(predicted, moved[1].at()) < 0.05,
        "mode {mode}: tip {:?}, closed form {predicted:?}",
        moved[1].at()
    );
    let title = drawing.texts("title", panel).join(" ");
    assert!(title.contains(&format!("mode {mode} · oscillatory")), "{title}");
    let subtitle = drawing.texts("subtitle", panel).join(" ");
    let f = ((2.0 + sign * 2f64.sqrt()) * 9.81 / l).sqrt() / std::f64::consts::TAU;
    let [_, lo, hi] = numbers_in(&subtitle)[..] else {
        panic!("{subtitle}")
    };
    assert!(lo <= f && f <= hi, "{subtitle} does not contain the exact {f}");
    check_caption(drawing, mode, base, 2.0 * l, 2.0 * l_px);
}

/// The caption states the drawn motion: its largest displacement in per cent of the extent
/// (the pendulum's length) matches the picture, and lies between 10 and 15 %.
fn check_caption(drawing: &Drawing, mode: usize, base: (f64, f64), extent: f64, extent_px: f64) {
    let panel = Some(mode);
    let mut largest: f64 = 0.0;
    for (rest, moved) in [("rest-com", "mode-com"), ("rest-joint", "mode-joint")] {
        for (a, b) in drawing.of_class(rest, panel).iter().zip(drawing.of_class(moved, panel)) {
            largest = largest.max(distance(a.at(), b.at()));
        }
    }
    let caption = drawing.texts("caption", panel).join(" ");
    let stated = numbers_in(&caption);
    let percent = stated.get(stated.len() - 2).copied().expect("percentage");
    let measured = 100.0 * largest / extent_px;
    assert!(
        (percent - measured).abs() < 0.01 * measured,
        "{caption}: measured {measured} %"
    );
    assert!((10.0..=15.0).contains(&percent), "{caption}");
    assert!(
        (stated[stated.len() - 1] - extent).abs() < 1e-3 * extent,
        "{caption} vs {extent}"
    );
    assert!(
        drawing
            .of_class("ground", panel)
            .iter()
            .any(|g| distance(g.at(), base) < 20.0)
    );
}

#[test]
fn double_pendulum_mode_shapes_follow_the_closed_form() {
    let dir = scratch("pendulum");
    for (case, (m, l)) in [(1.5, 0.8), (0.2, 2.5), (7.0, 0.3)].into_iter().enumerate() {
        let scene = dir.join(format!("pendulum{case}.toml"));
        std::fs::write(&scene, double_pendulum(m, l)).expect("scene");
        let plots = dir.join(format!("plots{case}"));
        let (ok, _, err) = mechanica(&[
            "run",
            scene.to_str().expect("path"),
            "--plot",
            plots.to_str().expect("path"),
        ]);
        assert!(ok, "{err}");
        let drawing = Drawing::read(&plots.join("mode_shapes.svg"));
        drawing.assert_inside();
        assert_text_fits(&drawing, &["title", "subtitle", "caption"], 490.0);
        assert_eq!(drawing.of_class("panel", None).len(), 2);
        for mode in [1, 2] {
            check_pendulum_panel(&drawing, mode, l);
        }
        let legend = drawing.texts("legend-label", None).join(" ");
        assert!(
            legend.contains("centre of mass") && legend.contains("joint"),
            "{legend}"
        );
    }
}

/// The bars of `impact_energy.svg` have the energies of the JSON report on the plot's own axis,
/// and each law's change in per cent over its pair.
#[test]
fn impact_energy_bars_match_the_report() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes/spring_pendulum_chain.toml");
    let plots = scratch("impact");
    let (ok, out, err) = mechanica(&[
        "run",
        path.to_str().expect("path"),
        "--json",
        "--plot",
        plots.to_str().expect("path"),
    ]);
    assert!(ok, "{err}");
    let json: serde_json::Value = serde_json::from_str(&out).expect("JSON");
    let laws = step(&json, "impact")["laws"].as_array().expect("laws").clone();
    let drawing = Drawing::read(&plots.join("impact_energy.svg"));
    drawing.assert_inside();
    let (before, after) = (
        drawing.of_class("bar-before", None),
        drawing.of_class("bar-after", None),
    );
    let (names, changes) = (drawing.texts("law-label", None), drawing.texts("change-label", None));
    assert_eq!(laws.len(), 3);
    assert!(
        [before.len(), after.len(), names.len(), changes.len()]
            .iter()
            .all(|&n| n == laws.len())
    );
    let ticks: Vec<(f64, f64)> = drawing
        .of_class("tick-label", None)
        .iter()
        .map(|t| (t.text.parse().expect("a plain number"), t.at().1))
        .collect();
    assert!(ticks.len() >= 3, "{ticks:?}");
    let per_joule = (ticks[0].1 - ticks[1].1) / (ticks[1].0 - ticks[0].0);
    for pair in ticks.windows(2) {
        assert!(((pair[0].1 - pair[1].1) / (pair[1].0 - pair[0].0) - per_joule).abs() < 1e-3 * per_joule);
    }
    for (k, law) in laws.iter().enumerate() {
        let t_before = law["energy_before"].as_f64().expect("T before");
        let change = law["energy_change"].as_f64().expect("ΔT");
        assert!(names[k].contains(law["law"].as_str().expect("law")), "{names:?}");
        assert!((before[k].number("height") - per_joule * t_before).abs() < 0.05);
        assert!((after[k].number("height") - per_joule * (t_before + change)).abs() < 0.05);
        let percent = numbers_in(&changes[k])[0];
        let exact = 100.0 * change / t_before;
        assert!(
            (percent - exact).abs() < 5e-3 * exact.abs(),
            "{} vs {exact}",
            changes[k]
        );
    }
    assert_text_fits(&drawing, &["title"], 780.0);
    let titles = drawing.texts("axis-title", None).join(" ");
    assert!(
        titles.contains("kinetic energy T (J)") && titles.contains("restitution law"),
        "{titles}"
    );
    let legend = drawing.texts("legend-label", None).join(" ");
    assert!(legend.contains("before") && legend.contains("after"), "{legend}");
}

/// Every panel of a mode-shape drawing: one link line, one joint circle per body at rest and
/// (when the displaced shape is drawn) displaced, a heading, and the rest pose or a reason.
fn check_every_panel(drawing: &Drawing, bodies: usize, modes: usize) {
    drawing.assert_inside();
    assert_eq!(drawing.of_class("panel", None).len(), modes);
    for mode in 1..=modes {
        let panel = Some(mode);
        assert_eq!(drawing.of_class("rest-link", panel).len(), bodies, "panel {mode}");
        assert_eq!(drawing.of_class("rest-joint", panel).len(), bodies, "panel {mode}");
        let moved = drawing.of_class("mode-link", panel).len();
        let caption = drawing.texts("caption", panel).join(" ");
        assert!(
            moved == bodies || (moved == 0 && caption.starts_with("rest pose only")),
            "panel {mode}: {moved} displaced links, caption {caption}"
        );
        assert!(
            drawing
                .texts("title", panel)
                .join(" ")
                .starts_with(&format!("mode {mode} · "))
        );
        assert_eq!(drawing.of_class("subtitle", panel).len(), 1);
    }
    assert_text_fits(drawing, &["title", "subtitle", "caption"], 490.0);
}

/// Every text of `classes` fits into `width` pixels at its font size, at 0.64 em a character
/// (a DejaVu Sans digit; wider than most letters).
fn assert_text_fits(drawing: &Drawing, classes: &[&str], width: f64) {
    for class in classes {
        for text in drawing.of_class(class, None) {
            let needed = 0.64 * text.number("font-size") * text.text.chars().count() as f64;
            assert!(needed <= width, "{class} too wide ({needed} px): {}", text.text);
        }
    }
}

/// The double pendulum upside down (evaluated at q = (π, 0), where it balances unstably) with a
/// massless third link on a spring: unstable and infinite modes are drawn and named.
#[test]
fn unstable_and_massless_modes_are_drawn() {
    let dir = scratch("unstable");
    let scene = dir.join("inverted.toml");
    let massless = r#"
[[body]]
name = "vane"
mass_properties = { mass = 0.0, com = [0.0, 0.0, 0.0], inertia = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0] }
[[joint]]
name = "vane hinge"
type = "revolute"
parent = "lower"
child = "vane"
axis = [0.0, 1.0, 0.0]
origin = [0.0, 0.0, -0.5]
[[joint_spring]]
joint = "vane hinge"
stiffness = 3.0
"#;
    let text = double_pendulum(1.0, 0.5).replace("[analyses]", &format!("{massless}\n[analyses]"));
    std::fs::write(&scene, text).expect("scene");
    let plots = dir.join("plots");
    let (ok, _, err) = mechanica(&[
        "run",
        scene.to_str().expect("path"),
        "--q",
        "3.141592653589793,0,0",
        "--plot",
        plots.to_str().expect("path"),
    ]);
    assert!(ok, "{err}");
    let drawing = Drawing::read(&plots.join("mode_shapes.svg"));
    check_every_panel(&drawing, 3, 3);
    let titles = drawing.texts("title", None).join(" ");
    let subtitles = drawing.texts("subtitle", None).join(" ");
    assert!(
        titles.contains("unstable") && subtitles.contains("growth rate γ"),
        "{titles} {subtitles}"
    );
    assert!(
        titles.contains("infinite") && subtitles.contains("massless"),
        "{titles} {subtitles}"
    );
}

/// A spatial arm: a yaw joint about z, a pitch joint about y, a roll joint about x on links
/// offset along x, y and z, a sliding joint on a spring and a fixed tool.
fn spatial_arm() -> String {
    let link = |name: &str, m: f64, com: &str| {
        format!(
            r#"  <link name="{name}">
    <inertial><origin xyz="{com}" rpy="0 0 0"/><mass value="{m}"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.015"/></inertial>
  </link>
"#
        )
    };
    let joint = |name: &str, kind: &str, parent: &str, child: &str, xyz: &str, axis: &str| {
        format!(
            r#"  <joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>
    <origin xyz="{xyz}" rpy="0.1 0.2 0.3"/><axis xyz="{axis}"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
"#
        )
    };
    [
        "<?xml version=\"1.0\"?>\n<robot name=\"arm\">\n  <link name=\"base\"/>\n".to_string(),
        link("turret", 3.0, "0 0 0.1"),
        link("upper", 2.0, "0.3 0 0"),
        link("fore", 1.0, "0 0.25 -0.1"),
        link("slide", 0.5, "0 0 -0.1"),
        link("tool", 0.2, "0.05 0.05 0"),
        joint("yaw", "revolute", "base", "turret", "0 0 0.2", "0 0 1"),
        joint("pitch", "revolute", "turret", "upper", "0 0 0.3", "0 1 0"),
        joint("roll", "revolute", "upper", "fore", "0.6 0 0", "1 0 0"),
        joint("extend", "prismatic", "fore", "slide", "0 0.5 0", "0 0.6 0.8"),
        r#"  <joint name="mount" type="fixed"><parent link="slide"/><child link="tool"/>
    <origin xyz="0 0 -0.2" rpy="0 0 0"/></joint>
</robot>
"#
        .to_string(),
    ]
    .concat()
}

/// A spatial arm read from URDF: every mode (of the joints not resting on a limit) is drawn
/// inside the canvas with the world axes.
#[test]
fn spatial_urdf_arm_is_drawn() {
    let dir = scratch("urdf");
    let urdf = dir.join("arm.urdf");
    std::fs::write(&urdf, spatial_arm()).expect("URDF");
    let plots = dir.join("plots");
    let (ok, out, err) = mechanica(&[
        "run",
        urdf.to_str().expect("path"),
        "--json",
        "--plot",
        plots.to_str().expect("path"),
    ]);
    assert!(ok, "{err}");
    let json: serde_json::Value = serde_json::from_str(&out).expect("JSON");
    let bodies = step(&json, "build")["bodies"].as_array().expect("bodies").len();
    let modes = step(&json, "modes")["modes"].as_array().expect("modes").len();
    assert!(bodies == 6 && modes >= 1, "{bodies} bodies, {modes} modes");
    let drawing = Drawing::read(&plots.join("mode_shapes.svg"));
    check_every_panel(&drawing, bodies, modes);
    let axes = drawing.texts("axis-label", None);
    assert!(axes.iter().any(|a| a == "z"), "the world axes are shown: {axes:?}");
}

/// The caption names the body that moves most. A double pendulum of point masses m₁ (upper)
/// and m₂ (lower) on links of length l, in absolute angles φ: A = l² [[m₁ + m₂, m₂], [m₂, m₂]],
/// B = g l diag(m₁ + m₂, m₂). The upper mass moves l|φ₁|, the lower l|φ₁ + φ₂|: with a light
/// upper mass its fast mode is concentrated there (a light middle body, like a wrist between
/// heavy ones), which the caption must name, and the slow mode moves the lower mass most.
#[test]
fn the_caption_names_the_body_that_moves_most() {
    let dir = scratch("moves-most");
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut uniform = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut named = std::collections::BTreeSet::new();
    for case in 0..5 {
        let (m1, m2, l) = (10f64.powf(-3.0 + 4.0 * uniform()), 1.0, 0.5 + uniform());
        let scene = dir.join(format!("pendulum{case}.toml"));
        let text = double_pendulum(1.0, l).replacen("mass = 1", &format!("mass = {m1:?}"), 1);
        std::fs::write(&scene, text).expect("scene");
        let plots = dir.join(format!("plots{case}"));
        let (ok, _, err) = mechanica(&[
            "run",
            scene.to_str().expect("utf-8"),
            "--plot",
            plots.to_str().expect("utf-8"),
        ]);
        assert!(ok, "{err}");
        let drawing = Drawing::read(&plots.join("mode_shapes.svg"));
        // det(B − ω² A) = 0 per unit g/l: (m₁+m₂ − w(m₁+m₂))(m₂ − w m₂) − w² m₂² = 0.
        let (a, b, c) = (m1 * m2, -2.0 * (m1 + m2) * m2, (m1 + m2) * m2);
        let roots = [
            (-b - (b * b - 4.0 * a * c).sqrt()) / (2.0 * a),
            (-b + (b * b - 4.0 * a * c).sqrt()) / (2.0 * a),
        ];
        for (mode, w) in roots.into_iter().enumerate() {
            // Second row of (B − w A) φ = 0: −w m₂ φ₁ + (m₂ − w m₂) φ₂ = 0.
            let (phi1, phi2) = (1.0 - w, w);
            let (upper, lower) = (phi1.abs(), (phi1 + phi2).abs());
            if (upper / lower - 1.0).abs() < 0.2 {
                continue;
            }
            let expected = if upper > lower { "upper" } else { "lower" };
            let caption = drawing.texts("caption", Some(mode + 1)).join(" ");
            assert!(
                caption.contains(&format!("of \"{expected}\"")),
                "case {case}, m₁ = {m1}, mode {}: {caption} (upper {upper}, lower {lower})",
                mode + 1
            );
            named.insert(expected);
        }
    }
    assert_eq!(named.len(), 2, "the cases exercise both answers: {named:?}");
}
