//! `situ view` in a real browser: headless Chromium (Debian's `chromium`,
//! `scripts/install-chromium.sh`; a missing `chromium` fails these tests)
//! loads the page that `situ view` serves, runs its script, and dumps the
//! DOM: the state graph's SVG with the current state highlighted, the
//! agents' modes, the rules, no page error; for a recording, two times
//! chosen in the address show two different states and modes. Screenshots
//! are saved under `target/tmp/view/` for a person to open. Bad input (a
//! damaged recording, one of other rules, a port in use) exits 2 before
//! anything is served.
//!
//! A live run (`situ run … --serve`) is followed twice: by a page in
//! Chromium, and by a plain HTTP client that compares what it heard with
//! the run's recording and says how late it heard each change. Chromium is
//! driven over the DevTools protocol (`tests/python/cdp_view.py`) where a
//! person's hand or real time matters: the timeline scrubbed with the mouse,
//! a live page left open in real time.

mod common;
use common::*;
use std::io::{BufRead, BufReader};
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A `situ view` being served; stopped when dropped.
struct Served {
    child: Child,
    url: String,
}

impl Served {
    fn start(args: &[&str]) -> Served {
        Served::command(&[&["view"], args].concat())
    }

    /// `situ ARGS…` that prints `serving URL` as its first line.
    fn command(args: &[&str]) -> Served {
        let mut child = Command::new(env!("CARGO_BIN_EXE_situ"))
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("situ view starts");
        let mut out = BufReader::new(child.stdout.take().unwrap());
        let mut line = String::new();
        out.read_line(&mut line).expect("the first line");
        // The rest is read to its end: a run's report is not cut short.
        std::thread::spawn(move || std::io::copy(&mut out, &mut std::io::sink()));
        let url =
            line.trim().strip_prefix("serving ").unwrap_or_else(|| panic!("not a URL line: {line:?}")).to_string();
        assert!(url.starts_with("http://127.0.0.1:") && url.ends_with('/'), "{url}");
        Served { child, url }
    }
}

