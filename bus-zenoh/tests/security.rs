//! Only the Bulletinboard writes the status, only the processes of the
//! deployment write events: TLS with client certificates (made here, by a
//! CA of the test's own) and Zenoh's access control by certificate name.
//! Garbage on the keys is refused and counted, never a crash.

use rcgen::{BasicConstraints, CertificateParams, DnType, IsCa, Issuer, KeyPair};
use situ_bus_zenoh::deploy::Deployment;
use situ_bus_zenoh::wire;
use situ_bus_zenoh::{Placement, ZenohBus};
use situ_compiler::bundle::Content;
use situ_runtime::agent;
use situ_runtime::bus::inproc::Capacity;
use situ_runtime::bus::Bus;
use situ_runtime::demo;
use situ_runtime::realtime::{self, RealtimeConfig};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use zenoh::Wait;

fn content() -> Arc<Content> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/fig5/fig5.situ");
    let c = situ_compiler::check(&path, &situ_compiler::loader::FsLoader).unwrap();
    Arc::new(situ_compiler::bundle::build(&c))
}

fn port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

/// A CA, and a certificate and key signed by it for each name, in `dir`.
fn certificates(dir: &Path, names: &[&str]) {
    let mut ca_params = CertificateParams::new(Vec::<String>::new()).unwrap();
    ca_params.is_ca = IsCa::Ca(BasicConstraints::Unconstrained);
    ca_params.distinguished_name.push(DnType::CommonName, "situ test CA");
    let ca_key = KeyPair::generate().unwrap();
    let ca = ca_params.self_signed(&ca_key).unwrap();
    std::fs::write(dir.join("ca.pem"), ca.pem()).unwrap();
    let issuer = Issuer::new(ca_params, &ca_key);
    for name in names {
        let mut p = CertificateParams::new(vec!["localhost".to_string(), "127.0.0.1".to_string()]).unwrap();
        p.distinguished_name.push(DnType::CommonName, *name);
        let key = KeyPair::generate().unwrap();
        let cert = p.signed_by(&key, &issuer).unwrap();
        std::fs::write(dir.join(format!("{name}.pem")), cert.pem()).unwrap();
        std::fs::write(dir.join(format!("{name}.key")), key.serialize_pem()).unwrap();
    }
}

fn deployment(c: &Content, dir: &Path, board: u16, sensors: u16) -> Deployment {
    let text = format!(
        r#"robot = "secure"
[tls]
ca = "ca.pem"
[[process]]
name = "board"
board = true
listen = ["tls/127.0.0.1:{board}"]
cert = "board.pem"
key = "board.key"
[[process]]
name = "sensors"
agents = ["RFCCD", "LADAR", "Fusion", "LPL", "Drive"]
listen = ["tls/127.0.0.1:{sensors}"]
connect = ["tls/127.0.0.1:{board}"]
cert = "sensors.pem"
key = "sensors.key"
"#
    );
    let agents: Vec<String> = c.agents.iter().map(|a| a.name.clone()).collect();
    let mut d = Deployment::parse(&text, &agents).unwrap();
    d.dir = dir.to_path_buf();
    d
}

/// A Zenoh session of a rogue to one process at `port`, with the CA's
/// trust and the certificate `cert` if any; `None` if it cannot open.
fn rogue_session(dir: &Path, port: u16, cert: Option<&str>) -> Option<zenoh::Session> {
    let mut cfg = serde_json::json!({
        "mode": "peer",
        "connect": { "endpoints": [format!("tls/127.0.0.1:{port}")],
                     "retry": { "period_init_ms": 100, "period_max_ms": 200 } },
        "scouting": { "multicast": { "enabled": false }, "gossip": { "enabled": false } },
        "transport": { "link": { "tls": { "root_ca_certificate": dir.join("ca.pem").display().to_string(),
                                          "verify_name_on_connect": false } } },
    });
    if let Some(name) = cert {
        let tls = &mut cfg["transport"]["link"]["tls"];
        tls["connect_certificate"] = dir.join(format!("{name}.pem")).display().to_string().into();
        tls["connect_private_key"] = dir.join(format!("{name}.key")).display().to_string().into();
        tls["enable_mtls"] = true.into();
    }
    let config = zenoh::Config::from_json5(&cfg.to_string()).unwrap();
    zenoh::open(config).wait().ok()
}

