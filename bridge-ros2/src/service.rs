//! A ROS 2 service client on RustDDS, the bridge's own: a request writer
//! and a reply reader of raw bytes, with the request id carried as the RMW
//! of the nodes carries it ([`Rmw`]).
//!
//! It exists for two things `ros2-client`'s `Client` does not do:
//!
//! - **No request before its reply path.** A request is sent only once the
//!   request writer has matched a request reader and the reply reader has
//!   matched a reply writer; until then it waits here (at most the node's
//!   timeout). An rmw_cyclonedds server answers at once when the client's
//!   reader carries no `clientid=` user data, and an answer sent before the
//!   server's reply writer knows the bridge's reader is lost.
//! - **The sequence number as rmw_cyclonedds reads it.** The Cyclone request
//!   header is `{ uint64 guid; int64 seq; }` (rmw_cyclonedds'
//!   `cdds_request_header_t`); `ros2-client` 0.12.1 writes `seq` as two
//!   32-bit halves, high first (`service/wrappers.rs`, `CycloneHeader`),
//!   which an `int64` reader reads as `2 << 32` for 2. Here it is one `i64`.

use crate::raw::{Never, Raw, RawAdapter};
use rustdds::bytes::Bytes;
use rustdds::no_key::{self, DataReader, DataWriter};
use rustdds::{DomainParticipant, QosPolicies, RepresentationIdentifier, SampleIdentity, TopicKind};
use rustdds::{RTPSEntity, StatusEvented};
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::marker::PhantomData;
use std::time::{Duration, Instant};

/// How the lifecycle services are carried: the RMW of the nodes' ROS 2.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rmw {
    /// `rmw_cyclonedds_cpp`: a request header in the payload.
    CycloneDds,
    /// `rmw_fastrtps_cpp` (ROS 2's default): the request id in inline QoS.
    FastRtps,
}

/// A request's bytes as they go on the wire, after the encapsulation header.
pub struct Payload(pub Vec<u8>);

/// Writes [`Payload`] as it is, little-endian CDR.
pub struct PayloadAdapter;

impl no_key::SerializerAdapter<Payload> for PayloadAdapter {
    type Error = Never;

    fn output_encoding() -> RepresentationIdentifier {
        RepresentationIdentifier::CDR_LE
    }

    fn to_bytes(value: &Payload) -> Result<Bytes, Self::Error> {
        Ok(Bytes::copy_from_slice(&value.0))
    }
}

/// The Cyclone request header (rmw_cyclonedds' `cdds_request_header_t`):
/// the client's id, then the sequence number as one `int64`, little-endian.
pub fn cyclone_header(guid_low: [u8; 8], seq: i64) -> [u8; 16] {
    let mut h = [0; 16];
    h[..8].copy_from_slice(&guid_low);
    h[8..].copy_from_slice(&seq.to_le_bytes());
    h
}

/// The DDS names of a ROS 2 service's two topics and types: service
/// `/planner/get_state` of `lifecycle_msgs/srv/GetState`.
pub fn topics(service: &str, package: &str, name: &str) -> [(String, String); 2] {
    [
        (format!("rq{service}Request"), format!("{package}::srv::dds_::{name}_Request_")),
        (format!("rr{service}Reply"), format!("{package}::srv::dds_::{name}_Response_")),
    ]
}

/// How a request is known again in its reply.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Id {
    Cyclone(i64),
    Enhanced(SampleIdentity),
}

pub struct ServiceClient<Req, Resp> {
    rmw: Rmw,
    writer: DataWriter<Payload, PayloadAdapter>,
    reader: DataReader<Raw, RawAdapter>,
    guid_low: [u8; 8],
    seq: i64,
    sent: u64,
    writer_matched: i32,
    reader_matched: i32,
    /// A request waiting for the reply path, and when it was asked for.
    held: Option<(Req, Instant)>,
    /// The request whose reply is awaited.
    awaited: Option<Id>,
    _resp: PhantomData<Resp>,
}

