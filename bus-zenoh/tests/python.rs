//! A sensor agent written in Python (examples/python/ladar.py, with the
//! `eclipse-zenoh` package from PyPI and nothing of situ) plays LADAR
//! against the Rust Bulletinboard: its obstacle takes the stack to RO, and
//! it sees the status come back. The package must be installed
//! (`pip install -r examples/python/requirements.txt`, which `.ci/run`
//! does): a missing package fails this test, it does not skip it.

use situ_bus_zenoh::deploy::Deployment;
use situ_bus_zenoh::{Placement, ZenohBus};
use situ_runtime::agent;
use situ_runtime::bus::inproc::Capacity;
use situ_runtime::bus::Bus;
use situ_runtime::demo;
use situ_runtime::realtime::{self, RealtimeConfig};
use std::path::Path;
use std::process::Command;
use std::sync::{Arc, Mutex};
use std::time::Duration;

#[test]
fn a_python_agent_joins_the_rust_bulletinboard() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let checked =
        situ_compiler::check(&root.join("examples/fig5/fig5.situ"), &situ_compiler::loader::FsLoader).unwrap();
    let c = Arc::new(situ_compiler::bundle::build(&checked));
    let port = std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port();
    let agents: Vec<String> = c.agents.iter().map(|a| a.name.clone()).collect();
    let text = format!(
        "robot = \"py\"\n[[process]]\nname = \"board\"\nboard = true\nagents = [\"RFCCD\", \"Fusion\", \"LPL\", \"Drive\"]\nlisten = [\"tcp/127.0.0.1:{port}\"]\n"
    );
    let d = Deployment::parse(&text, &agents).unwrap();
    let p = d.board();
    let local: Vec<bool> = c.agents.iter().map(|a| p.agents.contains(&a.name)).collect();
    let placement = Placement { robot: "py".into(), local, board: true };
    let bus: Arc<dyn Bus> =
        Arc::new(ZenohBus::open(c.clone(), placement, &d.zenoh_config(p), Capacity::default()).unwrap());
    let log: demo::Log = Arc::new(Mutex::new(Vec::new()));
    let mine = demo::fig5(Duration::from_secs(3600), log.clone()).into_iter().filter(|a| a.name() != "LADAR").collect();
    let bound = agent::bind(&c, mine, false).unwrap();

    let python = std::thread::spawn(move || {
        Command::new("python3")
            .arg(root.join("examples/python/ladar.py"))
            .args(["--connect", &format!("tcp/127.0.0.1:{port}"), "--robot", "py", "--timeout", "15"])
            .output()
            .expect("python3 runs")
    });
    let config = RealtimeConfig { stop_on_final: false, ..RealtimeConfig::default() };
    let summary = realtime::run_on(c, bound, None, config, Duration::from_secs(8), bus, &mut |_| {});
    let out = python.join().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !stderr.contains("No module named 'zenoh'"),
        "the Python package eclipse-zenoh is missing: pip install -r examples/python/requirements.txt\n{stderr}"
    );
    assert!(out.status.success(), "the Python agent failed:\n{stdout}\n{stderr}");
    assert!(stdout.contains("status: RO"), "{stdout}");
    assert_eq!(summary.path[..2], ["RS", "RO"], "the Python LADAR's obstacle woke the stack");
    // And Fusion, woken, read RFCCD in the Rust process.
    assert!(log.lock().unwrap().iter().any(|(_, to, from)| to == "Fusion" && from == "RFCCD"));
}
