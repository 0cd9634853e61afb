//! The concurrency test `ffi-tests/c/test_threads.c` under ThreadSanitizer: several threads
//! call every handle-free function, use handles of their own and read one shared result, and
//! must agree bit for bit with a single-threaded pass. (The same program also runs under ASan
//! and UBSan with the other C tests.) It links the shared library, whose own accesses are
//! suppressed (`ffi-tests/tsan.supp` says why); a ThreadSanitizer build cannot suppress them
//! in a static link, where the library is part of the executable.

use mechanica_ffi_tests::*;

#[test]
fn the_concurrency_test_passes_under_thread_sanitizer() {
    let library = build_library("full", &[], BuildDir::Default).unwrap_or_else(|e| panic!("{e}"));
    let root = workspace_root();
    let exe = library.dir.join("test_threads_tsan");
    compile_with_flags(
        &root.join("ffi-tests/c/test_threads.c"),
        &exe,
        &library,
        LinkKind::Shared,
        TSAN_FLAGS,
        &[],
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let suppressions = root.join("ffi-tests/tsan.supp");
    let output = std::process::Command::new(&exe)
        .env_remove("LD_LIBRARY_PATH")
        .env(
            "TSAN_OPTIONS",
            format!(
                "halt_on_error=1 second_deadlock_stack=1 suppressions={}",
                suppressions.display()
            ),
        )
        .env("RUST_BACKTRACE", "0")
        .output()
        .unwrap_or_else(|e| panic!("could not start {}: {e}", exe.display()));
    check_success(&exe.display().to_string(), &output).unwrap_or_else(|e| panic!("{e}"));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        !stderr.contains("ThreadSanitizer"),
        "ThreadSanitizer reported:\n{stderr}"
    );
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(stdout.contains("agree bit for bit"), "unexpected output:\n{stdout}");
    let _ = std::fs::remove_file(&exe);
}