impl<Req: Serialize, Resp: DeserializeOwned> ServiceClient<Req, Resp> {
    /// The client of `service` (`/planner/get_state`) of type
    /// `package/srv/name`, reliable, volatile, keeping the last 10.
    pub fn new(
        participant: &DomainParticipant,
        rmw: Rmw,
        service: &str,
        package: &str,
        name: &str,
    ) -> Result<Self, String> {
        let qos = service_qos();
        let [(rq, rq_type), (rr, rr_type)] = topics(service, package, name);
        let err = |e: rustdds::dds::CreateError| format!("{service}: {e:?}");
        let rq_topic = participant.create_topic(rq, rq_type, &qos, TopicKind::NoKey).map_err(err)?;
        let rr_topic = participant.create_topic(rr, rr_type, &qos, TopicKind::NoKey).map_err(err)?;
        let writer = participant
            .create_publisher(&qos)
            .map_err(err)?
            .create_datawriter_no_key::<Payload, PayloadAdapter>(&rq_topic, Some(qos.clone()))
            .map_err(err)?;
        let reader = participant
            .create_subscriber(&qos)
            .map_err(err)?
            .create_datareader_no_key::<Raw, RawAdapter>(&rr_topic, Some(qos.clone()))
            .map_err(err)?;
        let mut guid_low = [0; 8];
        guid_low.copy_from_slice(&writer.guid().to_bytes()[8..16]);
        Ok(ServiceClient {
            rmw,
            writer,
            reader,
            guid_low,
            seq: 0,
            sent: 0,
            writer_matched: 0,
            reader_matched: 0,
            held: None,
            awaited: None,
            _resp: PhantomData,
        })
    }

    /// The reply reader, to register with the poll.
    pub fn reader_mut(&mut self) -> &mut DataReader<Raw, RawAdapter> {
        &mut self.reader
    }

    /// Whether a request would go out now: both ends have matched.
    pub fn matched(&mut self) -> bool {
        while let Some(s) = self.writer.try_recv_status() {
            if let rustdds::dds::statusevents::DataWriterStatus::PublicationMatched { current, .. } = s {
                self.writer_matched = current.count();
            }
        }
        while let Some(s) = self.reader.try_recv_status() {
            if let rustdds::dds::statusevents::DataReaderStatus::SubscriptionMatched { current, .. } = s {
                self.reader_matched = current.count();
            }
        }
        self.writer_matched > 0 && self.reader_matched > 0
    }

    /// Asks `request`: sent now if the reply path has matched, else held
    /// until it does (a newer request replaces a held one). Any reply to an
    /// earlier request is ignored from now on.
    pub fn request(&mut self, request: Req, now: Instant) {
        self.awaited = None;
        self.held = Some((request, now));
        self.flush(Duration::MAX, now);
    }

    /// Sends the held request if the reply path has matched; drops it once
    /// it waited `patience` (the asker has given up on it by then). Called
    /// on every turn of the loop: it also takes the endpoints' status
    /// events, whose channels are small and keep no event past their room.
    pub fn flush(&mut self, patience: Duration, now: Instant) {
        let matched = self.matched();
        let Some((_, since)) = &self.held else { return };
        if now.saturating_duration_since(*since) >= patience {
            self.held = None;
            return;
        }
        if !matched {
            return;
        }
        let Some((request, _)) = self.held.take() else { return };
        self.awaited = self.send(&request);
    }

    /// Whether a request waits for the reply path.
    pub fn holding(&self) -> bool {
        self.held.is_some()
    }

    /// The requests written so far.
    pub fn sent(&self) -> u64 {
        self.sent
    }

    fn send(&mut self, request: &Req) -> Option<Id> {
        self.sent += 1;
        let body = rustdds::cdr_encoding::to_vec::<Req, byteorder::LittleEndian>(request).ok()?;
        let options = rustdds::with_key::WriteOptionsBuilder::new().source_timestamp(rustdds::Timestamp::now()).build();
        match self.rmw {
            Rmw::CycloneDds => {
                self.seq += 1;
                let mut bytes = cyclone_header(self.guid_low, self.seq).to_vec();
                bytes.extend(body);
                self.writer.write_with_options(Payload(bytes), options).ok()?;
                Some(Id::Cyclone(self.seq))
            }
            Rmw::FastRtps => self.writer.write_with_options(Payload(body), options).ok().map(Id::Enhanced),
        }
    }

