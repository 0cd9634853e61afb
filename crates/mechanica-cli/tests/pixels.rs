//! Every picture `run --plot` and `modes --plot` write, rendered to pixels (resvg, shapes only: text is not
//! rasterised, its placement is checked in tests/plots.rs): it parses, renders at its declared
//! size, and is neither blank nor flooded (between 0.2 % and 50 % of its pixels drawn without
//! the text: a one-body mechanism's mode is a few strokes); the mechanism's stick figures of the mode shapes,
//! rendered alone on a canvas three times larger, land inside the picture's own canvas.

use resvg::{tiny_skia, usvg};
use std::path::{Path, PathBuf};
mod common;
use common::mechanica;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mechanica-pixels-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// The files of every `plots` step of `run args… --plot dir --json`.
fn plotted(args: &[&str], dir: &Path) -> Vec<PathBuf> {
    let mut args = args.to_vec();
    args.extend(["--plot", dir.to_str().expect("utf-8"), "--json"]);
    let (ok, out, err) = mechanica(&args);
    assert!(ok, "{err}");
    let report: serde_json::Value = serde_json::from_str(&out).expect("JSON");
    report["steps"]
        .as_array()
        .expect("steps")
        .iter()
        .filter(|s| s["analysis"] == "plots")
        .flat_map(|s| s["files"].as_array().expect("files").clone())
        .map(|f| PathBuf::from(f.as_str().expect("path")))
        .collect()
}

/// A fixed chain of n unit masses and unit springs as Matrix Market files (A, B) in `dir`.
fn lumped_chain(dir: &Path, n: usize) -> (String, String) {
    let write = |name: &str, entries: Vec<(usize, usize, f64)>| {
        let mut text = format!(
            "%%MatrixMarket matrix coordinate real symmetric\n{n} {n} {}\n",
            entries.len()
        );
        for (i, j, v) in entries {
            text.push_str(&format!("{} {} {v:?}\n", i + 1, j + 1));
        }
        let path = dir.join(name);
        std::fs::write(&path, text).expect("matrix file");
        path.to_str().expect("utf-8").to_string()
    };
    let mass = (0..n).map(|i| (i, i, 1.0)).collect();
    let mut stiffness: Vec<_> = (0..n).map(|i| (i, i, 2.0)).collect();
    stiffness.extend((1..n).map(|i| (i, i - 1, -1.0)));
    (write("a.mtx", mass), write("b.mtx", stiffness))
}

