//! Scenario validation: every file of `tests/scenarios-bad/` is refused with
//! the error its first line announces (`# expect: …`), naming the field or
//! the place; the built-in scenarios load.

use situ_sim::scenario;
use std::path::Path;

#[test]
fn each_bad_scenario_gives_its_error() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenarios-bad");
    let mut files: Vec<_> = std::fs::read_dir(&dir).expect("scenarios-bad").map(|e| e.expect("entry").path()).collect();
    files.sort();
    assert!(files.len() >= 10, "the bad inputs are there");
    for f in files {
        let text = std::fs::read_to_string(&f).expect("readable");
        let expect = text
            .lines()
            .next()
            .and_then(|l| l.strip_prefix("# expect: "))
            .unwrap_or_else(|| panic!("{}: first line must be `# expect: …`", f.display()));
        match scenario::load(&f) {
            Ok(_) => panic!("{}: accepted, expected: {expect}", f.display()),
            Err(e) => {
                let msg = e.to_string();
                println!("{}: {msg}", f.file_name().map(|n| n.to_string_lossy()).unwrap_or_default());
                assert!(msg.contains(expect), "{}:\n  got:      {msg}\n  expected: {expect}", f.display());
            }
        }
    }
}

#[test]
fn shipped_scenarios_load() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    for name in ["outdoor-default.toml", "dafflon-4.toml"] {
        let s = scenario::load(&dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(!s.name.is_empty());
    }
    let missing = scenario::load(&dir.join("nope.toml")).expect_err("no such file");
    assert!(missing.to_string().contains("cannot read scenario"));
}

#[test]
fn a_scenario_by_name_is_built_in_or_a_file_and_else_says_which_exist() {
    assert_eq!(scenario::named("dafflon-4").expect("built in").name, scenario::dafflon_4().name);
    let e = scenario::named("nowhere").expect_err("unknown");
    assert_eq!(
        e.to_string(),
        "no built-in scenario `nowhere` (outdoor-default, dafflon-4, dla-offices, dla-field) and no such file"
    );
    let bad = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenarios-bad/unknown-node.toml");
    let name = bad.display().to_string();
    let e = scenario::named(&name).expect_err("a bad file");
    let whole = scenario::load(&bad).expect_err("a bad file");
    assert_eq!(e.to_string(), format!("scenario `{name}`: {whole}"));
}
