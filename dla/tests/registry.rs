//! What `situ run` asks of DLA's crate before a run: which stack a program
//! is (the sim's or DLA's), the case base a run starts from, and whether a
//! series of missions can be made.

use situ_dla::missions::{check, load_or_train, Series};
use std::path::Path;

fn rules(name: &str) -> situ_compiler::bundle::Content {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../rules").join(name);
    let checked = situ_compiler::check(&path, &situ_compiler::loader::FsLoader).expect("the rules file reads");
    assert!(!checked.fails(false), "{name} checks clean");
    situ_compiler::bundle::build(&checked)
}

#[test]
fn the_registry_tells_dla_from_the_sims_stacks_and_lists_all_four() {
    let registry = situ_dla::registry();
    assert_eq!(registry.of(&rules("dla.situ")).map(|s| s.name()).ok(), Some(situ_dla::stack::NAME));
    assert_eq!(registry.of(&rules("ugv-merge.situ")).map(|s| s.name()).ok(), Some("ugv_merge"));
    assert_eq!(registry.of(&rules("outdoor.situ")).map(|s| s.name()).ok(), Some("outdoor"));
    let checked = situ_compiler::check_source(
        "minimal.situ",
        "states { IT initial RD final }\nagent Supervisor interface { event SVRDY }\nrule ready { when state == IT and SVRDY then RD }\n",
    );
    let e = registry.of(&situ_compiler::bundle::build(&checked)).err().expect("no stack");
    let text = e.to_string();
    assert!(
        text.ends_with(&format!(
            "of rules/ugv.situ ({}), of rules/ugv-merge.situ (those and Merger) and of rules/dla.situ ({})",
            situ_sim::stack::ugv::AGENTS.join(", "),
            situ_dla::stack::AGENTS.join(", ")
        )),
        "{text}"
    );
}

#[test]
fn a_damaged_case_base_is_refused_and_left_as_it_was() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cases.txt");
    std::fs::write(&path, "not a case base\n").unwrap();
    let e = load_or_train(Some(&path), 1).expect_err("refused");
    let text = e.to_string();
    assert!(text.starts_with(&format!("`{}`: ", path.display())), "{text}");
    assert!(text.ends_with(" (the file is left as it was)"), "{text}");
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "not a case base\n");
}

#[test]
fn a_series_has_between_one_and_ten_thousand_missions() {
    let series = |missions, held_out| Series { missions, held_out, seed: 1, until: 1.0, learn: true };
    assert!(check(&series(1, 0)).is_ok() && check(&series(10_000, 10_000)).is_ok());
    for bad in [series(0, 1), series(10_001, 1), series(2, 10_001)] {
        let e = check(&bad).expect_err("refused");
        assert_eq!(e.to_string(), "--missions must be between 1 and 10000, --evaluate at most 10000");
    }
}
