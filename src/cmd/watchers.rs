//! Who watches a run as it goes: Foxglove over its WebSocket protocol
//! (`--foxglove [ADDR]`) and the Supervisor's page (`--serve [ADDR]`, the
//! page of `situ view` fed live). Both are taps of the run's one
//! [`McapRecorder`]: the channels, schemas and messages of the recording,
//! as they are written, with or without a file.

use super::view::{self, data::Site};
use situ_runtime::record::live::{Live, PageTap};
use situ_runtime::record::mcap::{McapRecorder, Tap};
use std::io::Write as _;
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// The run's watchers: none, Foxglove, the page, or both.
#[derive(Default)]
pub struct Watchers {
    foxglove: Option<LiveServer>,
    page: Option<(String, Arc<Live>)>,
}

impl Watchers {
    /// Starts the servers asked for; `site` makes the page's rules (only
    /// called for `--serve`). The error is said (by [`super::exit_code`]);
    /// its exit code returned, as the run's commands expect.
    pub fn start(foxglove: Option<&str>, serve: Option<&str>, site: impl FnOnce() -> Site) -> Result<Watchers, u8> {
        let foxglove = foxglove
            .map(LiveServer::start)
            .transpose()
            .map_err(|e| super::exit_code(Err(super::CliError::Usage(format!("--foxglove: {e}")))))?;
        let page = serve.map(|addr| view::serve_live(site(), addr)).transpose()?;
        if let Some((url, _)) = &page {
            // The first line on standard output, as `situ view` prints it.
            println!("serving {url}");
            let _ = std::io::stdout().flush();
        }
        Ok(Watchers { foxglove, page })
    }

    /// Whether anyone may watch.
    pub fn any(&self) -> bool {
        self.foxglove.is_some() || self.page.is_some()
    }

    /// Sends the recorder's channels and messages to every watcher.
    pub fn attach(&self, recorder: &mut McapRecorder) {
        if let Some(f) = &self.foxglove {
            recorder.tap(Box::new(f.tap()));
        }
        if let Some((_, live)) = &self.page {
            recorder.tap(Box::new(PageTap::new(live.clone())));
        }
    }

    /// The recorder of a run: `file` (a recording being written) or one
    /// with no file, with every watcher attached; `None` when there is
    /// neither a file nor a watcher.
    pub fn recorder(
        &self,
        file: Option<McapRecorder>,
        content: &Arc<situ_compiler::bundle::Content>,
    ) -> Option<McapRecorder> {
        let mut recorder = match file {
            Some(r) => r,
            None if self.any() => McapRecorder::live(content.clone()),
            None => return None,
        };
        self.attach(&mut recorder);
        Some(recorder)
    }

    /// Waits for every watcher: a Foxglove client's first subscription, a
    /// page opened; so that a run in simulated time is watched from its
    /// start.
    pub fn wait(&self) {
        if let Some(f) = &self.foxglove {
            f.wait_for_a_client();
        }
        if let Some((url, live)) = &self.page {
            eprintln!("view: open {url} in a browser; the run starts when the page is open");
            live.wait_for_a_page(None);
            eprintln!("view: a page is open; running in real time");
        }
    }

    /// The run is over: the pages are told (a moment to hear it), the
    /// Foxglove server stops.
    pub fn end(self) {
        if let Some((_, live)) = &self.page {
            live.finish();
            live.wait_for_the_pages(Duration::from_secs(2));
            eprintln!("view: the run is over; the page keeps what it was sent");
        }
        if let Some(f) = self.foxglove {
            f.stop();
        }
    }
}

/// `--foxglove`: a Foxglove WebSocket server of its own (its own context,
/// so only this run's channels are on it).
struct LiveServer {
    context: Arc<foxglove::Context>,
    handle: foxglove::WebSocketServerHandle,
    addr: String,
    subscribed: Arc<(Mutex<bool>, std::sync::Condvar)>,
}

