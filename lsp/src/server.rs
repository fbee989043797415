//! The server loop: lifecycle, document synchronisation, dispatch, and the
//! publication of diagnostics.
//!
//! Messages are handled in order; after a burst (every message already
//! waiting), the stale analyses are checked once and their diagnostics
//! published, so that a run of keystrokes costs one check. A request checks
//! first what it needs. A handler that fails answers an error; one that
//! panics answers an internal error: the server goes on either way.

use crate::text::{uri_to_path, LineIndex};
use crate::transport::{self, Incoming};
use crate::world::{Analysis, Doc, Job, World};
use crate::{actions, complete, nav, tokens};
use lsp_server::{ErrorCode, Message, Notification, Request};
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::io::{BufReader, Read, Write};
use std::path::PathBuf;
use std::sync::mpsc;

/// A request's answer: a result, or an error code and message.
pub type Answer = Result<Value, (i32, String)>;

pub fn invalid_params(message: impl Into<String>) -> (i32, String) {
    (ErrorCode::InvalidParams as i32, message.into())
}

pub fn refused(message: impl Into<String>) -> (i32, String) {
    (ErrorCode::RequestFailed as i32, message.into())
}

/// What the server loop waits for.
enum Event {
    Frame(Incoming),
    /// A whole check (static checks included) is done.
    Checked(Job, Option<Box<Analysis>>),
}

/// Serves one client on `input` and `output` until `exit` or the end of the
/// input; the process's exit code (0 after a `shutdown`, 1 otherwise).
///
/// Three threads: one reads frames, one runs the static checks (the longest
/// part of a check) on copies of the documents, and this one answers. An
/// edit is checked here without the static checks (names, types: fast) and
/// published at once when that finds errors; otherwise the diagnostics wait
/// for the whole check, whose result is dropped if an edit came since.
pub fn serve(input: impl Read + Send + 'static, output: impl Write) -> i32 {
    let (tx, rx) = mpsc::channel();
    let frames = tx.clone();
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
    let mut server =
        Server { out: output, world: World::default(), state: Lifecycle::Starting, published: BTreeMap::new(), jobs };
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
    published: BTreeMap<String, Vec<Value>>,
    jobs: mpsc::Sender<Job>,
}

impl<W: Write> Server<W> {
    fn send(&mut self, value: Value) {
        // A client that stopped reading is seen at the end of the input.
        let _ = transport::write(&mut self.out, &value);
    }

    fn notify(&mut self, method: &str, params: Value) {
        self.send(json!({ "jsonrpc": "2.0", "method": method, "params": params }));
    }

    fn error(&mut self, id: Value, code: i32, message: String) {
        self.send(json!({ "jsonrpc": "2.0", "id": id, "error": { "code": code, "message": message } }));
    }

