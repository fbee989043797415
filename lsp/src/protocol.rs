//! The protocol's JSON, in one place: a request's params become the typed
//! input of a feature (a document, a place in it, a range), the feature's
//! answer becomes the LSP result, and what cannot be answered becomes a
//! JSON-RPC error. The features know nothing of JSON; the server loop knows
//! nothing of the features.

use crate::actions::{self, CodeAction, InlayHint};
use crate::complete::{self, Item};
use crate::data::{Location, Refusal, TextEdit, WorkspaceEdit};
use crate::diagnostics::Finding;
use crate::nav::{self, Highlight, Hover, RenamePlace, Symbol, WorkspaceSymbol};
use crate::text::{uri_to_path, LineIndex};
use crate::tokens::{self, Fold, SemanticToken, TOKEN_MODIFIERS, TOKEN_TYPES};
use crate::verdicts::{self, Lens, Settings};
use crate::world::{Analysis, Doc, World};
use lsp_server::ErrorCode;
use lsp_types::Position;
use serde_json::{json, Value};
use situ_grammar::ast::Span;
use situ_grammar::diag::FileId;
use std::path::PathBuf;

/// A JSON-RPC error: a code and a message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RpcError {
    pub code: i32,
    pub message: String,
}

impl RpcError {
    fn new(code: ErrorCode, message: impl Into<String>) -> RpcError {
        RpcError { code: code as i32, message: message.into() }
    }
}

/// A request's answer: a result, or an error.
pub type Answer = Result<Value, RpcError>;

/// The params do not say what the request needs.
pub fn invalid_params(message: impl Into<String>) -> RpcError {
    RpcError::new(ErrorCode::InvalidParams, message)
}

/// Well-formed, but declined (see [`Refusal`]).
pub fn refused(message: impl Into<String>) -> RpcError {
    RpcError::new(ErrorCode::RequestFailed, message)
}

pub fn not_initialized() -> RpcError {
    RpcError::new(ErrorCode::ServerNotInitialized, "initialize first")
}

/// A request the server's state does not allow (`message` says why).
pub fn invalid_request(message: impl Into<String>) -> RpcError {
    RpcError::new(ErrorCode::InvalidRequest, message)
}

pub fn method_not_found(method: &str) -> RpcError {
    RpcError::new(ErrorCode::MethodNotFound, format!("unknown method `{method}`"))
}

/// A handler that panicked.
pub fn internal_error(method: &str) -> RpcError {
    RpcError::new(ErrorCode::InternalError, format!("`{method}` failed"))
}

impl From<Refusal> for RpcError {
    fn from(r: Refusal) -> RpcError {
        refused(r.0)
    }
}

// ---------------------------------------------------------------- messages

pub fn response(id: Value, answer: Answer) -> Value {
    match answer {
        Ok(result) => json!({ "jsonrpc": "2.0", "id": id, "result": result }),
        Err(e) => error(id, e.code, e.message),
    }
}

pub fn error(id: Value, code: i32, message: String) -> Value {
    json!({ "jsonrpc": "2.0", "id": id, "error": { "code": code, "message": message } })
}

pub fn notification(method: &str, params: Value) -> Value {
    json!({ "jsonrpc": "2.0", "method": method, "params": params })
}

/// `window/logMessage` or `window/showMessage` (`kind` 1: an error, 3: information).
pub fn message(method: &str, kind: u32, message: &str) -> Value {
    notification(method, json!({ "type": kind, "message": message }))
}

/// `textDocument/publishDiagnostics`.
pub fn publish(uri: &str, version: Option<i32>, findings: &[Finding]) -> Value {
    let mut params = json!({ "uri": uri, "diagnostics": findings.iter().map(finding).collect::<Vec<_>>() });
    if let Some(v) = version {
        params["version"] = json!(v);
    }
    notification("textDocument/publishDiagnostics", params)
}

