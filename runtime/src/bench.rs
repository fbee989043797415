//! `situ bench`: the Bulletinboard's throughput and latency on a seeded
//! random event stream (or a stream file), as `bench/README.md` specifies.
//!
//! Two passes over the same stream:
//! 1. **throughput**: events are generated in chunks of [`CHUNK`] into a
//!    reused buffer, and only the posting of each chunk is timed;
//! 2. **latency**: every post is timed alone (`Instant` around it) into a
//!    fixed histogram; the clock's own cost is measured and reported beside.
//!
//! Missions end in final states: the engine is then reset before the next
//! event ([`Engine::reset_if_final`], §10.12 of the language reference;
//! `--no-reset` turns this off). Every event goes through the engine's
//! acceptance rule ([`Engine::admit`]), at the clock its line gives
//! (`@CLOCK`) if any: a refused one (a payload that does not fit its
//! event, out of order, from the future, an unknown event) changes
//! nothing, is counted by reason, and the run goes on, as a running
//! stack's does. Nothing grows with the stream: the
//! buffer, the histogram and the engine are of fixed size, so the peak
//! resident memory of 10,000,000 events is that of 1,000.

use crate::rete::{Engine, StepError};
use crate::stream::{self, Event, Generator};
use serde::Serialize;
use situ_bundle::{Content, Value};
use std::collections::BTreeMap;
use std::io::Write;
use std::sync::Arc;
use std::time::Instant;

/// Events per timed chunk.
pub const CHUNK: usize = 65_536;

/// Where the events come from.
pub enum Source<'a> {
    Random { events: u64, seed: u64 },
    File(&'a [Event]),
}

pub struct Options<'a> {
    pub source: Source<'a>,
    /// Reset to the initial state after a final state.
    pub reset_on_final: bool,
    /// Write the stream's text form here (random source only).
    pub stream_out: Option<&'a mut dyn Write>,
    /// Write the `INDEX STATE` lines here.
    pub states_out: Option<&'a mut dyn Write>,
}

#[derive(Debug, Clone, Serialize)]
pub struct Report {
    pub engine: &'static str,
    pub file: String,
    pub events: u64,
    pub seed: Option<u64>,
    pub seconds: f64,
    pub events_per_sec: f64,
    pub latency_ns: Latency,
    /// The cost of reading the clock twice, which each latency sample includes.
    pub timer_overhead_ns: u64,
    pub peak_rss_bytes: Option<u64>,
    pub nodes: Nodes,
    pub state_changes: u64,
    /// How many events arrived in each state (at rest).
    pub events_by_state: BTreeMap<String, u64>,
    pub firings: u64,
    pub missions: u64,
    pub cascade_errors: u64,
    /// Events the acceptance rule refused (`Engine::admit`): a payload that
    /// does not fit, out of order, from the future. They change nothing.
    pub refused: u64,
    /// The refused events by reason ([`crate::rete::PostError::key`]: `payload`, `out of
    /// order`, `from the future`, `unknown event`), as a running stack
    /// counts them.
    pub refused_by_reason: BTreeMap<String, u64>,
    /// The first refused event of each reason: where and why.
    pub first_refused: BTreeMap<String, Refusal>,
}

impl Report {
    /// The refused events for a person, one line per reason with the first
    /// of them (`place` names an event by its index: its line in a stream
    /// file); nothing when none was refused.
    pub fn refusals(&self, place: impl Fn(u64) -> String) -> Vec<String> {
        if self.refused == 0 {
            return Vec::new();
        }
        let mut lines = vec![format!(
            "{} of {} events refused, as every part of situ refuses them (language reference §10.4); the run went on:",
            self.refused, self.events
        )];
        for (key, n) in &self.refused_by_reason {
            if let Some(first) = self.first_refused.get(key) {
                lines.push(format!("  {key}: {n}, the first at {}: {}", place(first.index), first.reason));
            }
        }
        lines
    }
}

/// A refused event of a stream.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Refusal {
    /// Its 0-based index among the stream's events.
    pub index: u64,
    /// Why, as the runtime says it.
    pub reason: String,
}

#[derive(Debug, Clone, Copy, Serialize)]
pub struct Latency {
    pub p50: u64,
    pub p99: u64,
    pub max: u64,
}

#[derive(Debug, Clone, Copy, Serialize)]
pub struct Nodes {
    pub alpha: u32,
    pub beta: u32,
    pub terminals: u32,
    pub total: u32,
    pub saved_by_sharing: u32,
}

