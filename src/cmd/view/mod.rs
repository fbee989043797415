//! `situ view FILE|BUNDLE|RECORDING.mcap [--rules FILE] [--port N]`: the
//! Supervisor's console in a browser, served on 127.0.0.1 until Ctrl-C.
//!
//! The page (`index.html`, `app.js`, `style.css` beside this file, in the
//! binary: no CDN, no network) draws what the JSON endpoints serve:
//!
//! | path | what |
//! |---|---|
//! | `/api/program` | states, agents with their mode, function and links per state, rules with their source text |
//! | `/api/graph` | the state graph in SVG (`situ graph --view states`, laid out by [`super::graph::layout`]), each state's node marked `data-state` |
//! | `/api/timeline` | for a recording: the state changes with their rules and explanations, the agents' modes, the refused events and why |
//! | `/api/state?at=SECONDS` | the state, the states visited and the agents' modes at that time |
//!
//! The page selects a time with `?at=SECONDS` or `#t=SECONDS`, a state's
//! wiring with `?state=NAME`. A recording is read with the runtime's reader
//! (`situ_runtime::record::mcap`): a damaged one, or one made on other
//! rules than `--rules`, is refused before the server starts (exit 2), as
//! is a port in use.

mod data;

use super::USAGE;
use std::io::Write as _;
use std::net::TcpListener;
use std::path::Path;

const INDEX: &str = include_str!("index.html");
const APP: &str = include_str!("app.js");
const STYLE: &str = include_str!("style.css");

pub fn run(file: &Path, rules: Option<&Path>, port: Option<u16>) -> u8 {
    let site = match data::Site::load(file, rules) {
        Ok(s) => s,
        Err(code) => return code,
    };
    let listener = match TcpListener::bind(("127.0.0.1", port.unwrap_or(0))) {
        Ok(l) => l,
        Err(e) if e.kind() == std::io::ErrorKind::AddrInUse => {
            eprintln!(
                "error: port {} on 127.0.0.1 is in use: choose another with --port, or leave --port out for a free one",
                port.unwrap_or(0)
            );
            return USAGE;
        }
        Err(e) => {
            eprintln!("error: cannot listen on 127.0.0.1:{}: {e}", port.unwrap_or(0));
            return USAGE;
        }
    };
    let addr = match listener.local_addr() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("error: cannot tell the port listened on: {e}");
            return USAGE;
        }
    };
    let server = match tiny_http::Server::from_listener(listener, None) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: cannot serve on {addr}: {e}");
            return USAGE;
        }
    };
    // Ctrl-C ends the server; nothing is half written, nothing to undo.
    let _ = ctrlc::set_handler(|| std::process::exit(0));
    println!("serving http://{addr}/");
    let _ = std::io::stdout().flush();
    eprintln!("{}; Ctrl-C stops", site.summary());
    for request in server.incoming_requests() {
        let (status, kind, body) = answer(&site, request.url());
        let header = tiny_http::Header::from_bytes(&b"Content-Type"[..], kind.as_bytes()).expect("a valid header");
        let nocache = tiny_http::Header::from_bytes(&b"Cache-Control"[..], &b"no-store"[..]).expect("a valid header");
        let response = tiny_http::Response::from_data(body.into_bytes())
            .with_status_code(status)
            .with_header(header)
            .with_header(nocache);
        // A browser that went away is not an error of the server.
        let _ = request.respond(response);
    }
    super::OK
}

/// The status, content type and body for a request's URL.
fn answer(site: &data::Site, url: &str) -> (u16, &'static str, String) {
    let (path, query) = url.split_once('?').unwrap_or((url, ""));
    const JSON: &str = "application/json; charset=utf-8";
    match path {
        "/" | "/index.html" => (200, "text/html; charset=utf-8", INDEX.to_string()),
        "/app.js" => (200, "text/javascript; charset=utf-8", APP.to_string()),
        "/style.css" => (200, "text/css; charset=utf-8", STYLE.to_string()),
        "/api/program" => (200, JSON, site.program.clone()),
        "/api/graph" => (200, "image/svg+xml; charset=utf-8", site.graph.clone()),
        "/api/timeline" => (200, JSON, site.timeline.clone()),
        "/api/state" => {
            let at = query
                .split('&')
                .find_map(|kv| kv.strip_prefix("at="))
                .and_then(|v| v.parse::<f64>().ok())
                .filter(|v| v.is_finite() && *v >= 0.0);
            (200, JSON, site.state_at(at.map(|s| (s * 1e9) as u64)))
        }
        "/favicon.ico" => (204, "text/plain", String::new()),
        _ => (404, "text/plain; charset=utf-8", format!("no page {path}")),
    }
}
