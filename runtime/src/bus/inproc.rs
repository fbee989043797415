//! The in-process bus: bounded queues behind mutexes, with a condition
//! variable per receiver so that real-time agents can sleep until their next
//! step and still be woken by an urgent message.

use super::{Attention, Bus, BusCounters, DataMsg, Doorbell, EventMsg, StatusMsg, Wake};
use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::sync::{Condvar, Mutex, MutexGuard};
use std::time::Instant;

/// Queue sizes.
#[derive(Debug, Clone, Copy)]
pub struct Capacity {
    /// Data queued per receiving agent (urgent data has its own lane of the
    /// same size).
    pub data: usize,
    /// Events queued for the Bulletinboard.
    pub events: usize,
}

impl Default for Capacity {
    fn default() -> Self {
        Capacity { data: 64, events: 65_536 }
    }
}

#[derive(Default)]
struct Mailbox {
    data: VecDeque<DataMsg>,
    urgent: VecDeque<DataMsg>,
    status: Option<StatusMsg>,
    /// An urgent message arrived since the agent last waited.
    woken: bool,
    /// Some input (data or status) arrived since the agent last waited.
    input: bool,
    /// Rung on every arrival (a worker thread's bell).
    doorbell: Option<Arc<Doorbell>>,
}

#[derive(Default)]
struct Board {
    events: VecDeque<EventMsg>,
    urgent: VecDeque<EventMsg>,
    lost: u64,
    /// Something other than an event arrived for the board (another
    /// board's log): its wait ends.
    rung: bool,
}

struct Slot<T> {
    inner: Mutex<T>,
    bell: Condvar,
}

impl<T: Default> Slot<T> {
    fn new() -> Self {
        Slot { inner: Mutex::new(T::default()), bell: Condvar::new() }
    }

    fn lock(&self) -> MutexGuard<'_, T> {
        // A panicking agent must not take the bus down with it.
        self.inner.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}

#[derive(Default)]
struct Counters {
    data_sent: AtomicU64,
    data_overflow: AtomicU64,
    events_sent: AtomicU64,
    events_overflow: AtomicU64,
    status_sent: AtomicU64,
    urgent: AtomicU64,
}

pub struct InProc {
    capacity: Capacity,
    boxes: Vec<Slot<Mailbox>>,
    board: Slot<Board>,
    counters: Counters,
    closed: AtomicBool,
}

impl InProc {
    /// Ends the board's [`Bus::wait_events`] now (something other than an
    /// event arrived for it: another board's log).
    pub fn ring_board(&self) {
        self.board.lock().rung = true;
        self.board.bell.notify_all();
    }

    /// A bus for `agents` agents.
    pub fn new(agents: usize, capacity: Capacity) -> InProc {
        InProc {
            capacity,
            boxes: (0..agents).map(|_| Slot::new()).collect(),
            board: Slot::new(),
            counters: Counters::default(),
            closed: AtomicBool::new(false),
        }
    }
}

fn bump(c: &AtomicU64) {
    c.fetch_add(1, Ordering::Relaxed);
}

impl Bus for InProc {
    fn send_data(&self, msg: DataMsg) {
        let Some(slot) = self.boxes.get(msg.to as usize) else { return };
        bump(&self.counters.data_sent);
        let urgent = msg.urgent;
        let mut mb = slot.lock();
        let queue = if urgent { &mut mb.urgent } else { &mut mb.data };
        if queue.len() >= self.capacity.data {
            queue.pop_front();
            bump(&self.counters.data_overflow);
        }
        queue.push_back(msg);
        mb.input = true;
        if urgent {
            bump(&self.counters.urgent);
            mb.woken = true;
        }
        let bell = mb.doorbell.clone();
        drop(mb);
        slot.bell.notify_all();
        if let Some(b) = bell {
            b.ring();
        }
    }

