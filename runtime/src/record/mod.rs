//! What a run leaves behind: every event (accepted or refused), every change
//! of the state with the rules that fired, every data message's metadata and
//! every agent's mode changes. A [`Sink`] receives them as they happen;
//! [`mcap::McapRecorder`] writes them to an MCAP file (the Recorder agent of
//! the paper), [`Memory`] keeps them for tests.
//!
//! Read back: [`mcap::read`] decodes a recording, bounded; [`timeline`]
//! turns its messages into what the Supervisor's page draws, and [`live`]
//! keeps a live run's for its page.

pub mod live;
pub mod mcap;
pub mod timeline;

use crate::rete::StateChange;
use situ_bundle::{Mode, Value};

/// What became of an event.
#[derive(Debug, Clone, PartialEq)]
pub enum Verdict {
    Accepted,
    /// Refused, and why (in words); the run goes on.
    Refused(String),
}

/// An event as the Bulletinboard received it.
#[derive(Debug, Clone, PartialEq)]
pub struct EventRecord {
    pub time: u64,
    pub agent: u32,
    /// `u32::MAX` when the event id was not one of the bundle's.
    pub event: u32,
    pub payload: Vec<Value>,
    pub urgent: bool,
    pub verdict: Verdict,
}

/// What became of a datum.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Fate {
    Delivered,
    /// The sender was waiting: its data outputs are suppressed.
    Suppressed,
    /// The receiver sleeps: the datum is dropped.
    ToSleeping,
    /// No active link to the receiver named.
    Unrouted,
}

#[derive(Debug, Clone, PartialEq)]
pub struct DataRecord {
    pub time: u64,
    pub from: u32,
    /// `u32::MAX` when no receiver was reached.
    pub to: u32,
    pub urgent: bool,
    pub size: usize,
    pub fate: Fate,
}

#[derive(Debug, Clone, PartialEq)]
pub struct ModeRecord {
    pub time: u64,
    pub agent: u32,
    pub state: u32,
    pub mode: Mode,
    pub function: Option<String>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Level {
    Info,
    Warning,
    Error,
}

/// The receiver of a run's records.
pub trait Sink: Send {
    fn event(&mut self, rec: &EventRecord);
    /// A change of the state at rest (or firings that came back to it).
    fn change(&mut self, change: &StateChange);
    fn data(&mut self, rec: &DataRecord);
    fn mode(&mut self, rec: &ModeRecord);
    fn diagnostic(&mut self, time: u64, level: Level, text: &str);
    /// The Bulletinboard's clock moved without an event and rules fired
    /// (kept so that a replay fires them at the same time).
    fn tick(&mut self, time: u64);
    /// Makes everything so far durable.
    fn flush(&mut self) -> std::io::Result<()>;
    /// Ends the recording.
    fn finish(&mut self) -> std::io::Result<()>;
}

/// A sink that keeps everything in memory (tests, summaries).
#[derive(Debug, Default, Clone)]
pub struct Memory {
    pub events: Vec<EventRecord>,
    pub changes: Vec<StateChange>,
    pub data: Vec<DataRecord>,
    pub modes: Vec<ModeRecord>,
    pub diagnostics: Vec<(u64, String)>,
    pub ticks: Vec<u64>,
}

impl Sink for Memory {
    fn event(&mut self, rec: &EventRecord) {
        self.events.push(rec.clone());
    }
    fn change(&mut self, change: &StateChange) {
        self.changes.push(change.clone());
    }
    fn data(&mut self, rec: &DataRecord) {
        self.data.push(rec.clone());
    }
    fn mode(&mut self, rec: &ModeRecord) {
        self.modes.push(rec.clone());
    }
    fn diagnostic(&mut self, time: u64, _level: Level, text: &str) {
        self.diagnostics.push((time, text.to_string()));
    }
    fn tick(&mut self, time: u64) {
        self.ticks.push(time);
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
    fn finish(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// A [`Memory`] shared with whoever wants to look at it during a run.
#[derive(Clone, Default)]
pub struct SharedMemory(pub std::sync::Arc<std::sync::Mutex<Memory>>);

impl SharedMemory {
    pub fn snapshot(&self) -> Memory {
        self.0.lock().unwrap_or_else(|p| p.into_inner()).clone()
    }
}

macro_rules! forward {
    ($($name:ident($($arg:ident: $ty:ty),*) $(-> $ret:ty)?;)*) => {
        impl Sink for SharedMemory {
            $(fn $name(&mut self, $($arg: $ty),*) $(-> $ret)? {
                self.0.lock().unwrap_or_else(|p| p.into_inner()).$name($($arg),*)
            })*
        }
    };
}

forward! {
    event(rec: &EventRecord);
    change(change: &StateChange);
    data(rec: &DataRecord);
    mode(rec: &ModeRecord);
    diagnostic(time: u64, level: Level, text: &str);
    tick(time: u64);
    flush() -> std::io::Result<()>;
    finish() -> std::io::Result<()>;
}

/// Several sinks fed the same records (a recording and a summary, say).
pub struct Tee(pub Vec<Box<dyn Sink>>);

impl Sink for Tee {
    fn event(&mut self, rec: &EventRecord) {
        self.0.iter_mut().for_each(|s| s.event(rec));
    }
    fn change(&mut self, change: &StateChange) {
        self.0.iter_mut().for_each(|s| s.change(change));
    }
    fn data(&mut self, rec: &DataRecord) {
        self.0.iter_mut().for_each(|s| s.data(rec));
    }
    fn mode(&mut self, rec: &ModeRecord) {
        self.0.iter_mut().for_each(|s| s.mode(rec));
    }
    fn diagnostic(&mut self, time: u64, level: Level, text: &str) {
        self.0.iter_mut().for_each(|s| s.diagnostic(time, level, text));
    }
    fn tick(&mut self, time: u64) {
        self.0.iter_mut().for_each(|s| s.tick(time));
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.0.iter_mut().try_for_each(|s| s.flush())
    }
    fn finish(&mut self) -> std::io::Result<()> {
        self.0.iter_mut().try_for_each(|s| s.finish())
    }
}

/// Any sink shared with whoever else writes to it or reads it during a run
/// (a recording that the simulation adds its own channels to, say).
impl<S: Sink> Sink for std::sync::Arc<std::sync::Mutex<S>> {
    fn event(&mut self, rec: &EventRecord) {
        self.lock().unwrap_or_else(|p| p.into_inner()).event(rec)
    }
    fn change(&mut self, change: &StateChange) {
        self.lock().unwrap_or_else(|p| p.into_inner()).change(change)
    }
    fn data(&mut self, rec: &DataRecord) {
        self.lock().unwrap_or_else(|p| p.into_inner()).data(rec)
    }
    fn mode(&mut self, rec: &ModeRecord) {
        self.lock().unwrap_or_else(|p| p.into_inner()).mode(rec)
    }
    fn diagnostic(&mut self, time: u64, level: Level, text: &str) {
        self.lock().unwrap_or_else(|p| p.into_inner()).diagnostic(time, level, text)
    }
    fn tick(&mut self, time: u64) {
        self.lock().unwrap_or_else(|p| p.into_inner()).tick(time)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.lock().unwrap_or_else(|p| p.into_inner()).flush()
    }
    fn finish(&mut self) -> std::io::Result<()> {
        self.lock().unwrap_or_else(|p| p.into_inner()).finish()
    }
}
