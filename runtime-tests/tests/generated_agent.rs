//! A generated Rust agent runs on the runtime: `examples/mower/agents/battery.rs`
//! is `situ gen agent Battery examples/mower/mower.situ --lang rust`, committed
//! (`tests/gen_cmd.rs` checks that regenerating it gives the same bytes).
//! Here the user's side implements its trait, and the agent, alone on the
//! simulated-time scheduler (the other agents absent), reports a falling
//! charge until the rules send the mower home: MOWING -> DOCKING.

#[path = "../../examples/mower/agents/battery.rs"]
mod battery;

use battery::{BatteryAgent, BatteryFunctions, BatteryIo};
use situ_compiler::bundle::Mode;
use situ_runtime::agent::{self, Agent};
use situ_runtime::sched::{SimConfig, SimRuntime};
use std::path::Path;
use std::sync::{Arc, Mutex};

/// What the user's code saw at each step: the state, the mode, the receivers.
type Seen = Arc<Mutex<Vec<(String, Mode, Vec<String>)>>>;

/// The user's battery: its charge falls by 10 % a step.
struct FallingCharge {
    charge: f64,
    seen: Seen,
}

impl BatteryFunctions for FallingCharge {
    fn without_function(&mut self, io: &mut BatteryIo<'_, '_>) {
        let receivers = io.receivers().iter().map(|r| r.to_string()).collect();
        self.seen.lock().unwrap().push((io.state().to_string(), io.mode(), receivers));
        io.batt(self.charge).expect("BATT is Battery's");
        if io.state() == "DOCKING" {
            io.docked().expect("DOCKED is Battery's");
        }
        self.charge -= 10.0;
    }
}

fn mower() -> Arc<situ_compiler::bundle::Content> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/mower/mower.situ");
    let checked = situ_compiler::check(&path, &situ_compiler::loader::FsLoader).unwrap();
    assert_eq!(checked.errors(), 0);
    Arc::new(situ_compiler::bundle::build(&checked))
}

#[test]
fn the_generated_battery_sends_the_mower_home() {
    let content = mower();
    let seen = Seen::default();
    let user = FallingCharge { charge: 50.0, seen: seen.clone() };
    let agents: Vec<Box<dyn Agent>> = vec![Box::new(BatteryAgent::new(user))];
    let bound = agent::bind(&content, agents, false).unwrap_or_else(|e| panic!("{e}"));
    let config = SimConfig { stop_on_final: false, ..SimConfig::default() };
    let mut rt = SimRuntime::new(content.clone(), bound, None, config);
    let mut changes = Vec::new();
    rt.run_until(8_000_000_000, &mut |c| {
        if c.changed() {
            changes.push((content.states[c.from as usize].name.clone(), content.states[c.to as usize].name.clone()));
        }
    });
    assert_eq!(changes, [("MOWING".to_string(), "DOCKING".to_string())], "the low charge sent it home");
    assert_eq!(rt.summary().path, ["MOWING", "DOCKING"]);
    let seen = seen.lock().unwrap();
    // 1 Hz from t = 0: 50, 40, 30, 20 in MOWING; 10 % sends it home, and the
    // next steps see the new status.
    let states: Vec<&str> = seen.iter().map(|(s, _, _)| s.as_str()).collect();
    assert_eq!(states[..5], ["MOWING"; 5], "{states:?}");
    assert!(states[5..].iter().all(|s| *s == "DOCKING") && states.len() > 5, "{states:?}");
    // No table: running in every state, no links, so no receivers.
    assert!(seen.iter().all(|(_, m, r)| *m == Mode::Running && r.is_empty()));
}

#[test]
fn the_generated_data_matches_the_rules() {
    let content = mower();
    let def = &content.agents[content.agent_id(battery::AGENT).unwrap() as usize];
    assert_eq!(battery::STATES.len(), content.states.len());
    assert!(battery::STATES.iter().zip(&content.states).all(|(a, b)| *a == b.name));
    assert!(battery::FUNCTIONS.is_empty() && def.functions.is_empty());
    assert!(battery::TABLE.iter().all(|(_, a)| a.is_some_and(|a| a.mode == Mode::Running && a.to.is_empty())));
    assert_eq!(battery::BUNDLE_SHA256.len(), 64);
    assert_eq!(battery::SITU_VERSION, env!("CARGO_PKG_VERSION"));
    // The agent binds by name and offers what the rules ask of it.
    let a = BatteryAgent::new(FallingCharge { charge: 0.0, seen: Seen::default() });
    assert_eq!(a.name(), "Battery");
    assert!(a.functions().is_empty());
}
