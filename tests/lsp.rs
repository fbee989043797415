//! `situ lsp` driven as an editor drives it: the real binary over standard
//! input and output, JSON-RPC with `Content-Length` framing. Golden answers
//! on the repository's rule files (insta snapshots, URIs relative to the
//! repository).

#[path = "lsp/verdicts.rs"]
mod verdicts;

use serde_json::{json, Value};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{self, Receiver};
use std::time::Duration;

/// How long to wait for one message before calling the server stuck: a
/// bound on the test, not a measurement.
const PATIENCE: Duration = Duration::from_secs(60);

struct Client {
    child: Child,
    stdin: ChildStdin,
    rx: Receiver<Value>,
    next_id: i64,
    /// Notifications received while waiting for something else.
    notifications: Vec<Value>,
}

fn read_frame(r: &mut impl BufRead) -> Option<Value> {
    let mut length = None;
    loop {
        let mut line = String::new();
        if r.read_line(&mut line).ok()? == 0 {
            return None;
        }
        let line = line.trim_end();
        if line.is_empty() {
            break;
        }
        if let Some(v) = line.strip_prefix("Content-Length: ") {
            length = v.parse::<usize>().ok();
        }
    }
    let mut body = vec![0; length?];
    r.read_exact(&mut body).ok()?;
    serde_json::from_slice(&body).ok()
}

impl Client {
    fn start() -> Client {
        let mut child = Command::new(env!("CARGO_BIN_EXE_situ"))
            .arg("lsp")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("situ lsp starts");
        let stdin = child.stdin.take().unwrap();
        let mut stdout = BufReader::new(child.stdout.take().unwrap());
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            while let Some(v) = read_frame(&mut stdout) {
                if tx.send(v).is_err() {
                    break;
                }
            }
        });
        Client { child, stdin, rx, next_id: 0, notifications: Vec::new() }
    }

    /// Started and initialized, without the verdicts of properties and tests
    /// (their own tests are in `lsp/verdicts.rs`): the publications these
    /// tests wait for are the compiler's.
    fn ready() -> Client {
        Client::ready_with(json!({ "verdicts": false }), json!({}))
    }

    /// Started and initialized with these options and client capabilities.
    fn ready_with(options: Value, capabilities: Value) -> Client {
        let mut c = Client::start();
        let params = json!({ "processId": null, "rootUri": null, "capabilities": capabilities, "initializationOptions": options });
        let init = c.request("initialize", params);
        assert!(init["result"]["capabilities"]["hoverProvider"] == true, "{init}");
        c.notify("initialized", json!({}));
        c
    }

    fn raw(&mut self, bytes: &[u8]) {
        self.stdin.write_all(bytes).unwrap();
        self.stdin.flush().unwrap();
    }

    fn send(&mut self, v: &Value) {
        let body = v.to_string();
        self.raw(format!("Content-Length: {}\r\n\r\n{body}", body.len()).as_bytes());
    }

    fn next(&mut self) -> Value {
        self.rx.recv_timeout(PATIENCE).expect("the server answers")
    }

    /// The answer to the request with this id (notifications kept aside).
    fn answer(&mut self, id: &Value) -> Value {
        for _ in 0..10_000 {
            let m = self.next();
            if m.get("method").is_some() {
                self.notifications.push(m);
            } else if &m["id"] == id {
                return m;
            }
        }
        panic!("no answer to {id}");
    }

    /// The whole response (`result` or `error`).
    fn request(&mut self, method: &str, params: Value) -> Value {
        self.next_id += 1;
        let id = json!(self.next_id);
        self.send(&json!({ "jsonrpc": "2.0", "id": id, "method": method, "params": params }));
        self.answer(&id)
    }

    fn result(&mut self, method: &str, params: Value) -> Value {
        let r = self.request(method, params);
        assert!(r.get("error").is_none(), "{method}: {r}");
        r["result"].clone()
    }

    fn notify(&mut self, method: &str, params: Value) {
        self.send(&json!({ "jsonrpc": "2.0", "method": method, "params": params }));
    }

    /// The next notification of this method (for this URI, if given).
    fn notification(&mut self, method: &str, uri: Option<&str>) -> Value {
        let fits = |m: &Value| m["method"] == method && uri.is_none_or(|u| m["params"]["uri"] == u);
        if let Some(i) = self.notifications.iter().position(fits) {
            return self.notifications.remove(i);
        }
        for _ in 0..10_000 {
            let m = self.next();
            if fits(&m) {
                return m;
            }
            if m.get("method").is_some() {
                self.notifications.push(m);
            }
        }
        panic!("no {method}");
    }

    fn diagnostics(&mut self, uri: &str) -> Vec<Value> {
        let n = self.notification("textDocument/publishDiagnostics", Some(uri));
        n["params"]["diagnostics"].as_array().unwrap().clone()
    }

    fn open(&mut self, uri: &str, text: &str) {
        let doc = json!({ "uri": uri, "languageId": "situ", "version": 1, "text": text });
        self.notify("textDocument/didOpen", json!({ "textDocument": doc }));
    }

    fn change(&mut self, uri: &str, version: i64, changes: Value) {
        let doc = json!({ "uri": uri, "version": version });
        self.notify("textDocument/didChange", json!({ "textDocument": doc, "contentChanges": changes }));
    }

    /// Shuts down and exits; the exit code.
    fn stop(mut self) -> i32 {
        assert_eq!(self.result("shutdown", Value::Null), Value::Null);
        self.notify("exit", Value::Null);
        for _ in 0..600 {
            if let Some(status) = self.child.try_wait().unwrap() {
                return status.code().expect("exited normally");
            }
            std::thread::sleep(Duration::from_millis(100));
        }
        let _ = self.child.kill();
        panic!("the server did not exit");
    }
}