    fn send_event(&self, msg: EventMsg) {
        bump(&self.counters.events_sent);
        let urgent = msg.urgent;
        let mut b = self.board.lock();
        if b.events.len() + b.urgent.len() >= self.capacity.events {
            b.lost += 1;
            bump(&self.counters.events_overflow);
            return;
        }
        if urgent {
            bump(&self.counters.urgent);
            b.urgent.push_back(msg);
        } else {
            b.events.push_back(msg);
        }
        drop(b);
        self.board.bell.notify_all();
    }

    fn send_status(&self, msg: StatusMsg) {
        bump(&self.counters.status_sent);
        // Each distinct bell once, after every mailbox has the status.
        let mut bells: Vec<Arc<Doorbell>> = Vec::new();
        for slot in &self.boxes {
            let mut mb = slot.lock();
            mb.status = Some(msg);
            mb.input = true;
            if let Some(b) = &mb.doorbell {
                if !bells.iter().any(|x| Arc::ptr_eq(x, b)) {
                    bells.push(b.clone());
                }
            }
            drop(mb);
            slot.bell.notify_all();
        }
        for b in bells {
            b.ring();
        }
    }

    fn set_doorbell(&self, agent: u32, bell: Arc<Doorbell>) {
        if let Some(slot) = self.boxes.get(agent as usize) {
            slot.lock().doorbell = Some(bell);
        }
    }

    fn attention(&self, agent: u32) -> Attention {
        let Some(slot) = self.boxes.get(agent as usize) else { return Attention::default() };
        let mut mb = slot.lock();
        Attention { urgent: std::mem::take(&mut mb.woken), input: std::mem::take(&mut mb.input) }
    }

    fn recv_data(&self, agent: u32, out: &mut Vec<DataMsg>) {
        let Some(slot) = self.boxes.get(agent as usize) else { return };
        let mut mb = slot.lock();
        out.extend(mb.urgent.drain(..));
        out.extend(mb.data.drain(..));
        mb.woken = false;
        mb.input = false;
    }

    fn discard_data(&self, agent: u32) -> usize {
        let Some(slot) = self.boxes.get(agent as usize) else { return 0 };
        let mut mb = slot.lock();
        let n = mb.data.len() + mb.urgent.len();
        mb.data.clear();
        mb.urgent.clear();
        mb.woken = false;
        n
    }

    fn recv_events(&self, out: &mut Vec<EventMsg>) -> u64 {
        let mut b = self.board.lock();
        out.extend(b.urgent.drain(..));
        out.extend(b.events.drain(..));
        std::mem::take(&mut b.lost)
    }

    fn status(&self, agent: u32) -> Option<StatusMsg> {
        self.boxes.get(agent as usize).and_then(|s| s.lock().status)
    }

    fn wait(&self, agent: u32, deadline: Instant) -> Wake {
        let Some(slot) = self.boxes.get(agent as usize) else { return Wake::Closed };
        let mut mb = slot.lock();
        loop {
            if self.closed.load(Ordering::Acquire) {
                return Wake::Closed;
            }
            if mb.woken {
                mb.woken = false;
                return Wake::Urgent;
            }
            let now = Instant::now();
            if now >= deadline {
                return Wake::Deadline;
            }
            mb = slot.bell.wait_timeout(mb, deadline - now).unwrap_or_else(|p| p.into_inner()).0;
        }
    }

    fn wait_input(&self, agent: u32, deadline: Instant) -> Wake {
        let Some(slot) = self.boxes.get(agent as usize) else { return Wake::Closed };
        let mut mb = slot.lock();
        loop {
            if self.closed.load(Ordering::Acquire) {
                return Wake::Closed;
            }
            if mb.input || mb.woken {
                mb.input = false;
                return if std::mem::take(&mut mb.woken) { Wake::Urgent } else { Wake::Deadline };
            }
            let now = Instant::now();
            if now >= deadline {
                return Wake::Deadline;
            }
            mb = slot.bell.wait_timeout(mb, deadline - now).unwrap_or_else(|p| p.into_inner()).0;
        }
    }

