//! Golden tests of the command line: they run the real `situ` binary and
//! check its exit codes and outputs, as scripts and users rely on them.

mod common;

use common::{code, situ, stderr, stdout, write};

const VALID: &str = "states { IT initial RD final }\nagent Ready sensor { event RDY }\nrule ready { when state == IT and RDY then RD }\n";

#[test]
fn the_papers_stacks_check_clean() {
    for file in ["rules/outdoor.situ", "rules/ugv.situ", "rules/ugv-merge.situ"] {
        let o = situ(&["check", file]);
        assert_eq!(code(&o), 0, "{file}:\n{}{}", stdout(&o), stderr(&o));
        assert!(stdout(&o).contains("no findings"), "{}", stdout(&o));
        let json = situ(&["check", "--format", "json", file]);
        assert_eq!(stdout(&json), "", "{file} has findings in JSON");
    }
}

#[test]
fn a_missing_file_is_a_usage_error_that_names_it() {
    let o = situ(&["check", "no/such/file.situ"]);
    assert_eq!(code(&o), 2);
    assert!(stderr(&o).contains("no/such/file.situ"), "{}", stderr(&o));
}

#[test]
fn a_directory_is_a_usage_error() {
    let o = situ(&["check", "tests"]);
    assert_eq!(code(&o), 2, "{}", stderr(&o));
}

#[test]
fn no_arguments_is_a_usage_error() {
    assert_eq!(code(&situ(&["check"])), 2);
    assert_eq!(code(&situ(&["frobnicate"])), 2);
}

#[test]
fn findings_exit_one_with_a_report() {
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), "bad.situ", "states { IT initial }\nrule r { when state == IT then RX }\n");
    let o = situ(&["check", &f]);
    assert_eq!(code(&o), 1);
    let out = stdout(&o);
    assert!(out.contains("situ::E0101"), "{out}");
    assert!(out.contains("undefined state `RX`"), "{out}");
    assert!(out.contains("1 error, 0 warnings"), "{out}");
}

#[test]
fn json_has_one_object_per_finding() {
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), "bad.situ", "states { IT initial }\nrule r { when state == IT and NOPE then RX }\n");
    let o = situ(&["check", "--format", "json", &f]);
    assert_eq!(code(&o), 1);
    let lines: Vec<serde_json::Value> =
        stdout(&o).lines().map(|l| serde_json::from_str(l).expect("each line is a JSON object")).collect();
    assert_eq!(lines.len(), 2);
    let codes: Vec<&str> = lines.iter().map(|l| l["code"].as_str().unwrap()).collect();
    assert_eq!(codes, ["situ::E0104", "situ::E0101"]);
    let first = &lines[0];
    assert_eq!(first["severity"], "error");
    assert_eq!(first["file"], f);
    assert_eq!(first["line"], 2);
    assert_eq!(first["column"], 31);
    assert!(first["message"].as_str().unwrap().contains("NOPE"));
    assert!(first.get("witness").is_some());
}

#[test]
fn sarif_is_a_sarif_2_1_0_log() {
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), "bad.situ", "states { IT initial }\nrule r { when state == IT then RX }\n");
    let o = situ(&["check", "--format", "sarif", &f]);
    assert_eq!(code(&o), 1);
    let log: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("one JSON document");
    assert_eq!(log["version"], "2.1.0");
    let run = &log["runs"][0];
    assert_eq!(run["tool"]["driver"]["name"], "situ");
    let result = &run["results"][0];
    assert_eq!(result["ruleId"], "situ::E0101");
    assert_eq!(result["level"], "error");
    let region = &result["locations"][0]["physicalLocation"]["region"];
    assert_eq!(region["startLine"], 2);
    let rule_index = result["ruleIndex"].as_u64().unwrap() as usize;
    assert_eq!(run["tool"]["driver"]["rules"][rule_index]["id"], "situ::E0101");
}

#[test]
fn explain_prints_the_long_text() {
    let o = situ(&["explain", "situ::e0101"]);
    assert_eq!(code(&o), 0);
    let out = stdout(&o);
    assert!(out.starts_with("# E0101"), "{out}");
    for section in ["## What it does", "## Why is this bad", "## Example", "## Use instead"] {
        assert!(out.contains(section), "{out}");
    }
    let unknown = situ(&["explain", "E9999"]);
    assert_eq!(code(&unknown), 2);
    assert!(stderr(&unknown).contains("E9999"));
    let all = situ(&["explain"]);
    assert_eq!(code(&all), 0);
    assert!(stdout(&all).contains("situ::E0204"));
}

