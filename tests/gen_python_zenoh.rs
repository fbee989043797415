//! Generated Python agents against the real binary's Bulletinboard over
//! Zenoh (built with `--features zenoh`): two agents of a user's rules file
//! (`tests/gen/launch.situ`) in one Python process report what they were
//! asked to, the board takes it, whether the board starts before or after
//! them, and everything ends at the final state; `situ up` leaves a process
//! marked `external` to them; the Python agent's Zenoh configuration is the
//! one situ makes for the same process. Loopback only, on free ports. The
//! packages of `examples/python/requirements.txt` must be installed: a
//! missing one fails these tests.
#![cfg(feature = "zenoh")]

mod common;

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

const RULES: &str = "tests/gen/launch.situ";
const AGENTS: [&str; 2] = ["Mission", "Flight"];

/// The user's code: the planner reports its mission and, once flying, its
/// end; the flight controller reports that it is armed. Both report in their
/// first step, whenever that is; they run in one process, on one session,
/// until the final state (`--deploy D [--process P]` on the command line).
const USER: &str = r#"
import sys
import threading

import flight_agent as flight
import mission_agent as mission

lock = threading.Lock()


def say(line: str) -> None:
    """One whole line at a time: the agents run in threads of their own."""
    with lock:
        sys.stdout.write(line + "\n")
        sys.stdout.flush()


class Planner(mission.Handlers):
    def __init__(self) -> None:
        self.ready = self.flying = self.done = False

    def on_status(self, state: str, seq: int) -> None:
        say(f"Mission status {state} {seq}")
        self.flying = self.flying or state == "FLYING"

    def on_safe_mode(self, entered: bool) -> None:
        say(f"Mission safe mode {entered}")

    def without_function(self, step: mission.Step) -> None:
        if not self.ready:
            self.ready = True
            step.report(mission.mpready(waypoints=4))
            say(f"Mission reported MPREADY, safe mode {step.safe_mode}")
        if self.flying and not self.done:
            self.done = True
            step.report(mission.mpdone())


class Controller(flight.Handlers):
    armed = False

    def on_status(self, state: str, seq: int) -> None:
        say(f"Flight status {state} {seq}")

    def on_safe_mode(self, entered: bool) -> None:
        say(f"Flight safe mode {entered}")

    def hold(self, step: flight.Step) -> None:
        if not self.armed:
            self.armed = True
            step.report(flight.fcarmed(armed=True))
            say(f"Flight reported FCARMED, safe mode {step.safe_mode}")

    def fly(self, step: flight.Step) -> None:
        pass


runners = mission.run_all([Planner(), Controller()], duration=40.0)
for r in runners:
    say(f"{r.agent}: finished {r.finished}, seen {r.states_seen}, {r.counters}")
sys.exit(0 if all(r.finished for r in runners) else 1)
"#;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

/// The generated modules, the user's script and a deployment (the board, and
/// the Python process, external) in a temporary directory.
fn setup() -> (tempfile::TempDir, String) {
    let dir = tempfile::tempdir().unwrap();
    for agent in AGENTS {
        let o = Command::new(env!("CARGO_BIN_EXE_situ"))
            .args(["gen", "agent", agent, RULES, "--lang", "python", "-o", dir.path().to_str().unwrap()])
            .current_dir(root())
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", common::text(&o));
    }
    std::fs::write(dir.path().join("user.py"), USER).unwrap();
    let b = port();
    let deploy = format!(
        "robot = \"launch{b}\"\n\
         [[process]]\nname = \"board\"\nboard = true\nlisten = [\"tcp/127.0.0.1:{b}\"]\n\
         [[process]]\nname = \"py\"\nagents = [\"Mission\", \"Flight\"]\nconnect = [\"tcp/127.0.0.1:{b}\"]\nexternal = true\n"
    );
    let path = common::write(dir.path(), "deploy.toml", deploy);
    (dir, path)
}

/// A process whose lines (standard output and error) come on a channel, and
/// are kept.
struct Watched {
    child: Child,
    lines: mpsc::Receiver<String>,
    seen: Vec<String>,
}

impl Watched {
    fn start(mut c: Command) -> Watched {
        let mut child = c.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().expect("the process starts");
        let (tx, lines) = mpsc::channel();
        let out: Box<dyn std::io::Read + Send> = Box::new(child.stdout.take().unwrap());
        let err: Box<dyn std::io::Read + Send> = Box::new(child.stderr.take().unwrap());
        for stream in [out, err] {
            let tx = tx.clone();
            std::thread::spawn(move || {
                for line in BufReader::new(stream).lines().map_while(Result::ok) {
                    let _ = tx.send(line);
                }
            });
        }
        Watched { child, lines, seen: Vec::new() }
    }

    /// Waits (at most 40 s) for a line that contains `what`.
    fn wait_for(&mut self, what: &str) {
        if self.seen.iter().any(|l| l.contains(what)) {
            return;
        }
        while let Ok(line) = self.lines.recv_timeout(Duration::from_secs(40)) {
            self.seen.push(line);
            if self.seen.last().is_some_and(|l| l.contains(what)) {
                return;
            }
        }
        panic!("no line with `{what}`:\n{}", self.seen.join("\n"));
    }

    /// Waits for the end (each process ends by its own `--duration`); its
    /// success and every line.
    fn finish(mut self) -> (bool, String) {
        let ok = self.child.wait().unwrap().success();
        while let Ok(line) = self.lines.recv_timeout(Duration::from_secs(5)) {
            self.seen.push(line);
        }
        (ok, self.seen.join("\n"))
    }
}

fn python_agents(dir: &Path, args: &[&str]) -> Watched {
    let mut c = Command::new("python3");
    c.arg("user.py").args(args).current_dir(dir);
    Watched::start(c)
}