/// The answer to `initialize`.
pub fn capabilities() -> Value {
    json!({
        "capabilities": {
            "positionEncoding": "utf-16",
            "textDocumentSync": { "openClose": true, "change": 2, "save": { "includeText": false } },
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
            "semanticTokensProvider": { "legend": { "tokenTypes": TOKEN_TYPES, "tokenModifiers": TOKEN_MODIFIERS }, "full": true },
            "foldingRangeProvider": true,
            "inlayHintProvider": true,
            "codeLensProvider": { "resolveProvider": false },
            "executeCommandProvider": { "commands": [verdicts::INSERT_COMMAND] },
        },
        "serverInfo": { "name": "situ", "version": env!("CARGO_PKG_VERSION") },
    })
}

// ---------------------------------------------------------------- params

/// The document's path, from `params.textDocument.uri`.
pub fn doc_path(params: &Value) -> Result<PathBuf, RpcError> {
    let uri = params
        .pointer("/textDocument/uri")
        .and_then(Value::as_str)
        .ok_or_else(|| invalid_params("no textDocument.uri"))?;
    uri_path(uri)
}

fn uri_path(uri: &str) -> Result<PathBuf, RpcError> {
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

/// The analysis and file of `params.textDocument`.
fn analysis<'w>(world: &'w World, params: &Value) -> Result<(&'w Analysis, FileId), RpcError> {
    let path = doc_path(params)?;
    world.primary(&path).ok_or_else(|| invalid_params(format!("`{}` is not open", path.display())))
}

/// The analysis, file and byte offset of `params.textDocument` and `params.position`.
fn locate<'w>(world: &'w World, params: &Value) -> Result<(&'w Analysis, FileId, usize), RpcError> {
    let (a, file) = analysis(world, params)?;
    let pos: Position = params
        .get("position")
        .cloned()
        .and_then(|p| serde_json::from_value(p).ok())
        .ok_or_else(|| invalid_params("no position"))?;
    let offset = a.lines[file.0 as usize]
        .offset(a.text(file), pos)
        .ok_or_else(|| invalid_params(format!("line {} is past the end of the document", pos.line)))?;
    Ok((a, file, offset))
}

/// `params.range` in the document's bytes, if it is there and inside it.
fn range(a: &Analysis, file: FileId, params: &Value) -> Option<Span> {
    let range = params.get("range").cloned().and_then(|r| serde_json::from_value(r).ok())?;
    a.lines[file.0 as usize].span(a.text(file), range)
}

fn required_range(a: &Analysis, file: FileId, params: &Value) -> Result<Span, RpcError> {
    range(a, file, params).ok_or_else(|| invalid_params("no range, or a range outside the document"))
}

// ---------------------------------------------------------------- requests