#[test]
fn the_shipped_situ_files_are_formatted() {
    // The .situ files a user reads and copies are in the formatter's layout.
    // The test corpora (tests/ui, tests/checks, tests/verify) are not: they
    // are compact on purpose, with expectations inline on given lines.
    let files = ["rules/outdoor.situ", "rules/ugv.situ", "examples/fig5/fig5.situ"];
    let o = situ(&[&["fmt", "--check"][..], &files[..]].concat());
    assert_eq!(code(&o), 0, "run `situ fmt` on them:\n{}{}", stdout(&o), stderr(&o));
}

#[test]
fn fmt_check_reports_and_fmt_rewrites() {
    let dir = tempfile::tempdir().unwrap();
    let messy = "states{IT initial RD}  // the states\nagent Ready sensor{event RDY}\nrule ready{when state==IT and RDY then RD}\n";
    let f = write(dir.path(), "messy.situ", messy);
    let o = situ(&["fmt", "--check", &f]);
    assert_eq!(code(&o), 1);
    assert!(stdout(&o).contains("would reformat"), "{}", stdout(&o));
    assert_eq!(std::fs::read_to_string(&f).unwrap(), messy, "--check must not write");

    let o = situ(&["fmt", &f]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let formatted = std::fs::read_to_string(&f).unwrap();
    assert_ne!(formatted, messy);
    assert!(formatted.contains("// the states"), "comments are kept:\n{formatted}");
    assert_eq!(code(&situ(&["fmt", "--check", &f])), 0, "formatting is idempotent:\n{formatted}");
    assert_eq!(code(&situ(&["check", &f])), 0);
    let leftovers: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(leftovers.len(), 1, "no temporary file is left behind");
}

#[test]
fn fmt_refuses_a_broken_file_and_leaves_it_alone() {
    let dir = tempfile::tempdir().unwrap();
    let broken = "states { IT initial \nrule r { when then }\n";
    let f = write(dir.path(), "broken.situ", broken);
    let o = situ(&["fmt", &f]);
    assert_eq!(code(&o), 1);
    assert!(stdout(&o).contains("situ::E0001"), "{}", stdout(&o));
    assert_eq!(std::fs::read_to_string(&f).unwrap(), broken);
    assert_eq!(code(&situ(&["fmt", "no/such.situ"])), 2);
}

/// Exit 1 with at least one finding of `expected`, and no panic.
fn fails_with(path: &str, expected: &str) {
    let o = situ(&["check", "--format", "json", path]);
    let err = stderr(&o);
    assert!(!err.contains("panicked"), "{path}: {err}");
    assert_eq!(code(&o), 1, "{path}: {}{err}", stdout(&o));
    let out = stdout(&o);
    assert!(out.contains(&format!("\"situ::{expected}\"")), "{path}: expected {expected} in\n{out}");
}

#[test]
fn bad_input_gets_diagnostics_never_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fails_with(&write(d, "empty.situ", ""), "E0107");
    let binary: Vec<u8> = (0..4096u32).map(|i| (i.wrapping_mul(2654435761) >> 13) as u8).collect();
    fails_with(&write(d, "binary.situ", binary), "E0002");
    fails_with(&write(d, "latin1.situ", b"// caf\xe9\nstates { IT initial }\n"), "E0002");
    fails_with(&write(d, "nul.situ", "states { IT initial }\0\0\0"), "E0001");
    let deep = format!("property \"p\" {{ always {}true{} }}", "(".repeat(10_000), ")".repeat(10_000));
    fails_with(&write(d, "deep.situ", deep), "E0006");
    fails_with(&write(d, "braces.situ", "{".repeat(100_000)), "E0006");
    fails_with(&write(d, "include.situ", "include \"nowhere.situ\"\nstates { IT initial }\n"), "E0003");
    write(d, "a.situ", "include \"b.situ\"\nstates { IT initial }\n");
    write(d, "b.situ", "include \"a.situ\"\n");
    fails_with(&d.join("a.situ").display().to_string(), "E0004");
    fails_with(&write(d, "self.situ", "include \"self.situ\"\nstates { IT initial }\n"), "E0004");
    fails_with(
        &write(
            d,
            "huge_int.situ",
            "states { IT initial }\nrule r salience 99999999999999999999 { when state == IT then IT }\n",
        ),
        "E0007",
    );
}

