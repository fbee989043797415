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
    let group = BoardGroup { name: name.into(), lease: Duration::from_secs(5), log, beats: d.beats(p).unwrap() };
    ZenohBus::open_in_group(content.clone(), placement, &d.zenoh_config(p), Capacity::default(), Some(group)).unwrap()
}

/// Two boards, `a` and `b`, on loopback; `b` connects to `a`.
fn two_boards() -> Deployment {
    let (a, b) = (port(), port());
    let text = format!(
        "robot = \"sb{a}\"\n[[process]]\nname = \"a\"\nboard = true\nlisten = [\"tcp/127.0.0.1:{a}\"]\n\
         [[process]]\nname = \"b\"\nboard = true\nlisten = [\"tcp/127.0.0.1:{b}\"]\nconnect = [\"tcp/127.0.0.1:{a}\"]\n"
    );
    Deployment::parse(&text, &["S".to_string()]).unwrap()
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
    let d = two_boards();
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
    // All of it behind a state the agents were told: every chunk of the
    // answer says so, past its own last entry.
    leader_log.lock().unwrap().decide(1500);
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
    assert!(got.iter().all(|b| b.decided == 1500), "{:?}", got.iter().map(|b| b.decided).collect::<Vec<_>>());
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

/// The Base of DLA: it drives or stops, and reports nothing here.
struct Base;

impl situ_runtime::agent::Agent for Base {
    fn name(&self) -> &str {
        "Base"
    }
    fn functions(&self) -> Vec<String> {
        vec!["drive".into(), "stop".into()]
    }
    fn step(&mut self, _: &mut situ_runtime::agent::Context<'_>) {}
}

/// DLA's central server with a standby: two boards and the agents' processes
/// meet only through a router. The route takes the stack to `Following`;
/// the leading board then goes silent (its process ends), the other leads
/// from `Following`, and the agents never see `Planning` again.
#[test]
fn dla_through_a_router_keeps_its_state_when_the_leading_board_goes_silent() {
    use situ_runtime::bus::Bus;
    use situ_runtime::realtime::{self, RealtimeConfig};
    use situ_runtime::standby::{Standby, StandbyConfig};
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let checked = situ_compiler::check(&root.join("rules/dla.situ"), &situ_compiler::loader::FsLoader).unwrap();
    let c = Arc::new(situ_compiler::bundle::build(&checked));
    let names: Vec<String> = c.agents.iter().map(|a| a.name.clone()).collect();
    let r = port();
    let client = |name: &str, extra: &str| {
        format!("[[process]]\nname = \"{name}\"\nmode = \"client\"\nconnect = [\"tcp/127.0.0.1:{r}\"]\n{extra}")
    };
    let text = format!(
        "robot = \"dla{r}\"\n[[process]]\nname = \"router\"\nmode = \"router\"\nlisten = [\"tcp/127.0.0.1:{r}\"]\n{}{}{}{}",
        client("board-a", "board = true\n"),
        client("board-b", "board = true\n"),
        client("deliberative", "agents = [\"Mapper\", \"RoutePlanner\", \"PathPlanner\"]\n"),
        client("reactive", "agents = [\"Reactive\", \"Base\"]\n"),
    );
    let d = Deployment::parse(&text, &names).unwrap();
    let router = situ_bus_zenoh::Router::open(&d.zenoh_config(d.process("router").unwrap())).unwrap();
    let board = |name: &str, seconds: u64| {
        let p = d.process(name).unwrap();
        let config = StandbyConfig::new(name, d.rank(name).unwrap(), Duration::from_millis(200));
        let log = SharedLog::default();
        let group = BoardGroup { name: name.into(), lease: config.lease, log: log.clone(), beats: None };
        let bus = ZenohBus::open_in_group(
            c.clone(),
            Placement::of(&d, p, &c),
            &d.zenoh_config(p),
            Capacity::default(),
            Some(group),
        )
        .unwrap();
        let peers = bus.peers().unwrap();
        let standby = Standby { config, peers, log, tell: None };
        let config =
            RealtimeConfig { board: true, stop_on_final: false, standby: Some(standby), ..RealtimeConfig::default() };
        let bound = situ_runtime::agent::bind(&c, Vec::new(), false).unwrap();
        realtime::run_on(c.clone(), bound, None, config, Duration::from_secs(seconds), Arc::new(bus), &mut |_| {})
    };
    let (a, b, reactive, seen) = std::thread::scope(|scope| {
        let a = scope.spawn(|| board("board-a", 4));
        let b = scope.spawn(|| {
            std::thread::sleep(Duration::from_millis(200));
            board("board-b", 8)
        });
        let reactive = scope.spawn(|| {
            let p = d.process("reactive").unwrap();
            let bus: Arc<dyn Bus> = Arc::new(
                ZenohBus::open(c.clone(), Placement::of(&d, p, &c), &d.zenoh_config(p), Capacity::default()).unwrap(),
            );
            let config = RealtimeConfig { board: false, stop_on_final: false, ..RealtimeConfig::default() };
            let bound = situ_runtime::agent::bind(&c, vec![Box::new(Base)], false).unwrap();
            realtime::run_on(c.clone(), bound, None, config, Duration::from_secs(8), bus, &mut |_| {})
        });
        // The deliberative process reports a route until its state comes
        // back, then watches the status: still `Following` once board-a
        // has gone silent (at 4 s), from board-b.
        let deliberative = scope.spawn(|| {
            let p = d.process("deliberative").unwrap();
            let bus =
                ZenohBus::open(c.clone(), Placement::of(&d, p, &c), &d.zenoh_config(p), Capacity::default()).unwrap();
            let (route, planner) = (c.event_id("ROUTE").unwrap(), c.agent_id("RoutePlanner").unwrap());
            let following = c.state_id("Following").unwrap();
            let start = Instant::now();
            let mut next = start;
            let mut routed = false;
            let mut late = None;
            while start.elapsed() < Duration::from_secs(7) {
                let status = bus.status(planner);
                routed |= status.is_some_and(|s| s.state == following);
                if !routed && Instant::now() >= next {
                    let time = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap();
                    let msg = EventMsg {
                        agent: planner,
                        event: route,
                        time: time.as_nanos() as u64,
                        payload: vec![situ_compiler::bundle::Value::I64(1), situ_compiler::bundle::Value::I64(4)],
                        urgent: false,
                    };
                    bus.send_event(msg);
                    next = Instant::now() + Duration::from_millis(200);
                }
                if start.elapsed() > Duration::from_millis(6500) {
                    // The status and how old it is (a board beats every 50 ms).
                    let now = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap();
                    late =
                        status.map(|s| (s.state, Duration::from_nanos((now.as_nanos() as u64).saturating_sub(s.time))));
                }
                std::thread::sleep(Duration::from_millis(5));
            }
            (routed, late)
        });
        (a.join().unwrap(), b.join().unwrap(), reactive.join().unwrap(), deliberative.join().unwrap())
    });
    drop(router);
    let following = c.state_id("Following").unwrap();
    assert!(seen.0, "the route took the stack to Following");
    let (state, age) = seen.1.expect("a status at the end");
    assert_eq!(state, following, "the state is still Following after board-a went silent");
    assert!(
        age < Duration::from_millis(1500),
        "and a board still broadcasts it ({age:?} old at 6.5 s; board-a ended at 4 s)"
    );
    assert_eq!(a.path, ["Planning", "Following"], "board-a led: {:?}", a.path);
    assert_eq!(b.path, ["Planning", "Following"], "board-b applied the log, then led from Following: {:?}", b.path);
    assert_eq!(reactive.path, ["Planning", "Following"], "the agents never went back: {:?}", reactive.path);
}

/// A follower that lacks a decision the agents were told. The leader's
/// beats say its log has 100 entries, all behind a broadcast state
/// (`decided`), and it answers no catch-up (it is not the leader on this
/// bus: a leader killed while the follower catches up); then the beats
/// stop. The follower must not lead from its empty log at its lease: it
/// says it waits, and after `give_up` leads from the rules' initial state.
/// With `decided` 0 (no state broadcast yet) it leads at its lease.
fn follower_behind(decided: u64) -> Vec<String> {
    use situ_runtime::realtime::{self, RealtimeConfig};
    use situ_runtime::standby::{Standby, StandbyConfig};
    let checked = situ_compiler::check_source("t.situ", RULES);
    let content = Arc::new(situ_compiler::bundle::build(&checked));
    let d = two_boards();
    let leader = open(&d, "a", &content, SharedLog::default());
    let lp = leader.peers().unwrap();
    let told: Arc<std::sync::Mutex<Vec<String>>> = Arc::default();
    let t = told.clone();
    let mut config = StandbyConfig::new("b", 1, Duration::from_millis(200));
    config.give_up = Duration::from_millis(1500);
    let log = SharedLog::default();
    let p = d.process("b").unwrap();
    let group = BoardGroup { name: "b".into(), lease: config.lease, log: log.clone(), beats: None };
    let placement = Placement { robot: d.robot.clone(), local: vec![false; content.agents.len()], board: true };
    let bus = ZenohBus::open_in_group(content.clone(), placement, &d.zenoh_config(p), Capacity::default(), Some(group))
        .unwrap();
    let peers = bus.peers().unwrap();
    let fp = peers.clone();
    let tell: situ_runtime::standby::Tell = Arc::new(move |s: &str| t.lock().unwrap().push(s.to_string()));
    let standby = Standby { config, peers, log, tell: Some(tell) };
    let follower = std::thread::spawn({
        let content = content.clone();
        move || {
            let config = RealtimeConfig {
                board: true,
                stop_on_final: false,
                standby: Some(standby),
                ..RealtimeConfig::default()
            };
            let bound = situ_runtime::agent::bind(&content, Vec::new(), false).unwrap();
            realtime::run_on(content, bound, None, config, Duration::from_secs(6), Arc::new(bus), &mut |_| {})
        }
    });
    // The leader's beats until the follower has heard them for a second:
    // a log of 100 entries of epoch 7·256, up to `decided` behind a state.
    let beat = Batch { epoch: 7 << 8, board: "a".into(), first: 101, prev_epoch: 7 << 8, decided, entries: Vec::new() };
    let start = Instant::now();
    let mut heard_since = None;
    while heard_since.is_none_or(|h: Instant| h.elapsed() < Duration::from_secs(1)) {
        assert!(start.elapsed() < Duration::from_secs(30), "the follower never heard the leader");
        lp.publish(&beat);
        if heard_since.is_none() && fp.heard().is_some_and(|(e, _)| e == 7 << 8) {
            heard_since = Some(Instant::now());
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    assert!(told.lock().unwrap().is_empty(), "the follower led while it heard the leader: {:?}", told.lock().unwrap());
    // The leader falls silent (killed).
    drop(leader);
    let summary = follower.join().unwrap();
    assert!(summary.board.cascade_errors == 0);
    let told = told.lock().unwrap().clone();
    told
}

#[test]
fn a_follower_that_lacks_a_decision_waits_then_leads_from_the_initial_state() {
    let told = follower_behind(100);
    let at = |what: &str| told.iter().position(|s| s.contains(what));
    let (waits, afresh, leads) = (at("cannot lead yet"), at("starts from the initial state"), at("leads at epoch"));
    assert!(waits.is_some(), "it said it waits: {told:#?}");
    assert!(waits < afresh && afresh < leads, "it waited, then started afresh and led: {told:#?}");
    assert!(told[waits.unwrap()].contains("the agents were told the state of entry 100"), "{told:#?}");
    assert!(told[leads.unwrap()].contains("from entry 0 of the log"), "{told:#?}");
}

#[test]
fn a_follower_behind_on_entries_no_state_was_broadcast_from_leads_at_its_lease() {
    let told = follower_behind(0);
    assert!(told.iter().any(|s| s.contains("leads at epoch")), "{told:#?}");
    assert!(!told.iter().any(|s| s.contains("cannot lead") || s.contains("initial state")), "{told:#?}");
}

/// The resident memory of this process (bytes), from /proc/self/statm.
fn resident() -> u64 {
    let statm = std::fs::read_to_string("/proc/self/statm").unwrap();
    let pages: u64 = statm.split_whitespace().nth(1).unwrap().parse().unwrap();
    pages * 4096
}

/// What a long log costs: the leader's memory per entry, and how long a
/// board that returns takes to receive it (one catch-up query; the
/// answer's chunks of 512 entries). `SITU_LOG_ENTRIES` (200,000): events
/// with a float field, every third entry a heartbeat.
#[test]
#[ignore = "a benchmark: cargo test --release -p situ-bus-zenoh --test standby -- --ignored --nocapture long_log"]
fn long_log_memory_and_catch_up_time() {
    let n: u64 = std::env::var("SITU_LOG_ENTRIES").ok().and_then(|s| s.parse().ok()).unwrap_or(200_000);
    let checked = situ_compiler::check_source("t.situ", RULES);
    let content = Arc::new(situ_compiler::bundle::build(&checked));
    let d = two_boards();
    let leader_log = SharedLog::default();
    let before = resident();
    {
        let mut log = leader_log.lock().unwrap();
        for i in 0..n {
            let entry = if i % 3 == 0 {
                Entry::Tick { time: i }
            } else {
                let payload = vec![situ_compiler::bundle::Value::F64(i as f64)];
                Entry::Event { msg: EventMsg { agent: 0, event: 0, time: i, payload, urgent: false }, accepted: true }
            };
            log.push(Logged { epoch: 7 << 8, entry });
        }
        log.decide(n);
    }
    let per_entry = (resident().saturating_sub(before)) as f64 / n as f64;
    let leader = open(&d, "a", &content, leader_log.clone());
    let follower = open(&d, "b", &content, SharedLog::default());
    let (lp, fp) = (leader.peers().unwrap(), follower.peers().unwrap());
    lp.set_leading(Some(7 << 8));
    // Wait until the follower reaches the leader's queryable (a short log).
    let mut got: Vec<Batch> = Vec::new();
    let start = Instant::now();
    let mut received = 0u64;
    let mut next = 1u64;
    let mut asked: Option<Instant> = None;
    while next <= n {
        assert!(start.elapsed() < Duration::from_secs(300), "caught up to {next} of {n}");
        if asked.is_none_or(|t| t.elapsed() > Duration::from_secs(6)) {
            fp.request(next);
            asked = Some(Instant::now());
        }
        std::thread::sleep(Duration::from_millis(5));
        fp.take_batches(&mut got);
        got.sort_by_key(|b| b.first);
        for b in got.drain(..) {
            if b.first <= next && b.last() >= next {
                received += b.last() + 1 - next;
                next = b.last() + 1;
            }
        }
    }
    let took = start.elapsed();
    eprintln!(
        "a log of {n} entries: {per_entry:.0} bytes of the leader's memory per entry ({:.1} MiB); a returning board \
         received it in {:.2} s ({:.0} entries/s, {received} entries, in one or more catch-up queries)",
        per_entry * n as f64 / 1048576.0,
        took.as_secs_f64(),
        n as f64 / took.as_secs_f64()
    );
}

fn udp_port() -> u16 {
    std::net::UdpSocket::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

/// A leader's beat also goes over UDP, and a follower whose Zenoh link is
/// gone still hears it alive from its datagrams, and only from those of
/// the board and epoch it heard over Zenoh: a datagram never raises the
/// epoch, and another board's or epoch's renews nothing.
#[test]
fn a_leader_s_beats_over_udp_keep_it_alive_but_never_change_who_leads() {
    let checked = situ_compiler::check_source("t.situ", RULES);
    let content = Arc::new(situ_compiler::bundle::build(&checked));
    let (a, b, ua, ub) = (port(), port(), udp_port(), udp_port());
    // What the test hears of the leader's beats.
    let tap = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    tap.set_read_timeout(Some(Duration::from_millis(100))).unwrap();
    let t = tap.local_addr().unwrap().port();
    let text = format!(
        "robot = \"ub{a}\"\n[[process]]\nname = \"a\"\nboard = true\nlisten = [\"tcp/127.0.0.1:{a}\"]\n\
         beats = {{ listen = \"udp/127.0.0.1:{ua}\", send = [\"udp/127.0.0.1:{ub}\", \"udp/127.0.0.1:{t}\"] }}\n\
         [[process]]\nname = \"b\"\nboard = true\nlisten = [\"tcp/127.0.0.1:{b}\"]\nconnect = [\"tcp/127.0.0.1:{a}\"]\n\
         beats = {{ listen = \"udp/127.0.0.1:{ub}\", send = [\"udp/127.0.0.1:{ua}\"] }}\n"
    );
    let d = Deployment::parse(&text, &["S".to_string()]).unwrap();
    let leader = open(&d, "a", &content, SharedLog::default());
    let follower = open(&d, "b", &content, SharedLog::default());
    let (lp, fp) = (leader.peers().unwrap(), follower.peers().unwrap());
    assert_eq!(fp.beats_addr().map(|a| a.port()), Some(ub));
    let epoch = 9 << 8;
    lp.set_leading(Some(epoch));
    let beat = Batch { epoch, board: "a".into(), first: 1, prev_epoch: 0, decided: 0, entries: vec![] };
    until("the follower hears the leader over Zenoh", || {
        lp.publish(&beat);
        fp.heard().is_some_and(|(e, _)| e == epoch)
    });
    // The beat went out as a datagram too.
    let mut buf = [0u8; 512];
    let mut datagram = None;
    until("the leader's beat reaches the tap over UDP", || {
        lp.publish(&beat);
        datagram = tap.recv_from(&mut buf).ok().map(|(n, _)| buf[..n].to_vec());
        datagram.is_some()
    });
    let w: serde_json::Value = serde_json::from_slice(&datagram.unwrap()).unwrap();
    assert_eq!((w["board"].as_str(), w["epoch"].as_u64()), (Some("a"), Some(epoch)), "{w}");
    // The leader's Zenoh session closed: only datagrams reach the follower.
    drop((leader, lp));
    let raw = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let send = |text: &str| raw.send_to(text.as_bytes(), ("127.0.0.1", ub)).unwrap();
    let datagram = |board: &str, e: u64| format!("{{\"v\": 1, \"board\": \"{board}\", \"epoch\": {e}}}");
    // The datagrams are taken in order: once a garbage datagram sent after
    // them is counted, the ones before it were heard.
    let settle = || {
        let before = fp.refused();
        until("the garbage datagram counted", || {
            send("not a beat");
            std::thread::sleep(Duration::from_millis(20));
            fp.refused() > before
        });
    };
    let (_, at) = fp.heard().unwrap();
    until("a datagram of the leader renews it", || {
        send(&datagram("a", epoch));
        fp.heard().is_some_and(|(e, when)| e == epoch && when > at)
    });
    settle();
    let renewed = fp.heard().unwrap();
    for (board, e) in [("a", epoch + 1), ("a", epoch - 1), ("c", epoch), ("b", epoch)] {
        send(&datagram(board, e));
    }
    settle();
    assert_eq!(
        fp.heard(),
        Some(renewed),
        "another board's or epoch's datagram renewed the leader or changed the epoch"
    );
}
