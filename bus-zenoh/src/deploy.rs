//! The deployment file: the paper's process table (which agents run in
//! which process) and host table (how the processes find each other), in
//! TOML, and the Zenoh configuration of each process made from it.
//!
//! ```toml
//! robot = "amr"                      # the key prefix: situ/amr/…
//! max_skew_ms = 50                   # optional: events stamped further ahead
//!                                    # of the Bulletinboard's clock are refused
//!
//! [tls]                              # optional: TLS with client certificates
//! ca = "certs/ca.pem"                # (mTLS) and access control by name
//!
//! [[process]]
//! name = "board"                     # with TLS, its certificate's common name
//! board = true                       # hosts the Bulletinboard
//! journal = "board.journal"          # optional: its log, to resume from after a crash
//! listen = ["tcp/127.0.0.1:7447"]
//! cert = "certs/board.pem"           # with TLS
//! key = "certs/board.key"
//!
//! # [[process]]                    # a second board: a standby (issue of
//! # name = "board-b"                 # docs/reliability.md): the first listed
//! # board = true                     # leads at start, the others follow its log
//! # listen = ["tcp/127.0.0.1:7450"]  # and one of them leads when it falls silent
//! # beats = { listen = "udp/127.0.0.1:7461", send = ["udp/127.0.0.1:7460"] }
//! #                                  # optional, on every board or none: the leader's
//! #                                  # beats over UDP too (a lossy network; `crate::beats`)
//!
//! # [standby]                        # optional, with two boards or more
//! # lease_ms = 400                   # a follower leads after this long without the leader
//! # replicate_within_ms = 100        # a change waits this long at most for the followers
//! # give_up_ms = 5000                # a follower that lacks a decision waits this long, then starts afresh
//!
//! [[process]]
//! name = "sensors"
//! agents = ["RFCCD", "LADAR"]
//! connect = ["tcp/127.0.0.1:7447"]
//! # mode = "peer"                    # or "client" (through a router), "router"
//! # external = true                  # started by someone else: `situ up` leaves it out
//! ```
//!
//! Peers by default, multicast scouting off, explicit endpoints only. A
//! process may be a Zenoh router (`mode = "router"`), with or without
//! agents: the others then connect to it alone (as `client`s), and it
//! carries their messages. With `[tls]`
//! every process presents its certificate and checks the others' against
//! the CA; Zenoh's access control then lets only the process marked `board`
//! put on `situ/<robot>/status`, and only the processes of the table put
//! events and data.

mod error;

pub use error::{DeployError, DeployErrorKind};

use serde::Deserialize;
use std::path::{Path, PathBuf};

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Deployment {
    pub robot: String,
    /// How far ahead of the Bulletinboard's clock an event may be stamped
    /// (ms); [`DEFAULT_MAX_SKEW_MS`] when not given.
    #[serde(default)]
    pub max_skew_ms: Option<u64>,
    #[serde(default)]
    pub tls: Option<Tls>,
    #[serde(rename = "process")]
    pub processes: Vec<Process>,
    /// The standby boards' settings (with two boards or more).
    #[serde(default)]
    pub standby: Option<StandbySettings>,
    /// The directory of the file (relative paths are relative to it).
    #[serde(skip)]
    pub dir: PathBuf,
}

/// `[standby]`: how the boards of a standby group hand over.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StandbySettings {
    /// A follower leads after this long without hearing the leader (ms;
    /// default two status periods, 400).
    #[serde(default)]
    pub lease_ms: Option<u64>,
    /// A change of state waits at most this long for the followers to have
    /// its entries before it is broadcast (ms; default 100).
    #[serde(default)]
    pub replicate_within_ms: Option<u64>,
    /// A follower whose log lacks a decision the agents were told does not
    /// lead at its lease; it waits this long more for a board that has it,
    /// then leads from the rules' initial state (ms; default 25 status
    /// periods, 5000).
    #[serde(default)]
    pub give_up_ms: Option<u64>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Tls {
    pub ca: PathBuf,
}

