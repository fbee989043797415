//! The real-time run's threads under `SCHED_FIFO` when asked
//! (`RealtimeConfig::priority`): the agents' workers and the
//! Bulletinboard's thread run under it, the caller's thread gets its own
//! policy back, and a refusal is said in the recording while the run goes
//! on. The kernel grants `SCHED_FIFO` to root (as the fault tests, which
//! need root for their namespaces, run); without the privilege the first
//! test fails with the refusal's text.

use situ_compiler::bundle::Content;
use situ_runtime::agent::{self, Agent, Context};
use situ_runtime::priority;
use situ_runtime::realtime::{self, RealtimeConfig};
use situ_runtime::record::SharedMemory;
use std::sync::{Arc, Mutex};
use std::time::Duration;

const RULES: &str = "states { A initial B final }
    agent S sensor { rate 100Hz event E }
    rule go { when state == A and E then B }";

fn content() -> Arc<Content> {
    let c = situ_compiler::check_source("t.situ", RULES);
    assert!(c.diagnostics.iter().all(|d| d.code >= "E0300"), "{:?}", c.diagnostics);
    Arc::new(situ_compiler::bundle::build(&c))
}

/// The sensor: reports `E` and notes the policy of the thread it runs on.
struct Sensor(Arc<Mutex<Vec<Option<i32>>>>);

impl Agent for Sensor {
    fn name(&self) -> &str {
        "S"
    }
    fn functions(&self) -> Vec<String> {
        Vec::new()
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        self.0.lock().unwrap().push(priority::current());
        cx.report("E", &[]).unwrap();
    }
}

/// Runs the rules with `priority`; what the sensor's thread, the thread of
/// the changes (the Bulletinboard's) and the recording's diagnostics saw.
fn run(priority: Option<i32>) -> (Vec<Option<i32>>, Vec<Option<i32>>, Vec<String>) {
    let c = content();
    let seen = Arc::new(Mutex::new(Vec::new()));
    let bound = agent::bind(&c, vec![Box::new(Sensor(seen.clone()))], true).unwrap();
    let memory = SharedMemory::default();
    let config = RealtimeConfig { priority, workers: 1, ..RealtimeConfig::default() };
    let mut board = Vec::new();
    let summary = realtime::run(c, bound, Some(Box::new(memory.clone())), config, Duration::from_secs(30), &mut |_| {
        board.push(priority::current())
    });
    assert_eq!(summary.final_state, "B", "the run went on to its end");
    let diagnostics = memory.snapshot().diagnostics.into_iter().map(|(_, t)| t).collect();
    let seen = seen.lock().unwrap().clone();
    (seen, board, diagnostics)
}

#[test]
fn the_workers_and_the_board_run_under_sched_fifo_when_asked() {
    let before = priority::current();
    assert_eq!(before, None, "the test's thread starts under the normal scheduler");
    let (seen, board, diagnostics) = run(Some(20));
    assert!(diagnostics.iter().all(|d| !d.contains("SCHED_FIFO")), "refused: {diagnostics:?}");
    assert!(!seen.is_empty() && seen.iter().all(|p| *p == Some(20)), "the sensor's worker: {seen:?}");
    assert_eq!(board, [Some(20)], "the Bulletinboard's thread, at the change A -> B");
    assert_eq!(priority::current(), before, "the caller's thread has its policy back");
}

#[test]
fn without_a_priority_the_threads_keep_the_normal_scheduler() {
    let (seen, board, _) = run(None);
    assert!(!seen.is_empty() && seen.iter().all(Option::is_none), "{seen:?}");
    assert_eq!(board, [None]);
}

#[test]
fn a_refused_priority_is_said_once_and_the_run_goes_on() {
    // 100 is past SCHED_FIFO's range (1 to 99): the kernel refuses it
    // (EINVAL) whatever the privilege, as it refuses an unprivileged one.
    let (seen, board, diagnostics) = run(Some(100));
    let said: Vec<&String> = diagnostics.iter().filter(|d| d.contains("SCHED_FIFO at priority 100 refused")).collect();
    assert_eq!(said.len(), 1, "said once: {diagnostics:?}");
    assert!(said[0].contains("normal scheduler"), "{}", said[0]);
    assert!(seen.iter().all(Option::is_none) && board == [None], "{seen:?} {board:?}");
}