/// Answers a request of a running server.
pub fn request(world: &World, method: &str, params: &Value) -> Answer {
    match method {
        "textDocument/hover" => {
            let (a, file, offset) = locate(world, params)?;
            Ok(nav::hover(a, file, offset).map_or(Value::Null, |h| hover(&h)))
        }
        "textDocument/definition" => {
            let (a, file, offset) = locate(world, params)?;
            Ok(nav::definition(a, file, offset).map_or(Value::Null, |l| location(&l)))
        }
        "textDocument/references" => {
            let (a, file, offset) = locate(world, params)?;
            let with_decl = params.pointer("/context/includeDeclaration").and_then(Value::as_bool).unwrap_or(true);
            Ok(list(&nav::references(a, file, offset, with_decl), location))
        }
        "textDocument/documentHighlight" => {
            let (a, file, offset) = locate(world, params)?;
            Ok(list(&nav::highlight(a, file, offset), highlight))
        }
        "textDocument/documentSymbol" => {
            let (a, file) = analysis(world, params)?;
            Ok(list(&nav::document_symbols(a, file), symbol))
        }
        "workspace/symbol" => {
            let query = params.get("query").and_then(Value::as_str).unwrap_or("");
            Ok(list(&nav::workspace_symbols(world, query), workspace_symbol))
        }
        "textDocument/prepareRename" => {
            let (a, file, offset) = locate(world, params)?;
            Ok(rename_place(&nav::prepare_rename(a, file, offset)?))
        }
        "textDocument/rename" => {
            let (a, file, offset) = locate(world, params)?;
            let new = params.get("newName").and_then(Value::as_str).ok_or_else(|| invalid_params("no newName"))?;
            Ok(workspace_edit(&nav::rename(a, file, offset, new)?))
        }
        "textDocument/completion" => {
            let (a, file, offset) = locate(world, params)?;
            Ok(completion(&complete::completion(a, file, offset)))
        }
        "textDocument/formatting" => {
            let (a, file) = analysis(world, params)?;
            Ok(actions::formatting(a, file).map_or(Value::Null, |e| list(&e, text_edit)))
        }
        "textDocument/rangeFormatting" => {
            let (a, file) = analysis(world, params)?;
            let span = required_range(a, file, params)?;
            Ok(actions::range_formatting(a, file, span).map_or(Value::Null, |e| list(&e, text_edit)))
        }
        "textDocument/codeAction" => {
            let (a, file) = analysis(world, params)?;
            let span = required_range(a, file, params)?;
            let mut all = actions::code_actions(a, file, span);
            all.extend(verdicts::code_actions(world, &doc_path(params)?, a.range(file, span)));
            Ok(list(&all, code_action))
        }
        "textDocument/codeLens" => Ok(list(&verdicts::lenses(world, &doc_path(params)?), code_lens)),
        "textDocument/inlayHint" => {
            let (a, file) = analysis(world, params)?;
            Ok(list(&actions::inlay_hints(a, file, range(a, file, params)), inlay_hint))
        }
        "textDocument/semanticTokens/full" => {
            let (a, file) = analysis(world, params)?;
            Ok(semantic_tokens(&tokens::semantic_tokens(a, file)))
        }
        "textDocument/foldingRange" => {
            let (a, file) = analysis(world, params)?;
            Ok(list(&tokens::folding(a, file), fold))
        }
        _ => Err(method_not_found(method)),
    }
}

// ---------------------------------------------------------------- notifications

/// Why a notification of the client was not applied to the documents (the
/// text is shown to the user; the documents stay as they were).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SyncError {
    /// The notification lacks what it must carry (`didOpen without a URI`).
    #[error("{0}")]
    Incomplete(&'static str),
    /// Its document is not a `file:` URI of a path.
    #[error("{0}")]
    Uri(String),
    #[error("didChange of `{}`, which is not open", .0.display())]
    NotOpen(PathBuf),
    #[error("a change with a bad range: {0}")]
    BadRange(String),
    #[error("change {index} of `{}` has an impossible range {}:{}-{}:{}; the change was not applied", path.display(), range.start.line, range.start.character, range.end.line, range.end.character)]
    ImpossibleRange { index: usize, path: PathBuf, range: lsp_types::Range },
    /// A setting that is not what it must be (the settings stay as they were).
    #[error("{0}")]
    Settings(String),
    /// The handler of the notification failed (a bug of situ, reported).
    #[error("`{0}` failed")]
    Failed(String),
}

/// Applies didOpen, didChange, didClose and friends to the documents; why
/// not, for the user.
pub fn sync(world: &mut World, method: &str, p: &Value) -> Result<(), SyncError> {
    match method {
        "textDocument/didOpen" => {
            let uri = p.pointer("/textDocument/uri").and_then(Value::as_str);
            let uri = uri.ok_or(SyncError::Incomplete("didOpen without a URI"))?;
            let text = p.pointer("/textDocument/text").and_then(Value::as_str);
            let text = text.ok_or(SyncError::Incomplete("didOpen without a text"))?;
            let version = p.pointer("/textDocument/version").and_then(Value::as_i64).unwrap_or(0) as i32;
            let path = uri_path(uri).map_err(|e| SyncError::Uri(e.message))?;
            world.open(path.clone(), Doc::new(uri.to_string(), text.to_string(), version));
            world.verdicts.want(path);
        }
        "textDocument/didSave" => {
            let path = doc_path(p).map_err(|e| SyncError::Uri(e.message))?;
            world.verdicts.want(path);
        }
        "workspace/didChangeConfiguration" => {
            if let Some(v) = p.pointer("/settings/situ/verdicts") {
                world.verdicts.settings = settings(v).map_err(SyncError::Settings)?;
            }
        }
        "textDocument/didChange" => did_change(world, p)?,
        "textDocument/didClose" => {
            let path = doc_path(p).map_err(|e| SyncError::Uri(e.message))?;
            world.close(&path);
        }
        "workspace/didChangeWatchedFiles" => {
            let roots: Vec<PathBuf> = world.analyses.keys().cloned().collect();
            for r in roots {
                world.touch(&r);
            }
        }
        _ => {} // `initialized`, `$/cancelRequest`, `$/setTrace`, and anything else
    }
    Ok(())
}

