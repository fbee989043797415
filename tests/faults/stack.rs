//! A deployment of situ spread over a lab's hosts: the deployment file, the
//! real `situ` binary in each host, the observer, and what they leave (the
//! observer's lines, the recordings' safe-mode periods).

use super::lab::{Lab, Pid, Relay};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

/// How long a process of a scenario may run (s): scenarios stop them with
/// SIGTERM when they have seen what they came for. 120, or a minute more
/// than a soak's `SITU_SOAK_SECONDS` (a longer soak's faults must not
/// outlast the processes).
pub fn run_for() -> String {
    let soak = std::env::var("SITU_SOAK_SECONDS").ok().and_then(|v| v.parse::<u64>().ok()).unwrap_or(0);
    (soak + 60).max(120).to_string()
}

/// One process of a deployment, placed on a host.
#[derive(Debug, Clone)]
pub struct Proc {
    pub name: &'static str,
    pub host: &'static str,
    pub board: bool,
    pub agents: &'static [&'static str],
    /// `peer`, `client` or `router`.
    pub mode: &'static str,
    /// The port it listens on (its host's address).
    pub listen: Option<u16>,
    /// The processes it connects to, by name.
    pub connect: &'static [&'static str],
}

/// Figure 5's three processes as peers (examples/fig5/deploy.toml), each
/// on its own host: `board`, `sensors`, `pipeline`.
pub fn fig5_peers() -> Vec<Proc> {
    vec![
        Proc { name: "board", host: "board", board: true, agents: &[], mode: "peer", listen: Some(7447), connect: &[] },
        Proc {
            name: "sensors",
            host: "sensors",
            board: false,
            agents: &["RFCCD", "LADAR"],
            mode: "peer",
            listen: Some(7448),
            connect: &["board"],
        },
        Proc {
            name: "pipeline",
            host: "pipeline",
            board: false,
            agents: &["Fusion", "LPL", "Drive"],
            mode: "peer",
            listen: Some(7449),
            connect: &["board", "sensors"],
        },
    ]
}

/// Figure 5's processes as clients of a router process on host `router`
/// (as examples/dla/deploy-router.toml does DLA's).
pub fn fig5_router() -> Vec<Proc> {
    let client = |name, agents, board| Proc {
        name,
        host: name,
        board,
        agents,
        mode: "client",
        listen: None,
        connect: &["router"],
    };
    vec![
        Proc {
            name: "router",
            host: "router",
            board: false,
            agents: &[],
            mode: "router",
            listen: Some(7447),
            connect: &[],
        },
        client("board", &[], true),
        client("sensors", &["RFCCD", "LADAR"], false),
        client("pipeline", &["Fusion", "LPL", "Drive"], false),
    ]
}

/// The rules of examples/fig5 with another `stale after` for the sensors
/// (500 ms there), written in the lab: the router restart leaves every
/// agent unheard for longer than 500 ms, which the rules rightly take for
/// an emergency and a stop; with a longer bound the mission goes on, which
/// shows the reconnection itself.
pub fn fig5_rules_with_stale(lab: &Lab, stale: &str) -> PathBuf {
    let text = std::fs::read_to_string(repo().join("examples/fig5/fig5.situ")).expect("examples/fig5/fig5.situ");
    assert_eq!(text.matches("stale after 500ms").count(), 2, "fig5.situ changed: update the fault tests");
    let path = lab.dir().join("fig5-stale.situ");
    std::fs::write(&path, text.replace("stale after 500ms", &format!("stale after {stale}"))).unwrap();
    path
}

pub fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

pub fn fig5_rules() -> PathBuf {
    repo().join("examples/fig5/fig5.situ")
}

/// Writes the deployment file of `procs` in the lab, the connections
/// through `relay` when there is one (it must route to every listening
/// process), directly to the hosts' addresses otherwise.
pub fn write_deployment(lab: &Lab, robot: &str, procs: &[Proc], relay: Option<&Relay>) -> PathBuf {
    deployment_file(lab, robot, procs, relay, false)
}

/// The port a board hears the others' beats on (UDP, its host's address).
pub const BEATS_PORT: u16 = 7460;