impl Drop for Client {
    fn drop(&mut self) {
        if let Ok(None) = self.child.try_wait() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn uri_of(path: &Path) -> String {
    let mut out = String::from("file://");
    for b in path.to_string_lossy().bytes() {
        if b.is_ascii_alphanumeric() || b"/-_.~".contains(&b) {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}

/// The position (line, UTF-16 column) of the `nth` occurrence of `needle`, plus `skip` characters.
fn pos(text: &str, needle: &str, nth: usize, skip: usize) -> Value {
    let at = text.match_indices(needle).nth(nth).unwrap_or_else(|| panic!("no {needle} #{nth}")).0 + skip;
    let line = text[..at].matches('\n').count();
    let start = text[..at].rfind('\n').map_or(0, |i| i + 1);
    json!({ "line": line, "character": text[start..at].encode_utf16().count() })
}

fn at(uri: &str, text: &str, needle: &str, nth: usize) -> Value {
    json!({ "textDocument": { "uri": uri }, "position": pos(text, needle, nth, 0) })
}

/// `v` with the repository's URI written `file://REPO`.
fn redact(v: &Value) -> Value {
    let s = v.to_string().replace(&uri_of(&repo()), "file://REPO");
    serde_json::from_str(&s).unwrap()
}

fn open_repo_file(c: &mut Client, rel: &str) -> (String, String) {
    let path = repo().join(rel);
    let text = std::fs::read_to_string(&path).unwrap();
    let uri = uri_of(&path);
    c.open(&uri, &text);
    (uri, text)
}

#[test]
fn lifecycle_and_garbage_get_error_answers_and_the_server_goes_on() {
    let mut c = Client::start();
    // Before `initialize`.
    let early = c.request("textDocument/hover", json!({}));
    assert_eq!(early["error"]["code"], -32002, "{early}");
    let init = c.result("initialize", json!({ "capabilities": {} }));
    assert_eq!(init["serverInfo"]["name"], "situ");
    // The crate's legend (the mower test decodes tokens with it) is the one announced.
    let legend = &init["capabilities"]["semanticTokensProvider"]["legend"];
    assert_eq!(legend["tokenTypes"], json!(situ_lsp::TOKEN_TYPES), "{legend}");
    c.notify("initialized", json!({}));

    // Not JSON.
    c.raw(b"Content-Length: 9\r\n\r\n{not json");
    let e = c.next();
    assert_eq!((e["id"].clone(), e["error"]["code"].clone()), (Value::Null, json!(-32700)), "{e}");
    // JSON, not a message.
    c.send(&json!({ "jsonrpc": "2.0", "id": 41, "method": 5 }));
    let e = c.answer(&json!(41));
    assert_eq!(e["error"]["code"], -32600, "{e}");
    c.send(&json!([1, 2, 3]));
    assert_eq!(c.next()["error"]["code"], -32600);
    // A header that is not one.
    c.raw(b"Hello there\r\n\r\n");
    assert_eq!(c.next()["error"]["code"], -32700);
    // An unknown method; an unknown notification is dropped.
    assert_eq!(c.request("situ/unknown", json!({}))["error"]["code"], -32601);
    c.notify("situ/whatever", json!({}));
    // Parameters that do not fit.
    assert_eq!(c.request("textDocument/hover", json!(7))["error"]["code"], -32602);

    let uri = "file:///nonexistent/situ-lsp/garbage.situ";
    let text =
        "states { IT initial RD final }\nagent A sensor { event E }\nrule r { when state == IT and E then RD }\n";
    c.open(uri, text);
    assert!(c.diagnostics(uri).is_empty());
    // An edit whose range is outside the document: refused, reported, the document unchanged.
    let bad = json!([{ "range": { "start": { "line": 40, "character": 0 }, "end": { "line": 41, "character": 0 } }, "text": "x" }]);
    c.change(uri, 2, bad);
    let shown = c.notification("window/showMessage", None);
    assert_eq!(shown["params"]["type"], 1);
    assert!(shown["params"]["message"].as_str().unwrap().contains("impossible range"), "{shown}");
    let backwards = json!([{ "range": { "start": { "line": 1, "character": 0 }, "end": { "line": 0, "character": 0 } }, "text": "" }]);
    c.change(uri, 3, backwards);
    c.notification("window/showMessage", None);
    // A position past the end.
    let far = c.request(
        "textDocument/hover",
        json!({ "textDocument": { "uri": uri }, "position": { "line": 99, "character": 0 } }),
    );
    assert_eq!(far["error"]["code"], -32602, "{far}");
    // Still answering, on the unchanged text.
    let hover = c.result("textDocument/hover", at(uri, text, "RD", 1));
    assert!(hover["contents"]["value"].as_str().unwrap().contains("entered by `r`"), "{hover}");
    assert_eq!(c.stop(), 0);
}

#[test]
fn exit_without_shutdown_is_a_failure() {
    let mut c = Client::ready();
    c.notify("exit", Value::Null);
    let mut code = None;
    for _ in 0..600 {
        if let Some(s) = c.child.try_wait().unwrap() {
            code = s.code();
            break;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    assert_eq!(code, Some(1));
}

#[test]
fn diagnostics_follow_the_edits_with_related_places_and_fixes() {
    let mut c = Client::ready();
    let uri = "file:///nonexistent/situ-lsp/edits.situ";
    let text =
        "states { IT initial RD final }\nagent A sensor { event E }\nrule r { when state == IT and E then RDD }\n";
    c.open(uri, text);
    let d = c.diagnostics(uri);
    assert_eq!(d.len(), 1, "{d:?}");
    assert_eq!(d[0]["code"], "E0101");
    assert_eq!(
        d[0]["range"],
        json!({ "start": { "line": 2, "character": 37 }, "end": { "line": 2, "character": 40 } })
    );
    assert!(d[0]["message"].as_str().unwrap().contains("help:"), "{}", d[0]);
    // The did-you-mean fix is a code action.
    let range = d[0]["range"].clone();
    let actions = c.result(
        "textDocument/codeAction",
        json!({ "textDocument": { "uri": uri }, "range": range, "context": { "diagnostics": [d[0].clone()] } }),
    );
    let fix = &actions[0];
    assert_eq!(fix["title"], "change to `RD`");
    assert_eq!(fix["edit"]["changes"][uri][0]["newText"], "RD");
    // Applying it (an incremental change) clears the finding.
    c.change(uri, 2, json!([{ "range": range, "text": "RD" }]));
    assert!(c.diagnostics(uri).is_empty());
    // A duplicate points at the first declaration.
    c.change(uri, 3, json!([{ "text": "states { IT initial RD final RD }\nagent A sensor { event E }\nrule r { when E then RD }\n" }]));
    let d = c.diagnostics(uri);
    assert_eq!(d[0]["code"], "E0102", "{d:?}");
    assert!(d[0]["relatedInformation"].as_array().unwrap().len() >= 2, "{}", d[0]);
    // A syntax error, then a warning with an `allow` action.
    c.change(uri, 4, json!([{ "text": "states { IT initial RD }\nrule r { when E then }\n" }]));
    assert_eq!(c.diagnostics(uri)[0]["code"], "E0001");
    let warn = "states { IT initial RD final }\nagent A sensor { event E event F }\nrule r { when state == IT and E then RD }\n";
    c.change(uri, 5, json!([{ "text": warn }]));
    let d = c.diagnostics(uri);
    let unused = d.iter().find(|d| d["code"] == "W0308").expect("F is never read");
    assert_eq!(unused["tags"], json!([1]));
    let actions = c.result(
        "textDocument/codeAction",
        json!({ "textDocument": { "uri": uri }, "range": unused["range"], "context": { "diagnostics": [] } }),
    );
    let allow = actions.as_array().unwrap().iter().find(|a| a["title"] == "allow `W0308` on `A`").expect("allow");
    assert_eq!(allow["edit"]["changes"][uri][0]["newText"], "#[allow(W0308)]\n");
    assert_eq!(allow["edit"]["changes"][uri][0]["range"]["start"], json!({ "line": 1, "character": 0 }));
    assert_eq!(c.stop(), 0);
}

#[test]
fn an_include_is_checked_with_its_includer() {
    let dir = tempfile::tempdir().unwrap();
    let common = dir.path().join("common.situ");
    let main = dir.path().join("main.situ");
    std::fs::write(&common, "states { IT initial RD }\nagent A sensor { event E }\n").unwrap();
    let main_text = "include \"common.situ\"\nrule r { when E then RD }\n";
    std::fs::write(&main, main_text).unwrap();
    let (cu, mu) = (uri_of(&common), uri_of(&main));
    let mut c = Client::ready();
    c.open(&mu, main_text);
    assert!(c.diagnostics(&mu).is_empty());
    // Definition goes into the included file.
    let def = c.result("textDocument/definition", at(&mu, main_text, "RD", 0));
    assert_eq!(def["uri"], cu);
    // An edit of the included file (open now) is seen by the includer.
    let common_text = "states { IT initial }\nagent A sensor { event E }\n";
    c.open(&cu, common_text);
    let d = c.diagnostics(&mu);
    assert_eq!(d.len(), 1);
    assert_eq!(d[0]["code"], "E0101");
    // Rename across files.
    let rename = c.result(
        "textDocument/rename",
        json!({ "textDocument": { "uri": mu }, "position": pos(main_text, "E ", 0, 0), "newName": "EV" }),
    );
    assert_eq!(rename["changes"][&mu].as_array().unwrap().len(), 1);
    assert_eq!(rename["changes"][&cu].as_array().unwrap().len(), 1);
    assert_eq!(c.stop(), 0);
}

#[test]
fn outdoor_rules_golden() {
    let mut c = Client::ready();
    let (uri, text) = open_repo_file(&mut c, "rules/outdoor.situ");
    let diags = c.diagnostics(&uri);
    insta::assert_json_snapshot!("outdoor_diagnostics", redact(&json!(diags)));

    // A state declared under another name: every use is a finding with a did-you-mean and its fix.
    let decl = pos(&text, "    RS ", 0, 4);
    let end = json!({ "line": decl["line"], "character": decl["character"].as_u64().unwrap() + 2 });
    c.change(&uri, 2, json!([{ "range": { "start": decl, "end": end }, "text": "RSX" }]));
    let broken = c.diagnostics(&uri);
    assert!(broken.len() > 5 && broken.iter().all(|d| d["code"] == "E0101"), "{broken:?}");
    insta::assert_json_snapshot!("outdoor_diagnostics_after_an_edit", redact(&json!(broken[..2])));
    c.change(&uri, 3, json!([{ "text": text }]));
    assert!(c.diagnostics(&uri).is_empty());

    let hovers: Vec<Value> =
        [("    RS ", 0, 4), ("agent LADAR", 0, 6), ("LAOBS", 0, 0), ("road_obstacle_ladar", 0, 0), ("_  ", 0, 0)]
            .iter()
            .map(|(needle, nth, skip)| {
                let p = json!({ "textDocument": { "uri": uri }, "position": pos(&text, needle, *nth, *skip) });
                c.result("textDocument/hover", p)["contents"]["value"].clone()
            })
            .collect();
    insta::assert_json_snapshot!("outdoor_hover", hovers);

    let def = c.result("textDocument/definition", at(&uri, &text, "LAOBS", 1));
    assert_eq!(def["range"]["start"], pos(&text, "LAOBS", 0, 0));
    let refs = c.result("textDocument/references", json!({ "textDocument": { "uri": uri }, "position": pos(&text, "LAOBS", 0, 0), "context": { "includeDeclaration": true } }));
    insta::assert_json_snapshot!("outdoor_references_laobs", redact(&refs));
    let hl = c.result("textDocument/documentHighlight", at(&uri, &text, "LAOBS", 0));
    assert_eq!(hl.as_array().unwrap().len(), refs.as_array().unwrap().len());
    assert_eq!(hl[0]["kind"], 3);

    let symbols = c.result("textDocument/documentSymbol", json!({ "textDocument": { "uri": uri } }));
    let names: Vec<String> =
        symbols.as_array().unwrap().iter().map(|s| format!("{} {}", s["kind"], s["name"])).collect();
    insta::assert_json_snapshot!("outdoor_document_symbols", names);

    // Completion: states in a set, fields in a pattern, symbols of a field, units.
    let labels = |c: &mut Client, p: Value| -> Vec<String> {
        let r = c.result("textDocument/completion", json!({ "textDocument": { "uri": uri }, "position": p }));
        r["items"].as_array().unwrap().iter().map(|i| i["label"].as_str().unwrap().to_string()).collect()
    };
    let in_set = labels(&mut c, pos(&text, "state in {", 0, "state in {".len()));
    assert!(in_set.contains(&"RS".to_string()) && in_set.contains(&"EM".to_string()), "{in_set:?}");
    let fields = labels(&mut c, pos(&text, "LAOBS(", 1, "LAOBS(".len()));
    assert_eq!(fields, ["distance", "height"]);
    let units = labels(&mut c, pos(&text, "300ms", 0, 3));
    assert!(units.contains(&"ms".to_string()), "{units:?}");

    // Formatting: the file is formatted already.
    let fmt = c.result(
        "textDocument/formatting",
        json!({ "textDocument": { "uri": uri }, "options": { "tabSize": 4, "insertSpaces": true } }),
    );
    assert_eq!(fmt, json!([]));

    // Rename: refused onto a taken name or a keyword, else every place.
    let rename = |c: &mut Client, new: &str| {
        c.request(
            "textDocument/rename",
            json!({ "textDocument": { "uri": uri }, "position": pos(&text, "    RS ", 0, 4), "newName": new }),
        )
    };
    let taken = rename(&mut c, "RO");
    assert!(taken["error"]["message"].as_str().unwrap().contains("already a state `RO`"), "{taken}");
    let keyword = rename(&mut c, "state");
    assert!(keyword["error"]["message"].as_str().unwrap().contains("keyword"), "{keyword}");
    let ok = rename(&mut c, "ROAD");
    let edits = ok["result"]["changes"][&uri].as_array().unwrap().len();
    let refs = c.result("textDocument/references", json!({ "textDocument": { "uri": uri }, "position": pos(&text, "    RS ", 0, 4), "context": { "includeDeclaration": true } }));
    assert_eq!(edits, refs.as_array().unwrap().len());
    assert!(edits > 10, "{edits}");

    // Semantic tokens: five numbers per token, the first is the comment at the top.
    let tokens = c.result("textDocument/semanticTokens/full", json!({ "textDocument": { "uri": uri } }));
    let data = tokens["data"].as_array().unwrap();
    assert_eq!(data.len() % 5, 0);
    assert!(data.len() > 5 * 500);
    let folds = c.result("textDocument/foldingRange", json!({ "textDocument": { "uri": uri } }));
    assert!(folds.as_array().unwrap().len() > 20);
    let hints = c.result("textDocument/inlayHint", json!({ "textDocument": { "uri": uri }, "range": { "start": { "line": 0, "character": 0 }, "end": { "line": 200, "character": 0 } } }));
    let labels: Vec<Value> = hints.as_array().unwrap().iter().map(|h| h["label"].clone()).collect();
    insta::assert_json_snapshot!("outdoor_inlay_hints_first_200_lines", labels);
    assert_eq!(c.stop(), 0);
}

#[test]
fn mower_golden() {
    let mut c = Client::ready();
    let (uri, text) = open_repo_file(&mut c, "examples/mower/mower.situ");
    let diags = c.diagnostics(&uri);
    insta::assert_json_snapshot!("mower_diagnostics", redact(&json!(diags)));
    let hovers: Vec<Value> = [("MOWING initial", 0), ("agent Bumper", 6), ("BPHIT", 0), ("_      ", 0)]
        .iter()
        .map(|(needle, skip)| {
            let p = json!({ "textDocument": { "uri": uri }, "position": pos(&text, needle, 0, *skip) });
            c.result("textDocument/hover", p)["contents"]["value"].clone()
        })
        .collect();
    insta::assert_json_snapshot!("mower_hover", hovers);
    let symbols = c.result("workspace/symbol", json!({ "query": "bat" }));
    let names: Vec<String> =
        symbols.as_array().unwrap().iter().map(|s| s["name"].as_str().unwrap().to_string()).collect();
    insta::assert_json_snapshot!("mower_workspace_symbols_bat", names);
    // Symbols of an enumerated field, in a pattern and in a script.
    let labels = |c: &mut Client, p: Value| -> Vec<String> {
        let r = c.result("textDocument/completion", json!({ "textDocument": { "uri": uri }, "position": p }));
        r["items"].as_array().unwrap().iter().map(|i| i["label"].as_str().unwrap().to_string()).collect()
    };
    assert_eq!(labels(&mut c, pos(&text, "BPHIT(side: ", 0, "BPHIT(side: ".len())), ["left", "right", "front"]);
    let then = labels(&mut c, pos(&text, "then DOCKING", 0, "then ".len()));
    assert!(then.starts_with(&["MOWING".to_string(), "DOCKING".to_string()]), "{then:?}");
    let fmt = c.result(
        "textDocument/formatting",
        json!({ "textDocument": { "uri": uri }, "options": { "tabSize": 4, "insertSpaces": true } }),
    );
    assert_eq!(fmt, json!([]));

    // Semantic tokens of the first rule, decoded: `line:column text type [declaration]`.
    assert_eq!(c.request("initialize", json!({}))["error"]["code"], -32600, "a second initialize is refused");
    let tokens = c.result("textDocument/semanticTokens/full", json!({ "textDocument": { "uri": uri } }));
    let types = situ_lsp::TOKEN_TYPES;
    let data: Vec<u64> = tokens["data"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap()).collect();
    let lines: Vec<&str> = text.lines().collect();
    let (mut line, mut col) = (0u64, 0u64);
    let mut decoded = Vec::new();
    for t in data.chunks(5) {
        line += t[0];
        col = if t[0] == 0 { col + t[1] } else { t[1] };
        let word: String = lines[line as usize].chars().skip(col as usize).take(t[2] as usize).collect();
        let decl = if t[4] & 1 == 1 { " declaration" } else { "" };
        decoded.push(format!("{}:{} {word} {}{decl}", line + 1, col + 1, types[t[3] as usize]));
    }
    let first_rule = text[..text.find("rule battery_low").unwrap()].lines().count() + 1;
    let rule: Vec<&String> = decoded
        .iter()
        .filter(|d| {
            d.starts_with(&format!("{first_rule}:"))
                || d.starts_with(&format!("{}:", first_rule + 1))
                || d.starts_with(&format!("{}:", first_rule + 2))
        })
        .collect();
    insta::assert_json_snapshot!("mower_semantic_tokens_first_rule", rule);
    assert_eq!(c.stop(), 0);
}

#[test]
fn formatting_and_a_missing_table_row() {
    let mut c = Client::ready();
    let uri = "file:///nonexistent/situ-lsp/fmt.situ";
    let text = "states {   IT initial\n RD final }\nagent   A sensor { event E\n  function f\n  table {\n    IT => run f()\n  }\n}\nrule r { when state == IT and E then RD }\n";
    c.open(uri, text);
    let d = c.diagnostics(uri);
    let missing = d.iter().find(|d| d["code"] == "W0311").expect("RD has no entry");
    let actions = c.result(
        "textDocument/codeAction",
        json!({ "textDocument": { "uri": uri }, "range": missing["range"], "context": { "diagnostics": [] } }),
    );
    let row = actions
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["title"] == "add the missing table row `RD => sleep`")
        .expect("row");
    assert_eq!(row["edit"]["changes"][uri][0]["newText"], "    RD => sleep\n");
    assert_eq!(row["edit"]["changes"][uri][0]["range"]["start"], json!({ "line": 6, "character": 0 }));
    let fmt = c.result(
        "textDocument/formatting",
        json!({ "textDocument": { "uri": uri }, "options": { "tabSize": 4, "insertSpaces": true } }),
    );
    let edits = fmt.as_array().unwrap();
    assert_eq!(edits.len(), 1);
    // Applied, the edit gives what `situ fmt` gives.
    let mut applied = text.to_string();
    let e = &edits[0];
    let off = |p: &Value| {
        let line = p["line"].as_u64().unwrap() as usize;
        let start: usize = text.split_inclusive('\n').take(line).map(str::len).sum();
        start + p["character"].as_u64().unwrap() as usize
    };
    applied.replace_range(off(&e["range"]["start"])..off(&e["range"]["end"]), e["newText"].as_str().unwrap());
    assert_eq!(applied, situ_grammar::format(text).unwrap());
    // A range that touches the rule only formats the rule.
    let range = json!({ "start": { "line": 8, "character": 0 }, "end": { "line": 8, "character": 5 } });
    let ranged = c.result(
        "textDocument/rangeFormatting",
        json!({ "textDocument": { "uri": uri }, "range": range, "options": { "tabSize": 4, "insertSpaces": true } }),
    );
    for e in ranged.as_array().unwrap() {
        assert!(e["range"]["start"]["line"].as_u64().unwrap() >= 8, "{e}");
    }
    assert_eq!(c.stop(), 0);
}
