//! How fast `situ lsp` answers, driven in-process as an editor drives it
//! (JSON-RPC frames through the same server loop as `situ lsp`):
//!
//! ```sh
//! cargo run --release -p situ-lsp --example lsp_bench
//! ```
//!
//! - diagnostics after a one-character change to `rules/outdoor.situ`
//!   (alternately breaking and mending a state name, so that each change
//!   publishes), from the change sent to the diagnostics received;
//! - the same on a generated file of 10,000 rules;
//! - completion on `outdoor.situ`;
//! - the process's resident memory over 1,000 edits.
//!
//! With the argument `verdicts` (`cargo run --release -p situ-lsp --example
//! lsp_bench verdicts`), instead: how long the verdicts of properties and
//! tests take at the editor's budget on `rules/outdoor.situ` and the
//! mower, from the open to their code lenses.

use serde_json::{json, Value};
use std::io::{Read, Write};
use std::sync::mpsc::{channel, Receiver, Sender};
use std::time::{Duration, Instant};

/// The server's standard input: bytes sent by the client.
struct In {
    rx: Receiver<Vec<u8>>,
    buf: Vec<u8>,
    pos: usize,
}

impl Read for In {
    fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
        if self.pos == self.buf.len() {
            match self.rx.recv() {
                Ok(b) => (self.buf, self.pos) = (b, 0),
                Err(_) => return Ok(0),
            }
        }
        let n = out.len().min(self.buf.len() - self.pos);
        out[..n].copy_from_slice(&self.buf[self.pos..self.pos + n]);
        self.pos += n;
        Ok(n)
    }
}

/// The server's standard output: one message per flush.
struct Out {
    tx: Sender<Vec<u8>>,
    buf: Vec<u8>,
}

impl Write for Out {
    fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
        self.buf.extend_from_slice(b);
        Ok(b.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        let _ = self.tx.send(std::mem::take(&mut self.buf));
        Ok(())
    }
}

struct Client {
    tx: Sender<Vec<u8>>,
    rx: Receiver<Vec<u8>>,
    id: i64,
}

impl Client {
    fn start() -> Client {
        // Without the verdicts of properties and tests (run on open and save):
        // these figures are the compiler's diagnostics as one types.
        Client::start_with(json!({}), json!({ "verdicts": false }))
    }

    fn start_with(capabilities: Value, options: Value) -> Client {
        let (to_server, server_in) = channel();
        let (server_out, from_server) = channel();
        std::thread::spawn(move || {
            situ_lsp::serve(In { rx: server_in, buf: Vec::new(), pos: 0 }, Out { tx: server_out, buf: Vec::new() })
        });
        let mut c = Client { tx: to_server, rx: from_server, id: 0 };
        c.request("initialize", json!({ "capabilities": capabilities, "initializationOptions": options }));
        c.notify("initialized", json!({}));
        c
    }

    fn send(&self, v: Value) {
        let body = v.to_string();
        let _ = self.tx.send(format!("Content-Length: {}\r\n\r\n{body}", body.len()).into_bytes());
    }

    fn next(&self) -> Value {
        let frame = self.rx.recv_timeout(Duration::from_secs(600)).expect("the server answers");
        let at = frame.windows(4).position(|w| w == b"\r\n\r\n").expect("a header") + 4;
        serde_json::from_slice(&frame[at..]).expect("JSON")
    }

    fn request(&mut self, method: &str, params: Value) -> Value {
        self.id += 1;
        self.send(json!({ "jsonrpc": "2.0", "id": self.id, "method": method, "params": params }));
        loop {
            let m = self.next();
            if m["id"] == self.id {
                return m;
            }
        }
    }

    fn notify(&self, method: &str, params: Value) {
        self.send(json!({ "jsonrpc": "2.0", "method": method, "params": params }));
    }

    /// Waits for diagnostics of `uri`; how many.
    fn diagnostics(&self, uri: &str) -> usize {
        loop {
            let m = self.next();
            if m["method"] == "textDocument/publishDiagnostics" && m["params"]["uri"] == uri {
                return m["params"]["diagnostics"].as_array().map_or(0, Vec::len);
            }
        }
    }

    fn open(&self, uri: &str, text: &str) {
        let doc = json!({ "uri": uri, "languageId": "situ", "version": 1, "text": text });
        self.notify("textDocument/didOpen", json!({ "textDocument": doc }));
    }

    fn replace(&self, uri: &str, version: i64, line: usize, col: usize, len: usize, text: &str) {
        let range =
            json!({ "start": { "line": line, "character": col }, "end": { "line": line, "character": col + len } });
        self.notify(
            "textDocument/didChange",
            json!({ "textDocument": { "uri": uri, "version": version }, "contentChanges": [{ "range": range, "text": text }] }),
        );
    }
}