/// The changes, applied in order; none when one of them is bad.
fn did_change(world: &mut World, p: &Value) -> Result<(), SyncError> {
    let path = doc_path(p).map_err(|e| SyncError::Uri(e.message))?;
    let doc = world.docs.get(&path).ok_or_else(|| SyncError::NotOpen(path.clone()))?;
    let changes = p.get("contentChanges").and_then(Value::as_array);
    let changes = changes.ok_or(SyncError::Incomplete("didChange without contentChanges"))?;
    let mut text = doc.text.clone();
    for (i, c) in changes.iter().enumerate() {
        let new = c.get("text").and_then(Value::as_str).ok_or(SyncError::Incomplete("a change without text"))?;
        match c.get("range") {
            None | Some(Value::Null) => text = new.to_string(),
            Some(range) => {
                let range: lsp_types::Range =
                    serde_json::from_value(range.clone()).map_err(|e| SyncError::BadRange(e.to_string()))?;
                let span = LineIndex::new(&text).span(&text, range);
                let span =
                    span.ok_or_else(|| SyncError::ImpossibleRange { index: i + 1, path: path.clone(), range })?;
                text.replace_range(span.start..span.end, new);
            }
        }
    }
    let version = p.pointer("/textDocument/version").and_then(Value::as_i64).map(|v| v as i32);
    let doc = world.docs.get_mut(&path).ok_or(SyncError::NotOpen(path.clone()))?;
    doc.version = version.unwrap_or(doc.version);
    doc.lines = LineIndex::new(&text);
    doc.text = text;
    world.touch(&path);
    Ok(())
}

// ---------------------------------------------------------------- settings

/// The verdicts' settings: `false` (none run), `true`, or an object whose
/// fields (each optional) are `enabled`, `effort` (IC3's SAT propagations
/// per property), `depth` and `maxStates` (the exploration), `randomRuns`
/// and `randomLength` (the random search), `timeoutSeconds` (the
/// wall-clock guard on IC3). The rest stay [`verdicts::EDITOR_OPTIONS`]'s.
pub fn settings(v: &Value) -> Result<Settings, String> {
    let mut s = Settings::default();
    let fields = match v {
        Value::Bool(b) => {
            s.enabled = *b;
            return Ok(s);
        }
        Value::Object(fields) => fields,
        _ => return Err(format!("the setting `verdicts` is `{v}`: it must be true, false or an object")),
    };
    let o = &mut s.options;
    for (key, value) in fields {
        let number = || {
            value
                .as_u64()
                .ok_or_else(|| format!("the setting `verdicts.{key}` is `{value}`: it must be a whole number"))
        };
        match key.as_str() {
            "enabled" => {
                s.enabled = value.as_bool().ok_or_else(|| format!("the setting `verdicts.enabled` is `{value}`: it must be true or false"))?
            }
            "effort" => o.effort = number()?,
            "depth" => o.limits.depth = number()? as usize,
            "maxStates" => o.limits.max_states = number()? as usize,
            "randomRuns" => o.search.cases = u32::try_from(number()?).unwrap_or(u32::MAX),
            "randomLength" => o.search.length = number()? as usize,
            "timeoutSeconds" => o.timeout = Some(std::time::Duration::from_secs(number()?)),
            _ => return Err(format!("unknown setting `verdicts.{key}`: the settings are enabled, effort, depth, maxStates, randomRuns, randomLength and timeoutSeconds")),
        }
    }
    Ok(s)
}

