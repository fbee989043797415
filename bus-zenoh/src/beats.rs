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
use std::io::ErrorKind;
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

/// The board's UDP sockets: a thread hears on the `listen` one; beats go
/// from sockets of their own (one per address family), which never block.
/// (One socket could not be both: its duplicate for the thread would
/// share the non-blocking flag, and the thread would spin.)
#[derive(Debug)]
pub(crate) struct BeatLink {
    listen: SocketAddr,
    senders: Vec<(UdpSocket, Vec<SocketAddr>)>,
}

impl BeatLink {
    /// Binds `beats.listen` and starts the thread that hears on it; the
    /// thread ends once `hears` is dropped.
    pub(crate) fn open<H: Hears>(beats: &Beats, hears: Weak<H>) -> std::io::Result<BeatLink> {
        let socket = UdpSocket::bind(beats.listen)?;
        socket.set_read_timeout(Some(POLL))?;
        let listen = socket.local_addr()?;
        let mut senders = Vec::new();
        for v6 in [false, true] {
            let to: Vec<SocketAddr> = beats.send.iter().filter(|a| a.is_ipv6() == v6).copied().collect();
            if to.is_empty() {
                continue;
            }
            let any: SocketAddr = if v6 { "[::]:0" } else { "0.0.0.0:0" }.parse().expect("an address");
            let sender = UdpSocket::bind(any)?;
            // A datagram the kernel cannot take now is dropped, never
            // waited for: the board's thread sends them.
            sender.set_nonblocking(true)?;
            senders.push((sender, to));
        }
        std::thread::Builder::new().name("situ-beats".into()).spawn(move || listen_on(&socket, &hears))?;
        Ok(BeatLink { listen, senders })
    }

    /// Sends one beat to every address (a datagram the kernel cannot take
    /// now is dropped: the next beat follows).
    pub(crate) fn beat(&self, board: &str, epoch: u64) {
        let bytes = serde_json::to_vec(&BeatWire { v: VERSION, board: board.to_string(), epoch }).expect("JSON");
        for (socket, to) in &self.senders {
            for addr in to {
                let _ = socket.send_to(&bytes, addr);
            }
        }
    }

    /// The address it hears on (with the port the system chose for `:0`).
    pub(crate) fn listen_addr(&self) -> SocketAddr {
        self.listen
    }
}

fn listen_on<H: Hears>(socket: &UdpSocket, hears: &Weak<H>) {
    let mut buf = [0u8; MAX_DATAGRAM];
    loop {
        let got = socket.recv_from(&mut buf);
        let Some(h) = hears.upgrade() else { return };
        match got {
            Ok((n, _)) => match wire::parse::<BeatWire>(&buf[..n]) {
                Ok(b) => h.alive(&b.board, b.epoch),
                Err(_) => h.refused(),
            },
            // The poll's timeout: nothing to hear.
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut | ErrorKind::Interrupted) => {}
            // Anything else is not waited on in a loop: the next look is a
            // poll later.
            Err(_) => std::thread::sleep(POLL),
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
        let to = hearing.listen_addr();
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

    /// CPU time (clock ticks) of this process's threads named `name`.
    fn cpu_ticks(name: &str) -> u64 {
        let mut ticks = 0;
        for task in std::fs::read_dir("/proc/self/task").unwrap().flatten() {
            let comm = std::fs::read_to_string(task.path().join("comm")).unwrap_or_default();
            if comm.trim() != name {
                continue;
            }
            let stat = std::fs::read_to_string(task.path().join("stat")).unwrap_or_default();
            // After the command's closing parenthesis: fields 3 on; utime
            // and stime are fields 14 and 15.
            let rest = &stat[stat.rfind(')').map_or(0, |i| i + 2)..];
            let f: Vec<u64> = rest.split_whitespace().map(|x| x.parse().unwrap_or(0)).collect();
            ticks += f.get(11).unwrap_or(&0) + f.get(12).unwrap_or(&0);
        }
        ticks
    }

    #[test]
    fn the_thread_that_hears_sleeps_while_nothing_comes() {
        let heard = Arc::new(Heard::default());
        let any: SocketAddr = "127.0.0.1:0".parse().unwrap();
        let link = BeatLink::open(&Beats { listen: any, send: vec![any] }, Arc::downgrade(&heard)).unwrap();
        link.beat("a", 1);
        let before = cpu_ticks("situ-beats");
        std::thread::sleep(Duration::from_secs(1));
        // A thread that waits takes no CPU; one that spun (a non-blocking
        // socket) would take most of a core's 100 ticks a second.
        let used = cpu_ticks("situ-beats") - before;
        assert!(used < 25, "the threads that hear beats took {used} ticks in 1 s");
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
