//! Builds the library, then compiles and runs every C11 and C++17 ffi-test program under
//! ASan + UBSan, once against the static and once against the shared library; and proves
//! that a build with only the `modal` feature links and hides the other declarations.

use mechanica_ffi_tests::*;
use std::path::Path;

/// Compiles and runs `source` against `library` with `link`; returns the program's stdout.
/// A program that passed is deleted (a statically linked one holds a copy of the library);
/// a failed one stays for debugging.
fn compile_and_run(source: &Path, library: &BuiltLibrary, link: LinkKind, defines: &[&str]) -> Result<String, String> {
    let stem = source.file_stem().and_then(|s| s.to_str()).unwrap_or("program");
    let ext = source.extension().and_then(|s| s.to_str()).unwrap_or("");
    let exe = library.dir.join(format!("{stem}_{ext}_{link:?}").to_lowercase());
    compile(source, &exe, library, link, defines)?;
    let stdout = run(&exe)?;
    // Best effort: a program left behind costs disk, not correctness.
    let _ = std::fs::remove_file(&exe);
    Ok(stdout)
}

#[test]
fn every_c_and_cpp_program_passes_with_static_and_shared_library() {
    let library = build_library("full", &[], BuildDir::Default).unwrap_or_else(|e| panic!("{e}"));
    let mut sources = sources_in("c");
    sources.extend(sources_in("cpp"));
    assert!(
        sources.len() >= 2,
        "expected C and C++ test programs, found {sources:?}"
    );
    let mut failures = Vec::new();
    for source in &sources {
        for link in [LinkKind::Static, LinkKind::Shared] {
            match compile_and_run(source, &library, link, &[]) {
                Ok(stdout) => print!("[{link:?}] {stdout}"),
                Err(error) => failures.push(format!("[{link:?}] {error}")),
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} ffi-test run(s) failed:\n{}",
        failures.len(),
        failures.join("\n\n")
    );
}

#[test]
fn a_modal_only_build_links_and_leaves_out_the_other_declarations() {
    let library = build_library(
        "modal-only",
        &["--no-default-features", "--features", "modal"],
        BuildDir::HostTriple,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let subset_defines = ["-DMECH_FEATURES_EXPLICIT", "-DMECH_FEATURE_MODAL"];
    let subset = workspace_root().join("ffi-tests/subset");

    // The library holds no kinematics, mass or impulse symbols.
    let nm = std::process::Command::new("nm")
        .args(["-D", "--defined-only"])
        .arg(library.shared_lib())
        .output()
        .unwrap_or_else(|e| panic!("could not run nm: {e}"));
    let symbols = String::from_utf8_lossy(&nm.stdout);
    assert!(
        symbols.contains("mech_modal_check_pencil"),
        "modal symbols missing:\n{symbols}"
    );
    for absent in [
        "mech_quat_from_rotation_matrix",
        "mech_mass_point",
        "mech_collide_collinear",
        "mech_dynamics_create",
        "mech_simulation_create",
    ] {
        assert!(!symbols.contains(absent), "{absent} is exported by a modal-only build");
    }

    // A program using only modal compiles against the guarded header, links and runs.
    for link in [LinkKind::Static, LinkKind::Shared] {
        compile_and_run(&subset.join("modal_only.c"), &library, link, &subset_defines)
            .unwrap_or_else(|e| panic!("{e}"));
    }

    // A program that calls a kinematics function does not compile: the declaration is guarded out.
    let exe = library.dir.join("uses_kinematics");
    let result = compile(
        &subset.join("uses_kinematics.c"),
        &exe,
        &library,
        LinkKind::Static,
        &subset_defines,
    );
    match result {
        Err(message) => assert!(message.contains("mech_quat"), "failed for another reason:\n{message}"),
        Ok(()) => panic!("uses_kinematics.c compiled although MECH_FEATURE_KINEMATICS is not defined"),
    }
    // ...and the same program compiles when the feature macro is defined (so the failure above
    // is due to the guard, not to a broken test program).
    let full = build_library("full", &[], BuildDir::Default).unwrap_or_else(|e| panic!("{e}"));
    compile_and_run(&subset.join("uses_kinematics.c"), &full, LinkKind::Static, &[]).unwrap_or_else(|e| panic!("{e}"));
}
