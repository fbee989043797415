//! Native code (`situ build --native`) against the interpreter, on
//! operations decoded from the input: the modules of
//! `runtime-tests/native/` for `rules/outdoor.situ`, `rules/dla.situ` and
//! four random rule sets, each run by `Engine::with_native`, must answer
//! every operation (steps with payloads from the rules' own constants,
//! heartbeats, settling, resets, forced facts, states and staleness,
//! clocks, cascade bounds, the module's `step` called directly) as
//! `Engine::interpreted` does, and keep the same state. The input's first
//! byte picks the module; each further 4 bytes are an operation.
#![no_main]

#[rustfmt::skip]
#[path = "../../runtime-tests/native/outdoor.rs"]
mod outdoor;
#[rustfmt::skip]
#[path = "../../runtime-tests/native/dla.rs"]
mod dla;
#[rustfmt::skip]
#[path = "../../runtime-tests/native/r01.rs"]
mod r01;
#[rustfmt::skip]
#[path = "../../runtime-tests/native/r04.rs"]
mod r04;
#[rustfmt::skip]
#[path = "../../runtime-tests/native/r07.rs"]
mod r07;
#[rustfmt::skip]
#[path = "../../runtime-tests/native/r10.rs"]
mod r10;

use libfuzzer_sys::fuzz_target;
use situ_compiler::bundle::{AlphaNode, Check, Content, FieldType, Operand, Value};
use situ_runtime::rete::native::Native;
use situ_runtime::rete::{Engine, Step, StepError};
use std::sync::{Arc, OnceLock};

type StepFn = fn(&mut Engine, u32, u64, &[Value]) -> Result<Step, StepError>;

const MODULES: [(&str, &Native, StepFn); 6] = [
    ("rules/outdoor.situ", &outdoor::NATIVE, outdoor::step),
    ("rules/dla.situ", &dla::NATIVE, dla::step),
    ("runtime-tests/native/random/r01.situ", &r01::NATIVE, r01::step),
    ("runtime-tests/native/random/r04.situ", &r04::NATIVE, r04::step),
    ("runtime-tests/native/random/r07.situ", &r07::NATIVE, r07::step),
    ("runtime-tests/native/random/r10.situ", &r10::NATIVE, r10::step),
];

/// Each module's bundle, compiled once (only the front end's errors stop
/// it: the random rule sets have findings of the static checks).
fn contents() -> &'static [Arc<Content>] {
    static CONTENTS: OnceLock<Vec<Arc<Content>>> = OnceLock::new();
    CONTENTS.get_or_init(|| {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        MODULES
            .iter()
            .map(|(source, _, _)| {
                let checked = situ_compiler::check(&root.join(source), &situ_compiler::loader::FsLoader)
                    .unwrap_or_else(|e| panic!("{source}: {e:?}"));
                assert!(checked.diagnostics.iter().all(|d| d.code >= "E0300"), "{source}: front-end errors");
                Arc::new(situ_compiler::bundle::build(&checked))
            })
            .collect()
    })
}

/// Values for a field: edges, and each constant its rules compare it with,
/// below, at and above it.
fn pool(c: &Content, event: usize, field: usize) -> Vec<Value> {
    let mut out = match &c.events[event].fields[field].ty {
        FieldType::F64 => vec![Value::F64(f64::NAN), Value::F64(-1.0), Value::F64(0.0), Value::F64(1e9)],
        FieldType::I64 => vec![Value::I64(-1), Value::I64(0), Value::I64(1000)],
        FieldType::Bool => vec![Value::Bool(false), Value::Bool(true)],
        FieldType::Symbols(s) => (0..s.len() as u32 + 1).map(Value::Symbol).collect(),
    };
    for node in &c.network.alpha {
        let AlphaNode::Event { event: e, tests, .. } = node else { continue };
        if *e as usize != event {
            continue;
        }
        for t in tests.iter().filter(|t| t.field as usize == field) {
            let ops = match &t.check {
                Check::Compare { rhs, .. } => vec![*rhs],
                Check::Range { lo, hi, .. } => vec![*lo, *hi],
            };
            for o in ops {
                match o {
                    Operand::Value(Value::F64(f)) => out.extend([f - 0.5, f, f + 0.5].map(Value::F64)),
                    Operand::Value(Value::I64(i)) => out.extend([i - 1, i, i + 1].map(Value::I64)),
                    _ => {}
                }
            }
        }
    }
    out
}

fuzz_target!(|data: &[u8]| {
    let Some((&pick, ops)) = data.split_first() else { return };
    let m = pick as usize % MODULES.len();
    let (_, native, step) = MODULES[m];
    let content = contents()[m].clone();
    let mut fast = Engine::with_native(content.clone(), native).expect("the module of this bundle");
    let mut slow = Engine::interpreted(content.clone());
    let ne = content.events.len().max(1);
    let (ns, na) = (content.states.len() as u32, content.agents.len() as u32);
    let mut t: u64 = 0;
    for (i, op) in ops.chunks_exact(4).enumerate() {
        let (kind, a, gap, b) = (op[0], op[1] as usize, op[2], op[3] as usize);
        // Gaps in ms up to 255, or events stamped before now.
        t = if gap >= 250 { t.saturating_sub(u64::from(gap - 249) * 10_000_000) } else { t + u64::from(gap) * 1_000_000 };
        let e = a % ne;
        let payload: Vec<Value> = (0..content.events.get(e).map_or(0, |x| x.fields.len()))
            .map(|f| {
                let p = pool(&content, e, f);
                p[(b + f * 7) % p.len()]
            })
            .collect();
        let (x, y) = match kind % 16 {
            0 => {
                let c = if b % 2 == 0 { None } else { Some(t.saturating_sub(b as u64 * 1_000_000)) };
                fast.set_clock(c);
                slow.set_clock(c);
                (String::new(), String::new())
            }
            1 => (format!("{:?}", fast.advance(t)), format!("{:?}", slow.advance(t))),
            2 => (format!("{:?}", fast.settle()), format!("{:?}", slow.settle())),
            3 => (format!("{}", fast.reset_if_final()), format!("{}", slow.reset_if_final())),
            4 => {
                fast.force_state(a as u32 % (ns + 1));
                slow.force_state(a as u32 % (ns + 1));
                (String::new(), String::new())
            }
            5 => (
                format!("{:?}", fast.force_fact(e as u32, t, &payload, b as u64 % 4)),
                format!("{:?}", slow.force_fact(e as u32, t, &payload, b as u64 % 4)),
            ),
            6 => {
                fast.force_stale(a as u32 % (na + 1));
                slow.force_stale(a as u32 % (na + 1));
                (String::new(), String::new())
            }
            7 => {
                fast.set_cascade_limit(1 + b % 4 * 21);
                slow.set_cascade_limit(1 + b % 4 * 21);
                (String::new(), String::new())
            }
            k => {
                // A step, through `Engine::step` or the module's `step`;
                // an unknown event now and then.
                let ev = if k == 15 { ne as u32 + a as u32 % 2 } else { e as u32 };
                let x = if k % 2 == 0 { step(&mut fast, ev, t, &payload) } else { fast.step(ev, t, &payload) };
                let y = slow.step(ev, t, &payload);
                (
                    format!("{x:?} {:?}", x.map(|_| fast.last_change())),
                    format!("{y:?} {:?}", y.map(|_| slow.last_change())),
                )
            }
        };
        assert_eq!(x, y, "{}: op {i} ({op:?})", MODULES[m].0);
        assert_eq!(fast.state(), slow.state(), "{}: op {i}", MODULES[m].0);
        assert_eq!(fast.now(), slow.now());
    }
});
