//! The Recorder agent of the paper, as an MCAP file that Foxglove and the
//! `mcap` Python package read: JSON messages with JSON-schema schemas, zstd
//! chunks, one channel per stream.
//!
//! | topic | schema | what |
//! |---|---|---|
//! | `/state` | `situ.State` | every change of the state at rest: `state` (Foxglove's State Transitions panel draws it), `from`, the rules that fired and why |
//! | `/events` | `foxglove.Log` | every event as a log line (refused ones as warnings) |
//! | `/diagnostics` | `foxglove.Log` | refusals, losses, cascade errors |
//! | `/situ/events` | `situ.Event` | every event, structured (what `situ replay` reads) |
//! | `/situ/ticks` | `situ.Tick` | heartbeats that fired rules (for replays) |
//! | `/situ/data` | `situ.Data` | every data message's metadata: from, to, size, fate |
//! | `/situ/modes` | `situ.Mode` | every change of an agent's mode or function |
//!
//! More channels can be added ([`McapRecorder::add_channel`]): `situ run`
//! adds the vehicle's pose (`/pose`, `foxglove.PoseInFrame`) and the
//! obstacles (`/obstacles`, `foxglove.SceneUpdate`).
//!
//! Every channel and message can go elsewhere too, as it is written: a
//! [`Tap`] (`situ run --foxglove` serves them live over Foxglove's WebSocket
//! protocol), with or without a file ([`McapRecorder::live`]).
//!
//! The bundle that ran is attached (`bundle.json`), so that a replay needs
//! nothing else. Chunks are closed and the file flushed at least once a
//! second (of wall time, or of the messages' time for simulated runs) while
//! records come. Each chunk is written whole, and every flush leaves a
//! valid MCAP file (the records so far and a provisional end, see
//! [`staged`]), so a process killed mid-run loses at most its last second
//! of records and every reader (`situ replay`, Python's `mcap` with
//! `make_reader`, Foxglove) reads everything before the cut. Reading back
//! is bounded ([`read`]): a damaged file is an error, never an abort.

use super::{DataRecord, EventRecord, Level, ModeRecord, Sink, Verdict};
use crate::rete::{describe_fact, format_time, MatchedFact, StateChange};
use mcap::records::MessageHeader;
use serde_json::{json, Value as Json};
use situ_bundle::{Content, FieldType, Value};
use staged::Staged;
use std::collections::BTreeMap;
use std::fs::File;
use std::io;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

pub mod read;
pub mod staged;

pub use read::{attached_bundle, read_file, read_messages, read_recording, read_topics, FileError, ReadError, Reading};

/// Topic names, for readers.
pub mod topics {
    pub const STATE: &str = "/state";
    pub const EVENTS_LOG: &str = "/events";
    pub const DIAGNOSTICS: &str = "/diagnostics";
    pub const EVENTS: &str = "/situ/events";
    pub const TICKS: &str = "/situ/ticks";
    pub const DATA: &str = "/situ/data";
    pub const MODES: &str = "/situ/modes";
}

/// How often chunks are closed and the file flushed, at most.
pub const FLUSH_EVERY: Duration = Duration::from_secs(1);

/// Message bytes after which a flush comes whatever the time (what a
/// recording keeps in memory between flushes stays bounded).
pub const FLUSH_AFTER_BYTES: usize = 16 << 20;

/// The JSON schema of `foxglove.Log`: Foxglove's own, as published
/// (schemas/jsonschema/Log.json of github.com/foxglove/foxglove-sdk, MIT).
const LOG_SCHEMA: &str = include_str!("mcap/schemas/Log.json");

/// Another destination of a recording's channels and messages, told of each
/// as it is written (the same schemas, the same JSON bytes, the same times).
pub trait Tap: Send {
    /// A channel: its id (as in the file), topic, schema name and JSON schema.
    fn channel(&mut self, id: u16, topic: &str, schema_name: &str, schema: &str);
    /// A message on channel `id`, at `time` (ns), its JSON bytes.
    fn message(&mut self, id: u16, time: u64, bytes: &[u8]);
}

