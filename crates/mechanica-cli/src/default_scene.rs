//! The built-in default scene: two example scenes, a spring-loaded pendulum chain (mass
//! properties, equilibrium, stability, modes, free response, an impact, the dynamics and a
//! short simulation of the chain released from rest) and a bead on a
//! rotating hoop (a relative equilibrium in a rotating frame), run through the same pipeline
//! as any scene file and merged into one report, followed by Kane's double pendulum striking a
//! rough floor under each restitution law (Newton's gains energy; the default, Stronge's, never
//! does).

use crate::mechanism_run::records::{ShowcaseLaw, ShowcaseRecord};
use crate::report::{Command, Report};
use crate::scene::Scene;
use std::path::Path;

/// The built-in scenes, (label, text).
const SCENES: [(&str, &str); 2] = [
    (
        "built-in:spring_pendulum_chain.toml",
        include_str!("../../../examples/scenes/spring_pendulum_chain.toml"),
    ),
    (
        "built-in:rotating_hoop.toml",
        include_str!("../../../examples/scenes/rotating_hoop.toml"),
    ),
];

/// Runs the default scene and returns its report; with `plot_dir`, each part writes its plots
/// into its own subdirectory.
pub fn run(plot_dir: Option<&Path>) -> Result<Report, String> {
    let mut steps = Vec::new();
    for (label, text) in SCENES {
        let path = Path::new(label);
        let scene = Scene::parse(text, path).map_err(|e| e.to_string())?;
        let name = label.trim_start_matches("built-in:").trim_end_matches(".toml");
        let dir = plot_dir.map(|d| d.join(name));
        let report = crate::scene_run::run(&scene, path, dir.as_deref())?;
        for mut step in report.steps {
            step.scene = Some(scene.title.clone());
            steps.push(step);
        }
    }
    steps.push(crate::report::timed_step(
        "impulse: Kane's double pendulum on a rough floor, e = f = 0.5, every law",
        || {
            let outcomes = mechanica::impulse::showcase::kane_double_pendulum_demo().map_err(|e| e.to_string())?;
            let laws = outcomes
                .iter()
                .map(|o| ShowcaseLaw {
                    law: o.law.to_string(),
                    energy_before: o.energy_before,
                    energy_change: o.energy_change,
                })
                .collect();
            Ok::<_, String>(ShowcaseRecord { laws })
        },
    )?);
    Ok(Report::new(
        Command::Run,
        "default scene: spring-loaded pendulum chain and a bead on a rotating hoop".into(),
        steps,
    ))
}
