//! Why a deployment file is refused: a kind with a stable code, the file,
//! the process it concerns, and what is wrong.

use std::path::PathBuf;

/// What is wrong with a deployment file, as a kind: each has a stable
/// [`code`](DeployErrorKind::code) that the command line prints.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DeployErrorKind {
    /// The file cannot be read (missing, not a regular file, too large,
    /// not UTF-8).
    Read,
    /// Not TOML, or not the shape of a deployment (an unknown key, a wrong
    /// type).
    Syntax,
    /// A process's `mode` is not `peer`, `client` or `router`.
    Mode,
    /// `robot` is empty or has characters other than letters, digits, `_`, `-`.
    Robot,
    /// `max_skew_ms` is above its limit.
    MaxSkew,
    /// No process hosts the Bulletinboard.
    NoBoard,
    /// More than 255 boards.
    TooManyBoards,
    /// `[standby]` without a standby group, or a setting out of its range.
    Standby,
    /// Two processes of one name.
    DuplicateProcess,
    /// A process runs an agent the rules do not declare.
    UnknownAgent,
    /// An agent runs in two processes.
    AgentTwice,
    /// An endpoint is not `tcp/HOST:PORT` or `tls/HOST:PORT`, or its kind
    /// disagrees with the file's `[tls]`.
    Endpoint,
    /// `[tls]` without a process's `cert` and `key`, or with a client or a
    /// router.
    Tls,
    /// An `external` process that would run nothing.
    External,
    /// `journal` on a process that is not the single board.
    Journal,
    /// `beats` off the boards of a standby group, without `send`, on some
    /// boards only, or with an endpoint that is not `udp/HOST:PORT` or
    /// whose host does not resolve.
    Beats,
    /// A client without `connect`, or a router without endpoints.
    Topology,
}

impl DeployErrorKind {
    /// The kind's stable code (`error[CODE]: …` on the command line).
    pub fn code(self) -> &'static str {
        match self {
            DeployErrorKind::Read => "deploy-read",
            DeployErrorKind::Syntax => "deploy-syntax",
            DeployErrorKind::Mode => "deploy-mode",
            DeployErrorKind::Robot => "deploy-robot",
            DeployErrorKind::MaxSkew => "deploy-max-skew",
            DeployErrorKind::NoBoard => "deploy-no-board",
            DeployErrorKind::TooManyBoards => "deploy-too-many-boards",
            DeployErrorKind::Standby => "deploy-standby",
            DeployErrorKind::DuplicateProcess => "deploy-duplicate-process",
            DeployErrorKind::UnknownAgent => "deploy-unknown-agent",
            DeployErrorKind::AgentTwice => "deploy-agent-twice",
            DeployErrorKind::Endpoint => "deploy-endpoint",
            DeployErrorKind::Tls => "deploy-tls",
            DeployErrorKind::External => "deploy-external",
            DeployErrorKind::Journal => "deploy-journal",
            DeployErrorKind::Beats => "deploy-beats",
            DeployErrorKind::Topology => "deploy-topology",
        }
    }
}

/// Why a deployment file is refused. Shown as `FILE: MESSAGE` when the
/// file is known, the message naming the process and the key concerned.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{}{message}", .file.as_ref().map(|f| format!("{}: ", f.display())).unwrap_or_default())]
pub struct DeployError {
    pub kind: DeployErrorKind,
    /// The deployment file, when the error was found reading one.
    pub file: Option<PathBuf>,
    /// The process it concerns, if one.
    pub process: Option<String>,
    pub message: String,
}

impl DeployError {
    pub(crate) fn new(kind: DeployErrorKind, message: impl Into<String>) -> DeployError {
        DeployError { kind, file: None, process: None, message: message.into() }
    }

    /// The error concerns process `name`.
    pub(crate) fn of(mut self, name: &str) -> DeployError {
        self.process = Some(name.to_string());
        self
    }

    /// The error's stable code.
    pub fn code(&self) -> &'static str {
        self.kind.code()
    }
}
