//! The tests of `situ_runtime::organise` that compile a situ source (moved
//! here so that the runtime does not depend on the compiler).

use situ_bundle::Mode;
use situ_runtime::organise::*;
use std::sync::Arc;

fn org(src: &str) -> Organisation {
    let c = situ_compiler::check_source("t.situ", src);
    let front: Vec<_> = c.diagnostics.iter().filter(|d| d.code < "E0300").collect();
    assert!(front.is_empty(), "{front:?}");
    Organisation::new(Arc::new(situ_compiler::bundle::build(&c)))
}

const FIG5: &str = "states { RS initial RO EM }
    agent RFCCD sensor { function lines table { RS => run lines() to LPL  RO => run lines() to Fusion } }
    agent LADAR sensor { event LAOBS function detect table { RO => run detect() to Fusion  _ => wait detect() } }
    agent Fusion processing { function fuse table { RO => run fuse() from RFCCD, LADAR to LPL  _ => sleep } }
    agent LPL processing { function plan table { _ => run plan() } }
    agent Tele interface { event HB }
    agent Supervisor interface {
        event SVRDY function brief function watch function alarm
        fsm {
            Briefing initial => run brief()
            Watching => run watch() from LPL
            Alarm => run alarm()
            Briefing -> Watching on SVRDY
            Watching -> Alarm on state == EM
            Briefing -> Alarm on state == EM
        }
    }
    rule obstacle { when state == RS and LAOBS then RO }";

#[test]
fn figure_5_reorganises_with_the_state() {
    let mut o = org(FIG5);
    let id = |n: &str| o.content().agent_id(n).unwrap();
    let (rfccd, ladar, fusion, lpl, tele) = (id("RFCCD"), id("LADAR"), id("Fusion"), id("LPL"), id("Tele"));
    assert_eq!(o.mode(fusion), Mode::Sleeping);
    assert_eq!(o.mode(ladar), Mode::Waiting);
    assert_eq!(o.mode(tele), Mode::Running, "no table: always running");
    assert!(o.has_link(rfccd, lpl) && !o.has_link(ladar, fusion));
    o.on_state(1); // RO
    assert_eq!(o.mode(fusion), Mode::Running);
    assert_eq!(o.function(fusion), Some("fuse"));
    assert_eq!(o.links(), vec![(rfccd, fusion), (ladar, fusion), (fusion, lpl)]);
}

#[test]
fn fsms_follow_their_events_and_state_changes() {
    let mut o = org(FIG5);
    let sup = o.content().agent_id("Supervisor").unwrap();
    let svrdy = o.content().event_id("SVRDY").unwrap();
    assert_eq!(o.function(sup), Some("brief"));
    assert_eq!(o.on_event(sup, svrdy), Some(FsmMove { agent: sup, from: 0, to: 1 }));
    assert_eq!(o.function(sup), Some("watch"));
    assert!(o.has_link(o.content().agent_id("LPL").unwrap(), sup));
    assert!(o.on_event(sup, svrdy).is_none(), "no transition from Watching on SVRDY");
    assert_eq!(o.on_state(2).len(), 1); // EM
    assert_eq!(o.function(sup), Some("alarm"));
    assert!(o.on_state(2).is_empty(), "a state that continues does not trigger");
    o.reset();
    assert_eq!(o.function(sup), Some("brief"));
}