/// A process that is not in the deployment, with the CA's trust and a
/// certificate of its own (`cert`), or none. It tries for `patience` to meet
/// both processes, then for `writing` writes a status saying EM and an
/// obstacle event for LADAR, again and again, to each. Returns how many of
/// the deployment's processes it met.
///
/// One session per process, each with the one link: peers do not forward
/// for each other, and a session that meets the board both directly and
/// through the other process does not always learn the board's
/// subscription (Zenoh 1.10).
fn rogue(dir: &Path, board: u16, sensors: u16, cert: Option<&str>, patience: Duration, writing: Duration) -> usize {
    let sessions: Vec<zenoh::Session> =
        [board, sensors].into_iter().filter_map(|port| rogue_session(dir, port, cert)).collect();
    let met = || sessions.iter().map(|s| s.info().peers_zid().wait().count()).sum::<usize>();
    let give_up = std::time::Instant::now() + patience;
    while met() < 2 && std::time::Instant::now() < give_up {
        std::thread::sleep(Duration::from_millis(20));
    }
    let peers = met();
    let mut publishers = Vec::new();
    for s in &sessions {
        publishers.push((
            s.declare_publisher(wire::status_key("secure")).wait().unwrap(),
            s.declare_publisher(wire::event_key("secure", "LADAR")).wait().unwrap(),
        ));
    }
    // A writer learns of subscribers from declarations that follow the
    // connection: give the board's a moment (never, where the access
    // control keeps them from the rogue).
    let matched = || publishers.iter().any(|(_, e)| e.matching_status().wait().is_ok_and(|m| m.matching()));
    let give_up = std::time::Instant::now() + Duration::from_secs(3);
    while peers > 0 && !matched() && std::time::Instant::now() < give_up {
        std::thread::sleep(Duration::from_millis(20));
    }
    let status = serde_json::json!({ "v": 1, "state": "EM", "time_ns": 1, "seq": 999 }).to_string();
    let event = serde_json::json!({ "v": 1, "agent": "LADAR", "event": "LAOBS", "time_ns": 1,
                                    "payload": { "distance": 3.0, "height": 1.0 } });
    let until = std::time::Instant::now() + writing;
    while std::time::Instant::now() < until {
        for (status_publisher, event_publisher) in &publishers {
            let _ = status_publisher.put(status.clone()).wait();
            let mut e = event.clone();
            e["time_ns"] =
                (std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap().as_nanos() as u64).into();
            let _ = event_publisher.put(e.to_string()).wait();
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    drop(publishers);
    for s in sessions {
        let _ = s.close().wait();
    }
    peers
}

/// The tests start several Zenoh sessions with TLS each: one at a time, so
/// that they do not starve each other on a small machine.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

/// Runs the two processes of the deployment with a rogue writing with
/// certificate `rogue_cert` (and one with none) until both rogues are done
/// and one more second; returns each process's path of states.
fn run_with_rogues(rogue_cert: &'static str) -> Vec<(String, Vec<String>, u64)> {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().unwrap();
    certificates(dir.path(), &["board", "sensors", "rogue"]);
    let c = content();
    let (board_port, sensors_port) = (port(), port());
    let d = deployment(&c, dir.path(), board_port, sensors_port);
    let log: demo::Log = Arc::new(Mutex::new(Vec::new()));
    let paths = Arc::new(Mutex::new(Vec::new()));
    let stop = Arc::new(AtomicBool::new(false));
    std::thread::scope(|scope| {
        for p in &d.processes {
            let (c, d, log, paths, stop) = (c.clone(), &d, log.clone(), paths.clone(), stop.clone());
            scope.spawn(move || {
                let placement = Placement::of(d, p, &c);
                let bus = ZenohBus::open(c.clone(), placement, &d.zenoh_config(p), Capacity::default()).unwrap();
                let bus: Arc<dyn Bus> = Arc::new(bus);
                // No obstacle ever: only a rogue could take the state to RO or EM.
                let mine: Vec<Box<dyn agent::Agent>> = demo::fig5(Duration::from_secs(3600), log)
                    .into_iter()
                    .filter(|a| p.agents.iter().any(|n| n == a.name()))
                    .collect();
                let bound = agent::bind(&c, mine, false).unwrap();
                let config = RealtimeConfig {
                    board: p.board,
                    stop_on_final: false,
                    stop: Some(stop),
                    ..RealtimeConfig::default()
                };
                // The run ends when the test raises `stop`; 60 s is a bound.
                let s = realtime::run_on(c.clone(), bound, None, config, Duration::from_secs(60), bus, &mut |_| {});
                paths.lock().unwrap().push((p.name.clone(), s.path.clone(), s.bus.rejected));
            });
        }
        let dir = dir.path();
        let rogues = [
            // With a certificate of the CA, but maybe a name the deployment
            // does not give.
            scope.spawn(move || {
                std::thread::sleep(Duration::from_millis(500));
                rogue(
                    dir,
                    board_port,
                    sensors_port,
                    Some(rogue_cert),
                    Duration::from_secs(20),
                    Duration::from_millis(1500),
                )
            }),
            // With no certificate: the mTLS handshake fails, it never meets them.
            scope.spawn(move || {
                std::thread::sleep(Duration::from_millis(500));
                rogue(dir, board_port, sensors_port, None, Duration::from_secs(2), Duration::from_millis(500))
            }),
        ];
        let met: Vec<usize> = rogues.into_iter().map(|r| r.join().unwrap()).collect();
        // Time for the real LADAR's "no obstacle" to take the state back.
        std::thread::sleep(Duration::from_secs(1));
        stop.store(true, Ordering::SeqCst);
        assert_eq!(met, [2, 0], "the rogue with a certificate meets both processes, the one without none");
    });
    // The real processes did talk.
    assert!(log.lock().unwrap().iter().any(|(_, to, from)| to == "LPL" && from == "RFCCD"));
    let paths = paths.lock().unwrap().clone();
    assert_eq!(paths.len(), 2);
    paths
}

#[test]
fn only_the_deployment_writes_status_and_events() {
    // A certificate of the CA with a name the deployment does not give.
    for (name, path, _) in run_with_rogues("rogue") {
        assert_eq!(path, ["RS"], "{name}: no status or event of the rogues was taken");
    }
}

#[test]
fn only_the_bulletinboard_writes_the_status() {
    // The control experiment: with the sensors' own certificate, the
    // rogue's events are taken (the access control is what stopped the
    // other one), but its status is not: only `board` may write it.
    for (name, path, rejected) in run_with_rogues("sensors") {
        // RO from the rogue's obstacle; back to RS when the rogue stops and
        // the real LADAR reports no obstacle; never EM.
        assert_eq!(
            path.get(..2),
            Some(&["RS".to_string(), "RO".to_string()][..]),
            "{name}: the event is taken: {path:?}, {rejected} rejected"
        );
        assert!(!path.iter().any(|s| s == "EM"), "{name}: the status EM is not: {path:?}");
    }
}

#[test]
fn garbage_on_the_keys_is_refused_and_counted() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let c = content();
    let board_port = port();
    let text = format!(
        "robot = \"junk\"\n[[process]]\nname = \"board\"\nboard = true\nlisten = [\"tcp/127.0.0.1:{board_port}\"]\n"
    );
    let agents: Vec<String> = c.agents.iter().map(|a| a.name.clone()).collect();
    let d = Deployment::parse(&text, &agents).unwrap();
    let p = d.board();
    let placement = Placement { robot: "junk".into(), local: vec![false; c.agents.len()], board: true };
    let bus = Arc::new(ZenohBus::open(c.clone(), placement, &d.zenoh_config(p), Capacity::default()).unwrap());
    let cfg = format!(
        r#"{{ mode: "peer", connect: {{ endpoints: ["tcp/127.0.0.1:{board_port}"] }}, scouting: {{ multicast: {{ enabled: false }} }} }}"#
    );
    let session = zenoh::open(zenoh::Config::from_json5(&cfg).unwrap()).wait().unwrap();
    std::thread::sleep(Duration::from_millis(500));
    let key = wire::event_key("junk", "LADAR");
    let good = r#"{"v":1,"agent":"LADAR","event":"LAOBS","time_ns":5,"payload":{"distance":3.0,"height":1.0}}"#;
    let garbage: Vec<Vec<u8>> = vec![
        b"\xff\xfe not json".to_vec(),
        br#"{"v": 2, "agent": "LADAR", "event": "LAOBS", "time_ns": 1}"#.to_vec(),
        br#"{"v":1,"agent":"LADAR","event":"NOPE","time_ns":1}"#.to_vec(),
        br#"{"v":1,"agent":"LADAR","event":"LAOBS","time_ns":1,"payload":{"distance":"far","height":1}}"#.to_vec(),
        br#"{"v":1,"agent":"Ghost","event":"LAOBS","time_ns":1,"payload":{}}"#.to_vec(),
        vec![b'{'; 2 << 20],
        good.as_bytes().to_vec(),
    ];
    for g in garbage {
        session.put(key.clone(), g).wait().unwrap();
    }
    session.put(wire::event_key("junk", "RFCCD"), good).wait().unwrap(); // on another agent's key
    std::thread::sleep(Duration::from_millis(500));
    let mut events = Vec::new();
    let _ = bus.recv_events(&mut events);
    assert_eq!(events.len(), 1, "only the good event gets through");
    assert_eq!(bus.counters().rejected, 7);
    let reasons = bus.take_refusals().join("\n");
    for want in [
        "not a message of this protocol",
        "protocol version 2",
        "unknown event `NOPE`",
        "is not a f64",
        "an event of `Ghost` on the key of `LADAR`",
        "bytes (at most",
        "on the key of `RFCCD`",
    ] {
        assert!(reasons.contains(want), "{want}:\n{reasons}");
    }
    let _ = session.close().wait();
}