/// The number in attribute `name` of the root `<svg>` tag.
fn root_attribute(text: &str, name: &str) -> f64 {
    let root = &text[text.find("<svg").expect("an svg root")..];
    let root = &root[..root.find('>').expect("a closed tag")];
    let key = format!(" {name}=\"");
    let start = root.find(&key).unwrap_or_else(|| panic!("no {name} in {root}")) + key.len();
    let value = &root[start..];
    value[..value.find('"').expect("quoted")]
        .parse()
        .unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// `text` rendered at the scale 1 onto a pixmap of `width` × `height`.
fn render(text: &str, width: u32, height: u32) -> tiny_skia::Pixmap {
    let tree = usvg::Tree::from_str(text, &usvg::Options::default()).expect("a valid SVG");
    let mut pixmap = tiny_skia::Pixmap::new(width, height).expect("a pixmap");
    resvg::render(&tree, tiny_skia::Transform::identity(), &mut pixmap.as_mut());
    pixmap
}

/// The positions of the pixels that are not transparent and not white.
fn inked(pixmap: &tiny_skia::Pixmap) -> Vec<(u32, u32)> {
    let width = pixmap.width();
    pixmap
        .pixels()
        .iter()
        .enumerate()
        .filter(|(_, p)| p.alpha() > 0 && (p.red() < 250 || p.green() < 250 || p.blue() < 250))
        .map(|(i, _)| (i as u32 % width, i as u32 / width))
        .collect()
}

#[test]
fn every_plot_renders_at_its_size_and_is_drawn() {
    let dir = scratch("all");
    let chain = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes/spring_pendulum_chain.toml");
    let mut files = plotted(&["run", chain.to_str().expect("utf-8")], &dir.join("chain"));
    files.extend(plotted(&["run"], &dir.join("default")));
    let (a, b) = lumped_chain(&dir, 9);
    files.extend(plotted(
        &["modes", "--mass", &a, "--stiffness", &b],
        &dir.join("pencil"),
    ));
    let names: Vec<String> = files
        .iter()
        .filter_map(|f| f.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    for expected in [
        "spectrum.svg",
        "mode_shapes.svg",
        "response.svg",
        "impact_energy.svg",
        "motion.svg",
        "energy_drift.svg",
        "error_estimate.svg",
    ] {
        assert!(names.iter().any(|n| n == expected), "{expected} not written: {names:?}");
    }
    for file in &files {
        let text = std::fs::read_to_string(file).expect("svg file");
        let (width, height) = (root_attribute(&text, "width"), root_attribute(&text, "height"));
        let tree = usvg::Tree::from_str(&text, &usvg::Options::default())
            .unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        assert_eq!(
            (tree.size().width() as f64, tree.size().height() as f64),
            (width, height),
            "{}",
            file.display()
        );
        let pixmap = render(&text, width as u32, height as u32);
        let fraction = inked(&pixmap).len() as f64 / (width * height);
        assert!(
            (0.002..0.5).contains(&fraction),
            "{}: {:.2} % of the pixels drawn",
            file.display(),
            100.0 * fraction
        );
    }
}

/// The stick figures (the mechanism at rest and displaced) of `mode_shapes.svg` alone, in a
/// canvas with a margin of the picture's own size on every side.
fn stick_figures_with_margin(text: &str, width: f64, height: f64) -> String {
    let mut out = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{}" height="{}" viewBox="{} {} {} {}">"#,
        3.0 * width,
        3.0 * height,
        -width,
        -height,
        3.0 * width,
        3.0 * height
    );
    for line in text.lines() {
        let stick = ["mode-", "rest-"]
            .iter()
            .any(|p| line.contains(&format!("class=\"{p}")));
        if stick {
            out.push_str(line);
            out.push('\n');
        }
    }
    out.push_str("</svg>\n");
    out
}

#[test]
fn the_stick_figures_land_inside_the_canvas() {
    let dir = scratch("sticks");
    let chain = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes/spring_pendulum_chain.toml");
    let arm = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/cpp/panda_modes/panda.urdf");
    let humanoid = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/g1_29dof.urdf");
    for (scene, name) in [(chain, "chain"), (arm, "panda"), (humanoid, "g1")] {
        let files = plotted(&["run", scene.to_str().expect("utf-8")], &dir.join(name));
        let shapes = files
            .iter()
            .find(|f| f.ends_with("mode_shapes.svg"))
            .unwrap_or_else(|| panic!("{name}: no mode_shapes.svg in {files:?}"));
        let text = std::fs::read_to_string(shapes).expect("svg");
        let (width, height) = (root_attribute(&text, "width"), root_attribute(&text, "height"));
        let sticks = stick_figures_with_margin(&text, width, height);
        let pixmap = render(&sticks, (3.0 * width) as u32, (3.0 * height) as u32);
        let ink = inked(&pixmap);
        // Something of each panel's figure is drawn: at least a few pixels per panel.
        let panels = text.matches("class=\"panel\"").count();
        assert!(panels > 0 && ink.len() > 20 * panels, "{name}: {} pixels", ink.len());
        // A stroke may reach past its end point by half its width (≤ 2 px).
        let inside = |(x, y): (u32, u32)| {
            let (x, y) = (f64::from(x) - width, f64::from(y) - height);
            (-2.0..width + 2.0).contains(&x) && (-2.0..height + 2.0).contains(&y)
        };
        let outside: Vec<_> = ink.iter().copied().filter(|p| !inside(*p)).collect();
        assert!(
            outside.is_empty(),
            "{name}: {} pixels outside the canvas, e.g. {:?}",
            outside.len(),
            &outside[..outside.len().min(5)]
        );
    }
}

/// The centres (cx, cy) of the circles of class `class` in `panel` (one panel's SVG text).
fn circles(panel: &str, class: &str) -> Vec<(f64, f64)> {
    let number = |tag: &str, name: &str| -> f64 {
        let key = format!(" {name}=\"");
        let start = tag.find(&key).expect("attribute") + key.len();
        tag[start..].split('"').next().expect("value").parse().expect("number")
    };
    panel
        .lines()
        .filter(|l| l.starts_with("<circle") && l.contains(&format!("class=\"{class}\"")))
        .map(|l| (number(l, "cx"), number(l, "cy")))
        .collect()
}

/// The largest distance between matching circles of two classes, px.
fn largest_motion(panel: &str, rest: &str, moved: &str) -> f64 {
    circles(panel, rest)
        .iter()
        .zip(circles(panel, moved))
        .map(|(a, b)| (a.0 - b.0).hypot(a.1 - b.1))
        .fold(0.0, f64::max)
}

/// On a humanoid (Unitree G1, 29 joints: light hands on long arms) and an arm with a light
/// wrist (Panda), every mode's motion can be seen: its stick figure moves some joint or centre
/// of mass by 5 px or more, or the panel has a magnified detail in which the motion spans 20 px
/// or more.
#[test]
fn every_mode_shape_shows_a_visible_motion() {
    let dir = scratch("visible");
    let arm = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/cpp/panda_modes/panda.urdf");
    let humanoid = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/g1_29dof.urdf");
    for (scene, name) in [(arm, "panda"), (humanoid, "g1")] {
        let files = plotted(&["run", scene.to_str().expect("utf-8")], &dir.join(name));
        let shapes = files
            .iter()
            .find(|f| f.ends_with("mode_shapes.svg"))
            .expect("mode_shapes.svg");
        let text = std::fs::read_to_string(shapes).expect("svg");
        let panels: Vec<&str> = text.split("class=\"panel\"").skip(1).collect();
        assert!(panels.len() >= 4, "{name}: {} panels", panels.len());
        for (k, panel) in panels.iter().enumerate() {
            if panel.contains("rest pose only") {
                continue;
            }
            let main =
                largest_motion(panel, "rest-joint", "mode-joint").max(largest_motion(panel, "rest-com", "mode-com"));
            let detail = panel.split("class=\"detail\"").nth(1).map(|d| {
                largest_motion(d, "detail-rest-com", "detail-mode-com").max(largest_motion(
                    d,
                    "detail-rest-joint",
                    "detail-mode-joint",
                ))
            });
            assert!(
                main >= 5.0 || detail.is_some_and(|d| d >= 20.0),
                "{name}, panel {k}: motion {main:.2} px, detail {detail:?}"
            );
        }
    }
}
