//! CLI golden tests of `situ repl`: the real binary, its commands on
//! standard input (not a terminal), as a script of a session would run.

mod common;

use common::write;
use std::io::Write as _;
use std::process::{Command, Output, Stdio};

fn repl(file: &str, input: &str) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_situ"))
        .args(["repl", file])
        .env("NO_COLOR", "1")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    // A program that refuses its input (a damaged bundle) exits before it
    // reads standard input: the pipe is then closed, which is no failure of
    // the test; its exit code and output are what the test checks.
    if let Err(e) = child.stdin.take().unwrap().write_all(input.as_bytes()) {
        assert_eq!(e.kind(), std::io::ErrorKind::BrokenPipe, "writing the session: {e}");
    }
    child.wait_with_output().unwrap()
}

fn out(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[test]
fn a_session_on_the_mower_steps_explains_and_undoes() {
    let o = repl(
        "examples/mower/mower.situ",
        "GPFIX error=0.02\nBATT charge=15\nagents\nwhy\nBattery.DOCKED\nDrive.ARRIVED\nstate\nundo\nstate\n",
    );
    let text = out(&o);
    assert_eq!(o.status.code(), Some(0), "{text}");
    assert!(text.contains("MOWING -> DOCKING (battery_low)"), "{text}");
    assert!(text.contains("Drive    running home() from GPS"), "{text}");
    assert!(text.contains("Blades   sleeping"), "the FSM followed the state:\n{text}");
    assert!(text.contains("rule `battery_low` (examples/mower/mower.situ:"), "{text}");
    assert!(text.contains("DOCKING -> CHARGING (docked)"), "{text}");
    assert!(text.contains("took back ARRIVED; DOCKING"), "{text}");
}

#[test]
fn bad_lines_are_errors_and_the_session_goes_on() {
    let o = repl("examples/mower/mower.situ", "BATT charge=low\nBAT charge=1\nwait forever\nBATT charge=15\nstate\n");
    let text = out(&o);
    assert_eq!(o.status.code(), Some(1), "a script with a bad line fails:\n{text}");
    assert!(text.contains("`charge` is a number"), "{text}");
    assert!(text.contains("did you mean `BATT`"), "{text}");
    assert!(text.contains("not a duration"), "{text}");
    assert!(text.contains("DOCKING at 0.000s"), "the session went on:\n{text}");
}

#[test]
fn time_passing_makes_a_silent_agent_stale() {
    // A robot of the tests' own: the radio's heartbeat stops, the drone holds.
    let o = repl("tests/run/heartbeat.situ", "HB\nwait 200ms\nstate\nwait 200ms\nwhy\nHB x3\nfacts\n");
    let text = out(&o);
    assert_eq!(o.status.code(), Some(0), "{text}");
    assert!(text.contains("FLYING at 0.200s"), "{text}");
    assert!(text.contains("FLYING -> HOLD (link_lost)"), "{text}");
    assert!(text.contains("Radio stale"), "why names the staleness:\n{text}");
    assert!(text.contains("HOLD -> FLYING (link_back)"), "{text}");
    assert!(text.contains("Radio: HB x3"), "{text}");
}

#[test]
fn a_saved_session_is_a_test_that_passes() {
    let dir = tempfile::tempdir().unwrap();
    let saved = dir.path().join("session.situ");
    let rules = std::path::Path::new("examples/mower/mower.situ").canonicalize().unwrap();
    let o = repl(
        &rules.display().to_string(),
        &format!("GPFIX error=0.02\nBATT charge=10\nDrive.ARRIVED\nBattery.DOCKED\nreload\nsave {}\n", saved.display()),
    );
    assert_eq!(o.status.code(), Some(0), "{}", out(&o));
    assert!(out(&o).contains("no rule changed"), "{}", out(&o));
    let text = std::fs::read_to_string(&saved).unwrap();
    assert!(text.starts_with("include \"") && text.contains("expect state CHARGING"), "{text}");
    let t = common::situ(&["test", &saved.display().to_string(), "--filter", "session"]);
    assert_eq!(common::code(&t), 0, "{text}\n{}", common::text(&t));
    assert!(common::stdout(&t).contains("1 passed, 0 failed"), "{}", common::text(&t));
}

#[test]
fn a_bundle_can_be_stepped_through_too() {
    let dir = tempfile::tempdir().unwrap();
    let bundle = dir.path().join("m.bundle").display().to_string();
    let b = common::situ(&["build", "examples/mower/mower.situ", "-o", &bundle]);
    assert_eq!(common::code(&b), 0, "{}", common::text(&b));
    let o = repl(&bundle, "RAIN level=3 x3\nstate\n");
    assert!(out(&o).contains("MOWING -> RAIN_PAUSE (rain_starts)"), "{}", out(&o));
    let junk = write(dir.path(), "junk.bundle", "not a bundle");
    let o = repl(&junk, "state\n");
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn an_event_of_a_sleeping_agent_is_dropped_and_said_so() {
    // In DOCKING the blades sleep: a run never reports their stall.
    let o = repl("examples/mower/mower.situ", "BATT charge=15\nBlades.BLSTALL\nfacts\nstate\n");
    let text = out(&o);
    assert_eq!(o.status.code(), Some(0), "a dropped event is no error of the script:\n{text}");
    assert!(text.contains("MOWING -> DOCKING (battery_low)"), "{text}");
    assert!(
        text.contains("dropped: `Blades` sleeps in DOCKING, and a sleeping agent is not stepped: a run never reports its `BLSTALL` now; nothing changed"),
        "{text}"
    );
    assert!(!text.contains("Blades: BLSTALL"), "no fact of the blades:\n{text}");
    assert!(text.contains("DOCKING at 0.000s"), "{text}");
}
