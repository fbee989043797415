//! Reading a board: its agents, its facts and why it is in its state, each
//! as a view (a handle) that owns every string it hands out; free it with
//! its `situ_*_free`. A view is a copy: it does not change with the board.

use crate::board::situ_board;
use crate::error::{call, situ_status, Failure};
use crate::handle::{self, Kind};
use crate::value::{c_string, out_value, place, situ_value};
use situ_api::{AgentNow, Fact, FieldValue, Fired};
use std::ffi::{c_char, CString};
use std::sync::Mutex;

/// Every agent now (`situ_board_agents`).
pub struct situ_agents {
    _opaque: [u8; 0],
}
/// The working memory (`situ_board_facts`).
pub struct situ_facts {
    _opaque: [u8; 0],
}
/// The last change, rule by rule (`situ_board_why`).
pub struct situ_why {
    _opaque: [u8; 0],
}

/// An agent's mode in the current situation.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum situ_mode {
    SITU_RUNNING = 0,
    SITU_WAITING = 1,
    SITU_SLEEPING = 2,
}

/// An agent now. Strings and lists are owned by the `situ_agents` view.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct situ_agent {
    pub name: *const c_char,
    pub mode: situ_mode,
    /// The function it performs now; null when it has none.
    pub function: *const c_char,
    /// Whom it reads from and sends to now (a running agent's links).
    pub from: *const *const c_char,
    pub from_count: usize,
    pub to: *const *const c_char,
    pub to_count: usize,
    /// Its FSM's state, for an agent with an FSM; else null.
    pub fsm_state: *const c_char,
}

/// A field of a fact and its value.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct situ_field {
    pub name: *const c_char,
    pub value: situ_value,
}

/// An agent's fact: its latest event and payload.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct situ_fact {
    pub agent: *const c_char,
    pub event: *const c_char,
    /// Its stamp (ns).
    pub time: u64,
    pub fields: *const situ_field,
    pub field_count: usize,
}

/// An agent's entry in the working memory: its fact, unless it is stale.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct situ_fact_now {
    pub agent: *const c_char,
    pub stale: bool,
    /// Whether `fact` holds one (not for a stale agent).
    pub has_fact: bool,
    pub fact: situ_fact,
}

/// The last change as a whole.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct situ_why_info {
    pub from: *const c_char,
    pub to: *const c_char,
    pub time: u64,
    pub firing_count: usize,
}

/// One rule that fired in the last change, where it is written, and what
/// it matched.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct situ_firing {
    pub rule: *const c_char,
    pub file: *const c_char,
    pub line: u32,
    /// The rule's first line.
    pub text: *const c_char,
    pub from: *const c_char,
    pub to: *const c_char,
    /// The facts its patterns matched.
    pub facts: *const situ_fact,
    pub fact_count: usize,
    /// The agents its `stale` tests found stale.
    pub stale: *const *const c_char,
    pub stale_count: usize,
}

/// What a view owns: strings, lists of strings, fields and facts. Each is
/// heap memory that does not move when the arena's vectors grow.
#[derive(Default)]
struct Arena {
    strings: Vec<CString>,
    lists: Vec<Vec<*const c_char>>,
    fields: Vec<Vec<situ_field>>,
    facts: Vec<Vec<situ_fact>>,
}

impl Arena {
    fn text(&mut self, s: &str) -> *const c_char {
        let c = c_string(s);
        let p = c.as_ptr();
        self.strings.push(c);
        p
    }

    fn opt(&mut self, s: Option<&str>) -> *const c_char {
        s.map_or(std::ptr::null(), |s| self.text(s))
    }

    /// A list of strings: its pointer (null when empty) and length.
    fn list(&mut self, items: &[String]) -> (*const *const c_char, usize) {
        if items.is_empty() {
            return (std::ptr::null(), 0);
        }
        let list: Vec<_> = items.iter().map(|s| self.text(s)).collect();
        let p = list.as_ptr();
        self.lists.push(list);
        (p, items.len())
    }

    fn fact(&mut self, f: &Fact) -> situ_fact {
        let fields: Vec<situ_field> = f
            .fields
            .iter()
            .map(|(name, v)| {
                let symbol = match v {
                    FieldValue::Symbol(s) => self.text(s),
                    _ => std::ptr::null(),
                };
                situ_field { name: self.text(name), value: out_value(v, symbol) }
            })
            .collect();
        let (p, n) = (if fields.is_empty() { std::ptr::null() } else { fields.as_ptr() }, fields.len());
        self.fields.push(fields);
        situ_fact { agent: self.text(&f.agent), event: self.text(&f.event), time: f.time, fields: p, field_count: n }
    }

