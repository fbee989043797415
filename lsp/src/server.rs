//! The server loop: read a message, dispatch it, write the answer; the
//! lifecycle, and the publication of diagnostics. The JSON of each message
//! is [`crate::protocol`]'s.
//!
//! Messages are handled in order; after a burst (every message already
//! waiting), the stale analyses are checked once and their diagnostics
//! published, so that a run of keystrokes costs one check. A request checks
//! first what it needs. A handler that fails answers an error; one that
//! panics answers an internal error: the server goes on either way.

use crate::diagnostics::{self, Finding};
use crate::protocol::{self, Answer};
use crate::transport::{self, Incoming};
use crate::verdicts::{self, Outcome, Run};
use crate::world::{Analysis, Job, World};
use lsp_server::{Message, Notification, Request};
use serde_json::Value;
use std::collections::BTreeMap;
use std::io::{BufReader, Read, Write};
use std::sync::mpsc;

/// What the server loop waits for.
enum Event {
    Frame(Incoming),
    /// A whole check (static checks included) is done.
    Checked(Job, Option<Box<Analysis>>),
    /// The verdicts of a root are in (`None`: the run failed).
    Verdicts(Run, Option<Outcome>),
}

/// Serves one client on `input` and `output` until `exit` or the end of the
/// input; the process's exit code (0 after a `shutdown`, 1 otherwise).
///
/// Four threads: one reads frames, one runs the static checks (the longest
/// part of a check) on copies of the documents, one runs the properties and
/// tests ([`verdicts`]) when a document is opened or saved, and this one
/// answers. An edit is checked here without the static checks (names,
/// types: fast) and published at once when that finds errors; otherwise the
/// diagnostics wait for the whole check, whose result is dropped if an edit
/// came since. The verdicts of a run join the diagnostics of its files when
/// it ends, unless an edit came since.
pub fn serve(input: impl Read + Send + 'static, output: impl Write) -> i32 {
    let (tx, rx) = mpsc::channel();
    let frames = tx.clone();
    let verdicts_tx = tx.clone();
    std::thread::spawn(move || {
        let mut r = BufReader::new(input);
        while let Ok(Some(frame)) = transport::read(&mut r) {
            if frames.send(Event::Frame(frame)).is_err() {
                break;
            }
        }
    });
    let (jobs, todo) = mpsc::channel::<Job>();
    std::thread::spawn(move || {
        while let Ok(first) = todo.recv() {
            // Only the latest job of each root is worth running.
            let mut latest = BTreeMap::new();
            latest.insert(first.root.clone(), first);
            while let Ok(job) = todo.try_recv() {
                latest.insert(job.root.clone(), job);
            }
            for (_, job) in latest {
                let analysis = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| job.run())).ok().flatten();
                if tx.send(Event::Checked(job, analysis.map(Box::new))).is_err() {
                    return;
                }
            }
        }
    });
    let (runs, to_run) = mpsc::channel::<Run>();
    std::thread::spawn(move || {
        while let Ok(first) = to_run.recv() {
            // A newer run of a root supersedes the older ones still waiting.
            let mut latest = BTreeMap::new();
            latest.insert(first.root.clone(), first);
            while let Ok(run) = to_run.try_recv() {
                latest.insert(run.root.clone(), run);
            }
            for (_, run) in latest {
                let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| run.run())).ok();
                if verdicts_tx.send(Event::Verdicts(run, outcome)).is_err() {
                    return;
                }
            }
        }
    });
    let mut server = Server {
        out: output,
        world: World::default(),
        state: Lifecycle::Starting,
        published: BTreeMap::new(),
        jobs,
        runs,
        refresh_lenses: false,
        asked: 0,
    };
    while let Ok(first) = rx.recv() {
        if let Some(code) = server.event(first) {
            return code;
        }
        while let Ok(next) = rx.try_recv() {
            if let Some(code) = server.event(next) {
                return code;
            }
        }
        server.publish(false);
    }
    1
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Lifecycle {
    Starting,
    Running,
    ShutDown,
}

struct Server<W: Write> {
    out: W,
    world: World,
    state: Lifecycle,
    /// What was last published, by URI.
    published: BTreeMap<String, Vec<Finding>>,
    jobs: mpsc::Sender<Job>,
    runs: mpsc::Sender<Run>,
    /// The client refreshes its code lenses when asked.
    refresh_lenses: bool,
    /// Requests sent to the client so far (their ids).
    asked: u64,
}

impl<W: Write> Server<W> {
    fn send(&mut self, value: Value) {
        // A client that stopped reading is seen at the end of the input.
        let _ = transport::write(&mut self.out, &value);
    }

    /// Tells the user (a notification has no answer to carry an error).
    fn complain(&mut self, message: String) {
        self.send(protocol::message("window/logMessage", 1, &message));
        self.send(protocol::message("window/showMessage", 1, &message));
    }

