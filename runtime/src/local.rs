//! A Bulletinboard with the organisation around it, in one process and
//! driven by its caller: what `situ repl`, the library's embedded board
//! (`situ_api::Board`, hence the Python package and the C API) share, so
//! that they take, drop and refuse the same events as a running stack.
//!
//! [`LocalBoard::post`] is the one admission rule for a caller that
//! reports on the agents' behalf (language reference §10.4, §10.7):
//! - an event of an agent that sleeps in the current situation is
//!   **dropped** ([`NotTaken::Sleeping`]): a sleeping agent is not
//!   stepped, so a run of situ's agents never reports it (a caller whose
//!   agents are not situ's takes them: [`LocalBoard::set_take_sleeping`]);
//! - an event the engine's acceptance rule refuses (payload, out of
//!   order, from the future: [`Engine::admit`](crate::rete::Engine::admit))
//!   is **refused** ([`NotTaken::Refused`]).
//!
//! Either way nothing changes. A taken event moves the agent's FSM first,
//! then the rules come to rest, then every FSM sees the new state, as in
//! the running stack ([`crate::runner`]).

use crate::bulletinboard::{Bulletinboard, SwapError, SwapReport};
use crate::organise::Organisation;
use crate::rete::{PostError, StateChange};
use situ_bundle::{Content, Mode, Value};
use std::sync::Arc;

/// Why an event was not taken. Nothing changed.
#[derive(Debug, Clone, PartialEq)]
pub enum NotTaken {
    /// Its agent sleeps in the current situation.
    Sleeping { agent: u32, event: u32 },
    /// The acceptance rule refused it.
    Refused(PostError),
}

impl NotTaken {
    /// A stable word for counting and for bindings: `sleeping`, or the
    /// refusal's key (`out_of_order`, `future`, `type`, …).
    pub fn key(&self) -> &'static str {
        match self {
            NotTaken::Sleeping { .. } => "sleeping",
            NotTaken::Refused(e) => e.key(),
        }
    }

    /// The reason in the rules' own terms.
    pub fn describe(&self, c: &Content, state: &str) -> String {
        match self {
            NotTaken::Sleeping { agent, event } => format!(
                "`{}` sleeps in {state}, and a sleeping agent is not stepped: a run never reports its `{}` now",
                c.agents[*agent as usize].name, c.events[*event as usize].name
            ),
            NotTaken::Refused(e) => e.describe(c),
        }
    }
}

/// What a taken event did.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Taken {
    /// The state at rest changed: [`LocalBoard::last_change`] says how.
    pub changed: bool,
    /// The rules did not come to rest (a cascade): the board is in the
    /// state where they stopped.
    pub error: Option<PostError>,
}

/// A Bulletinboard and its organisation, driven by calls.
pub struct LocalBoard {
    content: Arc<Content>,
    board: Bulletinboard,
    org: Organisation,
    /// The latest time the board was given (an event's stamp, or a move of
    /// the clock).
    now: u64,
    /// The board's clock for the next events, if it has one: an event
    /// stamped more than the skew bound ahead of it is from the future.
    clock: Option<u64>,
    last: Option<StateChange>,
    /// Takes a sleeping agent's events, as a Bulletinboard whose agents are
    /// elsewhere (not situ's: a sensor that reports whatever its mode)
    /// does; by default they are dropped, as in a run of situ's agents.
    take_sleeping: bool,
}

impl LocalBoard {
    pub fn new(content: Arc<Content>) -> LocalBoard {
        let mut board = Bulletinboard::new(content.clone());
        // The last change is kept here; the board need keep no history.
        board.set_history_capacity(0);
        LocalBoard {
            board,
            org: Organisation::new(content.clone()),
            content,
            now: 0,
            clock: None,
            last: None,
            take_sleeping: false,
        }
    }

    /// With `true`, a sleeping agent's events are taken (the agents are not
    /// situ's and report whatever their mode, as a Bulletinboard of a
    /// distributed deployment takes them); by default they are dropped.
    pub fn set_take_sleeping(&mut self, take: bool) {
        self.take_sleeping = take;
    }

    pub fn content(&self) -> &Arc<Content> {
        &self.content
    }

    pub fn bulletinboard(&self) -> &Bulletinboard {
        &self.board
    }

    pub fn organisation(&self) -> &Organisation {
        &self.org
    }

    /// The state at rest.
    pub fn state(&self) -> u32 {
        self.board.state()
    }

    pub fn state_name(&self) -> &str {
        &self.content.states[self.board.state() as usize].name
    }

    /// The latest time the board was given.
    pub fn now(&self) -> u64 {
        self.now
    }

    /// The latest change of the state at rest (`None` in the initial
    /// state, before any rule fired).
    pub fn last_change(&self) -> Option<&StateChange> {
        self.last.as_ref()
    }

    /// Sets the clock the next events arrive at (`None`: each arrives at
    /// its stamp, and none is from the future).
    pub fn set_clock(&mut self, clock: Option<u64>) {
        self.clock = clock;
    }

    pub fn set_max_skew(&mut self, ns: u64) {
        self.board.set_max_skew(ns);
    }

