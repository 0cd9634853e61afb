//! URDF robots (the CLI's `urdf` and `scene` modules, included by path): loading never panics;
//! a robot that loads is a scene that validates. The input is written to a file in a private
//! temporary directory because the importer reads a path (mesh references resolve next to it).
#![no_main]

#[allow(dead_code)]
#[path = "../../crates/mechanica-cli/src/scene.rs"]
mod scene;
#[allow(dead_code)]
#[path = "../../crates/mechanica-cli/src/urdf.rs"]
mod urdf;

use libfuzzer_sys::fuzz_target;
use std::path::PathBuf;
use std::sync::OnceLock;

/// A directory of this process's own, removed after every input (so nothing is left behind).
fn scratch_dir() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| std::env::temp_dir().join(format!("mechanica-fuzz-urdf-{}", std::process::id())))
}

fuzz_target!(|data: &[u8]| {
    let dir = scratch_dir();
    std::fs::create_dir_all(dir).expect("temporary directory");
    let path = dir.join("robot.urdf");
    std::fs::write(&path, data).expect("write the robot file");
    for (repair_inertia, allow_missing_mesh) in [(false, false), (true, true)] {
        let options = urdf::UrdfOptions {
            repair_inertia,
            allow_missing_mesh,
        };
        if let Ok((scene, _notes)) = urdf::load(&path, options) {
            scene.check(&path).expect("a loaded robot is a valid scene");
        }
    }
    let _ = std::fs::remove_dir_all(dir);
});