    /// Tells the user (a notification has no answer to carry an error).
    fn complain(&mut self, message: String) {
        self.notify("window/logMessage", json!({ "type": 1, "message": message }));
        self.notify("window/showMessage", json!({ "type": 1, "message": message }));
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
        }
    }

    /// Handles one frame; `Some(code)` when the server must stop.
    fn handle(&mut self, frame: Incoming) -> Option<i32> {
        match frame {
            Incoming::Invalid { id, code, message } => self.error(id, code, message),
            Incoming::Message(Message::Request(req)) => self.request(req),
            Incoming::Message(Message::Notification(n)) => return self.notification(n),
            Incoming::Message(Message::Response(_)) => {} // the server asks nothing
        }
        None
    }

    fn request(&mut self, req: Request) {
        let id = serde_json::to_value(&req.id).unwrap_or(Value::Null);
        let answer = match (self.state, req.method.as_str()) {
            (Lifecycle::Starting, "initialize") => {
                self.state = Lifecycle::Running;
                Ok(capabilities())
            }
            (Lifecycle::Starting, _) => Err((ErrorCode::ServerNotInitialized as i32, "initialize first".into())),
            (Lifecycle::ShutDown, _) => Err((ErrorCode::InvalidRequest as i32, "the server is shut down".into())),
            (Lifecycle::Running, "initialize") => Err((ErrorCode::InvalidRequest as i32, "already initialized".into())),
            (Lifecycle::Running, "shutdown") => {
                self.state = Lifecycle::ShutDown;
                Ok(Value::Null)
            }
            (Lifecycle::Running, method) => {
                self.publish(false);
                let world = &self.world;
                let params = req.params;
                std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| dispatch(world, method, params)))
                    .unwrap_or_else(|_| Err((ErrorCode::InternalError as i32, format!("`{method}` failed"))))
            }
        };
        match answer {
            Ok(result) => self.send(json!({ "jsonrpc": "2.0", "id": id, "result": result })),
            Err((code, message)) => self.error(id, code, message),
        }
    }

    fn notification(&mut self, n: Notification) -> Option<i32> {
        if n.method == "exit" {
            return Some(if self.state == Lifecycle::ShutDown { 0 } else { 1 });
        }
        if self.state != Lifecycle::Running {
            return None; // before `initialize` or after `shutdown`: dropped
        }
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| sync(&mut self.world, &n)))
            .unwrap_or_else(|_| Err(format!("`{}` failed", n.method)));
        if let Err(message) = outcome {
            self.complain(message);
        }
        None
    }

    /// Checks what is stale (`force`: or an analysis came) and publishes what changed.
    fn publish(&mut self, force: bool) {
        match self.world.refresh() {
            Some(jobs) => {
                for job in jobs {
                    let _ = self.jobs.send(job);
                }
            }
            None if !force => return,
            None => {}
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
            self.notify("window/logMessage", json!({ "type": 3, "message": message }));
        }
        let now = crate::diagnostics::all(&self.world);
        let gone: Vec<String> = self.published.keys().filter(|u| !now.contains_key(*u)).cloned().collect();
        for uri in gone {
            self.published.remove(&uri);
            self.notify("textDocument/publishDiagnostics", json!({ "uri": uri, "diagnostics": [] }));
        }
        for (uri, found) in now {
            let Some((version, diags)) = found else { continue };
            if self.published.get(&uri) == Some(&diags) {
                continue;
            }
            let mut params = json!({ "uri": uri, "diagnostics": diags });
            if let Some(v) = version {
                params["version"] = json!(v);
            }
            self.published.insert(uri, diags);
            self.notify("textDocument/publishDiagnostics", params);
        }
    }
}

/// The document's path, from `params.textDocument.uri`.
pub fn doc_path(params: &Value) -> Result<PathBuf, (i32, String)> {
    let uri = params
        .pointer("/textDocument/uri")
        .and_then(Value::as_str)
        .ok_or_else(|| invalid_params("no textDocument.uri"))?;
    uri_path(uri)
}

fn uri_path(uri: &str) -> Result<PathBuf, (i32, String)> {
    match uri_to_path(uri) {
        Some(p) => Ok(p),
        // Not a file (an unsaved buffer): a name of its own, includes relative to nothing.
        None if !uri.is_empty() => {
            let safe: String = uri.chars().map(|c| if c.is_ascii_alphanumeric() { c } else { '_' }).collect();
            Ok(PathBuf::from(format!("/.situ-lsp-unsaved/{safe}.situ")))
        }
        None => Err(invalid_params("an empty URI")),
    }
}

