//! Links LAPACK from the system OpenBLAS for the bench-only `dsygvd` peer.
//!
//! Found through `pkg-config openblas` or `libopenblas.so` in the standard library directories:
//! emits `cargo:rustc-link-lib=openblas` and the cfg `mechanica_openblas`. Not found: a cargo
//! warning, and the LAPACK series are skipped at run time with a printed note
//! (`apt-get install libopenblas-dev` on Debian/Ubuntu).
//!
//! When `MECHANICA_PINOCCHIO_SHIM` names the Pinocchio shim built by
//! tools/pinocchio_dynamics_bench.sh (a `lib*.so`), links it into the benches with its directory
//! as run path and emits the cfg `mechanica_pinocchio`; the dynamics bench then times Pinocchio
//! beside mechanica. Unset: the Pinocchio series are skipped at run time with a printed note.

use std::path::{Path, PathBuf};
use std::process::Command;

fn main() {
    link_pinocchio_shim();
    println!("cargo::rustc-check-cfg=cfg(mechanica_openblas)");
    println!("cargo::rerun-if-env-changed=PKG_CONFIG_PATH");
    println!("cargo::rerun-if-env-changed=MECHANICA_NO_OPENBLAS");
    if std::env::var_os("MECHANICA_NO_OPENBLAS").is_some() {
        println!("cargo::warning=MECHANICA_NO_OPENBLAS is set: LAPACK dsygvd series are skipped");
        return;
    }
    match find_openblas() {
        Some(dir) => {
            println!("cargo::rustc-link-search=native={}", dir.display());
            println!("cargo::rustc-link-lib=openblas");
            println!("cargo::rustc-cfg=mechanica_openblas");
        }
        None => println!(
            "cargo::warning=OpenBLAS not found (pkg-config openblas, libopenblas.so): LAPACK dsygvd series are skipped"
        ),
    }
}

/// Links the Pinocchio shim named by `MECHANICA_PINOCCHIO_SHIM` into the bench targets.
fn link_pinocchio_shim() {
    println!("cargo::rustc-check-cfg=cfg(mechanica_pinocchio)");
    println!("cargo::rerun-if-env-changed=MECHANICA_PINOCCHIO_SHIM");
    let Some(path) = std::env::var_os("MECHANICA_PINOCCHIO_SHIM").map(PathBuf::from) else {
        return;
    };
    let name = path
        .file_name()
        .and_then(|n| n.to_str())
        .and_then(|n| n.strip_prefix("lib"))
        .and_then(|n| n.strip_suffix(".so"));
    match (path.parent(), name, path.is_file()) {
        (Some(dir), Some(name), true) => {
            println!("cargo::rerun-if-changed={}", path.display());
            println!("cargo::rustc-link-arg-benches=-L{}", dir.display());
            println!("cargo::rustc-link-arg-benches=-Wl,-rpath,{}", dir.display());
            println!("cargo::rustc-link-arg-benches=-l{name}");
            println!("cargo::rustc-cfg=mechanica_pinocchio");
        }
        _ => println!(
            "cargo::warning=MECHANICA_PINOCCHIO_SHIM={} is not a lib*.so file: Pinocchio series are skipped",
            path.display()
        ),
    }
}

/// The directory holding libopenblas.so.
fn find_openblas() -> Option<PathBuf> {
    let from_pkg_config = Command::new("pkg-config")
        .args(["--variable=libdir", "openblas"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| PathBuf::from(s.trim()))
        .filter(|d| has_library(d));
    if from_pkg_config.is_some() {
        return from_pkg_config;
    }
    let arch = std::env::var("CARGO_CFG_TARGET_ARCH").unwrap_or_default();
    let os = std::env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    let multiarch = format!("/usr/lib/{arch}-{os}-gnu");
    [multiarch.as_str(), "/usr/lib64", "/usr/lib", "/usr/local/lib"]
        .into_iter()
        .map(PathBuf::from)
        .find(|d| has_library(d))
}

fn has_library(dir: &Path) -> bool {
    dir.join("libopenblas.so").exists()
}