/// A histogram of nanoseconds: exact below [`EXACT`], then one bucket per
/// power of two.
struct Histogram {
    exact: Vec<u64>,
    log: [u64; 64],
    count: u64,
    max: u64,
}

const EXACT: usize = 16_384;

impl Histogram {
    fn new() -> Self {
        Histogram { exact: vec![0; EXACT], log: [0; 64], count: 0, max: 0 }
    }

    fn add(&mut self, ns: u64) {
        self.count += 1;
        self.max = self.max.max(ns);
        if (ns as usize) < EXACT {
            self.exact[ns as usize] += 1;
        } else {
            self.log[63 - ns.leading_zeros() as usize] += 1;
        }
    }

    fn quantile(&self, q: f64) -> u64 {
        let rank = ((self.count as f64) * q).ceil().max(1.0) as u64;
        let mut seen = 0;
        for (ns, &n) in self.exact.iter().enumerate() {
            seen += n;
            if seen >= rank {
                return ns as u64;
            }
        }
        for (bit, &n) in self.log.iter().enumerate() {
            seen += n;
            if seen >= rank {
                return (1u64 << bit).min(self.max);
            }
        }
        self.max
    }
}

/// The events of one chunk: ids, times, and payloads in one arena, and the
/// clocks they arrived at (when the stream says).
struct Chunk {
    events: Vec<(u32, u64, u32, u32)>,
    clocks: Vec<Option<u64>>,
    values: Vec<Value>,
}

impl Chunk {
    fn payload(&self, i: usize) -> &[Value] {
        let (_, _, s, e) = self.events[i];
        &self.values[s as usize..e as usize]
    }

    /// Posts event `i` through the engine's acceptance rule
    /// ([`Engine::admit`]), at its clock when the stream gives one.
    fn step(&self, engine: &mut Engine, i: usize) -> Result<crate::rete::Step, StepError> {
        let (event, time, _, _) = self.events[i];
        engine.set_clock(self.clocks[i]);
        engine.step(event, time, self.payload(i))
    }
}

/// Fills `chunk` with up to `n` events; returns how many.
fn fill(source: &mut ChunkSource, chunk: &mut Chunk, n: usize) -> usize {
    chunk.events.clear();
    chunk.clocks.clear();
    chunk.values.clear();
    for _ in 0..n {
        let start = chunk.values.len() as u32;
        let next = match source {
            ChunkSource::Random { gen, left } => {
                if *left == 0 {
                    None
                } else {
                    *left -= 1;
                    gen.next_into(&mut chunk.values).map(|(event, time)| (event, time, None))
                }
            }
            ChunkSource::File { events, at } => events.get(*at).map(|e| {
                *at += 1;
                chunk.values.extend_from_slice(&e.payload);
                (e.event, e.time, e.clock)
            }),
        };
        let Some((event, time, clock)) = next else { break };
        chunk.events.push((event, time, start, chunk.values.len() as u32));
        chunk.clocks.push(clock);
    }
    chunk.events.len()
}

enum ChunkSource<'a> {
    Random { gen: Box<Generator>, left: u64 },
    File { events: &'a [Event], at: usize },
}

impl<'a> ChunkSource<'a> {
    fn new(content: &Arc<Content>, source: &Source<'a>, reset_on_final: bool) -> Self {
        match source {
            Source::Random { events, seed } => ChunkSource::Random {
                gen: Box::new(Generator::new(content.clone(), *seed).reset_on_final(reset_on_final)),
                left: *events,
            },
            Source::File(events) => ChunkSource::File { events, at: 0 },
        }
    }
}

