//! Each subcommand's `--help` lists its own options only, and a bare `mechanica` still runs
//! the default scene.

mod common;
use common::mechanica;

const RUN_OPTIONS: [&str; 4] = [
    "--repair-inertia",
    "--allow-missing-mesh",
    "--max-response-values",
    "--plot",
];

#[test]
fn run_options_appear_in_run_help_only() {
    let (ok, run, err) = mechanica(&["run", "--help"]);
    assert!(ok, "{err}");
    for option in RUN_OPTIONS {
        assert!(run.contains(option), "run --help lacks {option}:\n{run}");
    }
    for command in ["mass", "modes", "version"] {
        let (ok, help, err) = mechanica(&[command, "--help"]);
        assert!(ok, "{err}");
        for option in RUN_OPTIONS {
            assert!(!help.contains(option), "{command} --help lists {option}:\n{help}");
        }
        assert!(help.contains("--json"), "{command} --help lacks --json:\n{help}");
    }
    let (ok, mass, _) = mechanica(&["mass", "--help"]);
    assert!(ok && mass.contains("--density") && !mass.contains("--lowest"), "{mass}");
    let (ok, modes, _) = mechanica(&["modes", "--help"]);
    assert!(
        ok && modes.contains("--lowest") && !modes.contains("--density"),
        "{modes}"
    );
    // An option of another subcommand is refused, not ignored.
    let (ok, _, err) = mechanica(&["mass", "--plot", "somewhere", "x.stl"]);
    assert!(!ok && err.contains("--plot"), "{err}");
}

#[test]
fn a_bare_command_runs_the_default_scene() {
    let (ok, out, err) = mechanica(&[]);
    assert!(ok, "{err}");
    assert!(
        out.contains("default scene") && out.contains("## ") && out.contains("stable"),
        "{out}"
    );
    let (ok, json, err) = mechanica(&["--json"]);
    assert!(ok, "{err}");
    let report: serde_json::Value = serde_json::from_str(&json).expect("JSON");
    assert_eq!(report["command"], "run");
    assert_eq!(report["schema_version"], 2);
}