/// How a process joins Zenoh (`mode` in the file; `peer` when not given).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Mode {
    /// Meets the processes it listens for or connects to, and no others'
    /// messages go through it: every pair that exchanges data must meet.
    #[default]
    Peer,
    /// Talks only through the router (or peer) it connects to.
    Client,
    /// Carries the messages of every process connected to it.
    Router,
}

impl Mode {
    pub fn name(self) -> &'static str {
        match self {
            Mode::Peer => "peer",
            Mode::Client => "client",
            Mode::Router => "router",
        }
    }
}

impl std::str::FromStr for Mode {
    type Err = ();
    fn from_str(s: &str) -> Result<Mode, ()> {
        match s {
            "peer" => Ok(Mode::Peer),
            "client" => Ok(Mode::Client),
            "router" => Ok(Mode::Router),
            _ => Err(()),
        }
    }
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Process {
    pub name: String,
    /// How it joins Zenoh: `mode` of the file, checked by [`Deployment::parse`].
    #[serde(skip)]
    pub mode: Mode,
    #[serde(rename = "mode", default)]
    mode_text: Option<String>,
    #[serde(default)]
    pub board: bool,
    #[serde(default)]
    pub agents: Vec<String>,
    #[serde(default)]
    pub listen: Vec<String>,
    #[serde(default)]
    pub connect: Vec<String>,
    #[serde(default)]
    pub cert: Option<PathBuf>,
    #[serde(default)]
    pub key: Option<PathBuf>,
    /// The host it runs on (the host table); `situ up` starts the processes
    /// of this host: those without `host`, or with `localhost`, `127.0.0.1`
    /// or this host's name.
    #[serde(default)]
    pub host: Option<String>,
    /// Started by someone else (a generated Python agent, a node of the
    /// robot's own): `situ up` does not start it, and says it expects it to
    /// join.
    #[serde(default)]
    pub external: bool,
    /// The board's journal (`board = true` only): a board restarted with it
    /// resumes its state and facts (`situ_runtime::journal`). Relative to
    /// the file's directory ([`Deployment::journal`]).
    #[serde(default)]
    pub journal: Option<PathBuf>,
    /// A board of a standby group: where it hears the other boards' beats
    /// over UDP, and where it sends its own while it leads
    /// ([`crate::beats`]).
    #[serde(default)]
    pub beats: Option<BeatsSettings>,
}

/// `beats = { listen = "udp/HOST:PORT", send = ["udp/HOST:PORT", …] }`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BeatsSettings {
    pub listen: String,
    #[serde(default)]
    pub send: Vec<String>,
}

impl Process {
    /// Whether `situ up` on this host starts it.
    pub fn is_local(&self) -> bool {
        match self.host.as_deref() {
            None | Some("localhost") | Some("127.0.0.1") => true,
            Some(h) => std::fs::read_to_string("/etc/hostname").is_ok_and(|n| n.trim() == h),
        }
    }

    /// A router and nothing else (no agent, no Bulletinboard): its process
    /// only carries the others' messages.
    pub fn routes_only(&self) -> bool {
        self.mode == Mode::Router && self.agents.is_empty() && !self.board
    }
}

/// How far ahead of the Bulletinboard's clock an event may be stamped,
/// when the file does not say (the runtime's default).
pub const DEFAULT_MAX_SKEW_MS: u64 = situ_runtime::runner::DEFAULT_MAX_SKEW / 1_000_000;

/// The largest `max_skew_ms` a file may give: beyond, one event could age
/// every fact of a typical stack past its `stale after`.
pub const MAX_SKEW_LIMIT_MS: u64 = 10_000;

impl Deployment {
    /// Reads and checks a deployment file against the agents of a bundle.
    pub fn load(path: &Path, agents: &[String]) -> Result<Deployment, DeployError> {
        let cannot = |e: &dyn std::fmt::Display| {
            DeployError::new(DeployErrorKind::Read, format!("cannot read `{}`: {e}", path.display()))
        };
        // A deployment is a small TOML file: what is not a regular file (a
        // FIFO, a device) or is larger than a source file is refused.
        let bytes =
            situ_compiler::loader::read_bounded(path, situ_compiler::loader::MAX_FILE_BYTES, "a deployment file")
                .map_err(|e| cannot(&e))?;
        let text = String::from_utf8(bytes).map_err(|e| cannot(&e))?;
        let mut d =
            Deployment::parse(&text, agents).map_err(|e| DeployError { file: Some(path.to_path_buf()), ..e })?;
        d.dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Ok(d)
    }

