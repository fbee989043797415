//! A process's `mode` (peer, client, router) in a deployment file, the DLA
//! deployments of `examples/dla/`, and a stack whose processes meet only
//! through a router process of situ's own (no zenohd).

use situ_bus_zenoh::deploy::{Deployment, Mode};
use situ_bus_zenoh::{Placement, Router, ZenohBus};
use situ_compiler::bundle::{Content, Value};
use situ_runtime::agent::Agent;
use situ_runtime::bus::inproc::Capacity;
use situ_runtime::bus::{Bus, EventMsg};
use situ_runtime::realtime::{self, RealtimeConfig};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};
use zenoh::Wait;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn dla() -> Arc<Content> {
    let c = situ_compiler::check(&root().join("rules/dla.situ"), &situ_compiler::loader::FsLoader).unwrap();
    assert_eq!(c.errors(), 0);
    Arc::new(situ_compiler::bundle::build(&c))
}

fn names(c: &Content) -> Vec<String> {
    c.agents.iter().map(|a| a.name.clone()).collect()
}

fn port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

/// The router deployment: a router, and the Bulletinboard and two agent
/// processes as its clients.
fn through_a_router(router: u16) -> String {
    format!(
        r#"robot = "dla"
[[process]]
name = "router"
mode = "router"
listen = ["tcp/127.0.0.1:{router}"]
[[process]]
name = "board"
board = true
mode = "client"
connect = ["tcp/127.0.0.1:{router}"]
[[process]]
name = "deliberative"
agents = ["Mapper", "RoutePlanner", "PathPlanner"]
mode = "client"
connect = ["tcp/127.0.0.1:{router}"]
[[process]]
name = "reactive"
agents = ["Reactive", "Base"]
mode = "client"
connect = ["tcp/127.0.0.1:{router}"]
"#
    )
}

#[test]
fn mode_is_peer_client_or_router_and_a_bad_one_names_its_process() {
    let agents = names(&dla());
    let d = Deployment::parse(&through_a_router(7999), &agents).unwrap();
    let router = d.process("router").unwrap();
    assert_eq!(router.mode, Mode::Router);
    assert!(router.routes_only(), "a router without agents and without the Bulletinboard only routes");
    assert!(!d.process("board").unwrap().routes_only());
    let cfg = |p: &str| serde_json::from_str::<serde_json::Value>(&d.zenoh_config(d.process(p).unwrap())).unwrap();
    assert_eq!(cfg("router")["mode"], "router");
    assert_eq!(cfg("reactive")["mode"], "client");
    assert_eq!(cfg("reactive")["connect"]["timeout_ms"], -1, "a client waits for its router");
    // Without `mode`: a peer, configured as before.
    let peers = through_a_router(7999).replace("mode = \"client\"\n", "");
    let d = Deployment::parse(&peers, &agents).unwrap();
    assert_eq!(d.process("reactive").unwrap().mode, Mode::Peer);
    let cfg: serde_json::Value = serde_json::from_str(&d.zenoh_config(d.process("reactive").unwrap())).unwrap();
    assert_eq!(cfg["mode"], "peer");
    assert!(cfg["connect"].get("timeout_ms").is_none());

    let bad = |text: String, want: &[&str]| {
        let e = Deployment::parse(&text, &agents).unwrap_err().to_string();
        assert!(want.iter().all(|w| e.contains(w)), "{want:?}: {e}");
    };
    let text = through_a_router(7999);
    let reactive_mode = "name = \"reactive\"\nagents = [\"Reactive\", \"Base\"]\nmode = \"client\"";
    bad(
        text.replace(reactive_mode, &reactive_mode.replace("client", "broker")),
        &["process `reactive`", "`mode = \"broker\"`", "`peer`, `client` or `router`"],
    );
    bad(text.replace("mode = \"router\"", "mode = \"Router\""), &["process `router`", "\"Router\""]);
    bad(
        text.replace("mode = \"router\"\nlisten = [\"tcp/127.0.0.1:7999\"]", "mode = \"router\""),
        &["process `router`", "a router needs `listen`"],
    );
    let no_connect = "mode = \"client\"\nconnect = [\"tcp/127.0.0.1:7999\"]\n[[process]]\nname = \"reactive\"";
    bad(
        text.replace(no_connect, "mode = \"client\"\n[[process]]\nname = \"reactive\""),
        &["process `deliberative`", "give it `connect`"],
    );
    // Access control is by the certificate at the other end of a link.
    let tls = "robot = \"dla\"\n[tls]\nca = \"ca.pem\"\n[[process]]\nname = \"router\"\nmode = \"router\"\n\
               listen = [\"tls/127.0.0.1:7999\"]\ncert = \"r.pem\"\nkey = \"r.key\"\n[[process]]\nname = \"board\"\n\
               board = true\nconnect = [\"tls/127.0.0.1:7999\"]\ncert = \"b.pem\"\nkey = \"b.key\"\n";
    bad(tls.into(), &["process `router`", "with `[tls]`: not supported"]);
}

/// Which processes meet (one listens on an endpoint the other connects to).
fn meet(d: &Deployment, a: &str, b: &str) -> bool {
    let (p, q) = (d.process(a).unwrap(), d.process(b).unwrap());
    p.connect.iter().any(|e| q.listen.contains(e)) || q.connect.iter().any(|e| p.listen.contains(e))
}

