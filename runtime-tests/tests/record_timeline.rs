//! A recording read as the page draws it (`record::timeline`): changes,
//! modes and refusals on the rules it was made on; other rules and foreign
//! recordings are typed errors.

use serde_json::{json, Value as Json};
use situ_compiler::bundle::Content;
use situ_runtime::record::mcap::{topics, Reading};
use situ_runtime::record::timeline::{Change, Timeline, TimelineError};

const RULES: &str = "states { RS initial RO }
agent LADAR sensor { event LAOBS { distance: f64 } event LAOBN function detect table { _ => run detect() } }
rule obstacle { when state == RS and LAOBS(distance < 30.0) then RO }
";

fn content() -> Content {
    situ_compiler::bundle::build(&situ_compiler::check_source("t.situ", RULES))
}

fn reading(messages: Vec<(&str, u64, Json)>) -> Reading {
    let messages: Vec<_> = messages.into_iter().map(|(t, time, m)| (t.to_string(), time, m)).collect();
    let end = messages.iter().map(|m| m.1).max().unwrap_or(0);
    Reading { messages, size: 0, cut: None, end }
}

#[test]
fn a_recording_reads_as_changes_modes_and_refusals_on_its_rules() {
    let r = reading(vec![
        ("/pose", 1, json!({})),
        (topics::EVENTS, 2, json!({"agent": "LADAR", "event": "LAOBS", "accepted": true})),
        (topics::STATE, 2, json!({"from": "RS", "state": "RO", "rules": ["obstacle"], "explain": "why"})),
        (topics::MODES, 3, json!({"agent": "LADAR", "function": "detect", "mode": "running"})),
        (topics::EVENTS, 4, json!({"agent": "LADAR", "event": "LAOBN", "accepted": false, "reason": "stale"})),
    ]);
    let c = content();
    let t = Timeline::read(&r, &c).unwrap();
    assert_eq!(
        t.changes,
        [Change { t: 2, from: "RS".into(), to: "RO".into(), rules: vec!["obstacle".into()], explain: "why".into() }]
    );
    assert_eq!(t.modes.len(), 1);
    assert_eq!(t.refused[0].reason, "stale");
    assert_eq!(t.end, 4);
    assert_eq!(t.state_at(&c, Some(1))["state"], "RS");
    let end = t.state_at(&c, None);
    assert_eq!(end["state"], "RO");
    assert_eq!(end["visited"], json!(["RS", "RO"]));
    assert_eq!(end["modes"]["LADAR"]["mode"], "running");
    assert_eq!(t.json()["changes"][0]["rules"], json!(["obstacle"]));
}

#[test]
fn other_rules_and_foreign_recordings_are_typed_errors() {
    let c = content();
    let other = reading(vec![(topics::STATE, 2, json!({"from": "RS", "state": "ZZ"}))]);
    assert_eq!(
        Timeline::read(&other, &c),
        Err(TimelineError::OtherRules { what: "its state `ZZ` is not a state".into() })
    );
    let agent = reading(vec![(topics::MODES, 2, json!({"agent": "Nobody", "mode": "running"}))]);
    assert!(matches!(Timeline::read(&agent, &c), Err(TimelineError::OtherRules { .. })));
    let foreign = reading(vec![("/pose", 1, json!({}))]);
    assert_eq!(Timeline::read(&foreign, &c), Err(TimelineError::NothingOfSitu));
}
