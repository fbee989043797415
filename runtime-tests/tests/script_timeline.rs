//! The tests of `situ_runtime::script::timeline` that compile a situ source (moved
//! here so that the runtime does not depend on the compiler).

use situ_bundle::spec::ScriptSpec;
use situ_bundle::Content;
use situ_compiler::spec;
use situ_runtime::script::timeline::*;
use std::sync::Arc;

const SRC: &str = "states { A initial B }\n\
    agent S sensor { rate 10Hz stale after 300ms event HB event GO { n: i64 } }\n\
    agent T sensor { event PING }\n\
    rule go { when state == A and GO(n > 2) then B }\n\
    rule hb { when state == B and HB and PING then A }\n\
    script \"s\" {\n\
        every 100ms S.HB from 0s to 1s\n\
        at 250ms T.PING\n\
        silent S from 500ms to 700ms\n\
        at 800ms S.GO(n: 3)\n\
        random 1s seed 4 from 2s\n\
    }\n";

fn program() -> (Arc<Content>, ScriptSpec) {
    let checked = situ_compiler::check_source("t.situ", SRC);
    let errors: Vec<_> = checked.diagnostics.iter().filter(|d| d.severity == situ_compiler::Severity::Error).collect();
    assert!(errors.is_empty(), "{errors:?}");
    (Arc::new(situ_compiler::bundle::build(&checked)), spec::scripts(&checked).remove(0))
}

#[test]
fn events_come_in_time_order_without_the_silenced_ones() {
    let (c, s) = program();
    let mut t = Timeline::of_script(c.clone(), &s);
    let due: Vec<Due> = t.by_ref().collect();
    let times: Vec<u64> = due.iter().map(|d| d.time).collect();
    assert!(times.windows(2).all(|w| w[0] <= w[1]), "{times:?}");
    let name = |d: &Due| c.events[d.event as usize].name.clone();
    let heartbeats: Vec<u64> =
        due.iter().filter(|d| name(d) == "HB" && d.time < 1_000_000_000).map(|d| d.time).collect();
    // 0, 100, …, 900 ms less 500 and 600 (silent).
    let ms: Vec<u64> = heartbeats.iter().map(|t| t / 1_000_000).collect();
    assert_eq!(ms, [0, 100, 200, 300, 400, 700, 800, 900]);
    assert_eq!(t.silenced[c.agent_id("S").unwrap() as usize], 2);
    let ping = due.iter().find(|d| name(d) == "PING").unwrap();
    assert_eq!((ping.time, ping.step), (250_000_000, 1));
    // The GO at 800 ms comes after the heartbeat of 800 ms (step order).
    let at800: Vec<String> = due.iter().filter(|d| d.time == 800_000_000).map(name).collect();
    assert_eq!(at800, ["HB", "GO"]);
    // The random section stays in [2 s, 3 s) and is the same every time.
    let random: Vec<&Due> = due.iter().filter(|d| d.step == 4).collect();
    assert!(!random.is_empty());
    assert!(random.iter().all(|d| (2_000_000_000..3_000_000_000).contains(&d.time)));
    let again: Vec<Due> = Timeline::of_script(c.clone(), &s).filter(|d| d.step == 4).collect();
    assert_eq!(random.into_iter().cloned().collect::<Vec<_>>(), again);
}

#[test]
fn a_whole_run_random_timeline_ends() {
    let (c, _) = program();
    let due: Vec<Due> = Timeline::random(c, 5_000_000_000, 9).collect();
    assert!(!due.is_empty() && due.iter().all(|d| d.time < 5_000_000_000));
}