    fn facts(&mut self, facts: &[Fact]) -> (*const situ_fact, usize) {
        if facts.is_empty() {
            return (std::ptr::null(), 0);
        }
        let list: Vec<situ_fact> = facts.iter().map(|f| self.fact(f)).collect();
        let p = list.as_ptr();
        self.facts.push(list);
        (p, facts.len())
    }
}

pub(crate) struct AgentsView {
    _arena: Arena,
    items: Vec<situ_agent>,
}
pub(crate) struct FactsView {
    _arena: Arena,
    items: Vec<situ_fact_now>,
}
pub(crate) struct WhyView {
    _arena: Arena,
    info: situ_why_info,
    firings: Vec<situ_firing>,
}

// A view is read-only once made, and its pointers point into memory it owns.
unsafe impl Send for AgentsView {}
unsafe impl Sync for AgentsView {}
unsafe impl Send for FactsView {}
unsafe impl Sync for FactsView {}
unsafe impl Send for WhyView {}
unsafe impl Sync for WhyView {}

impl Kind for AgentsView {
    const WHAT: &'static str = "situ_agents";
}
impl Kind for FactsView {
    const WHAT: &'static str = "situ_facts";
}
impl Kind for WhyView {
    const WHAT: &'static str = "situ_why";
}

fn agent(a: &mut Arena, now: &AgentNow) -> situ_agent {
    let mode = match now.mode {
        "running" => situ_mode::SITU_RUNNING,
        "sleeping" => situ_mode::SITU_SLEEPING,
        _ => situ_mode::SITU_WAITING,
    };
    let (from, from_count) = a.list(&now.from);
    let (to, to_count) = a.list(&now.to);
    situ_agent {
        name: a.text(&now.name),
        mode,
        function: a.opt(now.function.as_deref()),
        from,
        from_count,
        to,
        to_count,
        fsm_state: a.opt(now.fsm_state.as_deref()),
    }
}

fn firing(a: &mut Arena, f: &Fired) -> situ_firing {
    let (facts, fact_count) = a.facts(&f.facts);
    let (stale, stale_count) = a.list(&f.stale);
    situ_firing {
        rule: a.text(&f.rule),
        file: a.text(&f.file),
        line: f.line,
        text: a.text(&f.text),
        from: a.text(&f.from),
        to: a.text(&f.to),
        facts,
        fact_count,
        stale,
        stale_count,
    }
}

/// Runs `f` on a board's `situ_api::Board` under its lock.
fn with_board<R>(board: *const situ_board, f: impl FnOnce(&situ_api::Board) -> R) -> Result<R, Failure> {
    let cell = handle::get::<Mutex<crate::board::BoardCell>>(board as usize)?;
    let g = cell.lock().map_err(|_| Failure::new(situ_status::SITU_ERR_PANIC, "this board is unusable: free it"))?;
    Ok(f(&g.board))
}

/// Every agent's mode, function and links now, as a view.
#[no_mangle]
pub unsafe extern "C" fn situ_board_agents(board: *const situ_board, out: *mut *mut situ_agents) -> situ_status {
    call(|| {
        let out = place(out, "the place for the view (out)")?;
        *out = std::ptr::null_mut();
        let agents = with_board(board, |b| b.agents())?;
        let mut arena = Arena::default();
        let items = agents.iter().map(|x| agent(&mut arena, x)).collect();
        *out = handle::insert(AgentsView { _arena: arena, items }) as *mut situ_agents;
        Ok(())
    })
}

/// The working memory (every agent that has a fact or is stale), as a view.
#[no_mangle]
pub unsafe extern "C" fn situ_board_facts(board: *const situ_board, out: *mut *mut situ_facts) -> situ_status {
    call(|| {
        let out = place(out, "the place for the view (out)")?;
        *out = std::ptr::null_mut();
        let facts = with_board(board, |b| b.facts())?;
        let mut arena = Arena::default();
        let items = facts
            .iter()
            .map(|f| {
                let fact = f.fact.as_ref().map(|x| arena.fact(x));
                situ_fact_now {
                    agent: arena.text(&f.agent),
                    stale: f.stale,
                    has_fact: fact.is_some(),
                    fact: fact.unwrap_or(situ_fact {
                        agent: std::ptr::null(),
                        event: std::ptr::null(),
                        time: 0,
                        fields: std::ptr::null(),
                        field_count: 0,
                    }),
                }
            })
            .collect();
        *out = handle::insert(FactsView { _arena: arena, items }) as *mut situ_facts;
        Ok(())
    })
}

