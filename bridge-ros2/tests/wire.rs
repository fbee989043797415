//! The bridge's DDS shell against peers written here on raw RustDDS, over
//! real DDS on this host, in the ways an independent ROS 2 peer differs from
//! ros2-client: lifecycle servers that answer the instant a request comes
//! (as rmw_cyclonedds does for a client without `clientid=` user data) and
//! read the request header's sequence number as one `int64`, and a laser
//! that publishes in XCDR2. Each test has its own DDS domain.

use rustdds::no_key::{DataReader, DataWriter};
use rustdds::{DomainParticipant, QosPolicyBuilder, RepresentationIdentifier, StatusEvented, TopicKind};
use situ_bridge_ros2::core::Core;
use situ_bridge_ros2::dds::{self, Options, Report, Rmw};
use situ_bridge_ros2::msgs::{self, ChangeStateResponse, DiagnosticArray, GetStateResponse, Header, LaserScan, State};
use situ_bridge_ros2::raw::{Never, Raw, RawAdapter};
use situ_bridge_ros2::service::{self, Payload, PayloadAdapter};
use situ_compiler::{bundle, check_source};
use situ_grammar::diag::FileId;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

const RULES: &str = include_str!("../../tests/ros2/amr.situ");
const MAP: &str = include_str!("../../tests/ros2/amr.toml");
const NODES: [&str; 4] = ["/costmap", "/planner", "/recovery", "/controller"];
/// A bound on a test that has gone wrong, not a measure of anything.
const GIVE_UP: Duration = Duration::from_secs(20);

fn bridge(domain: u16, stop: Arc<AtomicBool>) -> std::thread::JoinHandle<Report> {
    bridge_on(domain, Rmw::CycloneDds, stop)
}

fn bridge_on(domain: u16, rmw: Rmw, stop: Arc<AtomicBool>) -> std::thread::JoinHandle<Report> {
    let checked = check_source("amr.situ", RULES);
    let content = Arc::new(bundle::build(&checked));
    let core =
        Core::new(content, &checked.model, MAP, &situ_ros2_map::Registry::carried(), FileId(1)).expect("the map");
    let options = Options { domain, rmw, heartbeat: Duration::from_millis(10), duration: None, stop };
    std::thread::spawn(move || dds::run(core, &options, None).expect("the bridge"))
}