/// As [`write_deployment`], each board of the standby group also with
/// `beats`: it hears on its host's [`BEATS_PORT`] and sends to the other
/// boards' (through the relay's datagram routes when there is one).
pub fn write_deployment_with_beats(lab: &Lab, robot: &str, procs: &[Proc], relay: Option<&Relay>) -> PathBuf {
    deployment_file(lab, robot, procs, relay, true)
}

fn deployment_file(lab: &Lab, robot: &str, procs: &[Proc], relay: Option<&Relay>, beats: bool) -> PathBuf {
    let endpoint = |name: &str| {
        let p = procs.iter().find(|p| p.name == name).unwrap_or_else(|| panic!("no process `{name}`"));
        let port = p.listen.unwrap_or_else(|| panic!("`{name}` listens nowhere"));
        match relay {
            Some(r) => r.endpoint(p.host, port),
            None => format!("tcp/{}:{port}", lab.addr(p.host)),
        }
    };
    let list = |v: Vec<String>| v.iter().map(|s| format!("\"{s}\"")).collect::<Vec<_>>().join(", ");
    let mut text = format!("robot = \"{robot}\"\n");
    for p in procs {
        text += &format!("\n[[process]]\nname = \"{}\"\nmode = \"{}\"\n", p.name, p.mode);
        if p.board {
            text += "board = true\n";
        }
        if !p.agents.is_empty() {
            text += &format!("agents = [{}]\n", list(p.agents.iter().map(|a| a.to_string()).collect()));
        }
        if let Some(port) = p.listen {
            text += &format!("listen = [\"tcp/{}:{port}\"]\n", lab.addr(p.host));
        }
        if !p.connect.is_empty() {
            text += &format!("connect = [{}]\n", list(p.connect.iter().map(|c| endpoint(c)).collect()));
        }
        if beats && p.board {
            let to = |q: &Proc| match relay {
                Some(r) => r.udp_endpoint(q.host, BEATS_PORT),
                None => format!("udp/{}:{BEATS_PORT}", lab.addr(q.host)),
            };
            let send = procs.iter().filter(|q| q.board && q.name != p.name).map(to).collect();
            text +=
                &format!("beats = {{ listen = \"udp/{}:{BEATS_PORT}\", send = [{}] }}\n", lab.addr(p.host), list(send));
        }
    }
    let path = lab.dir().join("deploy.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// The relay's targets for `procs`: every process that listens.
pub fn relay_targets(procs: &[Proc]) -> Vec<(&'static str, u16)> {
    procs.iter().filter_map(|p| p.listen.map(|port| (p.host, port))).collect()
}

/// The relay's datagram targets for the boards' beats: every board's
/// [`BEATS_PORT`].
pub fn beat_targets(procs: &[Proc]) -> Vec<(&'static str, u16)> {
    procs.iter().filter(|p| p.board).map(|p| (p.host, BEATS_PORT)).collect()
}

/// `situ run RULES --stack demo --transport zenoh --deploy D --process NAME`,
/// recorded to `NAME.mcap` in the lab.
pub fn situ_run(lab: &Lab, rules: &Path, deploy: &Path, process: &str) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_situ"));
    c.env("NO_COLOR", "1").current_dir(repo()).arg("run").arg(rules);
    c.args(["--stack", "demo", "--transport", "zenoh", "--deploy"]).arg(deploy);
    c.args(["--process", process, "--duration", &run_for()]);
    if !is_router(process) {
        c.arg("--record").arg(recording(lab, process));
    }
    c
}

fn is_router(process: &str) -> bool {
    process == "router"
}

pub fn recording(lab: &Lab, process: &str) -> PathBuf {
    lab.dir().join(format!("{process}.mcap"))
}

/// A deployment running in a lab: each process's `Pid` by name.
pub struct Running {
    pub procs: BTreeMap<String, Pid>,
    /// The processes with `board = true`.
    pub boards: Vec<String>,
    pub observer: Option<Pid>,
}

/// Starts every process of `procs` in its host.
pub fn start(lab: &mut Lab, rules: &Path, deploy: &Path, procs: &[Proc]) -> Running {
    let boards = procs.iter().filter(|p| p.board).map(|p| p.name.to_string()).collect();
    let mut running = Running { procs: BTreeMap::new(), boards, observer: None };
    for p in procs {
        let cmd = situ_run(lab, rules, deploy, p.name);
        let pid = lab.spawn(p.host, p.name, cmd);
        running.procs.insert(p.name.to_string(), pid);
    }
    running
}

/// The observer (`observer.py`) in `host`, on `endpoint`; waits until its
/// subscriber is declared.
pub fn observe(lab: &mut Lab, host: &str, endpoint: &str, mode: &str, robot: &str) -> Pid {
    let mut c = Command::new("python3");
    c.arg(repo().join("tests/faults/observer.py"));
    c.args(["--connect", endpoint, "--mode", mode, "--robot", robot]);
    let pid = lab.spawn(host, &format!("observer-{host}"), c);
    if !lab.wait_for_output(pid, "\"ready\"", Duration::from_secs(60)) {
        panic!("the observer did not start\n{}", lab.output(pid));
    }
    pid
}

/// Asks a process to stop as Ctrl-C would (SIGTERM: the run ends cleanly,
/// the recording finished, the summary printed).
pub fn terminate(lab: &mut Lab, pid: Pid) {
    if lab.wait(pid, Duration::ZERO).is_none() {
        let id = lab.os_pid(pid);
        // SAFETY: kill(2) with a live child's pid and a signal number.
        unsafe { libc::kill(id as i32, libc::SIGTERM) };
    }
}

/// Stops every process of `running` at once (SIGTERM), checks that each
/// ended well, and returns when the signals went (ns). At once: a board
/// that outlives its agents by their `stale after` takes them for silent
/// (an emergency), agents that outlive the board by 600 ms enter safe
/// mode; the scenarios judge what happened before this time. A process
/// the scenario killed is taken out of `running.procs` first.
pub fn stop_all(lab: &mut Lab, running: &Running) -> u64 {
    let stopping = now_ns();
    for pid in running.procs.values() {
        terminate(lab, *pid);
    }
    for pid in running.procs.values() {
        lab.expect_success(*pid, Duration::from_secs(60));
    }
    stopping
}

pub fn now_ns() -> u64 {
    SystemTime::now().duration_since(UNIX_EPOCH).unwrap().as_nanos() as u64
}

/// One status as the observer saw it.
#[derive(Debug, Clone, PartialEq)]
pub struct Seen {
    pub at_ns: u64,
    pub state: String,
    pub seq: u64,
    pub epoch: Option<u64>,
    pub board: Option<String>,
}

/// The statuses the observer printed so far.
pub fn seen(lab: &Lab, observer: Pid) -> Vec<Seen> {
    lab.stdout(observer)
        .lines()
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .filter(|v| v.get("at_ns").is_some())
        .map(|v| Seen {
            at_ns: v["at_ns"].as_u64().unwrap_or(0),
            state: v["state"].as_str().unwrap_or("").to_string(),
            seq: v["seq"].as_u64().unwrap_or(0),
            epoch: v.get("epoch").and_then(|e| e.as_u64()),
            board: v.get("board").and_then(|b| b.as_str()).map(str::to_string),
        })
        .collect()
}

/// Waits until the observer has seen a status for which `f` holds (a
/// status that arrived after `after_ns`); the first such, or `None` after
/// `timeout`.
pub fn wait_seen(
    lab: &Lab,
    observer: Pid,
    after_ns: u64,
    timeout: Duration,
    f: impl Fn(&Seen) -> bool,
) -> Option<Seen> {
    let end = Instant::now() + timeout;
    loop {
        if let Some(s) = seen(lab, observer).into_iter().find(|s| s.at_ns > after_ns && f(s)) {
            return Some(s);
        }
        if Instant::now() >= end {
            return None;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Waits until a process says on standard error that it follows `state`
/// (`NAME: state RO`).
pub fn wait_state(lab: &mut Lab, running: &Running, process: &str, state: &str, timeout: Duration) {
    let pid = running.procs[process];
    let end = Instant::now() + timeout;
    let text = format!("{process}: state {state}");
    while !lab.stderr(pid).contains(&text) {
        if Instant::now() >= end || lab.wait(pid, Duration::ZERO).is_some() {
            panic!("`{process}` did not reach {state} within {timeout:?}\n{}", lab.outputs());
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// The gaps between statuses arriving, in ms, with the arrival that ended
/// each: `(at_ns, gap_ms)`.
pub fn gaps(seen: &[Seen]) -> Vec<(u64, f64)> {
    seen.windows(2).map(|w| (w[1].at_ns, (w[1].at_ns.saturating_sub(w[0].at_ns)) as f64 / 1e6)).collect()
}

/// p50, p99 and max of a list of figures (0 for an empty list).
pub fn percentiles(v: &[f64]) -> (f64, f64, f64) {
    if v.is_empty() {
        return (0.0, 0.0, 0.0);
    }
    let mut v = v.to_vec();
    v.sort_by(|a, b| a.total_cmp(b));
    let at = |q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
    (at(0.5), at(0.99), v[v.len() - 1])
}

/// The time without status across `t_ns`: from the last arrival at or
/// before `t_ns` to the first after it (ms), with that first arrival;
/// `None` if nothing came after. Choose `t_ns` when nothing can arrive
/// (a cut host's heal, a router's restart): a status on its way at a
/// fault's start may arrive just after it.
pub fn gap_across(seen: &[Seen], t_ns: u64) -> Option<(f64, u64)> {
    let before = seen.iter().filter(|s| s.at_ns <= t_ns).map(|s| s.at_ns).max()?;
    let after = seen.iter().find(|s| s.at_ns > t_ns)?.at_ns;
    Some(((after - before) as f64 / 1e6, after))
}

/// Epochs (when the status carries them) never go back, and within one
/// epoch (or without epochs) `seq` never goes back.
pub fn check_monotonic(seen: &[Seen]) -> Result<(), String> {
    for w in seen.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        match (a.epoch, b.epoch) {
            (Some(x), Some(y)) if y < x => return Err(format!("epoch went back: {a:?} then {b:?}")),
            (Some(x), Some(y)) if y > x => continue,
            _ => {}
        }
        if b.seq < a.seq {
            return Err(format!("seq went back within an epoch: {a:?} then {b:?}"));
        }
    }
    Ok(())
}

/// The safe-mode periods of a follower's recording that began before
/// `before` (ns): `(entered, left)`, times in ns (`None`: still in safe
/// mode when the recording ended).
pub fn safe_mode_periods(path: &Path, before: u64) -> Vec<(u64, Option<u64>)> {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let (messages, _) = situ_runtime::record::mcap::read_messages(&bytes).expect("a readable recording");
    let mut periods: Vec<(u64, Option<u64>)> = Vec::new();
    for (topic, time, m) in &messages {
        if topic != "/diagnostics" {
            continue;
        }
        let text = m["message"].as_str().unwrap_or("");
        if text.contains("no status from the Bulletinboard: safe mode") && *time < before {
            periods.push((*time, None));
        } else if text.contains("safe mode ends") {
            if let Some(last) = periods.last_mut().filter(|p| p.1.is_none()) {
                last.1 = Some(*time);
            }
        }
    }
    periods
}

/// The path a process's summary prints (`path: RS → RO`), as states.
pub fn path(stdout: &str) -> Vec<String> {
    let line = stdout.lines().find_map(|l| l.strip_prefix("path: ")).unwrap_or("");
    line.split(" → ").filter(|s| !s.is_empty()).map(str::to_string).collect()
}

/// The states the Bulletinboard's recording went through before `before`
/// (ns; its `/state` changes: a follower's recording has none, its
/// summary's [`path`] says what it followed).
pub fn recorded_states(path: &Path, before: u64) -> Vec<String> {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let (messages, _) = situ_runtime::record::mcap::read_messages(&bytes).expect("a readable recording");
    messages
        .iter()
        .filter(|(t, time, m)| t == "/state" && m["from"] != m["state"] && *time < before)
        .filter_map(|(_, _, m)| m["state"].as_str().map(str::to_string))
        .collect()
}