/// Why the board is in its state: the last change rule by rule, with the
/// file and line of each rule and the facts it matched, as a view. `*out`
/// is null (and the call succeeds) in the initial state before any rule
/// fired.
#[no_mangle]
pub unsafe extern "C" fn situ_board_why(board: *const situ_board, out: *mut *mut situ_why) -> situ_status {
    call(|| {
        let out = place(out, "the place for the view (out)")?;
        *out = std::ptr::null_mut();
        let Some(why) = with_board(board, |b| b.why())? else { return Ok(()) };
        let mut arena = Arena::default();
        let firings: Vec<situ_firing> = why.firings.iter().map(|f| firing(&mut arena, f)).collect();
        let info = situ_why_info {
            from: arena.text(&why.from),
            to: arena.text(&why.to),
            time: why.time,
            firing_count: firings.len(),
        };
        *out = handle::insert(WhyView { _arena: arena, info, firings }) as *mut situ_why;
        Ok(())
    })
}

fn item<'a, T: Copy>(items: &'a [T], index: usize, what: &str) -> Result<&'a T, Failure> {
    items.get(index).ok_or_else(|| {
        Failure::new(situ_status::SITU_ERR_ARGUMENT, format!("{what} {index} is past the end ({} in all)", items.len()))
    })
}

fn count<T: Kind>(view: usize, out: *mut usize, n: impl FnOnce(&T) -> usize) -> situ_status {
    call(|| {
        let view = handle::get::<T>(view)?;
        *unsafe { place(out, "the place for the count") }? = n(&view);
        Ok(())
    })
}

/// How many agents the view holds.
#[no_mangle]
pub unsafe extern "C" fn situ_agents_count(agents: *const situ_agents, out: *mut usize) -> situ_status {
    count::<AgentsView>(agents as usize, out, |v| v.items.len())
}

/// The agent at `index` (0 ≤ index < count).
#[no_mangle]
pub unsafe extern "C" fn situ_agents_get(
    agents: *const situ_agents,
    index: usize,
    out: *mut situ_agent,
) -> situ_status {
    call(|| {
        let view = handle::get::<AgentsView>(agents as usize)?;
        *place(out, "the place for the agent")? = *item(&view.items, index, "agent")?;
        Ok(())
    })
}

/// Frees an agents view (null: nothing to do).
#[no_mangle]
pub extern "C" fn situ_agents_free(agents: *mut situ_agents) -> situ_status {
    call(|| handle::remove::<AgentsView>(agents as usize))
}

/// How many entries the facts view holds.
#[no_mangle]
pub unsafe extern "C" fn situ_facts_count(facts: *const situ_facts, out: *mut usize) -> situ_status {
    count::<FactsView>(facts as usize, out, |v| v.items.len())
}

/// The entry at `index` (0 ≤ index < count).
#[no_mangle]
pub unsafe extern "C" fn situ_facts_get(
    facts: *const situ_facts,
    index: usize,
    out: *mut situ_fact_now,
) -> situ_status {
    call(|| {
        let view = handle::get::<FactsView>(facts as usize)?;
        *place(out, "the place for the fact")? = *item(&view.items, index, "fact")?;
        Ok(())
    })
}

/// Frees a facts view (null: nothing to do).
#[no_mangle]
pub extern "C" fn situ_facts_free(facts: *mut situ_facts) -> situ_status {
    call(|| handle::remove::<FactsView>(facts as usize))
}

/// The last change as a whole: from, to, time, how many rules fired.
#[no_mangle]
pub unsafe extern "C" fn situ_why_info_get(why: *const situ_why, out: *mut situ_why_info) -> situ_status {
    call(|| {
        let view = handle::get::<WhyView>(why as usize)?;
        *place(out, "the place for the change")? = view.info;
        Ok(())
    })
}

/// The rule at `index` of the last change (0 ≤ index < firing_count).
#[no_mangle]
pub unsafe extern "C" fn situ_why_firing(why: *const situ_why, index: usize, out: *mut situ_firing) -> situ_status {
    call(|| {
        let view = handle::get::<WhyView>(why as usize)?;
        *place(out, "the place for the firing")? = *item(&view.firings, index, "firing")?;
        Ok(())
    })
}

/// Frees a why view (null: nothing to do).
#[no_mangle]
pub extern "C" fn situ_why_free(why: *mut situ_why) -> situ_status {
    call(|| handle::remove::<WhyView>(why as usize))
}