    /// The reply to the awaited request, if it came; other replies (to
    /// requests given up on, or to other clients of the service) are taken
    /// and dropped, awaited or not: left in the reader they would wake the
    /// poll again at once.
    pub fn reply(&mut self) -> Option<Resp> {
        let mut failed = 0;
        loop {
            let sample = match self.reader.take_next_sample() {
                Ok(Some(s)) => s,
                Ok(None) => return None,
                // A reply that does not read (consumed): not ours to keep.
                // Bounded: the next turn of the loop reads on.
                Err(_) if failed < 256 => {
                    failed += 1;
                    continue;
                }
                Err(_) => return None,
            };
            let related = sample.sample_info().related_sample_identity();
            let bytes = sample.into_value().0;
            let Some((id, resp)) = self.decode(&bytes, related) else { continue };
            if Some(id) == self.awaited {
                self.awaited = None;
                return Some(resp);
            }
        }
    }

    fn decode(&self, bytes: &[u8], related: Option<SampleIdentity>) -> Option<(Id, Resp)> {
        let (header, body) = bytes.split_first_chunk::<4>()?;
        let little = match header[..2] {
            [0, 1] => true,
            [0, 0] => false,
            _ => return None,
        };
        let decode = |b: &[u8]| {
            if little {
                rustdds::cdr_encoding::from_bytes::<Resp, byteorder::LittleEndian>(b).ok().map(|r| r.0)
            } else {
                rustdds::cdr_encoding::from_bytes::<Resp, byteorder::BigEndian>(b).ok().map(|r| r.0)
            }
        };
        match self.rmw {
            Rmw::CycloneDds => {
                let (h, rest) = body.split_first_chunk::<16>()?;
                if h[..8] != self.guid_low {
                    return None; // another client's
                }
                let seq =
                    h[8..]
                        .try_into()
                        .ok()
                        .map(|s| if little { i64::from_le_bytes(s) } else { i64::from_be_bytes(s) })?;
                Some((Id::Cyclone(seq), decode(rest)?))
            }
            Rmw::FastRtps => Some((Id::Enhanced(related?), decode(body)?)),
        }
    }
}

/// Services are reliable and volatile, keeping the last 10 (ROS 2's
/// `rmw_qos_profile_services_default`).
pub fn service_qos() -> QosPolicies {
    rustdds::QosPolicyBuilder::new()
        .reliability(rustdds::policy::Reliability::Reliable { max_blocking_time: rustdds::Duration::from_millis(100) })
        .durability(rustdds::policy::Durability::Volatile)
        .history(rustdds::policy::History::KeepLast { depth: 10 })
        .build()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cyclone_header_carries_the_sequence_number_as_one_int64() {
        let h = cyclone_header([1, 2, 3, 4, 5, 6, 7, 8], 2);
        assert_eq!(h[..8], [1, 2, 3, 4, 5, 6, 7, 8]);
        // rmw_cyclonedds reads `int64 seq`: 2, not 2 << 32.
        assert_eq!(i64::from_le_bytes(h[8..].try_into().unwrap()), 2);
        assert_eq!(h[8..], [2, 0, 0, 0, 0, 0, 0, 0]);
    }

    #[test]
    fn a_service_has_ros_2s_topic_and_type_names() {
        let [(rq, rq_type), (rr, rr_type)] = topics("/planner/get_state", "lifecycle_msgs", "GetState");
        assert_eq!(
            (rq.as_str(), rq_type.as_str()),
            ("rq/planner/get_stateRequest", "lifecycle_msgs::srv::dds_::GetState_Request_")
        );
        assert_eq!(
            (rr.as_str(), rr_type.as_str()),
            ("rr/planner/get_stateReply", "lifecycle_msgs::srv::dds_::GetState_Response_")
        );
    }
}