/// From `initialize`'s params: the verdicts' settings
/// (`initializationOptions.verdicts`; the default when absent), and whether
/// the client asks to be told to refresh its code lenses.
pub fn initialization(params: &Value) -> (Result<Settings, String>, bool) {
    let s = params.pointer("/initializationOptions/verdicts").map_or(Ok(Settings::default()), settings);
    let refresh = params.pointer("/capabilities/workspace/codeLens/refreshSupport").and_then(Value::as_bool);
    (s, refresh == Some(true))
}

/// `workspace/executeCommand` of [`verdicts::INSERT_COMMAND`]: the params of
/// the `workspace/applyEdit` to ask of the client, if the document is still
/// the version the counterexample was found on.
pub fn execute(world: &World, params: &Value) -> Result<Value, RpcError> {
    let command = params.get("command").and_then(Value::as_str).ok_or_else(|| invalid_params("no command"))?;
    if command != verdicts::INSERT_COMMAND {
        return Err(invalid_params(format!("unknown command `{command}`")));
    }
    let arg = params.pointer("/arguments/0").ok_or_else(|| invalid_params("no arguments"))?;
    let uri = arg.get("uri").and_then(Value::as_str).ok_or_else(|| invalid_params("no uri"))?;
    let edit: lsp_types::TextEdit = arg
        .get("edit")
        .cloned()
        .and_then(|e| serde_json::from_value(e).ok())
        .ok_or_else(|| invalid_params("no edit"))?;
    let version = arg.get("version").and_then(Value::as_i64).map(|v| v as i32);
    let now = world.docs.get(&uri_path(uri)?).map(|d| d.version);
    if now != version {
        return Err(refused(
            "the document changed since this counterexample was found: save it to check the properties again",
        ));
    }
    let edit = TextEdit { range: edit.range, new_text: edit.new_text };
    Ok(
        json!({ "label": "append the counterexample as a test", "edit": workspace_edit(&[(uri.to_string(), vec![edit])].into()) }),
    )
}

/// A request of the server to the client.
pub fn server_request(id: &str, method: &str, params: Value) -> Value {
    json!({ "jsonrpc": "2.0", "id": id, "method": method, "params": params })
}

// ---------------------------------------------------------------- results

fn list<T>(items: &[T], each: impl Fn(&T) -> Value) -> Value {
    Value::Array(items.iter().map(each).collect())
}

pub fn location(l: &Location) -> Value {
    json!({ "uri": l.uri, "range": l.range })
}

pub fn text_edit(e: &TextEdit) -> Value {
    json!({ "range": e.range, "newText": e.new_text })
}

pub fn workspace_edit(changes: &WorkspaceEdit) -> Value {
    let changes: serde_json::Map<String, Value> =
        changes.iter().map(|(uri, edits)| (uri.clone(), list(edits, text_edit))).collect();
    json!({ "changes": changes })
}

/// A finding as an LSP `Diagnostic`.
pub fn finding(f: &Finding) -> Value {
    let related: Vec<Value> =
        f.related.iter().map(|(l, message)| json!({ "location": location(l), "message": message })).collect();
    let mut out = json!({
        "range": f.range,
        "severity": if f.error { 1 } else { 2 },
        "code": f.code,
        "source": "situ",
        "message": f.message,
        "relatedInformation": related,
        "data": { "help": f.help, "witness": f.witness },
    });
    if f.unnecessary {
        out["tags"] = json!([1]); // unnecessary: shown faded
    }
    out
}

fn hover(h: &Hover) -> Value {
    json!({ "contents": { "kind": "markdown", "value": h.markdown }, "range": h.range })
}