#[test]
fn a_ten_megabyte_file_is_checked() {
    let dir = tempfile::tempdir().unwrap();
    let mut text = String::from("states { IT initial RD }\nagent S sensor { event E { d: f64 } }\n");
    let mut i = 0;
    while text.len() < 10 * 1024 * 1024 {
        text.push_str(&format!("rule r{i} salience {i} {{ when state == IT and E(d < {i}.5) then RD }}\n"));
        i += 1;
    }
    let f = write(dir.path(), "big.situ", &text);
    let o = situ(&["check", "--format", "json", &f]);
    // A valid 10 MB file is checked in full; there is no finding to report.
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let garbage = "rule ((( }\n".repeat(1024 * 1024);
    let g = write(dir.path(), "garbage.situ", garbage);
    fails_with(&g, "E0008");
}

#[test]
fn deny_warnings_only_changes_the_exit_code_of_warnings() {
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), "ok.situ", VALID);
    assert_eq!(code(&situ(&["check", "--deny-warnings", &f])), 0);
    let bad = write(dir.path(), "bad.situ", "states { IT initial }\nrule r { when state == IT then RX }\n");
    assert_eq!(code(&situ(&["check", "--deny-warnings", &bad])), 1);
}

#[test]
fn several_files_are_checked_each_on_its_own() {
    let dir = tempfile::tempdir().unwrap();
    let ok = write(dir.path(), "ok.situ", VALID);
    let bad = write(dir.path(), "bad.situ", "states { IT initial }\nrule r { when state == IT then RX }\n");
    let o = situ(&["check", &ok, &bad]);
    assert_eq!(code(&o), 1);
    let out = stdout(&o);
    assert!(out.contains(&format!("{ok}: no findings")), "{out}");
    assert!(out.contains(&format!("{bad}: 1 error")), "{out}");
    let missing = situ(&["check", &ok, "missing.situ"]);
    assert_eq!(code(&missing), 2, "an unreadable file wins over findings");
}

