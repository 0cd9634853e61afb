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

/// The file the inputs are written to, in a directory of this process's own.
fn robot_file() -> &'static PathBuf {
    static FILE: OnceLock<PathBuf> = OnceLock::new();
    FILE.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("mechanica-fuzz-urdf-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temporary directory");
        dir.join("robot.urdf")
    })
}

fuzz_target!(|data: &[u8]| {
    let path = robot_file();
    std::fs::write(path, data).expect("write the robot file");
    for repair in [false, true] {
        if let Ok((scene, _notes)) = urdf::load(path, repair) {
            scene.check(path).expect("a loaded robot is a valid scene");
        }
    }
});
