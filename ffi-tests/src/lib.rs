//! Drives the C/C++ ffi-tests and the header checks from `cargo test`.
//!
//! The tests in `tests/programs.rs` build the `mechanica` library (static and shared) with cargo,
//! compile every program in `ffi-tests/c` (C11) and `ffi-tests/cpp` (C++17) with
//! `-Wall -Wextra -Werror -pedantic` under AddressSanitizer and UndefinedBehaviorSanitizer,
//! link each once against each library kind, and run them. A failing C assertion exits
//! non-zero, which fails the cargo test.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::Mutex;

/// Serialises library builds (builds with different features share cargo's output paths)
/// and remembers each finished build by label, so that tests asking for the same label share
/// one copy instead of building and copying it again.
static BUILT: Mutex<Vec<(String, BuiltLibrary)>> = Mutex::new(Vec::new());

/// The workspace root (the parent of `ffi-tests/`).
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default()
}

/// The cargo target directory in use (honours `CARGO_TARGET_DIR`).
pub fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| workspace_root().join("target"))
}

/// A built copy of the library: a directory holding `libmechanica.a` and `libmechanica.so`.
#[derive(Debug, Clone)]
pub struct BuiltLibrary {
    /// Directory with both library files.
    pub dir: PathBuf,
}

impl BuiltLibrary {
    /// Path of the static library.
    pub fn static_lib(&self) -> PathBuf {
        self.dir.join("libmechanica.a")
    }
    /// Path of the shared library.
    pub fn shared_lib(&self) -> PathBuf {
        self.dir.join("libmechanica.so")
    }
}

/// Which build directory a library build uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BuildDir {
    /// `target/debug`, shared with `cargo test` (fast: the test build already compiled it).
    Default,
    /// `target/<host triple>/debug`, for builds with other features. Cargo names a cdylib
    /// without a feature hash, so a subset build in the default directory would overwrite the
    /// full library; the host-triple directory keeps them apart (cargo-c uses it too).
    HostTriple,
}

/// The host target triple, from `rustc -vV`.
fn host_triple() -> Result<String, String> {
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let output = Command::new(rustc)
        .arg("-vV")
        .output()
        .map_err(|e| format!("could not run rustc: {e}"))?;
    String::from_utf8_lossy(&output.stdout)
        .lines()
        .find_map(|line| line.strip_prefix("host: ").map(str::to_string))
        .ok_or_else(|| "rustc -vV printed no host triple".to_string())
}

/// Builds the library with `cargo build -p mechanica --lib` and the given feature arguments
/// in `dir`, then copies the static and shared libraries into `target/ffi-tests/<label>/`, so
/// that later builds cannot change them under a running test. A label built before in this
/// process is returned as it is.
pub fn build_library(label: &str, feature_args: &[&str], dir: BuildDir) -> Result<BuiltLibrary, String> {
    let mut built_before = BUILT.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    if let Some((_, library)) = built_before.iter().find(|(built_label, _)| built_label == label) {
        return Ok(library.clone());
    }
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut command = Command::new(cargo);
    command
        .current_dir(workspace_root())
        .args(["build", "-p", "mechanica", "--lib"])
        .args(feature_args);
    let built = match dir {
        BuildDir::Default => target_dir().join("debug"),
        BuildDir::HostTriple => {
            let triple = host_triple()?;
            command.args(["--target", &triple]);
            target_dir().join(triple).join("debug")
        }
    };
    let output = command.output().map_err(|e| format!("could not start cargo: {e}"))?;
    check_success("cargo build -p mechanica", &output)?;
    let copy_dir = target_dir().join("ffi-tests").join(label);
    std::fs::create_dir_all(&copy_dir).map_err(|e| format!("{}: {e}", copy_dir.display()))?;
    for file in ["libmechanica.a", "libmechanica.so"] {
        std::fs::copy(built.join(file), copy_dir.join(file)).map_err(|e| format!("copy {file}: {e}"))?;
    }
    let library = BuiltLibrary { dir: copy_dir };
    built_before.push((label.to_string(), library.clone()));
    Ok(library)
}

/// How a test program links the library.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LinkKind {
    /// Against `libmechanica.a`.
    Static,
    /// Against `libmechanica.so`, found at run time through an rpath.
    Shared,
}

/// The language a test program is compiled as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Language {
    /// C11 with gcc.
    C11,
    /// C++17 with g++.
    Cxx17,
}

impl Language {
    /// The language of a source file, from its extension.
    pub fn of(path: &Path) -> Option<Self> {
        match path.extension()?.to_str()? {
            "c" => Some(Language::C11),
            "cpp" => Some(Language::Cxx17),
            _ => None,
        }
    }

    fn compiler_and_standard(self) -> (&'static str, &'static str) {
        match self {
            Language::C11 => ("gcc", "-std=c11"),
            Language::Cxx17 => ("g++", "-std=c++17"),
        }
    }
}