/// A channel of the recording: id, topic, schema name, JSON schema.
type ChannelInfo = (u16, String, String, String);

fn schema(title: &str, properties: Json) -> String {
    json!({ "title": title, "type": "object", "properties": properties }).to_string()
}

struct Channels {
    state: u16,
    events_log: u16,
    diagnostics: u16,
    events: u16,
    ticks: u16,
    data: u16,
    modes: u16,
}

/// Counts of messages written per topic.
pub type Counts = BTreeMap<String, u64>;

pub struct McapRecorder {
    writer: Option<mcap::Writer<Staged>>,
    /// Set before the summary is written (see [`staged`]).
    finishing: Arc<AtomicBool>,
    /// Message bytes written since the last flush.
    since_flush: usize,
    content: Arc<Content>,
    channels: Channels,
    counts: Counts,
    /// Channels added with [`McapRecorder::add_channel`]: id → topic.
    extra: BTreeMap<u16, String>,
    /// Every channel so far (for taps added later).
    all: Vec<ChannelInfo>,
    taps: Vec<Box<dyn Tap>>,
    finished: bool,
    last_flush: Instant,
    /// Flush by the messages' own time instead of the wall clock: the time
    /// of the last flush (simulated runs whose files must be the same bytes
    /// every time).
    by_message_time: Option<u64>,
    error: Option<io::Error>,
}

/// The recording's own channels, made with `channel` (topic, schema name,
/// JSON schema → id).
fn standard_channels(channel: &mut dyn FnMut(&str, &str, &str) -> io::Result<u16>) -> io::Result<Channels> {
    let time = json!({ "type": "integer", "description": "nanoseconds" });
    Ok(Channels {
        state: channel(
            topics::STATE,
            "situ.State",
            &schema(
                "situ.State",
                json!({ "state": {"type": "string"}, "from": {"type": "string"}, "time_ns": time,
                            "rules": {"type": "array", "items": {"type": "string"}}, "explain": {"type": "string"} }),
            ),
        )?,
        events_log: channel(topics::EVENTS_LOG, "foxglove.Log", LOG_SCHEMA)?,
        diagnostics: channel(topics::DIAGNOSTICS, "foxglove.Log", LOG_SCHEMA)?,
        events: channel(
            topics::EVENTS,
            "situ.Event",
            &schema(
                "situ.Event",
                json!({ "time_ns": time, "agent": {"type": "string"}, "event": {"type": "string"},
                            "payload": {"type": "object"}, "urgent": {"type": "boolean"},
                            "accepted": {"type": "boolean"}, "reason": {"type": "string"} }),
            ),
        )?,
        ticks: channel(topics::TICKS, "situ.Tick", &schema("situ.Tick", json!({ "time_ns": time })))?,
        data: channel(
            topics::DATA,
            "situ.Data",
            &schema(
                "situ.Data",
                json!({ "time_ns": time, "from": {"type": "string"}, "to": {"type": "string"},
                            "urgent": {"type": "boolean"}, "size": {"type": "integer"},
                            "fate": {"type": "string", "enum": ["delivered", "suppressed", "to_sleeping", "unrouted"]} }),
            ),
        )?,
        modes: channel(
            topics::MODES,
            "situ.Mode",
            &schema(
                "situ.Mode",
                json!({ "time_ns": time, "agent": {"type": "string"}, "state": {"type": "string"},
                            "mode": {"type": "string", "enum": ["running", "waiting", "sleeping"]},
                            "function": {"type": "string"} }),
            ),
        )?,
    })
}

fn mcap_err(e: mcap::McapError) -> io::Error {
    io::Error::other(e.to_string())
}

