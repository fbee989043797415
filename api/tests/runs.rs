//! Runs through the facade: a rules file on its script, recorded; the
//! recording replayed on the bundle it carries and on other rules.

use situ_api::{load_path, replay, run_script, Drive, Error, Trust};
use std::path::Path;

fn asleep() -> situ_api::Program {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/run/asleep.situ");
    load_path(&path, &Trust::Any, false).expect("the robot of tests/run loads")
}

#[test]
fn a_script_runs_to_its_path_and_its_recording_replays_the_same() {
    let program = asleep();
    let dir = tempfile::tempdir().expect("a temporary folder");
    let recording = dir.path().join("run.mcap");
    let report = run_script(&program, &Drive::Script(None), None, Some(&recording)).expect("the script runs");
    let states: Vec<&str> = report.timeline.iter().map(|(_, s)| s.as_str()).collect();
    assert_eq!(states, ["PATROL", "HALT"], "the changes of the path its header announces (DOCKED first)");
    assert!(report.driver.contains("a person at the dock"), "{}", report.driver);
    let leftovers: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(leftovers, ["run.mcap"], "the recording is renamed into place, nothing else is left");

    let bytes = std::fs::read(&recording).expect("the recording");
    let replayed = replay(&bytes, None, &Trust::Any).expect("it replays on the bundle it carries");
    assert!(replayed.signed_by.is_none(), "no policy asked for a signature");
    assert!(replayed.report.events > 0);
    assert_eq!(replayed.report.first_difference, None, "the same rules give the same states");
    assert_eq!(replayed.report.recorded.len(), 2);
}

#[test]
fn a_missing_script_and_a_foreign_recording_are_typed_errors() {
    let program = asleep();
    let e = run_script(&program, &Drive::Script(Some("at night".into())), None, None).expect_err("no such script");
    assert!(matches!(e, Error::Script(_)), "{e:?}");
    assert!(e.to_string().contains("\"a person at the dock, then on the route\""), "{e}");
    assert!(matches!(replay(b"not a recording", None, &Trust::Any), Err(Error::Recording(_))));
}
