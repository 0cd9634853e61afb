//! TOML scene files (the CLI's `scene` module, included by path): parsing and validation never
//! panic, and every error that carries a position points inside the text.
#![no_main]

#[allow(dead_code)]
#[path = "../../crates/mechanica-cli/src/scene.rs"]
mod scene;

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Err(error) = scene::Scene::parse(text, Path::new("fuzz.toml"))
        && let Some((line, column)) = error.position
    {
        let lines: Vec<&str> = text.split('\n').collect();
        assert!(
            (1..=lines.len()).contains(&line),
            "error at line {line} of {}: {error}",
            lines.len()
        );
        let length = lines[line - 1].len();
        assert!(
            (1..=length + 1).contains(&column),
            "error at column {column} of a {length}-byte line: {error}"
        );
    }
});
