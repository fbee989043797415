//! Two boards of a standby group over Zenoh on loopback, without agents:
//! a follower catches up on a log longer than one answer's chunk, the
//! leader waits for its acknowledgement, and a status carries the epoch.

use situ_bus_zenoh::deploy::Deployment;
use situ_bus_zenoh::standby::BoardGroup;
use situ_bus_zenoh::{Placement, ZenohBus};
use situ_runtime::bus::inproc::Capacity;
use situ_runtime::bus::EventMsg;
use situ_runtime::standby::{Batch, Entry, Logged, Peers, SharedLog};
use std::sync::Arc;
use std::time::{Duration, Instant};

const RULES: &str = "states { A initial B } agent S sensor { event E { x: f64 } }
                     rule r { when state == A and E(x > 1.0) then B }";

fn port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

fn open(d: &Deployment, name: &str, content: &Arc<situ_compiler::bundle::Content>, log: SharedLog) -> ZenohBus {
    let p = d.process(name).unwrap();
    let placement = Placement { robot: d.robot.clone(), local: vec![false; content.agents.len()], board: true };
    let group = BoardGroup { name: name.into(), lease: Duration::from_secs(5), log };
    ZenohBus::open_in_group(content.clone(), placement, &d.zenoh_config(p), Capacity::default(), Some(group)).unwrap()
}

fn until(what: &str, mut ok: impl FnMut() -> bool) {
    let deadline = Instant::now() + Duration::from_secs(20);
    while !ok() {
        assert!(Instant::now() < deadline, "{what}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn a_follower_catches_up_on_a_long_log_and_the_leader_waits_for_its_acknowledgement() {
    let checked = situ_compiler::check_source("t.situ", RULES);
    let content = Arc::new(situ_compiler::bundle::build(&checked));
    let (a, b) = (port(), port());
    let text = format!(
        "robot = \"sb{a}\"\n[[process]]\nname = \"a\"\nboard = true\nlisten = [\"tcp/127.0.0.1:{a}\"]\n\
         [[process]]\nname = \"b\"\nboard = true\nlisten = [\"tcp/127.0.0.1:{b}\"]\nconnect = [\"tcp/127.0.0.1:{a}\"]\n"
    );
    let d = Deployment::parse(&text, &["S".to_string()]).unwrap();
    // The leader's log: 1,500 entries (three answers' worth), NaN included.
    let leader_log = SharedLog::default();
    for i in 0..1500u64 {
        let entry = if i % 3 == 0 {
            Entry::Tick { time: i }
        } else {
            let x = if i % 7 == 0 { f64::NAN } else { i as f64 };
            let msg = EventMsg {
                agent: 0,
                event: 0,
                time: i,
                payload: vec![situ_compiler::bundle::Value::F64(x)],
                urgent: false,
            };
            Entry::Event { msg, accepted: i % 5 != 0 }
        };
        leader_log.lock().unwrap().push(Logged { epoch: 7 << 8, entry });
    }
    let leader = open(&d, "a", &content, leader_log.clone());
    let follower = open(&d, "b", &content, SharedLog::default());
    let (lp, fp) = (leader.peers().unwrap(), follower.peers().unwrap());
    lp.set_leading(Some(7 << 8));
    // The follower asks until the leader's queryable is known to it.
    let mut got: Vec<Batch> = Vec::new();
    until("the follower gets the whole log", || {
        if got.is_empty() {
            fp.request(1);
            std::thread::sleep(Duration::from_millis(200));
        }
        fp.take_batches(&mut got);
        got.iter().map(|b| b.entries.len()).sum::<usize>() >= 1500
    });
    let mut entries: Vec<Logged> = Vec::new();
    let mut next = 1;
    got.sort_by_key(|b| b.first);
    for b in &got {
        if b.first == next {
            next = b.last() + 1;
            entries.extend(b.entries.iter().cloned());
        }
    }
    assert_eq!(
        entries.len(),
        1500,
        "three chunks, in order: {:?}",
        got.iter().map(|b| (b.first, b.entries.len())).collect::<Vec<_>>()
    );
    let theirs = leader_log.lock().unwrap();
    for (i, e) in entries.iter().enumerate() {
        let want = theirs.batch_from(i as u64 + 1, 1, 0, "a").entries[0].clone();
        match (&e.entry, &want.entry) {
            (Entry::Event { msg: m, accepted: x }, Entry::Event { msg: w, accepted: y }) => {
                assert!(situ_runtime::standby::same_event(m, w) && x == y, "entry {}", i + 1)
            }
            (a, b) => assert_eq!(a, b, "entry {}", i + 1),
        }
        assert_eq!(e.epoch, want.epoch);
    }
    drop(theirs);
    // The follower has the first 1,500 entries: the leader, waiting for
    // the followers in step, is held for entry 1,501 until its
    // acknowledgement comes, and released by it.
    until("the leader hears the follower and waits for it", || {
        fp.ack(7 << 8, 1500);
        !lp.wait_acks(1501, 1501, Instant::now() + Duration::from_millis(50))
    });
    fp.ack(7 << 8, 1501);
    assert!(lp.wait_acks(1501, 1501, Instant::now() + Duration::from_secs(10)));
    // The follower heard the leader's epoch.
    until("the follower hears the leader's epoch", || {
        lp.publish(&leader_log.lock().unwrap().batch_from(1501, 0, 7 << 8, "a"));
        fp.heard().is_some_and(|(e, _)| e == 7 << 8)
    });
}