/// The warning and sanitizer flags every ffi-test program is built with.
pub const STRICT_FLAGS: &[&str] = &[
    "-Wall",
    "-Wextra",
    "-Werror",
    "-pedantic",
    "-g",
    "-fsanitize=address,undefined",
    "-fno-sanitize-recover=all",
    "-fno-omit-frame-pointer",
];

/// The flags of the ThreadSanitizer build of the concurrency test: the warnings of
/// [`STRICT_FLAGS`] with `-fsanitize=thread` (which excludes ASan) and `-pthread`.
pub const TSAN_FLAGS: &[&str] = &[
    "-Wall",
    "-Wextra",
    "-Werror",
    "-pedantic",
    "-g",
    "-fsanitize=thread",
    "-fno-omit-frame-pointer",
    "-pthread",
];

/// Libraries a Rust static library needs on Linux (`rustc --print native-static-libs`).
pub const STATIC_LINK_LIBS: &[&str] = &["-lgcc_s", "-lutil", "-lrt", "-lpthread", "-lm", "-ldl", "-lc"];

/// Compiles `source` into `exe` with [`STRICT_FLAGS`], the header directory, the extra
/// `defines`, and links it to `library` by `link`. Returns the compiler output on failure.
pub fn compile(
    source: &Path,
    exe: &Path,
    library: &BuiltLibrary,
    link: LinkKind,
    defines: &[&str],
) -> Result<(), String> {
    compile_with_flags(source, exe, library, link, STRICT_FLAGS, defines)
}

/// As [`compile`], with `flags` in place of [`STRICT_FLAGS`] (e.g. [`TSAN_FLAGS`]).
pub fn compile_with_flags(
    source: &Path,
    exe: &Path,
    library: &BuiltLibrary,
    link: LinkKind,
    flags: &[&str],
    defines: &[&str],
) -> Result<(), String> {
    let language = Language::of(source).ok_or_else(|| format!("{}: not a .c or .cpp file", source.display()))?;
    let (compiler, standard) = language.compiler_and_standard();
    let root = workspace_root();
    let mut cmd = Command::new(compiler);
    cmd.arg(standard)
        .args(flags)
        .args(defines)
        .arg("-I")
        .arg(root.join("include"))
        .arg("-I")
        .arg(root.join("ffi-tests/c"))
        .arg(source)
        .arg("-o")
        .arg(exe);
    match link {
        LinkKind::Static => {
            cmd.arg(library.static_lib()).args(STATIC_LINK_LIBS);
        }
        LinkKind::Shared => {
            cmd.arg(format!("-L{}", library.dir.display()))
                .arg("-lmechanica")
                // DT_RPATH (not RUNPATH), so that no LD_LIBRARY_PATH can substitute another build.
                .arg("-Wl,--disable-new-dtags")
                .arg(format!("-Wl,-rpath,{}", library.dir.display()))
                .arg("-lm");
        }
    }
    let output = cmd.output().map_err(|e| format!("could not start {compiler}: {e}"))?;
    check_success(&format!("{compiler} {}", source.display()), &output)
}

/// Runs a compiled test program with leak detection and UBSan stack traces on.
pub fn run(exe: &Path) -> Result<String, String> {
    // cargo test puts target/debug on LD_LIBRARY_PATH; the program must load the library it
    // was linked against (see `compile`), not whatever cargo built last.
    let output = Command::new(exe)
        .env_remove("LD_LIBRARY_PATH")
        .env("ASAN_OPTIONS", "detect_leaks=1:halt_on_error=1")
        .env("UBSAN_OPTIONS", "print_stacktrace=1:halt_on_error=1")
        .output()
        .map_err(|e| format!("could not start {}: {e}", exe.display()))?;
    check_success(&exe.display().to_string(), &output)?;
    Ok(String::from_utf8_lossy(&output.stdout).into_owned())
}

/// Turns a failed process into an error message with its output.
pub fn check_success(what: &str, output: &Output) -> Result<(), String> {
    if output.status.success() {
        return Ok(());
    }
    Err(format!(
        "{what} failed ({}):\n--- stdout\n{}\n--- stderr\n{}",
        output.status,
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    ))
}

/// The test sources under `ffi-tests/<dir>` with extension .c or .cpp, sorted.
pub fn sources_in(dir: &str) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(workspace_root().join("ffi-tests").join(dir))
        .map(|entries| entries.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    files.retain(|p| Language::of(p).is_some());
    files.sort();
    files
}

/// The names of all functions declared in a header text (`mech_xxx(` at the start of a
/// declaration, after its return type).
pub fn declared_functions(header: &str) -> Vec<String> {
    let mut names = Vec::new();
    for line in header.lines() {
        let trimmed = line.trim_start();
        if trimmed.starts_with('*') || trimmed.starts_with("/*") || trimmed.starts_with('#') {
            continue;
        }
        for (start, _) in trimmed.match_indices("mech_") {
            let rest = &trimmed[start..];
            let name: String = rest
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            if rest[name.len()..].starts_with('(') && !names.contains(&name) {
                names.push(name);
            }
        }
    }
    names
}