    fn event(&mut self, event: Event) -> Option<i32> {
        match event {
            Event::Frame(frame) => self.handle(frame),
            Event::Checked(job, analysis) => {
                if let Some(a) = analysis {
                    if self.world.accept(job.root, job.generation, *a) {
                        self.publish(true);
                    }
                }
                None
            }
            Event::Verdicts(run, outcome) => {
                let current = self.world.generation(&run.root);
                let Some(outcome) = outcome else {
                    self.world.verdicts.forget(&run.root);
                    let message =
                        format!("the properties of `{}` could not be checked (an error of situ)", run.root.display());
                    self.complain(message);
                    return None;
                };
                if self.world.verdicts.accept(&run.root, run.generation, current, outcome) {
                    self.publish(true);
                    self.refresh_lenses();
                }
                None
            }
        }
    }

    /// Handles one frame; `Some(code)` when the server must stop.
    fn handle(&mut self, frame: Incoming) -> Option<i32> {
        match frame {
            Incoming::Invalid { id, code, message } => self.send(protocol::error(id, code, message)),
            Incoming::Message(Message::Request(req)) => self.request(req),
            Incoming::Message(Message::Notification(n)) => return self.notification(n),
            Incoming::Message(Message::Response(_)) => {} // the server asks nothing
        }
        None
    }

    /// Asks the client to show the code lenses again, if it can.
    fn refresh_lenses(&mut self) {
        if self.refresh_lenses {
            self.ask("workspace/codeLens/refresh", Value::Null);
        }
    }

    /// Sends a request to the client (its answer is not awaited).
    fn ask(&mut self, method: &str, params: Value) {
        self.asked += 1;
        let id = format!("situ/{}", self.asked);
        self.send(protocol::server_request(&id, method, params));
    }

    fn request(&mut self, req: Request) {
        let id = serde_json::to_value(&req.id).unwrap_or(Value::Null);
        let answer: Answer = match (self.state, req.method.as_str()) {
            (Lifecycle::Starting, "initialize") => {
                self.state = Lifecycle::Running;
                let (settings, refresh) = protocol::initialization(&req.params);
                self.refresh_lenses = refresh;
                match settings {
                    Ok(s) => self.world.verdicts.settings = s,
                    Err(e) => self.complain(format!("{e}; the verdicts run on the editor's default budget")),
                }
                Ok(protocol::capabilities())
            }
            (Lifecycle::Starting, _) => Err(protocol::not_initialized()),
            (Lifecycle::ShutDown, _) => Err(protocol::invalid_request("the server is shut down")),
            (Lifecycle::Running, "initialize") => Err(protocol::invalid_request("already initialized")),
            (Lifecycle::Running, "shutdown") => {
                self.state = Lifecycle::ShutDown;
                Ok(Value::Null)
            }
            (Lifecycle::Running, "workspace/executeCommand") => {
                self.publish(false);
                protocol::execute(&self.world, &req.params).map(|edit| {
                    self.ask("workspace/applyEdit", edit);
                    Value::Null
                })
            }
            (Lifecycle::Running, method) => {
                self.publish(false);
                let world = &self.world;
                let params = req.params;
                std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| protocol::request(world, method, &params)))
                    .unwrap_or_else(|_| Err(protocol::internal_error(method)))
            }
        };
        self.send(protocol::response(id, answer));
    }

    fn notification(&mut self, n: Notification) -> Option<i32> {
        if n.method == "exit" {
            return Some(if self.state == Lifecycle::ShutDown { 0 } else { 1 });
        }
        if self.state != Lifecycle::Running {
            return None; // before `initialize` or after `shutdown`: dropped
        }
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            protocol::sync(&mut self.world, &n.method, &n.params)
        }))
        .unwrap_or_else(|_| Err(protocol::SyncError::Failed(n.method.clone())));
        if let Err(e) = outcome {
            self.complain(e.to_string());
        }
        None
    }

    /// Checks what is stale (`force`: or an analysis came) and publishes what changed.
    fn publish(&mut self, force: bool) {
        let refreshed = self.world.refresh();
        let stale = refreshed.is_some();
        for job in refreshed.into_iter().flatten() {
            let _ = self.jobs.send(job);
        }
        // The documents opened or saved: their properties and tests run.
        let runs = verdicts::start(&mut self.world);
        if !runs.is_empty() {
            self.refresh_lenses();
        }
        for run in runs {
            let _ = self.runs.send(run);
        }
        if !stale && !force {
            self.world.drop_retired();
            return;
        }
        let skipped: Vec<String> = self
            .world
            .analyses
            .values()
            .filter(|a| a.skipped && !self.published.contains_key(&a.uri(situ_grammar::diag::FileId(0))))
            .map(|a| {
                format!(
                    "`{}` has more than {} rules: the static checks are left to `situ check`",
                    a.root.display(),
                    crate::world::MAX_RULES_CHECKED
                )
            })
            .collect();
        for message in skipped {
            self.send(protocol::message("window/logMessage", 3, &message));
        }
        let now = diagnostics::all(&self.world);
        let gone: Vec<String> = self.published.keys().filter(|u| !now.contains_key(*u)).cloned().collect();
        for uri in gone {
            self.published.remove(&uri);
            self.send(protocol::publish(&uri, None, &[]));
        }
        for (uri, found) in now {
            let Some((version, findings)) = found else { continue };
            if self.published.get(&uri) == Some(&findings) {
                continue;
            }
            let message = protocol::publish(&uri, version, &findings);
            self.published.insert(uri, findings);
            self.send(message);
        }
        // The old analyses go once the diagnostics are out.
        self.world.drop_retired();
    }
}
