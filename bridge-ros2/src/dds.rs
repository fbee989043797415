//! The DDS shell of the bridge: one ROS 2 node (`/situ_bridge`, by
//! ros2-client on RustDDS) with a reader of raw CDR samples per mapped
//! topic, the publishers of the situation, and a `change_state` and a
//! `get_state` client per lifecycle node; one thread polls them all and
//! hands what arrives to the [`Core`].

use crate::bag::Bag;
use crate::core::{Core, Counters, Output};
use crate::msgs::{
    ChangeStateRequest, ChangeStateResponse, DiagnosticArray, GetStateRequest, GetStateResponse, StringMsg, Transition,
};
use crate::raw::{Raw, RawAdapter};
pub use crate::service::Rmw;
use crate::service::ServiceClient;
use ros2_client::QosProfile;
use ros2_client::{Context, ContextOptions, MessageTypeName, Name, Node, NodeName, NodeOptions, Publisher};
use rustdds::mio1::{Events, Interest, Poll, Token};
use rustdds::no_key::DataReader;
use rustdds::{QosPolicyBuilder, ReadCondition, GUID};
use std::fmt;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

#[derive(Debug, Clone)]
pub struct Options {
    /// The DDS domain (`ROS_DOMAIN_ID`).
    pub domain: u16,
    pub rmw: Rmw,
    /// How often the clock ticks when nothing arrives (staleness, timeouts).
    pub heartbeat: Duration,
    /// Run this long, then stop; `None`: until `stop`.
    pub duration: Option<Duration>,
    /// Raised from outside (Ctrl-C): the loop ends.
    pub stop: Arc<AtomicBool>,
}

/// The topics the bridge publishes, with their types.
pub const PUBLISHED: [(&str, &str); 3] = [
    ("/situ/state", "std_msgs/msg/String"),
    ("/situ/agents", "diagnostic_msgs/msg/DiagnosticArray"),
    ("/diagnostics", "diagnostic_msgs/msg/DiagnosticArray"),
];

/// Why the bridge could not run.
#[derive(Debug)]
pub struct DdsError(pub String);

impl fmt::Display for DdsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

fn dds<E: fmt::Debug>(what: &str) -> impl FnOnce(E) -> DdsError + '_ {
    move |e| DdsError(format!("{what}: {e:?}"))
}

/// What a run did.
#[derive(Debug, Clone)]
pub struct Report {
    pub state: String,
    pub counters: Counters,
    /// Nanoseconds from a message taken off its reader to the first
    /// `change_state` request it caused written, one per such message.
    pub latencies: Vec<u64>,
    /// Messages taken per second over the run.
    pub rate: f64,
    /// The time spent on the messages taken (decoding, the map, the rules,
    /// the outputs), over all of them.
    pub busy: Duration,
    /// The recording's first error, after which nothing more was recorded.
    pub record_error: Option<String>,
    /// The `get_state` requests written, per node of the map.
    pub get_state_sent: Vec<u64>,
    /// Samples of the bridge's own writers that its readers took and
    /// ignored (a map reading `/diagnostics` takes the bridge's status).
    pub own_ignored: u64,
}

/// Where what came and went is recorded, if anywhere.
struct Recording {
    bag: Option<Bag>,
    error: Option<String>,
}

impl Recording {
    fn keep(&mut self, write: impl FnOnce(&mut Bag) -> std::io::Result<()>) {
        if let Some(bag) = self.bag.as_mut() {
            if let Err(e) = write(bag) {
                self.error = Some(e.to_string());
                self.bag = None;
            }
        }
    }
}

/// The DDS name of a message type: `sensor_msgs/msg/LaserScan` → package
/// and name for [`MessageTypeName`].
/// The package, the kind (`msg`, `srv`, `action`) and the name of a full type name.
fn type_parts(full: &str) -> Option<(&str, &str, &str)> {
    let mut parts = full.split('/');
    Some((parts.next()?, parts.next()?, parts.next()?))
}

fn now_ns() -> u64 {
    SystemTime::now().duration_since(UNIX_EPOCH).map_or(0, |d| d.as_nanos() as u64)
}

