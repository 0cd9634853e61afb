//! Checks on include/mechanica.h: it is what cbindgen 0.29.4 generates from the current
//! sources (without warnings), it compiles alone and twice in one unit as C11 and C++17, and
//! every function it declares is exercised by an ffi-test program.
//!
//! Regenerate the header with `MECH_BLESS_HEADER=1 cargo test -p mechanica-ffi-tests --test header`.

use mechanica_ffi_tests::*;
use std::sync::Mutex;

/// Collects cbindgen's log messages at warning level and above.
struct WarningCollector;
static WARNINGS: Mutex<Vec<String>> = Mutex::new(Vec::new());

impl log::Log for WarningCollector {
    fn enabled(&self, metadata: &log::Metadata<'_>) -> bool {
        metadata.level() <= log::Level::Warn
    }
    fn log(&self, record: &log::Record<'_>) {
        if self.enabled(record.metadata()) {
            WARNINGS
                .lock()
                .unwrap_or_else(|p| p.into_inner())
                .push(format!("{}: {}", record.level(), record.args()));
        }
    }
    fn flush(&self) {}
}
static COLLECTOR: WarningCollector = WarningCollector;

fn header_path() -> std::path::PathBuf {
    workspace_root().join("include/mechanica.h")
}

#[test]
fn header_is_fresh_and_generated_without_warnings() {
    let _ = log::set_logger(&COLLECTOR);
    log::set_max_level(log::LevelFilter::Warn);
    let crate_dir = workspace_root().join("crates/mechanica");
    let config = cbindgen::Config::from_file(crate_dir.join("cbindgen.toml")).unwrap_or_else(|e| panic!("{e}"));
    let bindings = cbindgen::Builder::new()
        .with_crate(&crate_dir)
        .with_config(config)
        .generate()
        .unwrap_or_else(|e| panic!("cbindgen failed: {e}"));
    let mut generated = Vec::new();
    bindings.write(&mut generated);
    let generated = String::from_utf8(generated).unwrap_or_else(|e| panic!("{e}"));

    let warnings = WARNINGS.lock().unwrap_or_else(|p| p.into_inner()).clone();
    assert!(
        warnings.is_empty(),
        "cbindgen warned (e.g. a cargo feature without a [defines] entry in cbindgen.toml):\n{}",
        warnings.join("\n")
    );

    if std::env::var_os("MECH_BLESS_HEADER").is_some() {
        std::fs::write(header_path(), &generated).unwrap_or_else(|e| panic!("{e}"));
        return;
    }
    let checked_in = std::fs::read_to_string(header_path()).unwrap_or_else(|e| panic!("{e}"));
    if checked_in != generated {
        let line = checked_in
            .lines()
            .zip(generated.lines())
            .position(|(a, b)| a != b)
            .map_or(0, |i| i + 1);
        panic!(
            "include/mechanica.h is stale (first difference at line {line}). Regenerate it with\n  \
             MECH_BLESS_HEADER=1 cargo test -p mechanica-ffi-tests --test header\nand commit it."
        );
    }
}

#[test]
fn header_compiles_alone_and_twice_as_c11_and_cxx17() {
    let dir = target_dir().join("ffi-tests/header");
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("{e}"));
    let body = "#include \"mechanica.h\"\n#include \"mechanica.h\"\nint main(void) { return (int)mech_abi_version() - MECH_ABI_VERSION; }\n";
    for (file, compiler, standard) in [("twice.c", "gcc", "-std=c11"), ("twice.cpp", "g++", "-std=c++17")] {
        for defines in [&[][..], &["-DMECH_FEATURES_EXPLICIT"][..]] {
            let source = dir.join(file);
            std::fs::write(
                &source,
                body.replace("(void)", if file.ends_with("cpp") { "()" } else { "(void)" }),
            )
            .unwrap_or_else(|e| panic!("{e}"));
            let output = std::process::Command::new(compiler)
                .arg(standard)
                .args(["-Wall", "-Wextra", "-Werror", "-pedantic", "-fsyntax-only"])
                .args(defines)
                .arg("-I")
                .arg(workspace_root().join("include"))
                .arg(&source)
                .output()
                .unwrap_or_else(|e| panic!("could not run {compiler}: {e}"));
            check_success(&format!("{compiler} {standard} {defines:?} {file}"), &output)
                .unwrap_or_else(|e| panic!("{e}"));
        }
    }
}

