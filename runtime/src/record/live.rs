//! The live log of a run for its page (`situ run … --serve`): the run's recorder
//! tells a [`PageTap`] each message it writes; the tap keeps what the page
//! draws in a [`Live`] log; the page asks `/api/live?since=N` and the
//! answer comes as soon as there is something after `N` (a long poll: one
//! round trip on the loopback after a state change, no socket kept open
//! between two changes, no library in the page).
//!
//! The log keeps the run from its start, so a page opened late shows the
//! whole run; past [`KEEP`] entries the oldest are folded into a base (the
//! state, the states visited and the agents' modes at the first entry
//! kept), so that a long run's log stays bounded.

use super::mcap::Tap;
use super::timeline::{Entry, TOPICS};
use serde_json::{json, Value as Json};
use std::collections::{BTreeMap, HashMap, VecDeque};
use std::sync::{Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

/// Entries kept before the oldest are folded into the base.
pub const KEEP: usize = 200_000;
/// Entries folded at a time, once [`KEEP`] is passed.
const FOLD: usize = KEEP / 4;
/// Entries in one answer at most (the page asks again at once for more).
const BATCH: usize = 5_000;
/// How long a poll waits for something new before answering with nothing.
pub const POLL: Duration = Duration::from_secs(15);

/// The state, the states visited and the modes before the first entry kept.
#[derive(Default)]
struct Base {
    state: Option<String>,
    visited: Vec<String>,
    modes: BTreeMap<String, Json>,
    refused: u64,
}

#[derive(Default)]
struct Log {
    /// Each entry: its JSON for the page, and what folding it needs.
    entries: VecDeque<(Json, Fold)>,
    /// The sequence number of `entries[0]`.
    first: u64,
    base: Base,
    /// The run's latest time (ns).
    end_ns: u64,
    over: bool,
    /// Polls answered so far, those answered with the end, and polls
    /// waiting now.
    answered: u64,
    told_over: u64,
    waiting: usize,
}

/// What folding an entry into the base changes.
enum Fold {
    State(String),
    Mode(String),
    Refused,
}

/// The log of a run for its pages, shared by the run (writing) and the
/// server (reading).
#[derive(Default)]
pub struct Live {
    log: Mutex<Log>,
    moved: Condvar,
}

fn wall_us() -> u64 {
    SystemTime::now().duration_since(UNIX_EPOCH).map_or(0, |d| d.as_micros() as u64)
}

impl Live {
    fn lock(&self) -> MutexGuard<'_, Log> {
        self.log.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Adds a message's entry and wakes the pages waiting.
    pub fn push(&self, entry: Entry) {
        let mut log = self.lock();
        log.end_ns = log.end_ns.max(entry.time());
        let (mut json, fold) = match entry {
            Entry::Change(c) => {
                let to = c.to.clone();
                (c.json(), Fold::State(to))
            }
            Entry::Mode(m) => {
                let agent = m.agent.clone();
                (m.json(), Fold::Mode(agent))
            }
            Entry::Refused(r) => (r.json(), Fold::Refused),
            Entry::Time(_) => {
                drop(log);
                return;
            }
        };
        json["kind"] = json!(match fold {
            Fold::State(_) => "change",
            Fold::Mode(_) => "mode",
            Fold::Refused => "refused",
        });
        // When the server had it: the page measures how late it is.
        json["wall_us"] = json!(wall_us());
        log.entries.push_back((json, fold));
        if log.entries.len() > KEEP {
            log.fold(FOLD);
        }
        drop(log);
        self.moved.notify_all();
    }

    /// The run's clock moved (an accepted event, a tick) with nothing for
    /// the page to draw but the time; the pages are told with the next entry.
    pub fn clock(&self, t: u64) {
        let mut log = self.lock();
        log.end_ns = log.end_ns.max(t);
    }

    /// The run is over: every page waiting is answered so, and told so
    /// from now on.
    pub fn finish(&self) {
        self.lock().over = true;
        self.moved.notify_all();
    }

    /// Waits until a page asked for the run (or `until` passes).
    pub fn wait_for_a_page(&self, until: Option<Instant>) -> bool {
        let no_page = |l: &mut Log| l.answered == 0 && l.waiting == 0;
        match until {
            None => {
                drop(self.moved.wait_while(self.lock(), no_page).unwrap_or_else(|p| p.into_inner()));
                true
            }
            Some(u) => {
                let left = u.saturating_duration_since(Instant::now());
                let (log, r) =
                    self.moved.wait_timeout_while(self.lock(), left, no_page).unwrap_or_else(|p| p.into_inner());
                drop(log);
                !r.timed_out()
            }
        }
    }

    /// After [`finish`](Self::finish): waits (at most `at_most`) until no
    /// page is left waiting and, if a page ever asked, one heard the end
    /// (a page whose next poll is on its way when the run ends).
    pub fn wait_for_the_pages(&self, at_most: Duration) {
        let unheard = |l: &mut Log| l.waiting > 0 || (l.answered > 0 && l.told_over == 0);
        drop(self.moved.wait_timeout_while(self.lock(), at_most, unheard).unwrap_or_else(|p| p.into_inner()));
    }

    /// The answer to `/api/live?since=N`: the entries from `since` on, once
    /// there are any (or the run is over, or [`POLL`] passed), and whether
    /// it tells the end. The page counts as waiting until the server calls
    /// [`delivered`](Self::delivered), so that the run's process does not
    /// end with an answer half sent.
    pub fn poll(&self, since: u64) -> (String, bool) {
        let mut log = self.lock();
        log.waiting += 1;
        self.moved.notify_all();
        let nothing_new = |l: &mut Log| since >= l.first + l.entries.len() as u64 && !l.over;
        let (log, _) = self.moved.wait_timeout_while(log, POLL, nothing_new).unwrap_or_else(|p| p.into_inner());
        log.answer(since)
    }

    /// An answer of [`poll`](Self::poll) was sent (or could not be).
    pub fn delivered(&self, over: bool) {
        let mut log = self.lock();
        log.waiting = log.waiting.saturating_sub(1);
        log.answered += 1;
        log.told_over += u64::from(over);
        drop(log);
        self.moved.notify_all();
    }
}

impl Log {
    /// Folds the `n` oldest entries into the base.
    fn fold(&mut self, n: usize) {
        for (json, fold) in self.entries.drain(..n.min(self.entries.len())) {
            match fold {
                Fold::State(s) => {
                    if !self.base.visited.contains(&s) {
                        self.base.visited.push(s.clone());
                    }
                    self.base.state = Some(s);
                }
                Fold::Mode(agent) => {
                    self.base.modes.insert(agent, json);
                }
                Fold::Refused => self.base.refused += 1,
            }
        }
        self.first += n as u64;
    }

    /// The answer's JSON, and whether it tells the end.
    fn answer(&self, since: u64) -> (String, bool) {
        let next = self.first + self.entries.len() as u64;
        // A page behind the first entry kept starts again from the base.
        let reset = since < self.first;
        let from = if reset { 0 } else { (since - self.first).min(self.entries.len() as u64) as usize };
        let entries: Vec<&Json> = self.entries.iter().skip(from).take(BATCH).map(|(j, _)| j).collect();
        let upto = self.first + (from + entries.len()) as u64;
        let base = reset.then(|| {
            json!({
                "state": self.base.state,
                "visited": self.base.visited,
                "modes": self.base.modes,
                "refused": self.base.refused,
            })
        });
        let over = self.over && upto == next;
        let answer = json!({
            "first": self.first,
            "next": upto,
            "more": upto < next,
            "reset": reset,
            "base": base,
            "entries": entries,
            "end_ns": self.end_ns,
            // Over only once the page has every entry.
            "over": over,
            "wall_us": wall_us(),
        })
        .to_string();
        (answer, over)
    }
}

/// The recorder's [`Tap`] to the page: the messages of a situ run's topics
/// read as the page reads a recording's.
pub struct PageTap {
    live: std::sync::Arc<Live>,
    topics: HashMap<u16, &'static str>,
}

impl PageTap {
    pub fn new(live: std::sync::Arc<Live>) -> PageTap {
        PageTap { live, topics: HashMap::new() }
    }
}

impl Tap for PageTap {
    fn channel(&mut self, id: u16, topic: &str, _schema_name: &str, _schema: &str) {
        if let Some(t) = TOPICS.into_iter().find(|t| *t == topic) {
            self.topics.insert(id, t);
        }
    }

    fn message(&mut self, id: u16, time: u64, bytes: &[u8]) {
        let Some(topic) = self.topics.get(&id) else { return };
        let Ok(msg) = serde_json::from_slice::<Json>(bytes) else { return };
        match Entry::of(topic, time, &msg) {
            Some(Entry::Time(t)) => self.live.clock(t),
            Some(entry) => self.live.push(entry),
            None => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::timeline::{Change, ModeAt};

    fn change(t: u64, from: &str, to: &str) -> Entry {
        Entry::Change(Change { t, from: from.into(), to: to.into(), rules: vec!["r".into()], explain: String::new() })
    }

    fn answer(live: &Live, since: u64) -> Json {
        let (body, over) = live.poll(since);
        live.delivered(over);
        serde_json::from_str(&body).unwrap()
    }

    #[test]
    fn a_poll_gets_what_came_after_it() {
        let live = Live::default();
        live.push(change(5, "A", "B"));
        live.push(Entry::Mode(ModeAt { t: 6, agent: "X".into(), function: "f".into(), mode: "running".into() }));
        let a = answer(&live, 0);
        assert_eq!(a["next"], 2);
        assert_eq!(a["entries"][0]["kind"], "change");
        assert_eq!(a["entries"][0]["to"], "B");
        assert_eq!(a["entries"][1]["agent"], "X");
        assert_eq!(a["over"], false);
        live.push(change(9, "B", "C"));
        let b = answer(&live, 2);
        assert_eq!(b["entries"].as_array().unwrap().len(), 1);
        assert_eq!(b["end_ns"], 9);
        live.finish();
        let c = answer(&live, 3);
        assert_eq!(c["over"], true);
        assert!(c["entries"].as_array().unwrap().is_empty());
    }

    #[test]
    fn a_waiting_poll_is_answered_by_the_next_change() {
        let live = std::sync::Arc::new(Live::default());
        let l = live.clone();
        let page = std::thread::spawn(move || answer(&l, 0));
        assert!(live.wait_for_a_page(Some(Instant::now() + Duration::from_secs(10))));
        live.push(change(1, "A", "B"));
        let a = page.join().unwrap();
        assert_eq!(a["entries"][0]["to"], "B");
    }

    #[test]
    fn a_long_run_folds_its_oldest_entries_into_the_base() {
        let live = Live::default();
        let states = ["A", "B", "C"];
        for i in 0..KEEP + 1 {
            live.push(change(i as u64, states[i % 3], states[(i + 1) % 3]));
        }
        let a = answer(&live, 0);
        assert_eq!(a["reset"], true);
        assert_eq!(a["first"], FOLD as u64);
        // The entry folded last went to state FOLD % 3.
        assert_eq!(a["base"]["state"], states[FOLD % 3]);
        assert_eq!(a["base"]["visited"].as_array().unwrap().len(), 3);
        assert_eq!(a["entries"].as_array().unwrap().len(), BATCH);
        assert_eq!(a["more"], true);
        assert_eq!(a["entries"][0]["t"], FOLD as u64);
    }
}
