//! `situ test` proves properties for runs of any length on a rules file a
//! user wrote (a mower, not one of the papers' stacks), beyond the depth the
//! exhaustive search reaches, and finds deep counterexamples that replay.

mod common;

use common::{code, situ, stdout, write};

/// Docking needs 15 low-battery reports in a row: deeper than the
/// exhaustive search's 12 events.
const MOWER: &str = r#"states { Idle initial Mowing Docking Fault final }
agent Battery sensor { stale after 2s event LOW { level: f64 } event OK }
agent Blade actuator {
    event JAM
    function cut
    table { Mowing => run cut()  _ => sleep }
}
agent Remote interface { event GO event HALT }
rule go { when state == Idle and GO and OK then Mowing }
rule halt salience 5 { when state == Mowing and HALT then Idle }
rule dock { when state == Mowing and LOW(level < 0.2) x15 then Docking }
rule charged { when state == Docking and OK then Idle }
rule jam salience 20 { when state in {Idle, Mowing, Docking} and JAM then Fault }
rule silent salience 10 { when state == Mowing and stale Battery then Idle }
property "a fault is never left" { always (state == Fault -> next state == Fault) }
property "the blade cuts only while mowing" { always (Blade running -> state == Mowing) }
property "a jam is a fault" { always (JAM -> state == Fault) }
property "never docking" { never (state == Docking) }
"#;

#[test]
fn a_users_file_is_proved_and_a_deep_counterexample_replays() {
    let dir = tempfile::tempdir().unwrap();
    let text = MOWER;
    let file = write(dir.path(), "mower.situ", text);
    let o = situ(&["test", &file]);
    let out = stdout(&o);
    assert_eq!(code(&o), 1, "{out}");
    for name in ["a fault is never left", "the blade cuts only while mowing", "a jam is a fault"] {
        let at = out.find(&format!("property \"{name}\" ... ok")).unwrap_or_else(|| panic!("{name}: {out}"));
        let block = &out[at..out[at + 1..].find("\nproperty").map_or(out.len(), |e| at + 1 + e)];
        assert!(block.contains("symbolic: proved for runs of any length"), "{name}: {block}");
        assert!(block.contains("exhaustive: no counterexample up to"), "the search alone is bounded: {block}");
    }
    // Docking is 17 events away: IC3 finds it, the engine replays it.
    assert!(out.contains("property \"never docking\" ... FAILED"), "{out}");
    assert!(out.contains("counterexample (IC3, replayed on the engine, shrunk, "), "{out}");
    let test = &out[out.find("test \"counterexample: never docking\"").expect("a test block")..];
    let test: String =
        test.lines().take_while(|l| !l.trim().is_empty()).map(|l| format!("{}\n", l.trim_start())).collect();
    // Pasted into the file, the counterexample is a test that passes.
    let replay = write(dir.path(), "replay.situ", format!("{text}\n{test}"));
    let o = situ(&["test", &replay, "--filter", "counterexample"]);
    assert_eq!(code(&o), 0, "{}\n{test}", stdout(&o));
}