struct Lifecycle {
    change: ServiceClient<ChangeStateRequest, ChangeStateResponse>,
    get: ServiceClient<GetStateRequest, GetStateResponse>,
    /// How long a request may wait for its reply path (the node's timeout).
    patience: Duration,
}

struct Shell {
    _node: Node,
    state: Publisher<StringMsg>,
    agents: Publisher<DiagnosticArray>,
    diagnostics: Publisher<DiagnosticArray>,
    readers: Vec<(String, DataReader<Raw, RawAdapter>)>,
    lifecycle: Vec<Lifecycle>,
    /// The GUIDs of the bridge's own writers: a sample of theirs that a
    /// reader takes (a map that reads `/diagnostics`) is not the robot's.
    own: Vec<GUID>,
}

/// Whether a sample written by `writer` is the bridge's own: one of `own`,
/// its publishers' GUIDs. Its readers ignore such a sample, whatever the
/// map says: the bridge never feeds on what it writes.
pub fn is_own(own: &[GUID], writer: GUID) -> bool {
    own.contains(&writer)
}

/// The latched topics: a late subscriber (`ros2 topic echo`) gets the last one.
fn latched() -> QosProfile {
    QosProfile::publisher_default()
        .durability(ros2_client::qos::Durability::TransientLocal)
        .history(ros2_client::qos::History::KeepLast { depth: 1 })
}

fn open(core: &Core, options: &Options) -> Result<Shell, DdsError> {
    let context =
        Context::with_options(ContextOptions::new().domain_id(options.domain)).map_err(dds("the DDS participant"))?;
    let mut node = context
        .new_node(NodeName::new("/", "situ_bridge").map_err(dds("node name"))?, NodeOptions::new().enable_rosout(false))
        .map_err(dds("the node"))?;
    let publisher = |name: &str, package: &str, ty: &str, qos: QosProfile| {
        let topic = node
            .create_topic(&Name::parse(name).map_err(dds(name))?, MessageTypeName::new(package, ty), &qos)
            .map_err(dds(name))?;
        Ok::<_, DdsError>(topic)
    };
    let state_topic = publisher("/situ/state", "std_msgs", "String", latched())?;
    let agents_topic = publisher("/situ/agents", "diagnostic_msgs", "DiagnosticArray", latched())?;
    let diag_qos = QosProfile::publisher_default().history(ros2_client::qos::History::KeepLast { depth: 10 });
    let diagnostics_topic = publisher("/diagnostics", "diagnostic_msgs", "DiagnosticArray", diag_qos)?;
    let state = node.create_publisher(&state_topic, None).map_err(dds("/situ/state"))?;
    let agents = node.create_publisher(&agents_topic, None).map_err(dds("/situ/agents"))?;
    let diagnostics = node.create_publisher(&diagnostics_topic, None).map_err(dds("/diagnostics"))?;

    // Best effort matches every writer, reliable or not; a burst is kept.
    let read_qos = QosPolicyBuilder::new()
        .reliability(rustdds::policy::Reliability::BestEffort)
        .history(rustdds::policy::History::KeepLast { depth: 256 })
        .build();
    let subscriber = context.domain_participant().create_subscriber(&read_qos).map_err(dds("the subscriber"))?;
    let mut readers = Vec::new();
    let node_name = NodeName::new("/", "situ_bridge").map_err(dds("node name"))?;
    for (topic, ty) in core.topics() {
        let (package, kind, name) = type_parts(ty).ok_or_else(|| DdsError(format!("type `{ty}`")))?;
        let profile = QosProfile::subscription_default();
        let ros_name = Name::parse(&topic).map_err(dds(&topic))?;
        let t = if kind == "msg" {
            node.create_topic(&ros_name, MessageTypeName::new(package, name), &profile).map_err(dds(&topic))?
        } else {
            // A part of a service or an action (`pkg/action/Name_FeedbackMessage`):
            // its DDS type is `pkg::action::dds_::Name_FeedbackMessage_`.
            let dds_type = format!("{package}::{kind}::dds_::{name}_");
            let qos: rustdds::QosPolicies = (&profile).into();
            let dds_name = ros_name.to_dds_name("rt", &node_name, "");
            context
                .domain_participant()
                .create_topic(dds_name, dds_type, &qos, rustdds::TopicKind::NoKey)
                .map_err(dds(&topic))?
        };
        let reader =
            subscriber.create_datareader_no_key::<Raw, RawAdapter>(&t, Some(read_qos.clone())).map_err(dds(&topic))?;
        readers.push((topic, reader));
    }
    let mut lifecycle = Vec::new();
    let participant = context.domain_participant();
    for n in core.nodes() {
        let service = |s: &str| format!("{}/{s}", n.name);
        lifecycle.push(Lifecycle {
            change: ServiceClient::new(
                &participant,
                options.rmw,
                &service("change_state"),
                "lifecycle_msgs",
                "ChangeState",
            )
            .map_err(DdsError)?,
            get: ServiceClient::new(&participant, options.rmw, &service("get_state"), "lifecycle_msgs", "GetState")
                .map_err(DdsError)?,
            patience: n.timeout,
        });
    }
    let own = vec![state.guid(), agents.guid(), diagnostics.guid()];
    Ok(Shell { _node: node, state, agents, diagnostics, readers, lifecycle, own })
}