#[test]
fn build_writes_a_bundle_that_bench_and_graph_read() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("outdoor.bundle");
    let bin = dir.path().join("outdoor.bin");
    let o = situ(&["build", "rules/outdoor.situ", "-o", json.to_str().unwrap(), "--stats"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let out = stdout(&o);
    assert!(out.contains("33 terminals") && out.contains("sharing saved"), "{out}");
    let o = situ(&["build", "rules/outdoor.situ", "-o", bin.to_str().unwrap(), "--binary"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    for bundle in [&json, &bin] {
        let o = situ(&["bench", bundle.to_str().unwrap(), "--events", "20000", "--seed", "4"]);
        assert_eq!(code(&o), 0, "{}", stderr(&o));
        let report: serde_json::Value = serde_json::from_str(stdout(&o).trim()).expect("one JSON object");
        assert_eq!(report["events"], 20000);
        for key in ["events_per_sec", "peak_rss_bytes", "state_changes"] {
            assert!(report[key].as_f64().is_some_and(|v| v > 0.0), "{key}: {report}");
        }
        for key in ["p50", "p99", "max"] {
            assert!(report["latency_ns"][key].as_u64().is_some(), "{report}");
        }
        assert_eq!(report["nodes"]["terminals"], 33);
    }
    let o = situ(&["graph", json.to_str().unwrap(), "--view", "wiring", "--state", "RO"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert!(stdout(&o).contains("\"LADAR\" -> \"Fusion\""), "{}", stdout(&o));
}

#[test]
fn build_native_writes_the_module_that_the_runtime_tests_run() {
    let dir = tempfile::tempdir().unwrap();
    let bundle = dir.path().join("outdoor.bundle");
    let module = dir.path().join("outdoor_native.rs");
    let o =
        situ(&["build", "rules/outdoor.situ", "-o", bundle.to_str().unwrap(), "--native", module.to_str().unwrap()]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert!(stdout(&o).contains("(native code, "), "{}", stdout(&o));
    // The module is the one `runtime-tests/tests/native.rs` compiles and
    // holds to the interpreter (and `native_golden.rs` generates again).
    let written = std::fs::read_to_string(&module).unwrap();
    let committed = std::fs::read_to_string("runtime-tests/native/outdoor.rs").unwrap();
    assert!(written == committed, "situ build --native wrote another module than runtime-tests/native/outdoor.rs");
    assert!(bundle.exists());
    // A module that cannot be written is an error that names it.
    let nowhere = dir.path().join("no/such/dir/x.rs");
    let o =
        situ(&["build", "rules/outdoor.situ", "-o", bundle.to_str().unwrap(), "--native", nowhere.to_str().unwrap()]);
    assert_eq!(code(&o), 2);
    assert!(stderr(&o).contains("cannot write") && stderr(&o).contains("x.rs"), "{}", stderr(&o));
}

#[test]
fn build_refuses_findings_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let bad = write(dir.path(), "bad.situ", "states { IT initial }\nrule r { when state == IT then RX }\n");
    let out = dir.path().join("bad.bundle");
    let o = situ(&["build", &bad, "-o", out.to_str().unwrap()]);
    assert_eq!(code(&o), 1);
    assert!(stdout(&o).contains("situ::E0101"), "{}", stdout(&o));
    assert!(!out.exists(), "no bundle is written for a program with errors");
    assert_eq!(code(&situ(&["build", "no/such.situ", "-o", out.to_str().unwrap()])), 2);
}

#[test]
fn damaged_bundles_are_refused_with_exit_2_and_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.bundle");
    assert_eq!(code(&situ(&["build", "rules/ugv.situ", "-o", good.to_str().unwrap()])), 0);
    let text = std::fs::read_to_string(&good).unwrap();
    let cases = [
        ("edited.bundle", text.replacen("0.3", "0.4", 1), "modified after it was built"),
        ("cut.bundle", text[..text.len() / 2].to_string(), "truncated"),
        ("newer.bundle", text.replacen("\"format_version\":1", "\"format_version\":7", 1), "format version 7"),
        ("notes.bundle", "shopping: milk, eggs\n".to_string(), "not a situ bundle"),
    ];
    for (name, content, reason) in cases {
        let f = write(dir.path(), name, content);
        for args in [vec!["bench", &f, "--events", "10"], vec!["graph", &f, "--view", "rete"]] {
            let o = situ(&args);
            assert_eq!(code(&o), 2, "{name}: {}", stderr(&o));
            assert!(stderr(&o).contains(reason), "{name}: {}", stderr(&o));
            assert!(!stderr(&o).contains("panicked"), "{}", stderr(&o));
        }
    }
}

#[test]
fn graph_draws_states_rete_and_svg() {
    let o = situ(&["graph", "rules/outdoor.situ", "--view", "states"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert!(stdout(&o).starts_with("digraph states"), "{}", stdout(&o));
    assert!(stdout(&o).contains("\"RO\" -> \"RS\""), "{}", stdout(&o));
    let o = situ(&["graph", "rules/outdoor.situ", "--view", "rete"]);
    assert!(stdout(&o).contains("road_obstacle_ladar"), "{}", stdout(&o));
    let o = situ(&["graph", "rules/outdoor.situ", "--view", "wiring", "--state", "RS", "--format", "svg"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert!(stdout(&o).contains("<svg") && stdout(&o).contains("RFCCD"), "{}", stdout(&o));
    let o = situ(&["graph", "rules/outdoor.situ", "--view", "wiring", "--state", "XX"]);
    assert_eq!(code(&o), 2);
    assert!(stderr(&o).contains("no state `XX`"), "{}", stderr(&o));
}

#[cfg(not(feature = "zenoh"))]
#[test]
fn zenoh_without_the_feature_says_how_to_get_it() {
    let o = situ(&["run", "examples/fig5/fig5.situ", "--stack", "demo", "--transport", "zenoh"]);
    assert_eq!(code(&o), 2);
    assert!(stderr(&o).contains("--features zenoh"), "{}", stderr(&o));
}

#[test]
fn replay_checks_a_rule_change_against_a_recorded_drive() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("drive.mcap");
    let o = situ(&["run", "rules/outdoor.situ", "--until", "40", "--record", rec.to_str().unwrap()]);
    assert!(rec.exists(), "{}{}", stdout(&o), stderr(&o));
    let same = situ(&["replay", rec.to_str().unwrap()]);
    assert_eq!(code(&same), 0, "{}{}", stdout(&same), stderr(&same));
    assert!(stdout(&same).contains("same states"), "{}", stdout(&same));
    // Obstacles seen from 10 m instead of 30 m: the drive of yesterday goes otherwise.
    let rules = std::fs::read_to_string("rules/outdoor.situ").unwrap();
    let changed = write(dir.path(), "changed.situ", rules.replace("LAOBS(distance < 30.0", "LAOBS(distance < 10.0"));
    let o = situ(&["replay", rec.to_str().unwrap(), "--bundle", &changed, "--format", "json"]);
    assert_eq!(code(&o), 1, "{}{}", stdout(&o), stderr(&o));
    let report: serde_json::Value = serde_json::from_str(stdout(&o).trim()).unwrap();
    assert!(report["first_difference"].is_u64(), "{report}");
    let junk = write(dir.path(), "junk.mcap", "not a recording");
    assert_eq!(code(&situ(&["replay", &junk])), 2);
}