impl McapRecorder {
    /// Starts a recording at `path` for the bundle `content` (its file bytes
    /// in `bundle`, attached for replays).
    pub fn create(path: &Path, content: Arc<Content>, bundle: &[u8]) -> io::Result<McapRecorder> {
        let (file, finishing) = Staged::new(File::create(path)?);
        // Seeking disabled: each chunk is buffered and written whole, so no
        // chunk with a placeholder length is ever on disk.
        let mut w = mcap::WriteOptions::new()
            .compression(Some(mcap::Compression::Zstd))
            .profile("")
            .library(format!("situ {}", env!("CARGO_PKG_VERSION")))
            .disable_seeking(true)
            .create(file)
            .map_err(mcap_err)?;
        let mut all = Vec::new();
        let mut channel = |topic: &str, name: &str, schema_text: &str| -> io::Result<u16> {
            let schema = w.add_schema(name, "jsonschema", schema_text.as_bytes()).map_err(mcap_err)?;
            let id = w.add_channel(schema, topic, "json", &BTreeMap::new()).map_err(mcap_err)?;
            all.push((id, topic.to_string(), name.to_string(), schema_text.to_string()));
            Ok(id)
        };
        let channels = standard_channels(&mut channel)?;
        w.attach(&mcap::Attachment {
            log_time: 0,
            create_time: 0,
            name: "bundle.json".into(),
            media_type: "application/json".into(),
            data: std::borrow::Cow::Borrowed(bundle),
        })
        .map_err(mcap_err)?;
        // A valid file from the start: the header and the bundle.
        w.flush().map_err(mcap_err)?;
        Ok(McapRecorder::with(Some(w), finishing, content, channels, all))
    }

    /// A recording with no file: the same channels and messages, for the
    /// taps only ([`McapRecorder::tap`]).
    pub fn live(content: Arc<Content>) -> McapRecorder {
        let mut all = Vec::new();
        let mut channel = |topic: &str, name: &str, schema_text: &str| -> io::Result<u16> {
            let id = all.len() as u16 + 1;
            all.push((id, topic.to_string(), name.to_string(), schema_text.to_string()));
            Ok(id)
        };
        let channels = standard_channels(&mut channel).expect("no file, no error");
        McapRecorder::with(None, Arc::new(AtomicBool::new(false)), content, channels, all)
    }

    /// A recorder with nothing written yet but its channels.
    fn with(
        writer: Option<mcap::Writer<Staged>>,
        finishing: Arc<AtomicBool>,
        content: Arc<Content>,
        channels: Channels,
        all: Vec<ChannelInfo>,
    ) -> McapRecorder {
        McapRecorder {
            writer,
            finishing,
            since_flush: 0,
            content,
            channels,
            counts: Counts::new(),
            extra: BTreeMap::new(),
            all,
            taps: Vec::new(),
            finished: false,
            last_flush: Instant::now(),
            by_message_time: None,
            error: None,
        }
    }

    /// Sends every channel and message to `tap` too: the channels so far at
    /// once, the rest as they come.
    pub fn tap(&mut self, mut tap: Box<dyn Tap>) {
        for (id, topic, name, schema) in &self.all {
            tap.channel(*id, topic, name, schema);
        }
        self.taps.push(tap);
    }

    /// Closes chunks every second of the messages' time rather than of the
    /// wall clock, so that one simulated run always writes the same bytes.
    pub fn flush_by_message_time(mut self) -> McapRecorder {
        self.by_message_time = Some(0);
        self
    }

    /// Messages written per topic so far.
    pub fn counts(&self) -> &Counts {
        &self.counts
    }