#[test]
fn the_dla_deployments_place_every_agent_and_meet_as_they_must() {
    let c = dla();
    let agents = names(&c);
    let peers = Deployment::load(&root().join("examples/dla/deploy-peers.toml"), &agents).unwrap();
    let router = Deployment::load(&root().join("examples/dla/deploy-router.toml"), &agents).unwrap();
    for d in [&peers, &router] {
        let placed: Vec<&String> = d.processes.iter().flat_map(|p| &p.agents).collect();
        assert_eq!(placed.len(), agents.len(), "every agent of dla.situ runs somewhere, once");
        assert_eq!(d.board().name, "board");
    }
    // Peers: every pair meets (each pair exchanges events, status or data).
    let processes: Vec<&str> = peers.processes.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(processes, ["board", "sensors", "deliberative", "reactive"]);
    for (i, a) in processes.iter().enumerate() {
        for b in &processes[i + 1..] {
            assert!(meet(&peers, a, b), "`{a}` and `{b}` meet");
        }
        assert_eq!(peers.process(a).unwrap().mode, Mode::Peer);
    }
    // Through the router: each other process connects to it, and only to it.
    let r = router.process("router").unwrap();
    assert!(r.routes_only());
    for p in router.processes.iter().filter(|p| p.name != "router") {
        assert_eq!(p.mode, Mode::Client, "{}", p.name);
        assert_eq!(p.connect, r.listen, "{} connects to the router alone", p.name);
        assert!(p.listen.is_empty(), "{}", p.name);
    }
    // Their ports are their own (the Fig. 5 example uses 7447–7449).
    let fig5 = std::fs::read_to_string(root().join("examples/fig5/deploy.toml")).unwrap();
    for d in [&peers, &router] {
        for e in d.processes.iter().flat_map(|p| &p.listen) {
            assert!(!fig5.contains(e.as_str()), "{e}");
        }
    }
}

/// The Base of dla.situ, standing still whatever it is told.
struct Base;

impl Agent for Base {
    fn name(&self) -> &str {
        "Base"
    }
    fn functions(&self) -> Vec<String> {
        vec!["drive".into(), "stop".into()]
    }
    fn step(&mut self, _: &mut situ_runtime::agent::Context<'_>) {}
}

#[test]
fn an_event_crosses_a_router_to_the_board_and_its_state_to_the_agents() {
    let c = dla();
    let d = Deployment::parse(&through_a_router(port()), &names(&c)).unwrap();
    let router = Router::open(&d.zenoh_config(d.process("router").unwrap())).unwrap();
    let node = |name: &str| {
        let p = d.process(name).unwrap();
        ZenohBus::open(c.clone(), Placement::of(&d, p, &c), &d.zenoh_config(p), Capacity::default()).unwrap()
    };
    // A process of the stack that follows the Bulletinboard in real time
    // (the reactive layer's, with the Base), and the Bulletinboard.
    let run = |name: &str, board: bool| {
        let bus: Arc<dyn Bus> = Arc::new(node(name));
        let config = RealtimeConfig { board, stop_on_final: false, ..RealtimeConfig::default() };
        let agents: Vec<Box<dyn Agent>> = if board { Vec::new() } else { vec![Box::new(Base)] };
        let bound = situ_runtime::agent::bind(&c, agents, false).unwrap();
        realtime::run_on(c.clone(), bound, None, config, Duration::from_secs(4), bus, &mut |_| {})
    };
    let (board, reactive, seen) = std::thread::scope(|scope| {
        let board = scope.spawn(|| run("board", true));
        let reactive = scope.spawn(|| run("reactive", false));
        // The deliberative process reports a route (again every 200 ms
        // until its state comes back: the first may go out before the
        // Bulletinboard's subscription has crossed the router).
        let deliberative = scope.spawn(|| {
            let bus = node("deliberative");
            // Its one link is to a router (a peer in the middle would be
            // listed among the peers, not the routers).
            let info = bus.session().info();
            assert_eq!(info.routers_zid().wait().count(), 1, "the deliberative process met a router");
            assert_eq!(info.peers_zid().wait().count(), 0, "and no peer");
            let (route, planner) = (c.event_id("ROUTE").unwrap(), c.agent_id("RoutePlanner").unwrap());
            let following = c.state_id("Following").unwrap();
            let end = Instant::now() + Duration::from_secs(3);
            let mut next = Instant::now() + Duration::from_millis(300);
            while Instant::now() < end {
                if bus.status(planner).is_some_and(|s| s.state == following) {
                    return true;
                }
                if Instant::now() >= next {
                    let time = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap();
                    let payload = vec![Value::I64(1), Value::I64(4)];
                    bus.send_event(EventMsg {
                        agent: planner,
                        event: route,
                        time: time.as_nanos() as u64,
                        payload,
                        urgent: false,
                    });
                    next = Instant::now() + Duration::from_millis(200);
                }
                std::thread::sleep(Duration::from_millis(5));
            }
            false
        });
        (board.join().unwrap(), reactive.join().unwrap(), deliberative.join().unwrap())
    });
    drop(router);
    assert_eq!(board.path, ["Planning", "Following"], "the event reached the Bulletinboard through the router");
    assert_eq!(board.rules_fired.get("routed"), Some(&1));
    assert!(seen, "the deliberative process saw the state it caused");
    assert_eq!(reactive.path, ["Planning", "Following"], "the reactive process followed through the router");
}