    fn wait_events(&self, deadline: Instant) -> Wake {
        let mut b = self.board.lock();
        loop {
            if self.closed.load(Ordering::Acquire) {
                return Wake::Closed;
            }
            if !b.urgent.is_empty() {
                return Wake::Urgent;
            }
            if !b.events.is_empty() || b.lost > 0 || std::mem::take(&mut b.rung) {
                return Wake::Deadline;
            }
            let now = Instant::now();
            if now >= deadline {
                return Wake::Deadline;
            }
            b = self.board.bell.wait_timeout(b, deadline - now).unwrap_or_else(|p| p.into_inner()).0;
        }
    }

    fn close(&self) {
        self.closed.store(true, Ordering::Release);
        for slot in &self.boxes {
            let mb = slot.lock();
            slot.bell.notify_all();
            if let Some(b) = &mb.doorbell {
                b.ring();
            }
        }
        let _guard = self.board.lock();
        self.board.bell.notify_all();
    }

    fn counters(&self) -> BusCounters {
        let c = &self.counters;
        let get = |a: &AtomicU64| a.load(Ordering::Relaxed);
        BusCounters {
            data_sent: get(&c.data_sent),
            data_overflow: get(&c.data_overflow),
            events_sent: get(&c.events_sent),
            events_overflow: get(&c.events_overflow),
            status_sent: get(&c.status_sent),
            urgent: get(&c.urgent),
            rejected: 0,
            unsendable: 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::agent::Body;
    use std::sync::Arc;
    use std::time::Duration;

    fn datum(from: u32, to: u32, n: u64, urgent: bool) -> DataMsg {
        DataMsg { from, to, time: n, urgent, body: Body::local(n) }
    }

    #[test]
    fn data_keeps_the_latest_when_full() {
        let bus = InProc::new(2, Capacity { data: 3, events: 10 });
        for n in 0..10 {
            bus.send_data(datum(0, 1, n, false));
        }
        let mut out = Vec::new();
        bus.recv_data(1, &mut out);
        let kept: Vec<u64> = out.iter().map(|d| d.time).collect();
        assert_eq!(kept, [7, 8, 9]);
        assert_eq!(bus.counters().data_overflow, 7);
    }

    #[test]
    fn urgent_data_overtakes_the_queue() {
        let bus = InProc::new(2, Capacity::default());
        bus.send_data(datum(0, 1, 1, false));
        bus.send_data(datum(0, 1, 2, false));
        bus.send_data(datum(0, 1, 3, true));
        let mut out = Vec::new();
        bus.recv_data(1, &mut out);
        assert_eq!(out.iter().map(|d| d.time).collect::<Vec<_>>(), [3, 1, 2]);
    }

    #[test]
    fn events_are_never_lost_silently() {
        let bus = InProc::new(1, Capacity { data: 4, events: 5 });
        for t in 0..8 {
            bus.send_event(EventMsg { agent: 0, event: 0, time: t, payload: vec![], urgent: false });
        }
        let mut out = Vec::new();
        assert_eq!(bus.recv_events(&mut out), 3, "three events lost, and said so");
        assert_eq!(out.len(), 5);
        assert_eq!(bus.recv_events(&mut out), 0);
        assert_eq!(bus.counters().events_overflow, 3);
    }

    #[test]
    fn an_urgent_datum_wakes_a_waiting_receiver() {
        let bus = Arc::new(InProc::new(2, Capacity::default()));
        let sender = bus.clone();
        let start = Instant::now();
        let t = std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(20));
            sender.send_data(datum(0, 1, 1, true));
        });
        // Without the urgent datum it would sleep 10 s.
        let wake = bus.wait(1, start + Duration::from_secs(10));
        t.join().unwrap();
        assert_eq!(wake, Wake::Urgent);
        assert!(start.elapsed() < Duration::from_secs(10));
        bus.close();
        assert_eq!(bus.wait(1, Instant::now() + Duration::from_secs(10)), Wake::Closed);
    }
}