    /// Adds a channel of JSON messages with a JSON-schema schema (a
    /// Foxglove schema name such as `foxglove.PoseInFrame` makes Foxglove's
    /// panels show it); returns its id for [`write_message`](Self::write_message).
    pub fn add_channel(&mut self, topic: &str, schema_name: &str, schema_text: &str) -> io::Result<u16> {
        if self.finished {
            return Err(io::Error::other("the recording is finished"));
        }
        let id = match self.writer.as_mut() {
            Some(w) => {
                let schema = w.add_schema(schema_name, "jsonschema", schema_text.as_bytes()).map_err(mcap_err)?;
                w.add_channel(schema, topic, "json", &BTreeMap::new()).map_err(mcap_err)?
            }
            None => self.all.len() as u16 + 1,
        };
        self.extra.insert(id, topic.to_string());
        self.all.push((id, topic.to_string(), schema_name.to_string(), schema_text.to_string()));
        for tap in &mut self.taps {
            tap.channel(id, topic, schema_name, schema_text);
        }
        Ok(id)
    }

    /// Writes a message on a channel made by [`add_channel`](Self::add_channel),
    /// at `time` (ns); flushed with the rest, at least once a second.
    pub fn write_message(&mut self, channel: u16, time: u64, message: &Json) {
        let Some(topic) = self.extra.get(&channel).cloned() else {
            self.error.get_or_insert(io::Error::other(format!("no channel {channel} was added")));
            return;
        };
        self.write(channel, &topic, time, message);
    }

    fn write(&mut self, channel: u16, topic: &str, time: u64, message: &Json) {
        if self.finished {
            return;
        }
        let bytes = serde_json::to_vec(message).expect("JSON serializes");
        for tap in &mut self.taps {
            tap.message(channel, time, &bytes);
        }
        if let Some(w) = self.writer.as_mut() {
            let header = MessageHeader { channel_id: channel, sequence: 0, log_time: time, publish_time: time };
            if let Err(e) = w.write_to_known_channel(&header, &bytes) {
                self.error.get_or_insert(mcap_err(e));
                return;
            }
        }
        match self.counts.get_mut(topic) {
            Some(n) => *n += 1,
            None => {
                self.counts.insert(topic.to_string(), 1);
            }
        }
        self.since_flush = self.since_flush.saturating_add(bytes.len());
        if self.since_flush >= FLUSH_AFTER_BYTES {
            let _ = self.flush();
        }
        match self.by_message_time {
            Some(last) => {
                if time.saturating_sub(last) >= FLUSH_EVERY.as_nanos() as u64 {
                    let _ = self.flush();
                    self.by_message_time = Some(time);
                }
            }
            None => {
                if self.last_flush.elapsed() >= FLUSH_EVERY {
                    let _ = self.flush();
                }
            }
        }
    }

    fn agent(&self, a: u32) -> String {
        self.content.agents.get(a as usize).map_or_else(|| format!("#{a}"), |x| x.name.clone())
    }

    fn log(&mut self, channel: u16, topic: &'static str, time: u64, level: u8, name: &str, message: &str) {
        let msg = json!({
            "timestamp": { "sec": time / 1_000_000_000, "nsec": time % 1_000_000_000 },
            "level": level, "message": message, "name": name, "file": "", "line": 0,
        });
        self.write(channel, topic, time, &msg);
    }
}

/// A payload as a JSON object of field names.
fn payload_json(c: &Content, event: u32, payload: &[Value]) -> Json {
    let Some(e) = c.events.get(event as usize) else {
        return Json::Array(payload.iter().map(value_json).collect());
    };
    let mut map = serde_json::Map::new();
    for (f, v) in e.fields.iter().zip(payload) {
        let j = match (&f.ty, v) {
            (FieldType::Symbols(s), Value::Symbol(i)) => json!(s.get(*i as usize).cloned().unwrap_or_default()),
            _ => value_json(v),
        };
        map.insert(f.name.clone(), j);
    }
    Json::Object(map)
}

fn value_json(v: &Value) -> Json {
    match v {
        Value::F64(f) if f.is_finite() => json!(f),
        Value::F64(f) => json!(f.to_string()),
        Value::I64(i) => json!(i),
        Value::Bool(b) => json!(b),
        Value::Symbol(i) => json!(i),
    }
}