impl Shell {
    /// Sends the core's outputs, recording what it publishes; whether a
    /// `change_state` request was among them.
    fn send(&mut self, out: Vec<Output>, recording: &mut Recording) -> bool {
        let mut requested = false;
        let now = now_ns();
        for o in out {
            // A publication that fails (no reader's room) is dropped: the
            // next one carries the whole picture again.
            match o {
                Output::State(s) => {
                    let msg = StringMsg { data: s };
                    recording.keep(|b| b.write_serde(PUBLISHED[0].0, now, &msg));
                    drop(self.state.publish(msg));
                }
                Output::Agents(a) => {
                    recording.keep(|b| b.write_serde(PUBLISHED[1].0, now, &a));
                    drop(self.agents.publish(a));
                }
                Output::Diagnostics(d) => {
                    recording.keep(|b| b.write_serde(PUBLISHED[2].0, now, &d));
                    drop(self.diagnostics.publish(d));
                }
                Output::ChangeState { node, transition } => {
                    let request = ChangeStateRequest {
                        transition: Transition { id: transition.id(), label: transition.label().to_string() },
                    };
                    let l = &mut self.lifecycle[node];
                    l.change.request(request, Instant::now());
                    requested = !l.change.holding();
                }
                Output::GetState { node } => {
                    self.lifecycle[node].get.request(GetStateRequest::default(), Instant::now());
                }
            }
        }
        requested
    }
}