/// Runs the benchmark.
pub fn run(content: Arc<Content>, mut opts: Options) -> Report {
    let mut engine = Engine::new(content.clone());
    let mut chunk = Chunk {
        events: Vec::with_capacity(CHUNK),
        clocks: Vec::with_capacity(CHUNK),
        values: Vec::with_capacity(CHUNK * 4),
    };

    // Pass 1: throughput (and the optional stream and states files).
    let mut source = ChunkSource::new(&content, &opts.source, opts.reset_on_final);
    let mut elapsed = 0.0f64;
    let (mut total, mut changes, mut firings, mut missions, mut cascades) = (0u64, 0u64, 0u64, 0u64, 0u64);
    let mut refused = 0u64;
    let mut by_reason: BTreeMap<&'static str, u64> = BTreeMap::new();
    let mut first_refused = BTreeMap::new();
    let mut at_rest = engine.state();
    let mut by_state = vec![0u64; content.states.len()];
    let mut lines: Vec<(u64, u32)> = Vec::new();
    let mut text = String::new();
    loop {
        let n = fill(&mut source, &mut chunk, CHUNK);
        if n == 0 {
            break;
        }
        lines.clear();
        let start = Instant::now();
        for i in 0..n {
            by_state[at_rest as usize] += 1;
            match chunk.step(&mut engine, i) {
                Ok(step) => firings += step.firings as u64,
                Err(StepError::Cascade { .. }) => cascades += 1,
                Err(e) => {
                    let e = engine.post_error(e);
                    // Counted as a running stack counts it; the run goes on.
                    refused += 1;
                    *by_reason.entry(e.key()).or_default() += 1;
                    first_refused
                        .entry(e.key().to_string())
                        .or_insert_with(|| Refusal { index: total + i as u64, reason: e.describe(&content) });
                }
            }
            let state = engine.state();
            if state != at_rest {
                changes += 1;
                lines.push((total + i as u64, state));
                at_rest = state;
            }
            if opts.reset_on_final && engine.reset_if_final() {
                missions += 1;
                at_rest = engine.state();
            }
        }
        elapsed += start.elapsed().as_secs_f64();
        if let Some(out) = opts.states_out.as_mut() {
            text.clear();
            for (i, s) in &lines {
                text.push_str(&format!("{i} {}\n", content.states[*s as usize].name));
            }
            let _ = out.write_all(text.as_bytes());
        }
        if let (Some(out), Source::Random { .. }) = (opts.stream_out.as_mut(), &opts.source) {
            text.clear();
            for i in 0..n {
                let (event, time, _, _) = chunk.events[i];
                stream::write_line(&content, &mut text, event, time, chunk.payload(i));
            }
            let _ = out.write_all(text.as_bytes());
        }
        total += n as u64;
    }

    // Pass 2: latency of every post.
    let mut engine = Engine::new(content.clone());
    let mut source = ChunkSource::new(&content, &opts.source, opts.reset_on_final);
    let mut hist = Histogram::new();
    loop {
        let n = fill(&mut source, &mut chunk, CHUNK);
        if n == 0 {
            break;
        }
        for i in 0..n {
            let start = Instant::now();
            let _ = chunk.step(&mut engine, i);
            hist.add(start.elapsed().as_nanos() as u64);
            if opts.reset_on_final {
                engine.reset_if_final();
            }
        }
    }

    let stats = content.network.stats;
    Report {
        engine: "situ",
        file: content.source.clone(),
        events: total,
        seed: match opts.source {
            Source::Random { seed, .. } => Some(seed),
            Source::File(_) => None,
        },
        seconds: elapsed,
        events_per_sec: if elapsed > 0.0 { total as f64 / elapsed } else { 0.0 },
        latency_ns: Latency { p50: hist.quantile(0.5), p99: hist.quantile(0.99), max: hist.max },
        timer_overhead_ns: timer_overhead(),
        peak_rss_bytes: peak_rss(),
        nodes: Nodes {
            alpha: stats.alpha,
            beta: stats.beta,
            terminals: stats.terminals,
            total: stats.nodes(),
            saved_by_sharing: stats.saved(),
        },
        state_changes: changes,
        events_by_state: content.states.iter().zip(by_state).map(|(s, n)| (s.name.clone(), n)).collect(),
        firings,
        missions,
        cascade_errors: cascades,
        refused,
        refused_by_reason: by_reason.into_iter().map(|(k, n)| (k.to_string(), n)).collect(),
        first_refused,
    }
}

/// The median cost of `Instant::now()` twice and `elapsed`, in ns.
fn timer_overhead() -> u64 {
    let mut samples: Vec<u64> = (0..10_001)
        .map(|_| {
            let t = Instant::now();
            t.elapsed().as_nanos() as u64
        })
        .collect();
    samples.sort_unstable();
    samples[samples.len() / 2]
}

/// The peak resident set size of this process (Linux: `VmHWM`).
pub fn peak_rss() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_of_the_histogram() {
        let mut h = Histogram::new();
        for ns in 1..=100 {
            h.add(ns);
        }
        h.add(1_000_000);
        assert_eq!(h.quantile(0.5), 51);
        assert_eq!(h.quantile(0.99), 100);
        assert_eq!(h.max, 1_000_000);
        assert_eq!(h.quantile(1.0), 1 << 19, "above the exact range: the power of two below");
    }
}