#[test]
fn every_declared_function_is_called_by_an_ffi_test() {
    let header = std::fs::read_to_string(header_path()).unwrap_or_else(|e| panic!("{e}"));
    let functions = declared_functions(&header);
    assert!(
        functions.len() >= 8,
        "parsed too few functions from the header: {functions:?}"
    );
    let mut sources = String::new();
    for path in sources_in("c").into_iter().chain(sources_in("cpp")) {
        sources.push_str(&std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{e}")));
    }
    let untested: Vec<&String> = functions
        .iter()
        .filter(|f| !sources.contains(&format!("{f}(")))
        .collect();
    assert!(
        untested.is_empty(),
        "exported functions without a C/C++ test: {untested:?}"
    );
}

#[test]
fn every_declaration_in_the_header_has_a_doxygen_comment() {
    let header = std::fs::read_to_string(header_path()).unwrap_or_else(|e| panic!("{e}"));
    let lines: Vec<&str> = header.lines().collect();
    let mut undocumented = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let starts_declaration = line.starts_with("#define MECH_")
            || line.starts_with("typedef ")
            || (!line.starts_with(' ') && !declared_functions(line).is_empty());
        if !starts_declaration {
            continue;
        }
        let previous = lines[..i]
            .iter()
            .rev()
            .find(|l| !l.trim().is_empty())
            .map_or("", |l| l.trim());
        if !previous.ends_with("*/") {
            undocumented.push(format!("line {}: {line}", i + 1));
        }
    }
    assert!(
        undocumented.is_empty(),
        "declarations without a doc comment:\n{}",
        undocumented.join("\n")
    );
}

/// A program for a library built with `mechanism` but without `dynamics` sees no dynamics
/// declaration: a call to one does not compile, and compiles once MECH_FEATURE_DYNAMICS is
/// defined too (so the failure is the guard's).
#[test]
fn the_dynamics_declarations_are_guarded_by_their_feature() {
    let dir = target_dir().join("ffi-tests/header");
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("{e}"));
    let source = dir.join("uses_dynamics.c");
    let body = "#include \"mechanica.h\"\nint main(void) {\n    mech_dynamics_t *d = NULL;\n    \
                return (int)mech_dynamics_create(NULL, &d);\n}\n";
    std::fs::write(&source, body).unwrap_or_else(|e| panic!("{e}"));
    let mechanism_only = [
        "-DMECH_FEATURES_EXPLICIT",
        "-DMECH_FEATURE_KINEMATICS",
        "-DMECH_FEATURE_MASS",
        "-DMECH_FEATURE_MODAL",
        "-DMECH_FEATURE_MECHANISM",
    ];
    let compile = |extra: &[&str]| {
        std::process::Command::new("gcc")
            .args(["-std=c11", "-Wall", "-Wextra", "-Werror", "-pedantic", "-fsyntax-only"])
            .args(mechanism_only)
            .args(extra)
            .arg("-I")
            .arg(workspace_root().join("include"))
            .arg(&source)
            .output()
            .unwrap_or_else(|e| panic!("could not run gcc: {e}"))
    };
    let without = compile(&[]);
    assert!(
        !without.status.success(),
        "a dynamics call compiled without MECH_FEATURE_DYNAMICS"
    );
    assert!(
        String::from_utf8_lossy(&without.stderr).contains("mech_dynamics"),
        "failed for another reason:\n{}",
        String::from_utf8_lossy(&without.stderr)
    );
    check_success("gcc with MECH_FEATURE_DYNAMICS", &compile(&["-DMECH_FEATURE_DYNAMICS"]))
        .unwrap_or_else(|e| panic!("{e}"));
}

/// A program for a library built with `dynamics` but without `motion` sees no motion
/// declaration: a call to one does not compile, and compiles once MECH_FEATURE_MOTION is
/// defined too (so the failure is the guard's).
#[test]
fn the_motion_declarations_are_guarded_by_their_feature() {
    let dir = target_dir().join("ffi-tests/header");
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("{e}"));
    let source = dir.join("uses_motion.c");
    let body = "#include \"mechanica.h\"\nint main(void) {\n    mech_simulation_t *s = NULL;\n    \
                return (int)mech_simulation_create(NULL, NULL, NULL, NULL, NULL, 0, &s);\n}\n";
    std::fs::write(&source, body).unwrap_or_else(|e| panic!("{e}"));
    let dynamics_only = [
        "-DMECH_FEATURES_EXPLICIT",
        "-DMECH_FEATURE_KINEMATICS",
        "-DMECH_FEATURE_MASS",
        "-DMECH_FEATURE_MODAL",
        "-DMECH_FEATURE_MECHANISM",
        "-DMECH_FEATURE_DYNAMICS",
    ];
    let compile = |extra: &[&str]| {
        std::process::Command::new("gcc")
            .args(["-std=c11", "-Wall", "-Wextra", "-Werror", "-pedantic", "-fsyntax-only"])
            .args(dynamics_only)
            .args(extra)
            .arg("-I")
            .arg(workspace_root().join("include"))
            .arg(&source)
            .output()
            .unwrap_or_else(|e| panic!("could not run gcc: {e}"))
    };
    let without = compile(&[]);
    assert!(
        !without.status.success(),
        "a motion call compiled without MECH_FEATURE_MOTION"
    );
    assert!(
        String::from_utf8_lossy(&without.stderr).contains("mech_simulation"),
        "failed for another reason:\n{}",
        String::from_utf8_lossy(&without.stderr)
    );
    // A build with the `motion` feature has `impulse` too (contacts resolve impacts), so its
    // explicit macro set names both.
    let motion_build = ["-DMECH_FEATURE_MOTION", "-DMECH_FEATURE_IMPULSE"];
    check_success("gcc with MECH_FEATURE_MOTION", &compile(&motion_build)).unwrap_or_else(|e| panic!("{e}"));
}