impl Drop for Served {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn require_chromium() {
    let ok = Command::new("chromium").arg("--version").stdout(Stdio::null()).status().is_ok_and(|s| s.success());
    assert!(ok, "Debian's `chromium` is missing: run scripts/install-chromium.sh");
}

/// Where the screenshots go.
fn screens() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("view");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Headless Chromium on `url` with `extra` arguments, to its end (60 s at
/// most); its standard output.
fn chromium(url: &str, extra: &[&str]) -> String {
    let profile = tempfile::tempdir().unwrap();
    let out = tempfile::NamedTempFile::new().unwrap();
    let mut child = Command::new("chromium")
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--no-first-run",
            "--virtual-time-budget=5000",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .args(extra)
        .arg(url)
        .stdout(out.reopen().unwrap())
        .stderr(Stdio::null())
        .spawn()
        .expect("chromium starts");
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            assert!(status.success(), "chromium on {url} failed: {status}");
            break;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("chromium on {url} did not finish in 60 s");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    std::fs::read_to_string(out.path()).unwrap()
}

/// The page's DOM once its script ran.
fn dom(url: &str) -> String {
    let dom = chromium(url, &["--dump-dom"]);
    assert!(dom.contains("data-ready=\"true\""), "the page's script did not finish on {url}:\n{dom}");
    assert!(!dom.contains("<pre id=\"page-error\""), "the page reported an error on {url}:\n{dom}");
    dom
}

fn screenshot(url: &str, name: &str) {
    let path = screens().join(name);
    let _ = std::fs::remove_file(&path);
    chromium(url, &["--window-size=1400,900", &format!("--screenshot={}", path.display())]);
    let size = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
    assert!(size > 10_000, "no screenshot at {} ({size} bytes)", path.display());
    eprintln!("screenshot: {}", path.display());
}

/// The state the graph highlights as current (the one node of class
/// `current`), and the one the header names.
fn current(dom: &str) -> String {
    let highlighted: Vec<&str> = dom
        .split("<g ")
        .skip(1)
        .map(|g| &g[..g.find('>').unwrap()])
        .filter(|tag| {
            tag.split("class=\"").nth(1).is_some_and(|c| c[..c.find('"').unwrap()].split(' ').any(|w| w == "current"))
        })
        .filter_map(|tag| tag.split("data-state=\"").nth(1).map(|s| &s[..s.find('"').unwrap()]))
        .collect();
    assert_eq!(highlighted.len(), 1, "one highlighted state in the graph: {highlighted:?}");
    let at = dom.find("id=\"current-state\">").expect("the current state named") + 19;
    let named = &dom[at..at + dom[at..].find('<').unwrap()];
    assert_eq!(highlighted[0], named, "the graph and the header disagree");
    named.to_string()
}

/// An agent's mode in the wiring table.
fn mode(dom: &str, agent: &str) -> String {
    let at = dom.find(&format!("<tr data-agent=\"{agent}\">")).unwrap_or_else(|| panic!("no row of {agent}"));
    let row = &dom[at..at + dom[at..].find("</tr>").unwrap()];
    let m = row.find("data-mode=\"").expect("a mode") + 11;
    row[m..m + row[m..].find('"').unwrap()].to_string()
}

#[test]
fn the_rules_draw_in_a_browser() {
    require_chromium();
    let served = Served::start(&["rules/outdoor.situ"]);
    let dom = dom(&served.url);
    assert!(dom.contains("<svg") && dom.contains("data-state=\"RS\""), "the state graph's SVG");
    assert_eq!(current(&dom), "IT");
    // Every agent's mode and function in the initial state.
    assert_eq!(dom.matches("<tr data-agent=").count(), 12);
    assert_eq!(mode(&dom, "Localization"), "running");
    assert_eq!(mode(&dom, "RFCCD"), "waiting");
    assert!(dom.contains(">lines_far<"), "RFCCD's function");
    // The rules with their source text.
    assert!(dom.contains("data-rule=\"start_on_road\""));
    assert!(dom.contains("rule start_on_road"), "a rule's source text");
    // Another state's wiring, chosen in the address.
    let other = self::dom(&format!("{}?state=RS", served.url));
    assert!(other.contains("id=\"wiring-state\">RS<"), "the wiring of RS");
    assert_eq!(mode(&other, "RFCCD"), "running");
    screenshot(&served.url, "rules.png");
}

#[test]
fn a_recording_scrubs_in_a_browser() {
    require_chromium();
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("run.mcap");
    let rec = rec.to_str().unwrap();
    let run = situ(&["run", "rules/outdoor.situ", "--record", rec, "--until", "25"]);
    assert!(Path::new(rec).is_file(), "no recording: {}", text(&run));
    let served = Served::start(&[rec]);
    let early = dom(&format!("{}?at=0.1", served.url));
    let late = dom(&format!("{}#t=24", served.url));
    assert_eq!(current(&early), "IT");
    let later = current(&late);
    assert_ne!(later, "IT", "24 s later the robot is elsewhere");
    assert_ne!(mode(&early, "RFCCD"), mode(&late, "RFCCD"), "the modes move with the time");
    assert!(late.contains("(recorded)"), "the recorded modes are shown");
    // The firings with their explanations; the timeline.
    assert!(late.contains("by initialized") && late.contains("rule `initialized`"), "a firing explained");
    assert!(late.contains("id=\"scrub\""), "the timeline");
    // Played from the start, the page reaches the end of the recording.
    let played = dom(&format!("{}?play", served.url));
    assert_eq!(current(&played), later, "played to its end");
    assert!(played.contains("id=\"time-label\">25.000 s / 25.000 s<"), "at the end: {played}");
    assert!(played.contains("class=\"firing now\"") && played.contains("▶ play"), "stopped at the end");
    // The same with its rules given: they are the rules it was made on.
    let again = Served::start(&[rec, "--rules", "rules/outdoor.situ"]);
    assert_eq!(current(&dom(&format!("{}#t=24", again.url))), later);
    screenshot(&format!("{}#t=24", served.url), "recording.png");
}

#[test]
fn bad_input_exits_2_before_serving() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("run.mcap");
    let rec_s = rec.to_str().unwrap();
    situ(&["run", "rules/outdoor.situ", "--record", rec_s, "--until", "3"]);
    let mut bytes = std::fs::read(&rec).unwrap();
    let mid = bytes.len() / 2;
    bytes[mid..mid + 64].fill(0xff);
    let damaged = write(dir.path(), "damaged.mcap", &bytes);
    let o = situ(&["view", &damaged]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(stderr(&o).contains("not a readable recording"), "{}", text(&o));
    assert!(stdout(&o).is_empty(), "nothing served: {}", text(&o));

    let o = situ(&["view", rec_s, "--rules", "rules/ugv.situ"]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(stderr(&o).contains("recorded on other rules"), "{}", text(&o));

    let taken = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = taken.local_addr().unwrap().port().to_string();
    let o = situ(&["view", "rules/outdoor.situ", "--port", &port]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(stderr(&o).contains(&format!("port {port} on 127.0.0.1 is in use")), "{}", text(&o));
    // The same for a live run's page, before the run starts.
    let o = situ(&["run", "tests/view/greenhouse.situ", "--serve", &port]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(
        stderr(&o).contains(&format!("port {port} on 127.0.0.1 is in use: choose another with --serve")),
        "{}",
        text(&o)
    );
    let o = situ(&["run", "tests/view/greenhouse.situ", "--serve", "localhost:http"]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(stderr(&o).contains("is not a port or an address"), "{}", text(&o));
}

/// `GET path` from the server of `url` with these extra header lines: the
/// status, the content type and the body.
fn request(url: &str, path: &str, headers: &[&str]) -> (u16, String, String) {
    use std::io::{Read, Write};
    let addr = url.strip_prefix("http://").unwrap().trim_end_matches('/');
    let mut stream = std::net::TcpStream::connect(addr).expect("the server listens");
    stream.set_read_timeout(Some(Duration::from_secs(30))).unwrap();
    let lines: String = headers.iter().map(|h| format!("{h}\r\n")).collect();
    write!(stream, "GET {path} HTTP/1.0\r\n{lines}\r\n").unwrap();
    let mut response = String::new();
    stream.read_to_string(&mut response).expect("a whole response");
    let (head, body) = response.split_once("\r\n\r\n").expect("a head and a body");
    let status = head.split_whitespace().nth(1).and_then(|s| s.parse().ok()).expect("a status");
    let kind = head
        .lines()
        .find_map(|l| l.split_once(':').filter(|(k, _)| k.eq_ignore_ascii_case("content-type")))
        .map_or(String::new(), |(_, v)| v.trim().to_string());
    (status, kind, body.to_string())
}

/// A server at `url` answers `data` (a JSON endpoint) to a request for its
/// own address, and refuses it (403, plain text, a reason) to a rebinding
/// page's (a foreign `Host`) and to another site's page (a foreign `Origin`);
/// `also` (a live run's long poll) too.
fn answers_only_its_own_address(url: &str, data: &str, also: &str) {
    let addr = url.strip_prefix("http://").unwrap().trim_end_matches('/');
    let port = addr.rsplit_once(':').unwrap().1;
    let own = format!("Host: {addr}");
    let (status, _, body) = request(url, data, &[&own]);
    assert_eq!(status, 200, "{body}");
    assert!(serde_json::from_str::<serde_json::Value>(&body).is_ok(), "{body}");
    let (status, _, _) = request(url, data, &[&format!("Host: localhost:{port}"), &format!("Origin: http://{addr}")]);
    assert_eq!(status, 200, "localhost, and the page's own origin");
    for path in [data, also] {
        let rebound = format!("Host: evil.example:{port}");
        let (status, kind, body) = request(url, path, &[&rebound]);
        assert_eq!((status, kind.as_str()), (403, "text/plain; charset=utf-8"), "{path}: {body}");
        assert!(body.contains("Host `evil.example:") && body.contains("not this server's address"), "{body}");
        let (status, kind, body) = request(url, path, &[&own, "Origin: http://evil.example"]);
        assert_eq!((status, kind.as_str()), (403, "text/plain; charset=utf-8"), "{path}: {body}");
        assert!(body.contains("Origin `http://evil.example` is not a page of this server"), "{body}");
        let (status, _, body) = request(url, path, &[]);
        assert_eq!(status, 403, "no Host: {body}");
    }
    // What held before still holds: no file outside the page, plain-text 404s.
    for path in ["/../Cargo.toml", "/%2e%2e/Cargo.toml", "/src/main.rs"] {
        let (status, kind, body) = request(url, path, &[&own]);
        assert_eq!((status, kind.as_str()), (404, "text/plain; charset=utf-8"), "{path}: {body}");
        assert!(body.starts_with("no page"), "{body}");
    }
}

#[test]
fn the_servers_answer_only_their_own_address() {
    let served = Served::start(&["rules/outdoor.situ"]);
    answers_only_its_own_address(&served.url, "/api/timeline", "/api/state?at=1");
    // A live run's server, with its long poll (which waits for the run to
    // start: a refused poll is answered at once, and does not start it).
    let live = Served::command(&["run", "tests/view/greenhouse.situ", "--serve"]);
    answers_only_its_own_address(&live.url, "/api/program", "/api/live?since=0");
}

/// Follows a live run's `/api/live` to its end: every entry, and how late
/// each state change was heard (ms, the server's stamp to here).
fn follow(url: &str) -> (Vec<serde_json::Value>, Vec<f64>) {
    let (mut entries, mut lags) = (Vec::new(), Vec::new());
    let mut since = 0u64;
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        assert!(Instant::now() < deadline, "the run did not end");
        let a: serde_json::Value = serde_json::from_str(&http_get(&format!("{url}api/live?since={since}"))).unwrap();
        let heard = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap().as_micros() as f64;
        assert_eq!(a["reset"], false, "no entry folded in a short run");
        for e in a["entries"].as_array().unwrap() {
            if e["kind"] == "change" {
                lags.push((heard - e["wall_us"].as_f64().unwrap()) / 1000.0);
            }
            entries.push(e.clone());
        }
        since = a["next"].as_u64().unwrap();
        if a["over"] == true {
            return (entries, lags);
        }
    }
}

/// The state changes (from, to) of a recording.
fn recorded_changes(path: &Path) -> Vec<(String, String)> {
    let bytes = std::fs::read(path).unwrap();
    let (messages, _) = situ_runtime::record::mcap::read_messages(&bytes).unwrap();
    messages
        .iter()
        .filter(|(t, _, m)| t == "/state" && m["from"] != m["state"])
        .map(|(_, _, m)| (m["from"].as_str().unwrap().to_string(), m["state"].as_str().unwrap().to_string()))
        .collect()
}

fn percentile(lags: &mut [f64], p: f64) -> f64 {
    lags.sort_by(f64::total_cmp);
    lags[((lags.len() - 1) as f64 * p).round() as usize]
}

#[test]
fn a_live_run_is_heard_change_by_change() {
    let dir = tempfile::tempdir().unwrap();
    // A user's greenhouse on its script; then the reference stack.
    for (file, extra) in [("tests/view/greenhouse.situ", &[][..]), ("rules/outdoor.situ", &["--until", "4"][..])] {
        let rec = dir.path().join("live.mcap");
        let rec_s = rec.to_str().unwrap();
        let mut served = Served::command(&[&["run", file, "--serve", "--record", rec_s], extra].concat());
        let (entries, mut lags) = follow(&served.url);
        let status = served.child.wait().unwrap();
        assert!(status.code().is_some_and(|c| c < 2), "{file}: {status}");
        let heard: Vec<(String, String)> = entries
            .iter()
            .filter(|e| e["kind"] == "change")
            .map(|e| (e["from"].as_str().unwrap().to_string(), e["to"].as_str().unwrap().to_string()))
            .collect();
        assert!(!heard.is_empty(), "{file}: no change heard");
        assert_eq!(heard, recorded_changes(&rec), "{file}: the page heard the recording's changes, in order");
        assert!(entries.iter().any(|e| e["kind"] == "mode"), "{file}: the agents' modes");
        if file.ends_with("greenhouse.situ") {
            let path: Vec<&str> = heard.iter().map(|(_, to)| to.as_str()).collect();
            assert_eq!(path, ["VENTING", "GROWING", "HEATING", "PAUSED", "HEATING", "GROWING"]);
        }
        let (p50, max) = (percentile(&mut lags, 0.5), percentile(&mut lags, 1.0));
        eprintln!("{file}: {} changes heard; lag p50 {p50:.2} ms, max {max:.2} ms", lags.len());
    }
}

/// `tests/python/cdp_view.py MODE URL SCREENSHOT`: Chromium driven over the
/// DevTools protocol; its JSON lines.
fn cdp(mode: &str, url: &str, shot: &str) -> Vec<serde_json::Value> {
    require_chromium();
    let path = screens().join(shot);
    let o = Command::new("python3")
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python/cdp_view.py"))
        .args([mode, url])
        .arg(&path)
        .output()
        .expect("python3 runs");
    let all = text(&o);
    assert!(
        !all.contains("ModuleNotFoundError"),
        "a Python package is missing: pip install -r examples/python/requirements.txt\n{all}"
    );
    assert!(o.status.success(), "cdp_view.py {mode} {url}:\n{all}");
    eprintln!("screenshot: {}", path.display());
    stdout(&o).lines().map(|l| serde_json::from_str(l).unwrap()).collect()
}

#[test]
fn a_person_scrubs_a_recording_with_the_mouse() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("run.mcap");
    let rec = rec.to_str().unwrap();
    situ(&["run", "rules/outdoor.situ", "--record", rec, "--until", "25"]);
    let served = Served::start(&[rec]);
    let at = cdp("scrub", &served.url, "scrubbed.png");
    assert_eq!(at.len(), 4, "{at:?}");
    let (start, end, back) = (&at[0], &at[2], &at[3]);
    assert_eq!(start["state"], "IT", "at the start the robot initialises: {start}");
    assert_ne!(end["state"], start["state"], "at the end it is elsewhere: {end}");
    assert_ne!(end["modes"], start["modes"], "the agents' modes move with the slider");
    assert_eq!(back["state"], start["state"], "Home: the page shows the start again: {back}");
    assert_eq!(back["modes"], start["modes"]);
    assert_ne!(start["time"], end["time"], "the time label follows the slider");
}

#[test]
fn a_live_page_draws_each_change_in_real_time() {
    let served = Served::command(&["run", "tests/view/greenhouse.situ", "--serve"]);
    let out = cdp("live", &served.url, "live.png");
    let out = &out[0];
    assert_eq!(out["state"], "GROWING", "{out}");
    assert_eq!(out["firings"], 6, "six firings, as they came: {out}");
    let firings = out["firing_text"].as_str().unwrap();
    assert!(firings.contains("by door_open") && firings.contains("rule `door_open`"), "a firing explained: {out}");
    assert_eq!(out["modes"]["Heater"], "sleeping", "GROWING's wiring: {out}");
    assert!(out["time"].as_str().unwrap().ends_with("(live)"), "the timeline says it is live: {out}");
    let lags: Vec<f64> = out["lags_ms"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    assert_eq!(lags.len(), 6, "a lag per change: {out}");
    let mut sorted = lags.clone();
    sorted.sort_by(f64::total_cmp);
    eprintln!("the page drew each change {:.1}–{:.1} ms after the server stamped it", sorted[0], sorted[5]);
}
