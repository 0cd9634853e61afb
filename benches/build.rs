//! Links LAPACK from the system OpenBLAS for the bench-only `dsygvd` peer.
//!
//! Found through `pkg-config openblas` or `libopenblas.so` in the standard library directories:
//! emits `cargo:rustc-link-lib=openblas` and the cfg `mechanica_openblas`. Not found: a cargo
//! warning, and the LAPACK series are skipped at run time with a printed note
//! (`apt-get install libopenblas-dev` on Debian/Ubuntu).

use std::path::{Path, PathBuf};
use std::process::Command;

fn main() {
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
