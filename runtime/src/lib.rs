//! The situ runtime: it loads bundles and runs them. It never needs the
//! grammar: a bundle is everything it knows of a program.
//!
//! The engine and the board:
//! - [`rete`]: the inference machine, a Rete interpreter over the bundle's
//!   network and a working memory of one state and one fact per agent;
//! - [`bulletinboard`]: the Bulletinboard of Zhang & Zhu (2005) around it:
//!   posting events, the state history, subscriptions, explanations, hot swap;
//! - [`organise`]: what each agent does in the current state (tables, FSMs)
//!   and the wiring graph of the moment.
//!
//! The agents and their runs:
//! - [`agent`]: the agent SDK (what an agent sees in a step of its running
//!   cycle, functions bound by name before anything runs);
//! - [`bus`]: the three streams (data, events, status) and the in-process bus;
//! - [`runner`]: an agent's running cycle and the board's events monitor,
//!   shared by both schedulers;
//! - [`sched`]: the simulated-time scheduler (one thread, deterministic);
//! - [`realtime`]: the real-time scheduler (worker threads, the wall clock);
//!   [`priority`]: its threads under `SCHED_FIFO` when asked;
//! - [`script`]: scripted runs of any rules file (stand-in agents, the
//!   guided random generator, the timeline and the chart);
//! - [`demo`]: the scripted agents of the example of Fig. 5;
//! - [`summary`]: the figures of a run (a table, `metrics.json`).
//!
//! What a run leaves, and tools on it:
//! - [`record`]: the recorder (MCAP), its reader, the page's timeline and
//!   live log;
//! - [`replay`]: a recording's events fed to a bundle, the differences said;
//! - [`journal`]: the board's log in an append-only file, so that a board
//!   restarted after a crash recovers its state and facts;
//! - [`repl`]: a session of posts, waits and explanations (`situ repl`);
//! - [`bench`], [`stream`]: throughput and latency on seeded event streams
//!   (`situ bench`), and the streams' text form.
//!
//! `situ test` (scenario tests and properties) is the `situ-verify` crate.

pub mod agent;
pub mod bench;
pub mod bulletinboard;
pub mod bus;
pub mod demo;
pub mod journal;
pub mod local;
pub mod organise;
pub mod priority;
pub mod realtime;
pub mod record;
pub mod repl;
pub mod replay;
pub mod rete;
pub mod runner;
pub mod sched;
pub mod script;
pub mod standby;
pub mod stream;
pub mod summary;
