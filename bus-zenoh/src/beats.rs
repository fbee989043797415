//! The leader's beats over UDP, beside Zenoh: a liveness signal that no
//! lost segment can hold back.
//!
//! Everything the boards say goes over Zenoh, on TCP. On a lossy link a
//! segment lost twice stalls a TCP stream for its retransmission timeout
//! (Linux: 200 ms, then 400 ms), longer than a follower's lease: the
//! follower hears nothing, though the leader is alive, and takes over (a
//! false takeover). A datagram is never waited for: a lost beat is just
//! one beat fewer, and the next comes a beat period later.
//!
//! So a board given `beats` (deployment: `beats = { listen = "udp/…",
//! send = ["udp/…"] }`) sends each of its beats, while it leads, also as
//! one datagram ([`BeatWire`]) to every `send` address, and hears the
//! other boards' datagrams on `listen`. **A datagram only keeps alive a
//! leader already heard over Zenoh:** it renews "last heard" when its board
//! and epoch are the ones the board last heard through Zenoh, and does
//! nothing else. It never raises the epoch, never makes a leader step
//! down, never carries state. So a datagram that is forged, replayed or
//! from an old leader can at worst hold off a takeover while it keeps
//! coming; it cannot cause one, and it cannot change a decision (an
//! attacker who can send to the port can also drop the packets that
//! carry the status, which holds the agents in safe mode either way).

use crate::wire::{self, VERSION};
use serde::{Deserialize, Serialize};
use std::net::{SocketAddr, UdpSocket};
use std::sync::Weak;
use std::time::Duration;

/// The largest datagram read (a beat is some 60 bytes).
const MAX_DATAGRAM: usize = 512;

/// How often the listening thread looks whether its board is gone.
const POLL: Duration = Duration::from_millis(200);

/// Where a board hears beats and where it sends them, resolved.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Beats {
    pub listen: SocketAddr,
    pub send: Vec<SocketAddr>,
}

/// One beat: the leading board and its epoch.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct BeatWire {
    pub v: u32,
    pub board: String,
    pub epoch: u64,
}

/// What hears the beats (the board's inbox).
pub(crate) trait Hears: Send + Sync + 'static {
    /// A beat of `board` at `epoch` came.
    fn alive(&self, board: &str, epoch: u64);
    /// A datagram that is not a beat came.
    fn refused(&self);
}

/// The board's UDP socket: it sends beats from it and a thread hears on it.
#[derive(Debug)]
pub(crate) struct BeatLink {
    socket: UdpSocket,
    send: Vec<SocketAddr>,
}

impl BeatLink {
    /// Binds `beats.listen` and starts the thread that hears on it; the
    /// thread ends once `hears` is dropped.
    pub(crate) fn open<H: Hears>(beats: &Beats, hears: Weak<H>) -> std::io::Result<BeatLink> {
        let socket = UdpSocket::bind(beats.listen)?;
        socket.set_read_timeout(Some(POLL))?;
        let reader = socket.try_clone()?;
        std::thread::Builder::new().name("situ-beats".into()).spawn(move || listen(&reader, &hears))?;
        // Sending never blocks the board's thread.
        socket.set_nonblocking(true)?;
        Ok(BeatLink { socket, send: beats.send.clone() })
    }

    /// Sends one beat to every address (a datagram the kernel cannot take
    /// now is dropped: the next beat follows).
    pub(crate) fn beat(&self, board: &str, epoch: u64) {
        let bytes = serde_json::to_vec(&BeatWire { v: VERSION, board: board.to_string(), epoch }).expect("JSON");
        for to in &self.send {
            let _ = self.socket.send_to(&bytes, to);
        }
    }

    /// The address it hears on (with the port the system chose for `:0`).
    pub(crate) fn local_addr(&self) -> Option<SocketAddr> {
        self.socket.local_addr().ok()
    }
}