/// Tells the run that a client subscribed.
struct Subscriptions(Arc<(Mutex<bool>, std::sync::Condvar)>);

impl foxglove::websocket::ServerListener for Subscriptions {
    fn on_subscribe(&self, _client: foxglove::websocket::Client, _channel: foxglove::websocket::ChannelView) {
        let (lock, cvar) = &*self.0;
        *lock.lock().unwrap_or_else(|e| e.into_inner()) = true;
        cvar.notify_all();
    }
}

impl LiveServer {
    /// Listens on `addr` (HOST:PORT, or PORT on 127.0.0.1); the error
    /// names the address.
    fn start(addr: &str) -> Result<LiveServer, String> {
        let (host, port) = super::host_port(addr)
            .ok_or_else(|| format!("`{addr}` is not an address (HOST:PORT, say 127.0.0.1:8765)"))?;
        // The port must be free: the error names it (the server's own error
        // does not always).
        if let Err(e) = std::net::TcpListener::bind((host, port)) {
            return Err(if e.kind() == std::io::ErrorKind::AddrInUse {
                format!("cannot listen on {addr}: the port {port} is in use")
            } else {
                format!("cannot listen on {addr}: {e}")
            });
        }
        let context = foxglove::Context::new();
        let subscribed = Arc::new((Mutex::new(false), std::sync::Condvar::new()));
        let handle = foxglove::WebSocketServer::new()
            .name(format!("situ {}", env!("CARGO_PKG_VERSION")))
            .bind(host, port)
            .context(&context)
            .listener(Arc::new(Subscriptions(subscribed.clone())))
            .start_blocking()
            .map_err(|e| format!("cannot listen on {addr}: {e}"))?;
        let addr = format!("{host}:{}", handle.port());
        Ok(LiveServer { context, handle, addr, subscribed })
    }

    fn tap(&self) -> FoxgloveTap {
        FoxgloveTap { context: self.context.clone(), channels: std::collections::HashMap::new() }
    }

    /// Waits for a client's first subscription (and a moment for its
    /// others), so that the run is watched from its start.
    fn wait_for_a_client(&self) {
        eprintln!(
            "foxglove: serving ws://{} (Foxglove: Open connection, Foxglove WebSocket); waiting for a client",
            self.addr
        );
        let (lock, cvar) = &*self.subscribed;
        let mut done = lock.lock().unwrap_or_else(|e| e.into_inner());
        while !*done {
            done = cvar.wait(done).unwrap_or_else(|e| e.into_inner());
        }
        drop(done);
        std::thread::sleep(std::time::Duration::from_millis(500));
        eprintln!("foxglove: a client subscribed; running in real time");
    }

    fn stop(self) {
        // A moment for the last messages to leave.
        std::thread::sleep(std::time::Duration::from_millis(500));
        self.handle.stop().wait_blocking();
        eprintln!("foxglove: the run is over; server stopped");
    }
}

/// The recorder's [`Tap`] to the server: a raw JSON channel per channel.
struct FoxgloveTap {
    context: Arc<foxglove::Context>,
    channels: std::collections::HashMap<u16, Arc<foxglove::RawChannel>>,
}

impl Tap for FoxgloveTap {
    fn channel(&mut self, id: u16, topic: &str, schema_name: &str, schema: &str) {
        let built = foxglove::ChannelBuilder::new(topic)
            .message_encoding("json")
            .schema(foxglove::Schema::new(schema_name, "jsonschema", schema.as_bytes().to_vec()))
            .context(&self.context)
            .build_raw();
        match built {
            Ok(c) => {
                self.channels.insert(id, c);
            }
            Err(e) => eprintln!("foxglove: channel {topic}: {e}"),
        }
    }

    fn message(&mut self, id: u16, time: u64, bytes: &[u8]) {
        if let Some(c) = self.channels.get(&id) {
            c.log_with_meta(bytes, foxglove::PartialMetadata { log_time: Some(time) });
        }
    }
}
