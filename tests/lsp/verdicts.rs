//! The verdicts of properties and tests in the editor, driven as an editor
//! drives `situ lsp`: open, read the diagnostics and the code lenses, run
//! the lens's command, apply the edit the server asks for, save.

use super::*;

/// The budget under which the fixture's ladder is undecided (a setting of
/// the client, as docs/editors.md says).
fn tiny() -> Value {
    json!({ "verdicts": { "effort": 100000, "depth": 2, "maxStates": 1000, "randomRuns": 8, "randomLength": 3 } })
}

fn fixture() -> String {
    std::fs::read_to_string(repo().join("lsp/tests/fixtures/verdicts.situ")).unwrap()
}

/// The line of the first occurrence of `needle`.
fn line(text: &str, needle: &str) -> u64 {
    pos(text, needle, 0, 0)["line"].as_u64().unwrap()
}

impl Client {
    /// The next publication for `uri` that satisfies `done`, with its version.
    fn diagnostics_until(&mut self, uri: &str, done: impl Fn(&[Value]) -> bool) -> (Value, Vec<Value>) {
        for _ in 0..100 {
            let n = self.notification("textDocument/publishDiagnostics", Some(uri));
            let d = n["params"]["diagnostics"].as_array().unwrap().clone();
            if done(&d) {
                return (n["params"]["version"].clone(), d);
            }
        }
        panic!("no such publication");
    }

    fn save(&mut self, uri: &str) {
        self.notify("textDocument/didSave", json!({ "textDocument": { "uri": uri } }));
    }

    fn lenses(&mut self, uri: &str) -> Vec<Value> {
        self.result("textDocument/codeLens", json!({ "textDocument": { "uri": uri } })).as_array().unwrap().clone()
    }
}

fn with_code<'a>(d: &'a [Value], code: &str) -> Vec<&'a Value> {
    d.iter().filter(|d| d["code"] == code).collect()
}

fn titles(lenses: &[Value]) -> Vec<(u64, String)> {
    lenses
        .iter()
        .map(|l| (l["range"]["start"]["line"].as_u64().unwrap(), l["command"]["title"].as_str().unwrap().to_string()))
        .collect()
}

/// `edit` (an LSP `TextEdit`) applied to `text`.
fn apply(text: &str, edit: &Value) -> String {
    let offset = |p: &Value| {
        let line = p["line"].as_u64().unwrap() as usize;
        let start: usize = text.split_inclusive('\n').take(line).map(str::len).sum();
        start + p["character"].as_u64().unwrap() as usize
    };
    let mut out = text.to_string();
    out.replace_range(
        offset(&edit["range"]["start"])..offset(&edit["range"]["end"]),
        edit["newText"].as_str().unwrap(),
    );
    out
}

