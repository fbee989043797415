//! A small stack of scripted agents for the example of Fig. 5 of Zhang &
//! Zhu (2005) (`examples/fig5/fig5.situ`): road following on a straight
//! road until LADAR sees an obstacle, which wakes Fusion. Its data is JSON,
//! so it runs in one process or spread over several.
//!
//! - RFCCD sends the road it sees (`{"road": "straight"}`) to whoever its
//!   links name; it reports `RFRS`;
//! - LADAR reports `LAOBN`, and from `obstacle_after` on
//!   `LAOBS(distance: 12.0, height: 0.5)`, and sends its scans;
//! - Fusion sends `{"fused": [senders…]}`: what it merged;
//! - LPL plans from what arrives and reports `PLRS`/`PLRO` by its source;
//! - Drive reports `DRSTOP` while standing (it never moves here).
//!
//! Every agent writes what it received to a shared [`Log`], which tests
//! read.

use crate::agent::{Agent, Body, Context};
use situ_bundle::Value;
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// `(time, receiver, sender)` of every datum received.
pub type Log = Arc<Mutex<Vec<(u64, String, String)>>>;

struct Scripted {
    name: &'static str,
    function: &'static str,
    start: Option<u64>,
    obstacle_after: Duration,
    log: Log,
}

impl Agent for Scripted {
    fn name(&self) -> &str {
        self.name
    }

    fn functions(&self) -> Vec<String> {
        vec![self.function.to_string()]
    }

    fn step(&mut self, cx: &mut Context<'_>) {
        let start = *self.start.get_or_insert(cx.now());
        let age = Duration::from_nanos(cx.now().saturating_sub(start));
        {
            let mut log = self.log.lock().unwrap_or_else(|p| p.into_inner());
            for d in cx.inputs() {
                log.push((d.time, self.name.to_string(), cx.agent_name(d.from).to_string()));
            }
        }
        let json = |v: serde_json::Value| Body::json(v);
        match self.name {
            "RFCCD" => {
                let _ = cx.report("RFRS", &[]);
                cx.send(json(serde_json::json!({ "road": "straight" })));
            }
            "LADAR" => {
                if age >= self.obstacle_after {
                    let _ = cx.report("LAOBS", &[Value::F64(12.0), Value::F64(0.5)]);
                } else {
                    let _ = cx.report("LAOBN", &[]);
                }
                cx.send(json(serde_json::json!({ "scan": age.as_millis() as u64 })));
            }
            "Fusion" => {
                let from: Vec<&str> = cx.inputs().iter().map(|d| cx.agent_name(d.from)).collect();
                cx.send(json(serde_json::json!({ "fused": from })));
            }
            "LPL" => {
                if cx.inputs().iter().any(|d| cx.agent_name(d.from) == "Fusion") {
                    let _ = cx.report("PLRO", &[]);
                } else if !cx.inputs().is_empty() {
                    let _ = cx.report("PLRS", &[]);
                }
                cx.send(json(serde_json::json!({ "path": [] })));
            }
            "Drive" if cx.safe_mode() || !cx.inputs().is_empty() => {
                let _ = cx.report("DRSTOP", &[]);
            }
            _ => {}
        }
    }
}

/// The agents of `examples/fig5/fig5.situ`, by name: RFCCD, LADAR,
/// Fusion, LPL, Drive.
pub fn fig5(obstacle_after: Duration, log: Log) -> Vec<Box<dyn Agent>> {
    [("RFCCD", "lines"), ("LADAR", "detect"), ("Fusion", "fuse"), ("LPL", "plan"), ("Drive", "track")]
        .into_iter()
        .map(|(name, function)| {
            Box::new(Scripted { name, function, start: None, obstacle_after, log: log.clone() }) as Box<dyn Agent>
        })
        .collect()
}

/// An agent the demo does not have.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("the demo stack has no agent `{missing}` (it has {})", .known.join(", "))]
pub struct UnknownAgent {
    pub missing: String,
    pub known: Vec<String>,
}

/// The agents of [`fig5`] named in `names` (each must be one of them), the
/// obstacle after 1.5 s.
pub fn agents(names: &[String], log: Log) -> Result<Vec<Box<dyn Agent>>, UnknownAgent> {
    let all = fig5(Duration::from_millis(1500), log);
    let known: Vec<String> = all.iter().map(|a| a.name().to_string()).collect();
    if let Some(missing) = names.iter().find(|n| !known.contains(n)) {
        return Err(UnknownAgent { missing: missing.clone(), known });
    }
    Ok(all.into_iter().filter(|a| names.iter().any(|n| n == a.name())).collect())
}