fn highlight(h: &Highlight) -> Value {
    // DocumentHighlightKind: 3 a write (the declaration), 2 a read.
    json!({ "range": h.range, "kind": if h.declaration { 3 } else { 2 } })
}

fn rename_place(r: &RenamePlace) -> Value {
    json!({ "range": r.range, "placeholder": r.placeholder })
}

fn symbol(s: &Symbol) -> Value {
    json!({
        "name": s.name,
        "kind": s.kind,
        "range": s.range,
        "selectionRange": s.selection,
        "children": list(&s.children, symbol),
    })
}

fn workspace_symbol(s: &WorkspaceSymbol) -> Value {
    let mut v = json!({ "name": s.name, "kind": s.kind, "location": location(&s.location) });
    if let Some(c) = &s.container {
        v["containerName"] = json!(c);
    }
    v
}

pub fn completion(items: &[Item]) -> Value {
    let items = list(items, |i| {
        let mut v = if i.snippet {
            // InsertTextFormat 2: a snippet.
            json!({ "label": i.label, "kind": i.kind, "insertTextFormat": 2, "textEdit": text_edit(&i.edit) })
        } else {
            json!({ "label": i.label, "kind": i.kind, "textEdit": text_edit(&i.edit) })
        };
        if let Some(d) = &i.detail {
            v["detail"] = json!(d);
        }
        v
    });
    json!({ "isIncomplete": false, "items": items })
}

fn code_action(c: &CodeAction) -> Value {
    json!({
        "title": c.title,
        "kind": "quickfix",
        "diagnostics": [finding(&c.finding)],
        "isPreferred": c.preferred,
        "edit": workspace_edit(&c.edit),
    })
}

/// A lens: its title, and the command that appends a counterexample (an
/// empty command otherwise: a title only).
fn code_lens(l: &Lens) -> Value {
    let command = match &l.insert {
        Some(i) => json!({
            "title": l.title,
            "command": verdicts::INSERT_COMMAND,
            "arguments": [{ "uri": i.uri, "version": i.version, "edit": text_edit(&i.edit) }],
        }),
        None => json!({ "title": l.title, "command": "" }),
    };
    json!({ "range": l.range, "command": command })
}

fn inlay_hint(h: &InlayHint) -> Value {
    let mut v = json!({ "position": h.position, "label": h.label });
    if let Some(k) = h.kind {
        v["kind"] = json!(k);
    }
    if h.padding_left {
        v["paddingLeft"] = json!(true);
    }
    v["tooltip"] = json!(h.tooltip);
    v
}

/// The tokens, relative each to the one before: five numbers a token.
pub fn semantic_tokens(tokens: &[SemanticToken]) -> Value {
    let mut data = Vec::with_capacity(tokens.len() * 5);
    let (mut last_line, mut last_col) = (0u32, 0u32);
    for t in tokens {
        let delta_line = t.line - last_line;
        let delta_col = if delta_line == 0 { t.start - last_col } else { t.start };
        data.extend([delta_line, delta_col, t.length, t.ty.index(), u32::from(t.declaration)]);
        (last_line, last_col) = (t.line, t.start);
    }
    json!({ "data": data })
}