    /// Why this event, stamped `time`, would not be taken now, if it would
    /// not. Nothing changes.
    pub fn not_taken(&mut self, event: u32, time: u64, payload: &[Value]) -> Option<NotTaken> {
        let Some(def) = self.content.events.get(event as usize) else {
            return Some(NotTaken::Refused(PostError::UnknownEvent { event }));
        };
        if !self.take_sleeping && self.org.mode(def.agent) == Mode::Sleeping {
            return Some(NotTaken::Sleeping { agent: def.agent, event });
        }
        if let Some(clock) = self.clock {
            self.board.set_clock(clock);
        }
        self.board.engine().admit(event, time, payload).err().map(NotTaken::Refused)
    }

    /// Posts one event stamped `time`, if the admission rule takes it.
    pub fn post(&mut self, event: u32, time: u64, payload: &[Value]) -> Result<Taken, NotTaken> {
        if let Some(why) = self.not_taken(event, time, payload) {
            return Err(why);
        }
        let agent = self.content.events[event as usize].agent;
        self.org.on_event(agent, event);
        let result = match self.clock {
            Some(clock) => self.board.post_at(clock, event, time, payload),
            None => self.board.post(event, time, payload),
        };
        self.now = self.now.max(time).max(self.board.engine().now());
        Ok(self.after(result))
    }

    /// Moves time on to `now` without an event: facts age, silent agents
    /// go stale. Time never goes back: an earlier `now` changes nothing.
    pub fn advance(&mut self, now: u64) -> Taken {
        let now = now.max(self.now);
        self.now = now;
        if let Some(c) = self.clock.as_mut() {
            *c = (*c).max(now);
        }
        let result = self.board.advance(now);
        self.after(result)
    }

    fn after(&mut self, result: Result<Option<StateChange>, PostError>) -> Taken {
        match result {
            Ok(Some(change)) if change.changed() => {
                self.org.on_state(change.to);
                self.last = Some(change);
                Taken { changed: true, error: None }
            }
            Ok(_) => Taken::default(),
            Err(e) => {
                let state = self.board.state();
                if self.org.state() != state {
                    self.org.on_state(state);
                }
                Taken { changed: false, error: Some(e) }
            }
        }
    }

    /// A new mission (language reference §10.12): the initial state with
    /// no facts, the FSMs in their initial states; time and each agent's
    /// latest stamp are kept.
    pub fn reset(&mut self) {
        self.board.reset();
        self.org.reset();
        self.last = None;
    }

    /// Whether the state at rest is `final` (the mission is over).
    pub fn is_final(&self) -> bool {
        self.content.states.get(self.board.state() as usize).is_some_and(|s| s.is_final)
    }

    /// Takes new rules, keeping the state, the facts that still fit and
    /// every FSM's state (by name); on failure the old rules stay.
    pub fn reload(&mut self, new: Arc<Content>) -> Result<SwapReport, SwapError> {
        let old = self.content.clone();
        let report = self.board.swap(new.clone())?;
        let fsm: Vec<(String, Option<u32>)> = (0..old.agents.len() as u32)
            .map(|a| (old.agents[a as usize].name.clone(), self.org.fsm_state(a)))
            .collect();
        self.content = new.clone();
        self.org = Organisation::new(new.clone());
        self.org.set_state(self.board.state());
        for (name, state) in fsm {
            if let (Some(a), Some(s)) = (new.agent_id(&name), state) {
                self.org.set_fsm_state(a, s);
            }
        }
        // The last change stays what `why` explains while its rules and
        // states are where they were; else it is gone with the old rules.
        if !self.last.as_ref().is_some_and(|c| explains_the_same(&old, &new, c)) {
            self.last = None;
        }
        if let Some(c) = report.change.as_ref().filter(|c| c.changed()) {
            self.org.on_state(c.to);
            self.last = Some(c.clone());
        }
        Ok(report)
    }
}

/// Whether a change reads the same under the new rules: its states, rules,
/// matched events and stale agents have the same ids and names.
fn explains_the_same(old: &Content, new: &Content, c: &StateChange) -> bool {
    fn state(x: &Content, s: u32) -> Option<&String> {
        x.states.get(s as usize).map(|s| &s.name)
    }
    fn rule(x: &Content, r: u32) -> Option<&String> {
        x.rules.get(r as usize).map(|r| &r.name)
    }
    fn event(x: &Content, e: u32) -> Option<(&String, u32, &Vec<situ_bundle::FieldDef>)> {
        x.events.get(e as usize).map(|e| (&e.name, e.agent, &e.fields))
    }
    fn agent(x: &Content, a: u32) -> Option<&String> {
        x.agents.get(a as usize).map(|a| &a.name)
    }
    state(old, c.from) == state(new, c.from)
        && state(old, c.to) == state(new, c.to)
        && c.firings.iter().all(|f| {
            rule(old, f.rule) == rule(new, f.rule)
                && f.matched.iter().all(|m| event(old, m.event) == event(new, m.event))
                && f.stale.iter().all(|&a| agent(old, a) == agent(new, a))
        })
}