fn rss_kib() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// The changes that broke the program (published after the quick check),
/// then those that mended it (published after the whole check).
fn split(name: &str, times: &[Duration]) {
    summary(&format!("{name}, breaking"), times.iter().step_by(2).copied().collect());
    summary(&format!("{name}, mending"), times.iter().skip(1).step_by(2).copied().collect());
}

fn summary(name: &str, mut times: Vec<Duration>) {
    times.sort();
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    let p = |q: f64| times[((times.len() - 1) as f64 * q).round() as usize];
    println!(
        "{name:<58} n={:<5} median {:>8.2} ms   p95 {:>8.2} ms   max {:>8.2} ms",
        times.len(),
        ms(p(0.5)),
        ms(p(0.95)),
        ms(times[times.len() - 1])
    );
}

/// The line and column of the `then X` of the first rule of `text`.
fn target_of_first_rule(text: &str) -> (usize, usize, usize) {
    let rule = text.find("\nrule ").expect("a rule");
    let then = rule + text[rule..].find("then ").expect("then") + "then ".len();
    let line = text[..then].matches('\n').count();
    let col = then - text[..then].rfind('\n').map_or(0, |i| i + 1);
    let len = text[then..].find(|c: char| !c.is_ascii_alphanumeric() && c != '_').unwrap_or(0);
    (line, col, len)
}

/// Alternately breaks and mends the target of the first rule, `n` times;
/// the latency of each change's diagnostics.
fn edits(c: &Client, uri: &str, text: &str, n: usize, mut each: impl FnMut(usize)) -> Vec<Duration> {
    let (line, col, len) = target_of_first_rule(text);
    let name = &text[text.lines().take(line).map(|l| l.len() + 1).sum::<usize>() + col..][..len];
    let mut times = Vec::with_capacity(n);
    for i in 0..n {
        let broken = i % 2 == 0;
        let (old, new) = if broken { (len, format!("{name}Q")) } else { (len + 1, name.to_string()) };
        let t = Instant::now();
        c.replace(uri, i as i64 + 2, line, col, old, &new);
        let found = c.diagnostics(uri);
        times.push(t.elapsed());
        assert_eq!(found > 0, broken, "edit {i}");
        each(i + 1);
    }
    times
}

fn generated(rules: usize) -> String {
    let mut s = String::from("states {\n    IT initial\n    A\n    B\n    C\n    D final\n}\n\n");
    for a in 0..50 {
        s.push_str(&format!("agent G{a} sensor {{\n    event E{a} {{ v: f64, k: {{lo, hi}} }}\n}}\n\n"));
    }
    s.push_str("rule start { when state == IT and E0 then A }\nrule go { when state == C and E1 then D }\n");
    for i in 0..rules - 2 {
        let (from, to) = [("A", "B"), ("B", "C"), ("A", "C"), ("B", "A")][i % 4];
        s.push_str(&format!(
            "rule r{i} salience {} {{ when state == {from} and E{}(v > {}.5, k == hi) then {to} }}\n",
            i % 7,
            i % 50,
            i
        ));
    }
    s
}

/// The verdicts of a file at the editor's budget: from the open to the
/// second `workspace/codeLens/refresh` (the first says that they run).
fn verdicts(rel: &str) {
    let path = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/..")).join(rel);
    let path = path.canonicalize().unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let uri = format!("file://{}", path.display());
    let refresh = json!({ "workspace": { "codeLens": { "refreshSupport": true } } });
    let mut c = Client::start_with(refresh, json!({}));
    let t = Instant::now();
    c.open(&uri, &text);
    let mut refreshes = 0;
    while refreshes < 2 {
        if c.next()["method"] == "workspace/codeLens/refresh" {
            refreshes += 1;
        }
    }
    let elapsed = t.elapsed();
    let lenses = c.request("textDocument/codeLens", json!({ "textDocument": { "uri": uri } }));
    let mut words = std::collections::BTreeMap::new();
    for l in lenses["result"].as_array().unwrap() {
        let title = l["command"]["title"].as_str().unwrap();
        *words.entry(title.split([':', ' ']).next().unwrap().to_string()).or_insert(0) += 1;
    }
    let words: Vec<String> = words.iter().map(|(w, n)| format!("{n} {w}")).collect();
    println!(
        "{:<58} {:>8.2} ms ({})",
        format!("{rel}: open to verdicts"),
        elapsed.as_secs_f64() * 1e3,
        words.join(", ")
    );
}