fn listen<H: Hears>(socket: &UdpSocket, hears: &Weak<H>) {
    let mut buf = [0u8; MAX_DATAGRAM];
    loop {
        let got = socket.recv_from(&mut buf);
        let Some(h) = hears.upgrade() else { return };
        // An error is the poll's timeout, or an ICMP "port unreachable"
        // reported on this socket for a beat it sent: nothing to hear.
        if let Ok((n, _)) = got {
            match wire::parse::<BeatWire>(&buf[..n]) {
                Ok(b) => h.alive(&b.board, b.epoch),
                Err(_) => h.refused(),
            }
        }
    }
}

/// Whether `endpoint` is written `udp/HOST:PORT` (the host not resolved).
pub fn is_endpoint(endpoint: &str) -> bool {
    endpoint
        .strip_prefix("udp/")
        .and_then(|rest| rest.rsplit_once(':'))
        .is_some_and(|(h, p)| !h.is_empty() && p.parse::<u16>().is_ok())
}

/// `udp/HOST:PORT` as an address (the host resolved), or why not.
pub fn resolve(endpoint: &str) -> Result<SocketAddr, String> {
    if !is_endpoint(endpoint) {
        return Err(format!("`{endpoint}` is not `udp/HOST:PORT`"));
    }
    let rest = &endpoint["udp/".len()..];
    use std::net::ToSocketAddrs;
    let mut addrs = rest.to_socket_addrs().map_err(|e| format!("`{endpoint}`: {e}"))?;
    addrs.next().ok_or_else(|| format!("`{endpoint}`: the host has no address"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::{Arc, Mutex};
    use std::time::Instant;

    #[derive(Default)]
    struct Heard {
        beats: Mutex<Vec<(String, u64)>>,
        refused: Mutex<u32>,
    }

    impl Hears for Heard {
        fn alive(&self, board: &str, epoch: u64) {
            self.beats.lock().unwrap().push((board.to_string(), epoch));
        }
        fn refused(&self) {
            *self.refused.lock().unwrap() += 1;
        }
    }

    fn until(what: &str, ok: impl Fn() -> bool) {
        let deadline = Instant::now() + Duration::from_secs(10);
        while !ok() {
            assert!(Instant::now() < deadline, "{what}");
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    #[test]
    fn a_beat_sent_is_heard_and_garbage_is_counted() {
        let any: SocketAddr = "127.0.0.1:0".parse().unwrap();
        let heard = Arc::new(Heard::default());
        let hearing = BeatLink::open(&Beats { listen: any, send: vec![] }, Arc::downgrade(&heard)).unwrap();
        let to = hearing.local_addr().unwrap();
        let nobody = Arc::new(Heard::default());
        let sending = BeatLink::open(&Beats { listen: any, send: vec![to] }, Arc::downgrade(&nobody)).unwrap();
        // Datagrams on loopback may still be dropped: beat until one is heard.
        until("a beat heard", || {
            sending.beat("a", 7);
            !heard.beats.lock().unwrap().is_empty()
        });
        assert!(heard.beats.lock().unwrap().iter().all(|b| *b == ("a".to_string(), 7)));
        let raw = UdpSocket::bind(any).unwrap();
        until("garbage refused", || {
            raw.send_to(b"{\"v\": 1, \"board\": 3}", to).unwrap();
            *heard.refused.lock().unwrap() > 0
        });
    }

    #[test]
    fn endpoints_are_udp_host_port() {
        assert_eq!(resolve("udp/127.0.0.1:7460"), Ok("127.0.0.1:7460".parse().unwrap()));
        assert_eq!(resolve("udp/localhost:7460").map(|a| a.port()), Ok(7460));
        for bad in ["tcp/127.0.0.1:7460", "udp/127.0.0.1", "udp/:7460", "udp/127.0.0.1:99999", "127.0.0.1:7460"] {
            assert!(resolve(bad).unwrap_err().contains("is not `udp/HOST:PORT`"), "{bad}");
        }
    }
}