    pub fn parse(text: &str, agents: &[String]) -> Result<Deployment, DeployError> {
        let mut d: Deployment =
            toml::from_str(text).map_err(|e| DeployError::new(DeployErrorKind::Syntax, e.to_string()))?;
        for p in &mut d.processes {
            if let Some(m) = &p.mode_text {
                p.mode = m.parse().map_err(|()| {
                    DeployError::new(
                        DeployErrorKind::Mode,
                        format!("process `{}`: `mode = \"{m}\"`: `peer`, `client` or `router`", p.name),
                    )
                    .of(&p.name)
                })?;
            }
        }
        if d.robot.is_empty() || !d.robot.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
            return Err(DeployError::new(
                DeployErrorKind::Robot,
                format!("`robot = \"{}\"`: letters, digits, `_` and `-` only", d.robot),
            ));
        }
        if d.max_skew_ms.is_some_and(|ms| ms > MAX_SKEW_LIMIT_MS) {
            return Err(DeployError::new(
                DeployErrorKind::MaxSkew,
                format!(
                    "`max_skew_ms = {}`: at most {MAX_SKEW_LIMIT_MS} (the default is {DEFAULT_MAX_SKEW_MS})",
                    d.max_skew_ms.unwrap_or_default()
                ),
            ));
        }
        let boards: Vec<&str> = d.processes.iter().filter(|p| p.board).map(|p| p.name.as_str()).collect();
        if boards.is_empty() {
            return Err(DeployError::new(
                DeployErrorKind::NoBoard,
                "no process hosts the Bulletinboard (`board = true`): one does, or two and more (a standby group)",
            ));
        }
        if boards.len() > 255 {
            return Err(DeployError::new(
                DeployErrorKind::TooManyBoards,
                format!("{} boards: at most 255", boards.len()),
            ));
        }
        if let Some(s) = &d.standby {
            if boards.len() < 2 {
                return Err(DeployError::new(
                    DeployErrorKind::Standby,
                    "`[standby]` with one board: a standby group has two boards or more (`board = true`)",
                ));
            }
            if s.lease_ms.is_some_and(|ms| !(50..=60_000).contains(&ms)) {
                return Err(DeployError::new(DeployErrorKind::Standby, "`[standby] lease_ms`: from 50 to 60000"));
            }
            if s.replicate_within_ms.is_some_and(|ms| ms > 10_000) {
                return Err(DeployError::new(
                    DeployErrorKind::Standby,
                    "`[standby] replicate_within_ms`: at most 10000",
                ));
            }
            if s.give_up_ms.is_some_and(|ms| ms > 3_600_000) {
                return Err(DeployError::new(
                    DeployErrorKind::Standby,
                    "`[standby] give_up_ms`: at most 3600000 (an hour)",
                ));
            }
        }
        let mut seen: Vec<(&str, &str)> = Vec::new();
        for p in &d.processes {
            if d.processes.iter().filter(|q| q.name == p.name).count() > 1 {
                return Err(DeployError::new(
                    DeployErrorKind::DuplicateProcess,
                    format!("process `{}` is declared twice", p.name),
                )
                .of(&p.name));
            }
            for a in &p.agents {
                if !agents.contains(a) {
                    return Err(DeployError::new(
                        DeployErrorKind::UnknownAgent,
                        format!("process `{}` runs `{a}`, which the rules do not declare", p.name),
                    )
                    .of(&p.name));
                }
                if let Some((_, other)) = seen.iter().find(|(x, _)| x == a) {
                    return Err(DeployError::new(
                        DeployErrorKind::AgentTwice,
                        format!("agent `{a}` runs in both `{other}` and `{}`", p.name),
                    ));
                }
                seen.push((a, &p.name));
            }
            for e in p.listen.iter().chain(&p.connect) {
                let tls_link = e.starts_with("tls/");
                if !(e.starts_with("tcp/") || tls_link) {
                    return Err(DeployError::new(
                        DeployErrorKind::Endpoint,
                        format!("process `{}`: endpoint `{e}` is not `tcp/HOST:PORT` or `tls/HOST:PORT`", p.name),
                    )
                    .of(&p.name));
                }
                if tls_link != d.tls.is_some() {
                    return Err(DeployError::new(DeployErrorKind::Endpoint, format!(
                        "process `{}`: endpoint `{e}`: use `tls/` endpoints exactly when the file has a `[tls]` section",
                        p.name
                    )).of(&p.name));
                }
            }
            if d.tls.is_some() && (p.cert.is_none() || p.key.is_none()) {
                return Err(DeployError::new(
                    DeployErrorKind::Tls,
                    format!("process `{}` needs `cert` and `key` with `[tls]`", p.name),
                )
                .of(&p.name));
            }
            if p.external && p.agents.is_empty() && !p.board {
                return Err(DeployError::new(DeployErrorKind::External, format!(
                    "process `{}`: `external = true` but it runs no agents and hosts no Bulletinboard: nothing would join",
                    p.name
                )).of(&p.name));
            }
            if p.journal.is_some() && !p.board {
                return Err(DeployError::new(
                    DeployErrorKind::Journal,
                    format!(
                        "process `{}`: `journal` belongs to the process that hosts the Bulletinboard (`board = true`)",
                        p.name
                    ),
                )
                .of(&p.name));
            }
            if p.journal.is_some() && boards.len() > 1 {
                return Err(DeployError::new(
                    DeployErrorKind::Journal,
                    format!(
                        "process `{}`: `journal` is for a single board; the boards of a standby group recover from \
                     each other's log",
                        p.name
                    ),
                )
                .of(&p.name));
            }
            if let Some(b) = &p.beats {
                if !p.board || boards.len() < 2 {
                    return Err(DeployError::new(
                        DeployErrorKind::Beats,
                        format!(
                        "process `{}`: `beats` belongs to the boards of a standby group (two processes or more with \
                         `board = true`)",
                        p.name
                    ),
                    )
                    .of(&p.name));
                }
                if b.send.is_empty() {
                    return Err(DeployError::new(
                        DeployErrorKind::Beats,
                        format!(
                            "process `{}`: `beats` with no `send`: when it leads, its beats would reach no other board",
                            p.name
                        ),
                    )
                    .of(&p.name));
                }
                if let Some(q) = d.processes.iter().find(|q| q.board && q.beats.is_none()) {
                    return Err(DeployError::new(
                        DeployErrorKind::Beats,
                        format!(
                        "process `{}` has `beats` and board `{}` has not: give `beats` to every board of the standby \
                         group or to none (a leader without it sends none)",
                        p.name, q.name
                    ),
                    )
                    .of(&p.name));
                }
                for e in std::iter::once(&b.listen).chain(&b.send) {
                    if !crate::beats::is_endpoint(e) {
                        return Err(DeployError::new(
                            DeployErrorKind::Beats,
                            format!("process `{}`: `beats`: endpoint `{e}` is not `udp/HOST:PORT`", p.name),
                        )
                        .of(&p.name));
                    }
                }
            }
            if p.mode == Mode::Client && p.connect.is_empty() {
                return Err(DeployError::new(
                    DeployErrorKind::Topology,
                    format!(
                        "process `{}`: a client talks through what it connects to: give it `connect` (the router)",
                        p.name
                    ),
                )
                .of(&p.name));
            }
            if p.mode == Mode::Router && p.listen.is_empty() && p.connect.is_empty() {
                return Err(DeployError::new(
                    DeployErrorKind::Topology,
                    format!("process `{}`: a router needs `listen` endpoints (the others connect to it)", p.name),
                )
                .of(&p.name));
            }
            // Access control is by the certificate at the other end of a
            // link: through a router, the status would come from the router.
            if d.tls.is_some() && p.mode != Mode::Peer {
                return Err(DeployError::new(
                    DeployErrorKind::Tls,
                    format!(
                    "process `{}`: `mode = \"{}\"` with `[tls]`: not supported (access control is by the certificate \
                     at the other end of a link, and through a router that is the router's); use peers",
                    p.name,
                    p.mode.name()
                ),
                )
                .of(&p.name));
            }
        }
        Ok(d)
    }

    /// How far ahead of the Bulletinboard's clock an event may be stamped.
    pub fn max_skew(&self) -> std::time::Duration {
        std::time::Duration::from_millis(self.max_skew_ms.unwrap_or(DEFAULT_MAX_SKEW_MS))
    }

    pub fn process(&self, name: &str) -> Option<&Process> {
        self.processes.iter().find(|p| p.name == name)
    }

    /// The process that runs all of `agents` (for `--only`).
    pub fn process_of(&self, agents: &[String]) -> Option<&Process> {
        self.processes.iter().find(|p| agents.iter().all(|a| p.agents.contains(a)))
    }

    /// The process of the board that leads at start (the first listed).
    pub fn board(&self) -> &Process {
        self.processes.iter().find(|p| p.board).expect("checked: a board")
    }

    /// The boards, in their order of rank (the first leads at start).
    pub fn boards(&self) -> Vec<&Process> {
        self.processes.iter().filter(|p| p.board).collect()
    }

    /// Whether the boards form a standby group (two or more).
    pub fn has_standby(&self) -> bool {
        self.processes.iter().filter(|p| p.board).count() > 1
    }

    /// How `process`, a board of a standby group, hands over: the
    /// defaults for a status period of `status_every`, with the file's
    /// `[standby]` settings over them. `None`: no standby group, or not
    /// one of its boards.
    pub fn standby_config(
        &self,
        process: &str,
        status_every: std::time::Duration,
    ) -> Option<situ_runtime::standby::StandbyConfig> {
        let rank = self.rank(process).filter(|_| self.has_standby())?;
        let mut config = situ_runtime::standby::StandbyConfig::new(process, rank, status_every);
        let s = self.standby.clone().unwrap_or_default();
        let ms = std::time::Duration::from_millis;
        if let Some(v) = s.lease_ms {
            config.lease = ms(v);
        }
        if let Some(v) = s.replicate_within_ms {
            config.replicate_within = ms(v);
        }
        if let Some(v) = s.give_up_ms {
            config.give_up = ms(v);
        }
        Some(config)
    }

    /// Where `process` hears the boards' beats over UDP and where it sends
    /// its own, the hosts resolved; `None` when it has no `beats`.
    pub fn beats(&self, process: &Process) -> Result<Option<crate::beats::Beats>, DeployError> {
        let Some(b) = &process.beats else { return Ok(None) };
        let resolve = |e: &str| {
            crate::beats::resolve(e).map_err(|why| {
                DeployError::new(DeployErrorKind::Beats, format!("process `{}`: `beats`: {why}", process.name))
                    .of(&process.name)
            })
        };
        Ok(Some(crate::beats::Beats {
            listen: resolve(&b.listen)?,
            send: b.send.iter().map(|e| resolve(e)).collect::<Result<_, _>>()?,
        }))
    }

    /// A board's place among the boards (0 leads at start), if it is one.
    pub fn rank(&self, process: &str) -> Option<u32> {
        self.boards().iter().position(|p| p.name == process).map(|i| i as u32)
    }

    /// Where `process` keeps its journal, if it does (a relative `journal`
    /// is relative to the file's directory).
    pub fn journal(&self, process: &Process) -> Option<PathBuf> {
        process.journal.as_deref().map(|p| if p.is_absolute() { p.to_path_buf() } else { self.dir.join(p) })
    }

    fn path(&self, p: &Path) -> String {
        let full = if p.is_absolute() { p.to_path_buf() } else { self.dir.join(p) };
        full.display().to_string()
    }

    /// The Zenoh configuration (JSON5 text) of one process.
    pub fn zenoh_config(&self, process: &Process) -> String {
        let q = |v: &[String]| serde_json::to_string(v).expect("strings serialize");
        let mut cfg = serde_json::json!({
            "mode": process.mode.name(),
            "listen": { "endpoints": serde_json::from_str::<serde_json::Value>(&q(&process.listen)).unwrap_or_default() },
            // A process that comes back (a restarted Bulletinboard) is met again
            // within half a second.
            "connect": {
                "endpoints": serde_json::from_str::<serde_json::Value>(&q(&process.connect)).unwrap_or_default(),
                "retry": { "period_init_ms": 100, "period_max_ms": 500, "period_increase_factor": 2 },
            },
            "scouting": { "multicast": { "enabled": false }, "gossip": { "enabled": true } },
        });
        if process.mode == Mode::Client {
            // Zenoh's client gives up at once when its router is not there
            // yet; here it waits for it, as peers and routers do.
            cfg["connect"]["timeout_ms"] = (-1).into();
            cfg["connect"]["exit_on_failure"] = false.into();
        }
        if let (Some(tls), Some(cert), Some(key)) = (&self.tls, &process.cert, &process.key) {
            cfg["transport"] = serde_json::json!({ "link": { "tls": {
                "root_ca_certificate": self.path(&tls.ca),
                "listen_private_key": self.path(key),
                "listen_certificate": self.path(cert),
                "connect_private_key": self.path(key),
                "connect_certificate": self.path(cert),
                "enable_mtls": true,
                "verify_name_on_connect": false,
            }}});
            cfg["access_control"] = self.access_control();
        }
        cfg.to_string()
    }

    /// Who may put what, by certificate name: the board's status, the
    /// processes' events and data; subscribing is free.
    fn access_control(&self) -> serde_json::Value {
        let robot = &self.robot;
        let all: Vec<&str> = self.processes.iter().map(|p| p.name.as_str()).collect();
        serde_json::json!({
            "enabled": true,
            "default_permission": "deny",
            // A rule's subject is the other end of a link: a status comes in
            // only from the board, and goes out to any member.
            "rules": [
                { "id": "status_in", "messages": ["put"], "flows": ["ingress"], "permission": "allow",
                  "key_exprs": [format!("situ/{robot}/status")] },
                { "id": "status_out", "messages": ["put"], "flows": ["egress"], "permission": "allow",
                  "key_exprs": [format!("situ/{robot}/status")] },
                { "id": "streams", "messages": ["put"], "flows": ["ingress", "egress"], "permission": "allow",
                  "key_exprs": [format!("situ/{robot}/event/**"), format!("situ/{robot}/data/**")] },
                { "id": "boards", "messages": ["put", "query", "reply"], "flows": ["ingress", "egress"], "permission": "allow",
                  "key_exprs": [format!("situ/{robot}/board/**")] },
                { "id": "subscribe", "messages": ["declare_subscriber", "declare_liveliness_subscriber", "liveliness_token", "declare_queryable"],
                  "flows": ["ingress", "egress"], "permission": "allow", "key_exprs": ["**"] },
            ],
            "subjects": [
                { "id": "board", "cert_common_names": self.boards().iter().map(|p| p.name.as_str()).collect::<Vec<_>>() },
                { "id": "members", "cert_common_names": all },
            ],
            "policies": [
                { "id": "board_status", "rules": ["status_in", "boards"], "subjects": ["board"] },
                { "id": "members_streams", "rules": ["status_out", "streams", "subscribe"], "subjects": ["members"] },
            ],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn agents() -> Vec<String> {
        ["RFCCD", "LADAR", "Fusion"].iter().map(|s| s.to_string()).collect()
    }

    const GOOD: &str = r#"
robot = "amr"
[[process]]
name = "board"
board = true
listen = ["tcp/127.0.0.1:7447"]
[[process]]
name = "sensors"
agents = ["RFCCD", "LADAR"]
connect = ["tcp/127.0.0.1:7447"]
"#;

    #[test]
    fn a_device_or_a_directory_is_refused_not_read() {
        for path in ["/dev/zero", "/"] {
            let e = Deployment::load(Path::new(path), &agents()).unwrap_err();
            assert!(e.message.contains("cannot read") && e.message.contains(path), "{e}");
            assert_eq!(e.code(), "deploy-read");
        }
    }

    #[test]
    fn a_good_file_gives_each_process_its_config() {
        let d = Deployment::parse(GOOD, &agents()).unwrap();
        assert_eq!(d.board().name, "board");
        assert_eq!(d.process_of(&["LADAR".into()]).unwrap().name, "sensors");
        let cfg: serde_json::Value = serde_json::from_str(&d.zenoh_config(d.process("sensors").unwrap())).unwrap();
        assert_eq!(cfg["scouting"]["multicast"]["enabled"], false);
        assert_eq!(cfg["connect"]["endpoints"][0], "tcp/127.0.0.1:7447");
        assert!(cfg.get("access_control").is_none());
        assert_eq!(d.max_skew(), std::time::Duration::from_millis(DEFAULT_MAX_SKEW_MS));
        let d = Deployment::parse(&GOOD.replace("robot = \"amr\"", "robot = \"amr\"\nmax_skew_ms = 5"), &agents());
        assert_eq!(d.unwrap().max_skew(), std::time::Duration::from_millis(5));
    }

    #[test]
    fn the_board_journal_is_relative_to_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("d.toml");
        std::fs::write(&path, GOOD.replace("board = true", "board = true\njournal = \"state/board.journal\"")).unwrap();
        let d = Deployment::load(&path, &agents()).unwrap();
        assert_eq!(d.journal(d.board()), Some(dir.path().join("state/board.journal")));
        assert_eq!(d.journal(d.process("sensors").unwrap()), None);
        let d = Deployment::parse(&GOOD.replace("board = true", "board = true\njournal = \"/var/b.j\""), &agents());
        assert_eq!(d.as_ref().map(|d| d.journal(d.board())).unwrap(), Some(PathBuf::from("/var/b.j")));
    }

    #[test]
    fn two_boards_are_a_standby_group_ranked_in_their_order() {
        let text = format!("{GOOD}[[process]]\nname = \"b2\"\nboard = true\n[standby]\nlease_ms = 500\n");
        let d = Deployment::parse(&text, &agents()).unwrap();
        assert!(d.has_standby());
        assert_eq!((d.rank("board"), d.rank("b2"), d.rank("sensors")), (Some(0), Some(1), None));
        assert_eq!(d.board().name, "board");
        assert_eq!(d.standby.as_ref().and_then(|s| s.lease_ms), Some(500));
        assert!(!Deployment::parse(GOOD, &agents()).unwrap().has_standby());
    }

    /// [`GOOD`] with a second board, `b2`: `beats = { a }` on `board` and
    /// `beats = { b }` on `b2` (none for an empty text).
    fn group(a: &str, b: &str) -> String {
        let beats = |x: &str| if x.is_empty() { String::new() } else { format!("\nbeats = {{ {x} }}") };
        format!(
            "{}[[process]]\nname = \"b2\"\nboard = true{}\n",
            GOOD.replace("board = true", &format!("board = true{}", beats(a))),
            beats(b)
        )
    }

    #[test]
    fn a_board_s_beats_are_resolved_to_addresses() {
        let text = group(
            "listen = \"udp/127.0.0.1:7460\", send = [\"udp/127.0.0.1:7461\"]",
            "listen = \"udp/127.0.0.1:7461\", send = [\"udp/127.0.0.1:7460\", \"udp/localhost:7462\"]",
        );
        let d = Deployment::parse(&text, &agents()).unwrap();
        let beats = d.beats(d.process("b2").unwrap()).unwrap().unwrap();
        assert_eq!(beats.listen, "127.0.0.1:7461".parse().unwrap());
        assert_eq!(beats.send.iter().map(|a| a.port()).collect::<Vec<_>>(), [7460, 7462]);
        assert_eq!(d.beats(d.process("sensors").unwrap()).unwrap(), None);
        let unknown = text.replace("udp/localhost:7462", "udp/no-such-host.invalid:7462");
        let d = Deployment::parse(&unknown, &agents()).unwrap();
        let e = d.beats(d.process("b2").unwrap()).unwrap_err().to_string();
        assert!(e.starts_with("process `b2`: `beats`: `udp/no-such-host.invalid:7462`: "), "{e}");
    }

    #[test]
    fn bad_files_say_what_is_wrong() {
        let cases = [
            (GOOD.replace("board = true", ""), "no process hosts the Bulletinboard", "deploy-no-board"),
            (
                GOOD.replace("\"LADAR\"]", "\"LADAR\", \"Ghost\"]"),
                "`Ghost`, which the rules do not declare",
                "deploy-unknown-agent",
            ),
            (
                GOOD.replace(
                    "tcp/127.0.0.1:7447\"]\n[[process]]\nname = \"sensors\"",
                    "udp/1.2.3.4:1\"]\n[[process]]\nname = \"sensors\"",
                ),
                "is not `tcp/HOST:PORT`",
                "deploy-endpoint",
            ),
            (GOOD.replace("robot = \"amr\"", "robot = \"a/b\""), "letters, digits", "deploy-robot"),
            (GOOD.replace("agents = [", "agent = ["), "unknown field `agent`", "deploy-syntax"),
            (format!("{GOOD}\n[tls]\nca = \"ca.pem\"\n"), "use `tls/` endpoints", "deploy-endpoint"),
            (
                GOOD.replace("robot = \"amr\"", "robot = \"amr\"\nmax_skew_ms = 3600000"),
                "at most 10000",
                "deploy-max-skew",
            ),
            (format!("{GOOD}[standby]\nlease_ms = 300\n"), "a standby group has two boards or more", "deploy-standby"),
            (
                format!("{GOOD}[[process]]\nname = \"b2\"\nboard = true\n[standby]\nlease_ms = 10\n"),
                "`[standby] lease_ms`: from 50 to 60000",
                "deploy-standby",
            ),
            (
                format!("{GOOD}[[process]]\nname = \"x\"\nexternal = true\n"),
                "process `x`: `external = true` but it runs no agents",
                "deploy-external",
            ),
            (
                format!(
                    "{}[[process]]\nname = \"b2\"\nboard = true\n",
                    GOOD.replace("board = true", "board = true\njournal = \"j\"")
                ),
                "process `board`: `journal` is for a single board",
                "deploy-journal",
            ),
            (
                GOOD.replace("agents = [", "journal = \"s.journal\"\nagents = ["),
                "process `sensors`: `journal` belongs to the process that hosts the Bulletinboard",
                "deploy-journal",
            ),
            (
                GOOD.replace("board = true", "board = true\nbeats = { listen = \"udp/127.0.0.1:7460\" }"),
                "process `board`: `beats` belongs to the boards of a standby group",
                "deploy-beats",
            ),
            (
                group(
                    "listen = \"udp/127.0.0.1:1\", send = [\"udp/127.0.0.1:2\"]",
                    "listen = \"tcp/127.0.0.1:7460\", send = [\"udp/127.0.0.1:1\"]",
                ),
                "process `b2`: `beats`: endpoint `tcp/127.0.0.1:7460` is not `udp/HOST:PORT`",
                "deploy-beats",
            ),
            (
                group(
                    "listen = \"udp/127.0.0.1:1\", send = [\"udp/127.0.0.1\"]",
                    "listen = \"udp/127.0.0.1:2\", send = [\"udp/127.0.0.1:1\"]",
                ),
                "process `board`: `beats`: endpoint `udp/127.0.0.1` is not `udp/HOST:PORT`",
                "deploy-beats",
            ),
            (group("listen = \"udp/127.0.0.1:1\", to = []", ""), "unknown field `to`", "deploy-syntax"),
            (
                group("listen = \"udp/127.0.0.1:1\"", "listen = \"udp/127.0.0.1:2\""),
                "process `board`: `beats` with no `send`",
                "deploy-beats",
            ),
            (
                format!(
                    "{GOOD}[[process]]\nname = \"b2\"\nboard = true\nbeats = {{ listen = \"udp/127.0.0.1:1\", \
                     send = [\"udp/127.0.0.1:2\"] }}\n"
                ),
                "process `b2` has `beats` and board `board` has not",
                "deploy-beats",
            ),
        ];
        for (text, want, code) in cases {
            let e = Deployment::parse(&text, &agents()).unwrap_err();
            assert!(e.to_string().contains(want), "{want}: {e}");
            assert_eq!(e.code(), code, "{e}");
            // An error about a process names it in its field too.
            if let Some(p) = want.strip_prefix("process `").and_then(|w| w.split('`').next()) {
                assert_eq!(e.process.as_deref(), Some(p), "{e:?}");
            }
        }
    }
}