fn board(deploy: &str) -> Watched {
    let mut c = Command::new(env!("CARGO_BIN_EXE_situ"));
    c.args(["run", RULES, "--transport", "zenoh", "--deploy", deploy, "--process", "board"])
        .args(["--stack", "none", "--duration", "40"])
        .current_dir(root())
        .env("NO_COLOR", "1");
    Watched::start(c)
}

/// What both orders must show: the board went the whole way on the Python
/// agents' events, and both agents saw it from the first status to the end.
fn check(board: (bool, String), python: (bool, String)) {
    let (board_ok, board_out) = board;
    let (python_ok, python_out) = python;
    let all = format!("--- board\n{board_out}\n--- python\n{python_out}");
    assert!(!python_out.contains("No module named"), "pip install -r examples/python/requirements.txt\n{all}");
    assert!(board_ok && python_ok, "{all}");
    // PLANNED may be passed through, not at rest: both events came at once.
    for state in ["FLYING", "DONE"] {
        assert!(board_out.contains(&format!("board: state {state}")), "{state}\n{all}");
    }
    for agent in AGENTS {
        // Safe mode from the start, left with the first status, which
        // on_status gets (GROUND, the initial state that no change
        // announces, or a later one if the other agent's event came first).
        let first = |what: &str| python_out.find(&format!("{agent} {what}"));
        let (safe, status, left) = (first("safe mode True"), first("status "), first("safe mode False"));
        assert!(safe.is_some() && safe < status && status < left, "{agent}\n{all}");
        assert!(python_out.contains(&format!("{agent}: finished True")), "{agent}\n{all}");
        assert!(python_out.contains(&format!("{agent} status DONE")), "{agent}\n{all}");
    }
    assert!(python_out.contains("'held_dropped': 0"), "{all}");
}

#[test]
fn python_agents_started_before_their_board_are_heard_when_it_comes() {
    let (dir, deploy) = setup();
    let mut python = python_agents(dir.path(), &["--deploy", &deploy]);
    // Both have reported, before any board: their events are held.
    python.wait_for("Mission reported MPREADY, safe mode True");
    python.wait_for("Flight reported FCARMED, safe mode True");
    let board = board(&deploy);
    let (board, python) = (board.finish(), python.finish());
    assert!(python.1.contains("Mission: finished True") && python.1.contains("'held': 1"), "{}", python.1);
    check(board, python);
}

#[test]
fn python_agents_started_after_their_board_are_heard() {
    let (dir, deploy) = setup();
    let mut board = board(&deploy);
    board.wait_for("board: 0 agent(s) here, and the Bulletinboard");
    let python = python_agents(dir.path(), &["--deploy", &deploy, "--process", "py"]);
    check(board.finish(), python.finish());
}

#[test]
fn situ_up_leaves_an_external_process_to_its_owner() {
    let (dir, deploy) = setup();
    let mut c = Command::new(env!("CARGO_BIN_EXE_situ"));
    c.args(["up", &deploy, RULES, "--stack", "none", "--duration", "40"]).current_dir(root()).env("NO_COLOR", "1");
    let mut up = Watched::start(c);
    up.wait_for("expected to join: `py` (Mission, Flight)");
    up.wait_for("up: 1 process(es): board");
    let python = python_agents(dir.path(), &["--deploy", &deploy, "--process", "py"]);
    check(up.finish(), python.finish());
}

/// The Python agent's Zenoh configuration, from the deployment file, is the
/// one situ makes for the same process: peers, a client, a router, TLS.
#[test]
fn the_python_agent_configures_zenoh_as_situ_does() {
    use situ_bus_zenoh::deploy::Deployment;
    let (dir, _) = setup();
    let open = "robot = \"r\"\n\
        [[process]]\nname = \"router\"\nmode = \"router\"\nlisten = [\"tcp/127.0.0.1:7470\"]\n\
        [[process]]\nname = \"board\"\nboard = true\nmode = \"client\"\nconnect = [\"tcp/127.0.0.1:7470\"]\n\
        [[process]]\nname = \"py\"\nagents = [\"Mission\", \"Flight\"]\nlisten = [\"tcp/127.0.0.1:7471\"]\nconnect = [\"tcp/127.0.0.1:7470\"]\nexternal = true\n";
    let tls = "robot = \"r\"\n[tls]\nca = \"certs/ca.pem\"\n\
        [[process]]\nname = \"board\"\nboard = true\nlisten = [\"tls/127.0.0.1:7447\"]\ncert = \"certs/b.pem\"\nkey = \"certs/b.key\"\n\
        [[process]]\nname = \"py\"\nagents = [\"Mission\"]\nconnect = [\"tls/127.0.0.1:7447\"]\ncert = \"/abs/py.pem\"\nkey = \"certs/py.key\"\n";
    let agents: Vec<String> = AGENTS.iter().map(|a| a.to_string()).collect();
    for (file, text, processes) in
        [("open.toml", open, &["router", "board", "py"][..]), ("tls.toml", tls, &["board", "py"][..])]
    {
        let path = common::write(dir.path(), file, text);
        let d = Deployment::load(Path::new(&path), &agents).unwrap();
        for p in processes {
            let process = d.process(p).unwrap();
            let script = format!(
                "import json, mission_agent as m\n\
                 print(json.dumps(m.deployment_config({path:?}, {p:?}, {:?})[1]))\n",
                process.agents
            );
            let o = Command::new("python3").args(["-c", &script]).current_dir(dir.path()).output().unwrap();
            assert!(o.status.success(), "{}", common::text(&o));
            let python: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
            let rust: serde_json::Value = serde_json::from_str(&d.zenoh_config(process)).unwrap();
            assert_eq!(python, rust, "{file}: process `{p}`");
        }
    }
}
