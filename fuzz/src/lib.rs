//! What the fuzz targets share: an in-memory loader (never the file
//! system), the whole check of a program, and driving the engine of a
//! decoded bundle.

use situ_compiler::bundle::{self, Content, Encoding, FieldType, Value};
use situ_compiler::loader::MemLoader;
use situ_compiler::render;
use situ_runtime::rete::Engine;
use std::path::Path;
use std::sync::Arc;

/// The path the fuzzed program is served under.
pub const MAIN: &str = "fuzz/main.situ";

/// Checks a program (a loading, names, types, static checks), renders its
/// findings, and when it has no error builds its bundle, which must encode
/// and decode in both encodings and run.
pub fn check_all(loader: &MemLoader, root: &str, extra: &[&str]) {
    let extra: Vec<&Path> = extra.iter().map(Path::new).collect();
    let Ok(checked) = situ_compiler::check_with(Path::new(root), &extra, loader) else { return };
    // Every finding has a place in a known file (invariant 1): rendering
    // looks each one up.
    let _ = render::json_lines(&checked);
    let _ = render::human_all(&checked, render::Style::PLAIN);
    if checked.errors() > 0 {
        return;
    }
    let content = bundle::build(&checked);
    for encoding in [Encoding::Json, Encoding::Binary] {
        let bytes = bundle::encode(&content, encoding);
        match bundle::decode(&bytes) {
            Ok(back) => run(back),
            Err(e) => panic!("a program without errors built a bundle that does not decode ({encoding:?}): {e}"),
        }
    }
}

/// A value of each field's type: its default.
fn payload(ty: &FieldType) -> Value {
    match ty {
        FieldType::F64 => Value::F64(0.5),
        FieldType::I64 => Value::I64(1),
        FieldType::Bool => Value::Bool(true),
        FieldType::Symbols(_) => Value::Symbol(0),
    }
}

/// Builds the engine of a decoded (so validated) bundle and posts each of
/// its events (at most 16) twice: the runtime indexes what `validate`
/// checked without checking it again (invariant 8). The engine's fast path
/// (`Engine::new`) and its interpreter (`Engine::interpreted`) must answer
/// the same, firing for firing, and reach the same states.
pub fn run(content: Content) {
    let content = Arc::new(content);
    let mut engine = Engine::new(content.clone());
    let mut reference = Engine::interpreted(content.clone());
    let mut time = 0u64;
    for round in 0..2u64 {
        for (id, e) in content.events.iter().enumerate().take(16) {
            let values: Vec<Value> = e.fields.iter().map(|f| payload(&f.ty)).collect();
            time += 1_000_000 * (round + 1);
            // As text: NaN is unequal to itself under `PartialEq`.
            let fast = format!("{:?}", engine.post(id as u32, time, &values));
            let interpreted = format!("{:?}", reference.post(id as u32, time, &values));
            assert_eq!(fast, interpreted, "the fast path and the interpreter differ on event {id}");
            assert_eq!(engine.state(), reference.state());
        }
    }
}