/// What the lifecycle servers were asked: (node, service, sequence number
/// read as rmw_cyclonedds reads it, an `int64`, transition id or 0).
type Asked = Arc<Mutex<Vec<(usize, &'static str, i64, u8)>>>;

struct Endpoint {
    node: usize,
    service: &'static str,
    requests: DataReader<Raw, RawAdapter>,
    replies: DataWriter<Payload, PayloadAdapter>,
}

/// rmw_cyclonedds' lifecycle servers for the four nodes: each request is
/// answered the moment it is read, with its own 16-byte header before the
/// answer (every node unconfigured; every transition succeeds).
fn servers(domain: u16, asked: Asked, stop: Arc<AtomicBool>) -> std::thread::JoinHandle<()> {
    std::thread::spawn(move || {
        let participant = DomainParticipant::new(domain).expect("participant");
        let qos = service::service_qos();
        let subscriber = participant.create_subscriber(&qos).unwrap();
        let publisher = participant.create_publisher(&qos).unwrap();
        let mut endpoints = Vec::new();
        for (node, name) in NODES.iter().enumerate() {
            for (service, ty) in [("get_state", "GetState"), ("change_state", "ChangeState")] {
                let [(rq, rq_type), (rr, rr_type)] =
                    service::topics(&format!("{name}/{service}"), "lifecycle_msgs", ty);
                let rq = participant.create_topic(rq, rq_type, &qos, TopicKind::NoKey).unwrap();
                let rr = participant.create_topic(rr, rr_type, &qos, TopicKind::NoKey).unwrap();
                endpoints.push(Endpoint {
                    node,
                    service,
                    requests: subscriber.create_datareader_no_key(&rq, None).unwrap(),
                    replies: publisher.create_datawriter_no_key(&rr, None).unwrap(),
                });
            }
        }
        while !stop.load(Ordering::Relaxed) {
            for e in &mut endpoints {
                while let Ok(Some(sample)) = e.requests.take_next_sample() {
                    let bytes = sample.into_value().0;
                    let header: [u8; 16] = bytes[4..20].try_into().unwrap();
                    let seq = i64::from_le_bytes(header[8..].try_into().unwrap());
                    // The transition asked for (0 for get_state).
                    let transition = if e.service == "change_state" { bytes[20] } else { 0 };
                    asked.lock().unwrap().push((e.node, e.service, seq, transition));
                    let state = |id: u8| cdr(&GetStateResponse { current_state: State { id, label: String::new() } });
                    let answer = match e.service {
                        "get_state" => {
                            // First an answer to another client of the same
                            // service, with the same sequence number: replies
                            // go to every client, and this one is not the
                            // bridge's (were it taken, the node would be
                            // active and deactivated, not configured).
                            let mut other = header;
                            other[0] ^= 0xff;
                            let mut reply = other.to_vec();
                            reply.extend(state(3));
                            let _ = e.replies.write(Payload(reply), None);
                            state(1)
                        }
                        _ => cdr(&ChangeStateResponse { success: true }),
                    };
                    let mut reply = header.to_vec();
                    reply.extend(answer);
                    let _ = e.replies.write(Payload(reply), None);
                }
            }
            std::thread::sleep(Duration::from_millis(1));
        }
    })
}

fn cdr<T: serde::Serialize>(msg: &T) -> Vec<u8> {
    msgs::to_cdr(msg).unwrap()[4..].to_vec()
}

fn wait_until(what: &str, mut done: impl FnMut() -> bool) {
    let start = Instant::now();
    while !done() {
        assert!(start.elapsed() < GIVE_UP, "gave up waiting: {what}");
        std::thread::sleep(Duration::from_millis(5));
    }
}

#[test]
fn the_first_get_state_is_answered_and_its_sequence_number_is_an_int64() {
    let stop = Arc::new(AtomicBool::new(false));
    let asked: Asked = Arc::default();
    let servers = servers(63, asked.clone(), stop.clone());
    let bridge = bridge(63, stop.clone());
    // Every node configured: each answered its get_state.
    wait_until("a configure to every node", || {
        asked.lock().unwrap().iter().filter(|a| a.1 == "change_state").count() >= NODES.len()
    });
    stop.store(true, Ordering::Relaxed);
    let report = bridge.join().unwrap();
    servers.join().unwrap();
    let asked = asked.lock().unwrap().clone();
    for (node, name) in NODES.iter().enumerate() {
        let seqs = |service: &str| -> Vec<(i64, u8)> {
            asked.iter().filter(|a| a.0 == node && a.1 == service).map(|a| (a.2, a.3)).collect()
        };
        // One request, the first written (sequence number 1): the bridge
        // wrote nothing the server could not answer; and it took its own
        // answer (unconfigured: configure), not the other client's.
        assert_eq!(seqs("get_state"), [(1, 0)], "{name}: {asked:?}");
        assert_eq!(seqs("change_state"), [(1, 1)], "{name}: {asked:?}");
    }
    assert_eq!(report.get_state_sent, [1, 1, 1, 1], "{asked:?}");
}

/// Writes a LaserScan's little-endian CDR body under the encapsulation
/// `00 N`: for `00 07` (XCDR2) the same bytes are that scan, since a
/// LaserScan has no 8-byte field and no sequence of structures.
struct Under<const N: u8>;

impl<const N: u8> rustdds::no_key::SerializerAdapter<Payload> for Under<N> {
    type Error = Never;

    fn output_encoding() -> RepresentationIdentifier {
        match N {
            7 => RepresentationIdentifier::XCDR2_LE,
            _ => RepresentationIdentifier::PL_XCDR2_LE,
        }
    }

    fn to_bytes(value: &Payload) -> Result<rustdds::bytes::Bytes, Never> {
        Ok(rustdds::bytes::Bytes::copy_from_slice(&value.0))
    }
}

/// A laser publishing clear scans under `00 N` beside a bridge on
/// `domain`, until the bridge's own status on `/diagnostics` counts three
/// messages (the first scans may come before the bridge's reader knows the
/// laser: best effort, they are not for it); what the bridge reported of
/// /scan meanwhile, and its report.
fn scans<const N: u8>(domain: u16) -> (Vec<msgs::DiagnosticStatus>, Report) {
    let participant = DomainParticipant::new(domain).expect("participant");
    let qos = QosPolicyBuilder::new()
        .reliability(rustdds::policy::Reliability::Reliable { max_blocking_time: rustdds::Duration::from_millis(100) })
        .history(rustdds::policy::History::KeepLast { depth: 10 })
        .build();
    let scan_topic = participant
        .create_topic("rt/scan".into(), "sensor_msgs::msg::dds_::LaserScan_".into(), &qos, TopicKind::NoKey)
        .unwrap();
    let diag_topic = participant
        .create_topic(
            "rt/diagnostics".into(),
            "diagnostic_msgs::msg::dds_::DiagnosticArray_".into(),
            &qos,
            TopicKind::NoKey,
        )
        .unwrap();
    let laser: DataWriter<Payload, Under<N>> =
        participant.create_publisher(&qos).unwrap().create_datawriter_no_key(&scan_topic, None).unwrap();
    let mut diagnostics: DataReader<Raw, RawAdapter> =
        participant.create_subscriber(&qos).unwrap().create_datareader_no_key(&diag_topic, None).unwrap();

    let stop = Arc::new(AtomicBool::new(false));
    let bridge = bridge(domain, stop.clone());
    let mut matched = false;
    wait_until("the bridge's /scan reader", || {
        while let Some(s) = laser.try_recv_status() {
            if let rustdds::dds::statusevents::DataWriterStatus::PublicationMatched { current, .. } = s {
                matched = current.count() > 0;
            }
        }
        matched
    });
    let scan = LaserScan {
        header: Header::default(),
        angle_min: -1.0,
        angle_max: 1.0,
        angle_increment: 0.5,
        time_increment: 0.0,
        scan_time: 0.1,
        range_min: 0.05,
        range_max: 10.0,
        ranges: vec![3.0; 5],
        intensities: Vec::new(),
    };
    let mut reported = Vec::new();
    wait_until("three messages counted on /diagnostics", || {
        laser.write(Payload(cdr(&scan)), None).map_err(|_| "the write").unwrap();
        let mut counted = false;
        while let Ok(Some(sample)) = diagnostics.take_next_sample() {
            let bytes = sample.into_value().0;
            let (array, _) =
                rustdds::cdr_encoding::from_bytes::<DiagnosticArray, byteorder::LittleEndian>(&bytes[4..]).unwrap();
            for s in array.status {
                if s.name == "situ: bridge" {
                    counted |= s.values[0].value.parse::<u64>().unwrap() >= 3;
                } else if s.name == "situ: /scan" {
                    reported.push(s);
                }
            }
        }
        counted
    });
    stop.store(true, Ordering::Relaxed);
    (reported, bridge.join().unwrap())
}

#[test]
fn xcdr2_scans_are_read() {
    let (reported, report) = scans::<7>(64);
    assert!(reported.is_empty(), "{reported:?}");
    let c = report.counters;
    assert!(c.messages >= 3, "{report:?}");
    // Each one a CLEAR.
    assert_eq!((c.refused, c.events), (0, c.messages), "{report:?}");
}

#[test]
fn scans_in_an_encapsulation_not_read_are_refused_counted_and_reported() {
    let (reported, report) = scans::<0x0b>(65);
    let c = report.counters;
    assert!(c.messages >= 3, "{report:?}");
    assert_eq!((c.refused, c.events), (c.messages, 0), "{report:?}");
    assert!(!reported.is_empty());
    for status in &reported {
        assert!(status.message.contains("encapsulation 00 0b"), "{status:?}");
    }
}

/// What each node was asked: (node, transition id or `None` for `get_state`).
type Requests = Arc<Mutex<Vec<(usize, Option<u8>)>>>;

/// ros2-client's own lifecycle servers, in the mapping of `rmw`.
fn ros2_client_servers(domain: u16, rmw: Rmw, asked: Requests, stop: Arc<AtomicBool>) -> std::thread::JoinHandle<()> {
    use ros2_client::service::ServiceMapping;
    use ros2_client::{Context, ContextOptions, Name, NodeName, NodeOptions, QosProfile, ServiceTypeName};
    use situ_bridge_ros2::msgs::{ChangeStateRequest, GetStateRequest};
    std::thread::spawn(move || {
        let mapping = match rmw {
            Rmw::CycloneDds => ServiceMapping::Cyclone,
            Rmw::FastRtps => ServiceMapping::Enhanced,
        };
        let context = Context::with_options(ContextOptions::new().domain_id(domain)).expect("participant");
        let mut node = context
            .new_node(NodeName::new("/", "lifecycle_nodes").unwrap(), NodeOptions::new().enable_rosout(false))
            .expect("node");
        let qos = QosProfile::publisher_default().history(ros2_client::qos::History::KeepLast { depth: 10 });
        let mut servers = Vec::new();
        for n in NODES {
            let change = node
                .create_server::<ChangeStateRequest, ChangeStateResponse>(
                    mapping,
                    &Name::new(n, "change_state").unwrap(),
                    &ServiceTypeName::new("lifecycle_msgs", "ChangeState"),
                    qos.clone(),
                    qos.clone(),
                )
                .expect("server");
            let get = node
                .create_server::<GetStateRequest, GetStateResponse>(
                    mapping,
                    &Name::new(n, "get_state").unwrap(),
                    &ServiceTypeName::new("lifecycle_msgs", "GetState"),
                    qos.clone(),
                    qos.clone(),
                )
                .expect("server");
            servers.push((change, get));
        }
        while !stop.load(Ordering::Relaxed) {
            for (i, (change, get)) in servers.iter().enumerate() {
                while let Ok(Some((id, _))) = get.receive_request() {
                    asked.lock().unwrap().push((i, None));
                    let current_state = State { id: 1, label: "unconfigured".into() };
                    let _ = get.send_response(id, GetStateResponse { current_state });
                }
                while let Ok(Some((id, rq))) = change.receive_request() {
                    asked.lock().unwrap().push((i, Some(rq.transition.id)));
                    let _ = change.send_response(id, ChangeStateResponse { success: true });
                }
            }
            std::thread::sleep(Duration::from_millis(1));
        }
    })
}

/// Both mappings of the bridge's service client against ros2-client's
/// servers: the request ids and the answers are matched (every node is
/// configured), and each node is asked its state once.
#[test]
fn ros2_client_servers_are_driven_in_both_mappings() {
    for (domain, rmw) in [(66, Rmw::CycloneDds), (67, Rmw::FastRtps)] {
        let stop = Arc::new(AtomicBool::new(false));
        let asked: Requests = Arc::default();
        let servers = ros2_client_servers(domain, rmw, Arc::clone(&asked), stop.clone());
        let bridge = bridge_on(domain, rmw, stop.clone());
        wait_until("a configure to every node", || {
            asked.lock().unwrap().iter().filter(|(_, t)| t.is_some()).count() >= NODES.len()
        });
        stop.store(true, Ordering::Relaxed);
        let report = bridge.join().unwrap();
        servers.join().unwrap();
        let mut asked = asked.lock().unwrap().clone();
        asked.sort();
        let expected: Vec<_> = (0..NODES.len()).flat_map(|n| [(n, None), (n, Some(1))]).collect();
        assert_eq!(asked, expected, "{rmw:?}");
        assert_eq!(report.get_state_sent, [1, 1, 1, 1], "{rmw:?}");
        assert_eq!(report.counters.requests, 4, "{rmw:?}");
    }
}