fn fold(f: &Fold) -> Value {
    if f.comment {
        json!({ "startLine": f.start_line, "endLine": f.end_line, "kind": "comment" })
    } else {
        json!({ "startLine": f.start_line, "endLine": f.end_line })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tokens::TokenType;
    use crate::world::world_of;
    use lsp_types::Range;

    const SRC: &str =
        "states { IT initial RD final }\nagent A sensor { event E function f }\nrule r { when E then RD }\n";

    fn at(line: u32, character: u32) -> Position {
        Position { line, character }
    }

    /// Every request at many places of the repository's rule files, and of
    /// the same files cut short (as while typing): an answer, never a panic.
    #[test]
    fn every_place_gets_an_answer() {
        for name in ["rules/outdoor.situ", "examples/mower/mower.situ"] {
            let full = std::fs::read_to_string(format!("{}/../{name}", env!("CARGO_MANIFEST_DIR"))).unwrap();
            let half = (full.len() / 2..).find(|i| full.is_char_boundary(*i)).unwrap_or(full.len());
            for text in [full.clone(), full[..half].to_string()] {
                let path = PathBuf::from("/tmp/situ-lsp-every-place.situ");
                let uri = "file:///tmp/situ-lsp-every-place.situ";
                let mut w = World::default();
                w.open(path.clone(), Doc::new(uri.into(), text.clone(), 1));
                w.refresh_fully();
                let (a, file) = w.primary(&path).unwrap();
                let lines = &a.lines[file.0 as usize];
                for offset in (0..=text.len()).step_by(17).filter(|o| text.is_char_boundary(*o)) {
                    let _ = crate::complete::completion(a, file, offset);
                    let params = json!({ "textDocument": { "uri": uri }, "position": lines.position(&text, offset), "newName": "Zz" });
                    for method in ["hover", "definition", "references", "documentHighlight", "completion"] {
                        assert!(request(&w, &format!("textDocument/{method}"), &params).is_ok(), "{name} at {offset}");
                    }
                    // Refused where there is no name, or where `Zz` is taken: never a panic.
                    let _ = request(&w, "textDocument/rename", &params);
                }
                let doc = json!({ "textDocument": { "uri": uri } });
                for method in ["semanticTokens/full", "foldingRange", "documentSymbol", "formatting"] {
                    assert!(request(&w, &format!("textDocument/{method}"), &doc).is_ok(), "{name}: {method}");
                }
                let everywhere = json!({ "textDocument": { "uri": uri }, "range": { "start": { "line": 0, "character": 0 }, "end": lines.position(&text, text.len()) } });
                for method in ["codeAction", "inlayHint", "rangeFormatting"] {
                    assert!(request(&w, &format!("textDocument/{method}"), &everywhere).is_ok(), "{name}: {method}");
                }
            }
        }
    }

    #[test]
    fn params_that_say_too_little_are_invalid() {
        let (w, _) = world_of("protocol-params", SRC);
        let uri = "file:///nonexistent/situ-lsp/protocol-params.situ";
        let code = |method: &str, params: Value| request(&w, method, &params).unwrap_err();
        let hover = "textDocument/hover";
        assert_eq!(code(hover, json!({})), invalid_params("no textDocument.uri"));
        let closed = json!({ "textDocument": { "uri": "file:///nonexistent/other.situ" }, "position": at(0, 0) });
        assert_eq!(code(hover, closed), invalid_params("`/nonexistent/other.situ` is not open"));
        assert_eq!(code(hover, json!({ "textDocument": { "uri": uri } })), invalid_params("no position"));
        let past = json!({ "textDocument": { "uri": uri }, "position": at(9, 0) });
        assert_eq!(code(hover, past), invalid_params("line 9 is past the end of the document"));
        let doc = json!({ "textDocument": { "uri": uri } });
        let no_range = invalid_params("no range, or a range outside the document");
        assert_eq!(code("textDocument/codeAction", doc.clone()), no_range);
        assert_eq!(code("textDocument/nothing", doc).code, ErrorCode::MethodNotFound as i32);
        let nowhere = json!({ "textDocument": { "uri": uri }, "position": at(0, 0), "newName": "Zz" });
        assert_eq!(code("textDocument/rename", nowhere), refused("no name to rename here"));
    }

    #[test]
    fn tokens_are_written_relative_to_the_one_before() {
        let t = |line, start, length, ty| SemanticToken { line, start, length, ty, declaration: false };
        let tokens = [
            t(0, 2, 5, TokenType::Keyword),
            t(0, 10, 2, TokenType::Class),
            SemanticToken { declaration: true, ..t(2, 4, 1, TokenType::Variable) },
        ];
        assert_eq!(semantic_tokens(&tokens), json!({ "data": [0, 2, 5, 0, 0, 0, 8, 2, 5, 0, 2, 4, 1, 10, 1] }));
    }

    #[test]
    fn a_finding_carries_its_code_help_and_tags() {
        let place = Range { start: at(1, 2), end: at(1, 5) };
        let f = Finding {
            range: place,
            error: false,
            code: "W0308",
            message: "m\nhelp: h".into(),
            related: vec![(Location { uri: "file:///a.situ".into(), range: place }, "help: h".into())],
            help: Some("h".into()),
            witness: None,
            unnecessary: true,
        };
        let range = json!({ "start": { "line": 1, "character": 2 }, "end": { "line": 1, "character": 5 } });
        assert_eq!(
            finding(&f),
            json!({
                "range": range,
                "severity": 2,
                "code": "W0308",
                "source": "situ",
                "message": "m\nhelp: h",
                "relatedInformation": [{ "location": { "uri": "file:///a.situ", "range": range }, "message": "help: h" }],
                "data": { "help": "h", "witness": null },
                "tags": [1],
            })
        );
    }

    #[test]
    fn completion_items_and_snippets() {
        let range = Range { start: at(0, 0), end: at(0, 1) };
        let item = |label: &str, snippet| Item {
            label: label.into(),
            kind: lsp_types::CompletionItemKind::KEYWORD,
            detail: if snippet { None } else { Some("d".into()) },
            edit: TextEdit { range, new_text: label.into() },
            snippet,
        };
        let out = completion(&[item("a", false), item("b", true)]);
        assert_eq!(out["isIncomplete"], false);
        assert_eq!(out["items"][0]["detail"], "d");
        assert_eq!(out["items"][0]["kind"], 14);
        assert_eq!(out["items"][0]["textEdit"]["newText"], "a");
        assert!(out["items"][0].get("insertTextFormat").is_none());
        assert_eq!(out["items"][1]["insertTextFormat"], 2);
        assert!(out["items"][1].get("detail").is_none());
    }

    #[test]
    fn verdict_settings_and_their_errors() {
        let s = settings(&json!(false)).unwrap();
        assert!(!s.enabled);
        let s = settings(&json!({ "effort": 7, "depth": 3, "maxStates": 9, "randomRuns": 2, "randomLength": 4, "timeoutSeconds": 5 }))
            .unwrap();
        assert!(s.enabled);
        let o = s.options;
        assert_eq!((o.effort, o.limits.depth, o.limits.max_states, o.search.cases, o.search.length), (7, 3, 9, 2, 4));
        assert_eq!(o.timeout, Some(std::time::Duration::from_secs(5)));
        assert_eq!(o.search.seed, verdicts::EDITOR_OPTIONS.search.seed, "the rest is the editor's");
        let bad = settings(&json!({ "effort": -1 })).unwrap_err();
        assert_eq!(bad, "the setting `verdicts.effort` is `-1`: it must be a whole number");
        assert!(settings(&json!({ "efort": 1 })).unwrap_err().starts_with("unknown setting `verdicts.efort`"));
        assert!(settings(&json!("on")).is_err());
        let (s, refresh) = initialization(&json!({ "capabilities": {} }));
        assert!(s.unwrap().enabled && !refresh);
        let (s, refresh) = initialization(
            &json!({ "initializationOptions": { "verdicts": { "enabled": false } }, "capabilities": { "workspace": { "codeLens": { "refreshSupport": true } } } }),
        );
        assert!(!s.unwrap().enabled && refresh);
    }

    #[test]
    fn a_lens_with_and_without_its_command() {
        let range = Range { start: at(0, 0), end: at(0, 1) };
        let title = code_lens(&Lens { range, title: "passed".into(), insert: None });
        assert_eq!(title, json!({ "range": range, "command": { "title": "passed", "command": "" } }));
    }

    #[test]
    fn the_legend_is_announced() {
        let legend = &capabilities()["capabilities"]["semanticTokensProvider"]["legend"];
        assert_eq!(legend["tokenTypes"], json!(TOKEN_TYPES));
        assert_eq!(legend["tokenTypes"][TokenType::Type.index() as usize], "type");
        assert_eq!(legend["tokenModifiers"], json!(["declaration"]));
    }
}