/// didOpen, didChange, didClose and friends.
fn sync(world: &mut World, n: &Notification) -> Result<(), String> {
    let p = &n.params;
    match n.method.as_str() {
        "textDocument/didOpen" => {
            let uri = p.pointer("/textDocument/uri").and_then(Value::as_str).ok_or("didOpen without a URI")?;
            let text = p.pointer("/textDocument/text").and_then(Value::as_str).ok_or("didOpen without a text")?;
            let version = p.pointer("/textDocument/version").and_then(Value::as_i64).unwrap_or(0) as i32;
            let path = uri_path(uri).map_err(|e| e.1)?;
            world.open(path, Doc::new(uri.to_string(), text.to_string(), version));
        }
        "textDocument/didChange" => {
            let path = doc_path(p).map_err(|e| e.1)?;
            let doc =
                world.docs.get(&path).ok_or_else(|| format!("didChange of `{}`, which is not open", path.display()))?;
            let changes =
                p.get("contentChanges").and_then(Value::as_array).ok_or("didChange without contentChanges")?;
            let mut text = doc.text.clone();
            for (i, c) in changes.iter().enumerate() {
                let new = c.get("text").and_then(Value::as_str).ok_or("a change without text")?;
                match c.get("range") {
                    None | Some(Value::Null) => text = new.to_string(),
                    Some(range) => {
                        let range: lsp_types::Range = serde_json::from_value(range.clone())
                            .map_err(|e| format!("a change with a bad range: {e}"))?;
                        let span = LineIndex::new(&text).span(&text, range).ok_or_else(|| {
                            format!(
                                "change {} of `{}` has an impossible range {}:{}-{}:{}; the change was not applied",
                                i + 1,
                                path.display(),
                                range.start.line,
                                range.start.character,
                                range.end.line,
                                range.end.character
                            )
                        })?;
                        text.replace_range(span.start..span.end, new);
                    }
                }
            }
            let version = p.pointer("/textDocument/version").and_then(Value::as_i64).map(|v| v as i32);
            let doc = world.docs.get_mut(&path).ok_or("the document went away")?;
            doc.version = version.unwrap_or(doc.version);
            doc.lines = LineIndex::new(&text);
            doc.text = text;
            world.touch(&path);
        }
        "textDocument/didClose" => {
            let path = doc_path(p).map_err(|e| e.1)?;
            world.close(&path);
        }
        "workspace/didChangeWatchedFiles" => {
            let roots: Vec<PathBuf> = world.analyses.keys().cloned().collect();
            for r in roots {
                world.touch(&r);
            }
        }
        _ => {} // `initialized`, `didSave`, `$/cancelRequest`, `$/setTrace`, and anything else
    }
    Ok(())
}

fn dispatch(world: &World, method: &str, params: Value) -> Answer {
    match method {
        "textDocument/hover" => nav::hover(world, &params),
        "textDocument/definition" => nav::definition(world, &params),
        "textDocument/references" => nav::references(world, &params),
        "textDocument/documentHighlight" => nav::highlight(world, &params),
        "textDocument/documentSymbol" => nav::document_symbols(world, &params),
        "workspace/symbol" => nav::workspace_symbols(world, &params),
        "textDocument/prepareRename" => nav::prepare_rename(world, &params),
        "textDocument/rename" => nav::rename(world, &params),
        "textDocument/completion" => complete::completion(world, &params),
        "textDocument/formatting" => actions::formatting(world, &params),
        "textDocument/rangeFormatting" => actions::range_formatting(world, &params),
        "textDocument/codeAction" => actions::code_actions(world, &params),
        "textDocument/inlayHint" => actions::inlay_hints(world, &params),
        "textDocument/semanticTokens/full" => tokens::semantic_tokens(world, &params),
        "textDocument/foldingRange" => tokens::folding(world, &params),
        _ => Err((ErrorCode::MethodNotFound as i32, format!("unknown method `{method}`"))),
    }
}

fn capabilities() -> Value {
    json!({
        "capabilities": {
            "positionEncoding": "utf-16",
            "textDocumentSync": { "openClose": true, "change": 2 },
            "hoverProvider": true,
            "definitionProvider": true,
            "referencesProvider": true,
            "documentHighlightProvider": true,
            "documentSymbolProvider": true,
            "workspaceSymbolProvider": true,
            "completionProvider": { "triggerCharacters": ["{", "(", ",", ".", "?", " "] },
            "documentFormattingProvider": true,
            "documentRangeFormattingProvider": true,
            "renameProvider": { "prepareProvider": true },
            "codeActionProvider": { "codeActionKinds": ["quickfix"] },
            "semanticTokensProvider": { "legend": tokens::legend(), "full": true },
            "foldingRangeProvider": true,
            "inlayHintProvider": true,
        },
        "serverInfo": { "name": "situ", "version": env!("CARGO_PKG_VERSION") },
    })
}