impl Sink for McapRecorder {
    fn event(&mut self, rec: &EventRecord) {
        let c = self.content.clone();
        let name = c.events.get(rec.event as usize).map_or_else(|| format!("#{}", rec.event), |e| e.name.clone());
        let (accepted, reason) = match &rec.verdict {
            Verdict::Accepted => (true, None),
            Verdict::Refused(r) => (false, Some(r.clone())),
        };
        let mut msg = json!({
            "time_ns": rec.time, "agent": self.agent(rec.agent), "event": name,
            "payload": payload_json(&c, rec.event, &rec.payload), "urgent": rec.urgent, "accepted": accepted,
        });
        if let Some(r) = &reason {
            msg["reason"] = json!(r);
        }
        self.write(self.channels.events, topics::EVENTS, rec.time, &msg);
        let text = if (rec.event as usize) < c.events.len() && accepted {
            let m = MatchedFact {
                agent: rec.agent,
                event: rec.event,
                payload: rec.payload.clone(),
                time: rec.time,
                run: 1,
            };
            describe_fact(&c, &m)
        } else {
            format!("{name} refused: {}", reason.unwrap_or_default())
        };
        let agent = self.agent(rec.agent);
        self.log(self.channels.events_log, topics::EVENTS_LOG, rec.time, if accepted { 2 } else { 3 }, &agent, &text);
    }

    fn change(&mut self, change: &StateChange) {
        let c = self.content.clone();
        let rules: Vec<&str> = change.firings.iter().map(|f| c.rules[f.rule as usize].name.as_str()).collect();
        let msg = json!({
            "state": c.states[change.to as usize].name, "from": c.states[change.from as usize].name,
            "time_ns": change.time, "rules": rules, "explain": change.explain(&c),
        });
        self.write(self.channels.state, topics::STATE, change.time, &msg);
    }

    fn data(&mut self, rec: &DataRecord) {
        let to = if rec.to == u32::MAX { String::new() } else { self.agent(rec.to) };
        let msg = json!({
            "time_ns": rec.time, "from": self.agent(rec.from), "to": to,
            "urgent": rec.urgent, "size": rec.size, "fate": rec.fate,
        });
        self.write(self.channels.data, topics::DATA, rec.time, &msg);
    }

    fn mode(&mut self, rec: &ModeRecord) {
        let msg = json!({
            "time_ns": rec.time, "agent": self.agent(rec.agent),
            "state": self.content.states[rec.state as usize].name,
            "mode": rec.mode.adjective(), "function": rec.function.clone().unwrap_or_default(),
        });
        self.write(self.channels.modes, topics::MODES, rec.time, &msg);
    }

    fn diagnostic(&mut self, time: u64, level: Level, text: &str) {
        let level = match level {
            Level::Info => 2,
            Level::Warning => 3,
            Level::Error => 4,
        };
        let text = format!("{} {text}", format_time(time));
        self.log(self.channels.diagnostics, topics::DIAGNOSTICS, time, level, "Bulletinboard", &text);
    }

    fn tick(&mut self, time: u64) {
        self.write(self.channels.ticks, topics::TICKS, time, &json!({ "time_ns": time }));
    }

    fn flush(&mut self) -> io::Result<()> {
        self.last_flush = Instant::now();
        self.since_flush = 0;
        if let Some(w) = self.writer.as_mut() {
            w.flush().map_err(mcap_err)?;
        }
        match self.error.take() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    fn finish(&mut self) -> io::Result<()> {
        self.finished = true;
        if let Some(mut w) = self.writer.take() {
            // The summary, the footer and the magic, written over the last
            // provisional end (the writer flushes once they are written).
            self.finishing.store(true, Ordering::SeqCst);
            w.finish().map_err(mcap_err)?;
        }
        match self.error.take() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }
}

impl Drop for McapRecorder {
    fn drop(&mut self) {
        // Never leave a file without its summary when we can help it.
        let _ = self.finish();
    }
}

/// A recorded message: its topic, its log time (ns) and its JSON.
pub type Recorded = (String, u64, Json);