#[test]
fn verdicts_are_diagnostics_and_lenses_and_a_counterexample_becomes_a_test() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ladder.situ");
    let text = fixture();
    std::fs::write(&path, &text).unwrap();
    let uri = uri_of(&path);
    let refresh = json!({ "workspace": { "codeLens": { "refreshSupport": true } } });
    let mut c = Client::ready_with(tiny(), refresh);
    c.open(&uri, &text);
    let (version, d) = c.diagnostics_until(&uri, |d| d.iter().any(|d| d["code"] == "E0503"));
    assert_eq!(version, 1);
    let (violated, undecided, vacuous, failed) =
        (with_code(&d, "E0503"), with_code(&d, "E0502"), with_code(&d, "W0501"), with_code(&d, "E0504"));
    assert_eq!((violated.len(), undecided.len(), vacuous.len(), failed.len()), (1, 1, 1, 1), "{d:?}");
    // Each at its property's or test's place, with the severity of its code.
    let name = |name: &str| {
        let quoted = format!("\"{name}\"");
        json!({ "start": pos(&text, &quoted, 0, 0), "end": pos(&text, &quoted, 0, quoted.len()) })
    };
    assert_eq!(violated[0]["range"], name("the first step is never taken"));
    assert_eq!(undecided[0]["range"], name("the top is never reached"));
    assert_eq!(vacuous[0]["range"], name("vacuous"));
    assert_eq!(failed[0]["range"], name("one step reaches the second rung"));
    let severities: Vec<&Value> =
        [&violated, &undecided, &vacuous, &failed].iter().map(|d| &d[0]["severity"]).collect();
    assert_eq!(severities, [&json!(1), &json!(2), &json!(2), &json!(1)]);
    // The violated property: the run as related information, the test block in the message.
    let violated = violated[0];
    let run = violated["relatedInformation"][0]["message"].as_str().unwrap();
    assert!(run.starts_with("the run (exhaustive exploration, shortest):\n  start"), "{run}");
    assert!(run.contains("U1") && run.contains("S0 -> S1"), "{run}");
    assert!(violated["message"].as_str().unwrap().contains("test \"counterexample: the first step is never taken\" {"));
    assert!(
        undecided[0]["message"].as_str().unwrap().contains("symbolic: gave up at its work budget"),
        "{}",
        undecided[0]
    );
    // In the same publication as the compiler's own findings.
    assert_eq!(with_code(&d, "W0310").len(), 1, "`blink` is never run: {d:?}");

    let lenses = c.lenses(&uri);
    let expected = [
        (line(&text, "property \"the lamp"), "proved (IC3)"),
        (line(&text, "property \"the first"), "violated: 1 event (exhaustive exploration): append as a test"),
        (line(&text, "property \"vacuous"), "proved (IC3), vacuous: the premise never holds"),
        (
            line(&text, "property \"the top"),
            "undecided: explored 2 events, IC3 stopped at 3 events (work budget), 8 random runs",
        ),
    ];
    let got = titles(&lenses);
    assert_eq!(got[..4], expected.map(|(l, t)| (l, t.to_string())), "{got:?}");
    assert_eq!(got[4].0, line(&text, "test \"one step"));
    assert!(got[4].1.starts_with("failed: "), "{got:?}");

    // The lens's command: the server asks the client to append the block.
    let command = lenses[1]["command"].clone();
    assert_eq!(command["command"], "situ.insertCounterexample");
    let params = json!({ "command": command["command"], "arguments": command["arguments"] });
    assert_eq!(c.result("workspace/executeCommand", params.clone()), Value::Null);
    let ask = c.notification("workspace/applyEdit", None);
    c.send(&json!({ "jsonrpc": "2.0", "id": ask["id"], "result": { "applied": true } }));
    let edits = ask["params"]["edit"]["changes"][&uri].as_array().unwrap();
    assert_eq!(edits.len(), 1);
    let appended = apply(&text, &edits[0]);
    assert!(appended.starts_with(&text));
    let block = &appended[text.len()..];
    assert!(
        block.starts_with("\ntest \"counterexample: the first step is never taken\" {\n    on U1 at 0ms\n"),
        "{block}"
    );

    // Applied and saved: the block parses, and is a test that passes (the
    // run reaches the state the counterexample says); the property is still
    // violated by the same run.
    c.change(&uri, 2, json!([{ "text": appended }]));
    c.save(&uri);
    let stale = c.request("workspace/executeCommand", params);
    assert!(stale["error"]["message"].as_str().unwrap().contains("the document changed"), "{stale}");
    let (version, d) = c.diagnostics_until(&uri, |d| d.iter().any(|d| d["code"] == "E0503"));
    assert_eq!(version, 2);
    assert!(d.iter().all(|d| d["code"] != "E0001"), "{d:?}");
    assert_eq!(with_code(&d, "E0504").len(), 1, "only the old test fails: {d:?}");
    assert_eq!(with_code(&d, "E0503")[0]["message"], violated["message"]);
    let got = titles(&c.lenses(&uri));
    assert_eq!(got.len(), 6, "{got:?}");
    assert_eq!(got[5], (line(&appended, "test \"counterexample"), "passed".to_string()));
    assert_eq!(c.stop(), 0);
}

#[test]
fn bad_verdict_settings_are_said_and_the_default_budget_runs() {
    let mut c = Client::ready_with(json!({ "verdicts": { "effort": "lots" } }), json!({}));
    let shown = c.notification("window/showMessage", None);
    let message = shown["params"]["message"].as_str().unwrap();
    assert!(message.contains("`verdicts.effort` is `\"lots\"`: it must be a whole number"), "{message}");
    // A setting changed later: refused the same way, the server goes on.
    c.notify("workspace/didChangeConfiguration", json!({ "settings": { "situ": { "verdicts": { "depth": -1 } } } }));
    let shown = c.notification("window/showMessage", None);
    assert!(shown["params"]["message"].as_str().unwrap().contains("`verdicts.depth`"), "{shown}");
    assert_eq!(c.stop(), 0);
}