/// Runs the bridge until `options.duration` passes or `options.stop` is
/// raised, recording into `bag` when there is one (finished on return).
pub fn run(mut core: Core, options: &Options, bag: Option<Bag>) -> Result<Report, DdsError> {
    let mut recording = Recording { bag, error: None };
    for (topic, ty) in core.topics().into_iter().chain(PUBLISHED.map(|(t, ty)| (t.to_string(), ty))) {
        recording.keep(|b| b.add_topic(&topic, ty));
    }
    let mut shell = open(&core, options)?;
    let mut poll = Poll::new().map_err(dds("poll"))?;
    let mut readers = std::mem::take(&mut shell.readers);
    for (i, (_, reader)) in readers.iter_mut().enumerate() {
        poll.registry().register(reader, Token(i), Interest::READABLE).map_err(dds("poll"))?;
    }
    let base = readers.len();
    for (i, l) in shell.lifecycle.iter_mut().enumerate() {
        let (change, get) = (l.change.reader_mut(), l.get.reader_mut());
        poll.registry().register(change, Token(base + 2 * i), Interest::READABLE).map_err(dds("poll"))?;
        poll.registry().register(get, Token(base + 2 * i + 1), Interest::READABLE).map_err(dds("poll"))?;
    }
    let started = Instant::now();
    let out = core.start(now_ns());
    shell.send(out, &mut recording);
    let mut events = Events::with_capacity(64);
    let mut latencies = Vec::new();
    let mut busy = Duration::ZERO;
    let mut next_tick = Instant::now() + options.heartbeat;
    let mut own_ignored = 0;
    loop {
        if options.stop.load(Ordering::Relaxed) || options.duration.is_some_and(|d| started.elapsed() >= d) {
            break;
        }
        let wait = next_tick.saturating_duration_since(Instant::now());
        // An interrupted poll (a signal) is a tick like any other.
        let _ = poll.poll(&mut events, Some(wait));
        for (topic, reader) in &mut readers {
            // In batches: one take per sample walks the reader's cache each time.
            let mut failed = 0;
            loop {
                let samples = match reader.take(256, ReadCondition::not_read()) {
                    Ok(s) if s.is_empty() => break,
                    Ok(s) => s,
                    // The sample that failed is consumed: count it, read on
                    // (a bounded number of times: the next poll reads on).
                    Err(e) => {
                        core.on_unreadable(topic, &format!("not read: {e}"));
                        failed += 1;
                        if failed >= 256 {
                            break;
                        }
                        continue;
                    }
                };
                for sample in samples {
                    if is_own(&shell.own, sample.sample_info().writer_guid()) {
                        own_ignored += 1;
                        continue;
                    }
                    let taken = Instant::now();
                    let bytes = sample.into_value().0;
                    let now = now_ns();
                    recording.keep(|b| b.write(topic, now, &bytes));
                    let out = core.on_message(topic, &bytes, now);
                    if shell.send(out, &mut recording) {
                        latencies.push(taken.elapsed().as_nanos() as u64);
                    }
                    busy += taken.elapsed();
                }
            }
        }
        for i in 0..shell.lifecycle.len() {
            let l = &mut shell.lifecycle[i];
            l.change.flush(l.patience, Instant::now());
            l.get.flush(l.patience, Instant::now());
            if let Some(answer) = l.change.reply() {
                let out = core.on_change_state(i, answer.success, now_ns());
                shell.send(out, &mut recording);
            }
            let l = &mut shell.lifecycle[i];
            if let Some(answer) = l.get.reply() {
                let out = core.on_get_state(i, answer.current_state.id, now_ns());
                shell.send(out, &mut recording);
            }
        }
        if Instant::now() >= next_tick {
            next_tick = Instant::now() + options.heartbeat;
            let out = core.on_tick(now_ns());
            shell.send(out, &mut recording);
            recording.keep(Bag::flush_if_due);
        }
    }
    recording.keep(|b| b.finish().map(drop));
    let counters = core.counters();
    let rate = counters.messages as f64 / started.elapsed().as_secs_f64().max(1e-9);
    let get_state_sent = shell.lifecycle.iter().map(|l| l.get.sent()).collect();
    Ok(Report {
        state: core.state_name().to_string(),
        counters,
        latencies,
        rate,
        busy,
        record_error: recording.error,
        get_state_sent,
        own_ignored,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The GUID of writer `key` (entity kind 0x03) of participant `prefix`.
    fn writer(prefix: u8, key: u8) -> GUID {
        let mut bytes = [prefix; 16];
        bytes[12..].copy_from_slice(&[0, 0, key, 0x03]);
        GUID::from_bytes(bytes)
    }

    #[test]
    fn only_the_bridges_own_writers_are_ignored() {
        let own = [writer(1, 1), writer(1, 2), writer(1, 3)];
        assert!(own.iter().all(|&w| is_own(&own, w)));
        // Another writer of the same participant, or the same entity of another.
        assert!(!is_own(&own, writer(1, 4)));
        assert!(!is_own(&own, writer(2, 1)));
        assert!(!is_own(&[], writer(1, 1)));
    }

    /// Why the map refuses relative topic names (E0415): ros2-client
    /// resolves one from the bridge's node, in the root namespace, to a DDS
    /// topic with an empty token, which no ROS 2 node writes.
    #[test]
    fn a_relative_name_would_read_nothing() {
        let node = NodeName::new("/", "situ_bridge").unwrap();
        assert_eq!(Name::parse("scan").unwrap().to_dds_name("rt", &node, ""), "rt//scan");
        assert_eq!(Name::parse("/scan").unwrap().to_dds_name("rt", &node, ""), "rt/scan");
    }
}