/// What a change to the 10,000-rule file costs, stage by stage, in-process
/// (no JSON-RPC): the parse from scratch and through the item cache, the
/// quick check, the whole analysis (with the index of names), and the
/// diagnostics as the protocol's findings.
fn stages() {
    use situ_grammar::diag::FileId;
    use situ_lsp::world::{Analysis, Doc, World};
    let big = generated(10_000);
    let path = std::path::PathBuf::from("/bench/rules10k.situ");
    let mut world = World::default();
    world.open(path.clone(), Doc::new("file:///bench/rules10k.situ".into(), big.clone(), 1));
    world.refresh();
    let (line, col, len) = target_of_first_rule(&big);
    let at = big.lines().take(line).map(|l| l.len() + 1).sum::<usize>() + col;
    let mut times: [Vec<Duration>; 7] = Default::default();
    for i in 0..20 {
        let mut text = big.clone();
        if i % 2 == 0 {
            text.insert(at + len, 'Q');
        }
        let t = Instant::now();
        let parsed = situ_grammar::parse(&text, FileId(0));
        times[0].push(t.elapsed());
        drop(parsed);
        world.docs.get_mut(&path).unwrap().text = text.clone();
        let t = Instant::now();
        let parsed = world.parses.parse(&text, FileId(0));
        times[1].push(t.elapsed());
        drop(parsed);
        let loader = situ_lsp::world::DocLoader { docs: &world.docs };
        let t = Instant::now();
        let checked = situ_compiler::check_quick_cached(&path, &loader, &mut world.parses);
        times[2].push(t.elapsed());
        drop(checked);
        let t = Instant::now();
        let analysis = Analysis::with_cache(&path, &world.docs, false, Some(&mut world.parses));
        times[3].push(t.elapsed());
        drop(analysis);
        world.touch(&path);
        let t = Instant::now();
        world.refresh();
        times[4].push(t.elapsed());
        let t = Instant::now();
        let _ = situ_lsp::diagnostics::all(&world);
        times[5].push(t.elapsed());
        world.drop_retired();
        let mut cache = situ_grammar::ItemCache::new();
        let t = Instant::now();
        let parsed = cache.parse(&text, FileId(0));
        times[6].push(t.elapsed());
        drop((parsed, cache));
    }
    let names = [
        "parse from scratch",
        "parse through the item cache",
        "check_quick_cached (parse, resolve, allow)",
        "Analysis (check, ASTs, line index, name index)",
        "World::refresh (the old analysis kept to drop later)",
        "diagnostics::all (findings to publish)",
        "parse through an empty cache (an open)",
    ];
    for (name, t) in names.iter().zip(times) {
        split(&format!("10,000 rules: {name}"), &t);
    }
}

fn main() {
    if std::env::args().nth(1).as_deref() == Some("verdicts") {
        verdicts("rules/outdoor.situ");
        verdicts("examples/mower/mower.situ");
        return;
    }
    if std::env::args().nth(1).as_deref() == Some("stages") {
        stages();
        return;
    }
    let outdoor = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../rules/outdoor.situ")).unwrap();
    let c = Client::start();
    let uri = "file:///bench/outdoor.situ";
    let t = Instant::now();
    c.open(uri, &outdoor);
    c.diagnostics(uri);
    println!("{:<58} {:>8.2} ms", "outdoor.situ: open to diagnostics", t.elapsed().as_secs_f64() * 1e3);
    split("outdoor.situ: change to diagnostics", &edits(&c, uri, &outdoor, 200, |_| {}));

    let mut c2 = c;
    let pos = {
        let at = outdoor.find("state in {").unwrap() + "state in {".len();
        let line = outdoor[..at].matches('\n').count();
        json!({ "line": line, "character": at - outdoor[..at].rfind('\n').map_or(0, |i| i + 1) })
    };
    let mut times = Vec::new();
    for _ in 0..200 {
        let t = Instant::now();
        let r = c2.request("textDocument/completion", json!({ "textDocument": { "uri": uri }, "position": pos }));
        times.push(t.elapsed());
        assert!(r["result"]["items"].as_array().is_some_and(|i| !i.is_empty()));
    }
    summary("outdoor.situ: completion in `state in {`", times);

    let mut marks = Vec::new();
    let mem = edits(&c2, uri, &outdoor, 1000, |i| {
        if [1, 100, 250, 500, 750, 1000].contains(&i) {
            marks.push((i, rss_kib().unwrap_or(0)));
        }
    });
    split("outdoor.situ: 1,000 more changes", &mem);
    let shown: Vec<String> = marks.iter().map(|(i, k)| format!("after {i}: {:.1} MiB", *k as f64 / 1024.0)).collect();
    println!("resident memory over 1,000 edits: {}", shown.join(", "));

    let big = generated(10_000);
    let uri = "file:///bench/rules10k.situ";
    let t = Instant::now();
    c2.open(uri, &big);
    let n = c2.diagnostics(uri);
    println!(
        "{:<58} {:>8.2} ms ({} lines, {n} findings)",
        "10,000 rules: open to diagnostics",
        t.elapsed().as_secs_f64() * 1e3,
        big.lines().count()
    );
    split("10,000 rules: change to diagnostics", &edits(&c2, uri, &big, 40, |_| {}));
}
