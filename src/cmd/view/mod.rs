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
//!
//! Both servers (this one and a live run's, [`serve_live`]) answer only
//! requests addressed to them ([`guard::Guard`]): a foreign `Host` or
//! `Origin` gets a 403 with the reason, so that no other site's page can
//! read the rules or the run through DNS rebinding.

pub mod data;
pub mod guard;

use super::{CliError, Outcome};
use guard::Guard;
use situ_runtime::record::live::Live;
use std::io::Write as _;
use std::net::TcpListener;
use std::path::PathBuf;
use std::sync::Arc;

const INDEX: &str = include_str!("index.html");
const APP: &str = include_str!("app.js");
const STYLE: &str = include_str!("style.css");

/// Pages waiting on `/api/live` at once, at most (each waits in a thread
/// of its own); one more is told to come back.
const MAX_WAITING: usize = 64;

// The arguments of `situ view`.
#[derive(clap::Args)]
pub struct Args {
    /// A `.situ` source, a bundle, or an MCAP recording of `situ run --record`.
    pub file: PathBuf,
    /// The rules of a recording (a `.situ` source or a bundle); default: the bundle attached to it. Refused (exit 2) when the recording was made on other rules.
    #[arg(long, value_name = "FILE")]
    pub rules: Option<PathBuf>,
    /// The port to listen on (default: a free one); the URL is the first line on standard output.
    #[arg(long)]
    pub port: Option<u16>,
}

pub fn run(args: &Args) -> Outcome {
    let site = data::Site::load(&args.file, args.rules.as_deref())?;
    let host = "127.0.0.1";
    let server = listen(host, args.port.unwrap_or(0), "--port")?;
    // Ctrl-C ends the server; nothing is half written, nothing to undo.
    let _ = ctrlc::set_handler(|| std::process::exit(0));
    println!("serving http://{}/", server.1);
    let _ = std::io::stdout().flush();
    eprintln!("{}; Ctrl-C stops", site.summary());
    serve(Arc::new(site), server.0, Guard::new(server.1, host), None);
    Ok(super::OK)
}

/// Serves a run's page live (`situ run … --serve [ADDR]`) from a thread of
/// its own: the page's URL, and the log the run's
/// [`situ_runtime::record::live::PageTap`] fills.
/// `addr` is `PORT` or `HOST:PORT` (default host 127.0.0.1). The error
/// is said (by [`super::exit_code`]) and its exit code returned, as the
/// run's commands expect.
pub fn serve_live(site: data::Site, addr: &str) -> Result<(String, Arc<Live>), u8> {
    start_live(site, addr).map_err(|e| super::exit_code(Err(e)))
}

fn start_live(site: data::Site, addr: &str) -> Result<(String, Arc<Live>), CliError> {
    let Some((host, port)) = super::host_port(addr) else {
        return Err(CliError::Usage(format!(
            "--serve `{addr}` is not a port or an address (PORT or HOST:PORT, say 127.0.0.1:8080)"
        )));
    };
    let (server, bound) = listen(host, port, "--serve")?;
    let live = Arc::new(Live::default());
    let site = Arc::new(site);
    let l = live.clone();
    let guard = Guard::new(bound, host);
    let thread = std::thread::Builder::new().name("situ-view".into());
    thread
        .spawn(move || serve(site, server, guard, Some(l)))
        .map_err(|e| CliError::Usage(format!("cannot start the page's server: {e}")))?;
    Ok((format!("http://{bound}/"), live))
}

/// A server listening on `host:port`; the error names the port and the
/// option that chose it.
fn listen(host: &str, port: u16, option: &str) -> Result<(tiny_http::Server, std::net::SocketAddr), CliError> {
    let listener = TcpListener::bind((host, port)).map_err(|e| {
        CliError::Usage(if e.kind() == std::io::ErrorKind::AddrInUse {
            format!(
                "port {port} on {host} is in use: choose another with {option}, or leave the port out for a free one"
            )
        } else {
            format!("cannot listen on {host}:{port}: {e}")
        })
    })?;
    let addr = listener.local_addr().map_err(|e| CliError::Usage(format!("cannot tell the port listened on: {e}")))?;
    let server = tiny_http::Server::from_listener(listener, None)
        .map_err(|e| CliError::Usage(format!("cannot serve on {addr}: {e}")))?;
    Ok((server, addr))
}

fn respond(request: tiny_http::Request, status: u16, kind: &str, body: String) {
    let header = tiny_http::Header::from_bytes(&b"Content-Type"[..], kind.as_bytes()).expect("a valid header");
    let nocache = tiny_http::Header::from_bytes(&b"Cache-Control"[..], &b"no-store"[..]).expect("a valid header");
    let response = tiny_http::Response::from_data(body.into_bytes())
        .with_status_code(status)
        .with_header(header)
        .with_header(nocache);
    // A browser that went away is not an error of the server.
    let _ = request.respond(response);
}

/// A request's header, if it has it (the first of that name).
fn header<'r>(request: &'r tiny_http::Request, name: &'static str) -> Option<&'r str> {
    request.headers().iter().find(|h| h.field.equiv(name)).map(|h| h.value.as_str())
}

/// Answers requests until the process ends (those `guard` lets through);
/// a live page's polls wait in threads of their own.
fn serve(site: Arc<data::Site>, server: tiny_http::Server, guard: Guard, live: Option<Arc<Live>>) {
    let waiting = Arc::new(std::sync::atomic::AtomicUsize::new(0));
    for request in server.incoming_requests() {
        if let Err(reason) = guard.check(header(&request, "Host"), header(&request, "Origin")) {
            respond(request, 403, "text/plain; charset=utf-8", reason);
            continue;
        }
        let url = request.url().to_string();
        let (path, query) = url.split_once('?').unwrap_or((&url, ""));
        match (&live, path) {
            (Some(live), "/api/live") => {
                use std::sync::atomic::Ordering::SeqCst;
                if waiting.fetch_add(1, SeqCst) >= MAX_WAITING {
                    waiting.fetch_sub(1, SeqCst);
                    respond(request, 503, "text/plain; charset=utf-8", "too many pages waiting".into());
                    continue;
                }
                let since = query.split('&').find_map(|kv| kv.strip_prefix("since=")).and_then(|v| v.parse().ok());
                let (live, count) = (live.clone(), waiting.clone());
                let spawned = std::thread::Builder::new().name("situ-view-poll".into()).spawn(move || {
                    let (body, over) = live.poll(since.unwrap_or(0));
                    respond(request, 200, "application/json; charset=utf-8", body);
                    live.delivered(over);
                    count.fetch_sub(1, SeqCst);
                });
                if spawned.is_err() {
                    waiting.fetch_sub(1, SeqCst);
                }
            }
            _ => {
                let (status, kind, body) = answer(&site, &url);
                respond(request, status, kind, body);
            }
        }
    }
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
