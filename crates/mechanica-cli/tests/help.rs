//! The command line's surface: each subcommand's `--help` lists its own options only, a bare
//! `mechanica` still runs the default scene, and `version` names the compiled-in features.

mod common;
use common::mechanica;

const RUN_OPTIONS: [&str; 5] = [
    "--repair-inertia",
    "--allow-missing-mesh",
    "--max-response-values",
    "--q <Q1,Q2,...>",
    "--matrices",
];

#[test]
fn run_options_appear_in_run_help_only() {
    let (ok, run, err) = mechanica(&["run", "--help"]);
    assert!(ok, "{err}");
    for option in RUN_OPTIONS {
        assert!(run.contains(option), "run --help lacks {option}:\n{run}");
    }
    for option in ["--density", "--shell", "--lowest", "--stiffness", "--shapes"] {
        assert!(!run.contains(option), "run --help lists {option}:\n{run}");
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
    assert!(
        ok && mass.contains("--density") && !mass.contains("--lowest") && !mass.contains("--plot"),
        "{mass}"
    );
    let (ok, modes, _) = mechanica(&["modes", "--help"]);
    assert!(
        ok && modes.contains("--lowest") && !modes.contains("--density"),
        "{modes}"
    );
    // --plot is an option of run and of modes, each with its own meaning.
    assert!(run.contains("--plot") && run.contains("free response"), "{run}");
    assert!(
        modes.contains("--plot") && modes.contains("coordinate index"),
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

#[test]
fn the_version_report_names_the_compiled_in_features() {
    let (ok, json, err) = mechanica(&["version", "--json"]);
    assert!(ok, "{err}");
    let report: serde_json::Value = serde_json::from_str(&json).expect("JSON");
    let library = &report["steps"][0];
    assert_eq!(library["analysis"], "library");
    // The CLI enables every feature of the facade (crates/mechanica-cli/Cargo.toml), one bit each.
    let mut names: Vec<&str> = library["features"]
        .as_array()
        .expect("features")
        .iter()
        .filter_map(|f| f.as_str())
        .collect();
    names.sort_unstable();
    let mut expected = [
        "kinematics",
        "mass",
        "impulse",
        "modal",
        "mechanism",
        "dynamics",
        "motion",
        "urdf",
    ];
    expected.sort_unstable();
    assert_eq!(names, expected);
    let bits = library["feature_bits"].as_u64().expect("bits");
    assert_eq!(bits.count_ones() as usize, names.len());
}
