//! Inputs the fuzz targets of `fuzz/` found crashing (`scripts/fuzz.sh`),
//! each kept here as it was found, in `tests/fuzz/`: each must now be
//! refused with a reason, never a panic. And the fuzz targets' corpora
//! that reach the engine (`parse_check`, `script`, `bundle_decode`, whose
//! programs `situ_fuzz::run` drives): on each, the engine's fast path
//! answers as the interpreter (`twin/mod.rs`).

mod twin;

use situ_compiler::bundle::{Content, Value};
use situ_compiler::loader::MemLoader;
use situ_runtime::record::mcap::{attached_bundle, read_recording, ReadError};
use situ_runtime::stream::Generator;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use twin::{posts, twins};

fn input(name: &str) -> Vec<u8> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz").join(name);
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// `mcap_read`: an attachment record whose header leaves fewer than the 4
/// bytes of its CRC made the `mcap` crate (0.26) slice out of bounds, in
/// `read_recording` and in `attached_bundle`. The scan refuses it first.
#[test]
fn an_attachment_shorter_than_its_crc_is_damage_not_a_panic() {
    let bytes = input("mcap_read-attachment-shorter-than-its-crc.mcap");
    let err = read_recording(&bytes).expect_err("a damaged recording");
    assert!(matches!(&err, ReadError::Damaged { why, .. } if why.contains("attachment")), "{err}");
    assert_eq!(attached_bundle(&bytes), None);
}

/// The check that refuses it accepts the attachment of a whole recording
/// (`situ run tests/run/heartbeat.situ --until 2 --record`, kept as a file):
/// the bundle is found and every message read.
#[test]
fn a_whole_recording_still_reads_with_its_bundle() {
    let bytes = input("heartbeat-whole.mcap");
    let reading = read_recording(&bytes).expect("a whole recording");
    assert!(reading.cut.is_none(), "{:?}", reading.cut);
    assert!(!reading.messages.is_empty());
    let bundle = attached_bundle(&bytes).expect("the attached bundle");
    situ_compiler::bundle::decode(&bundle).expect("the attached bundle decodes");
}

fn corpus(target: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz/corpus").join(target);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .flatten()
        .map(|e| e.path())
        .collect();
    files.sort();
    files
}

/// The events `situ_fuzz::run` posts (each event, at most 16, twice, with
/// a default payload), then a seeded stream of the benchmark's generator;
/// the fast path must answer as the interpreter. Returns the firings.
fn both_engines(content: Content, what: &str) -> usize {
    let content = Arc::new(content);
    let mut events = Vec::new();
    let mut time = 0u64;
    for round in 0..2u64 {
        for (id, e) in content.events.iter().enumerate().take(16) {
            let payload = e
                .fields
                .iter()
                .map(|f| match &f.ty {
                    situ_compiler::bundle::FieldType::F64 => Value::F64(0.5),
                    situ_compiler::bundle::FieldType::I64 => Value::I64(1),
                    situ_compiler::bundle::FieldType::Bool => Value::Bool(true),
                    situ_compiler::bundle::FieldType::Symbols(_) => Value::Symbol(0),
                })
                .collect();
            time += 1_000_000 * (round + 1);
            events.push((id as u32, time, payload));
        }
    }
    let mut g = Generator::new(content.clone(), 7);
    // The generator's times start at 0: after the posts above, shifted.
    events.extend((0..400).filter_map(|_| g.next_event()).map(|e| (e.event, e.time + time, e.payload)));
    twins(&content, &posts(&events, true)).unwrap_or_else(|e| panic!("{what}: {e}"))
}

/// A program of a fuzz corpus, checked as its target checks it; its bundle
/// if it has no error.
fn bundle_of(loader: &MemLoader, root: &str, extra: &[&str]) -> Option<Content> {
    let extra: Vec<&Path> = extra.iter().map(Path::new).collect();
    let checked = situ_compiler::check_with(Path::new(root), &extra, loader).ok()?;
    (checked.errors() == 0).then(|| situ_compiler::bundle::build(&checked))
}

#[test]
fn the_fuzz_corpora_run_the_same_on_the_fast_path() {
    let (mut programs, mut fired) = (0, 0);
    // `parse_check`: the bytes as a rules file, with a file it may include.
    const LIB: &str = "agent LibAgent sensor { event LIB_EV { x: f64 } }\n";
    for path in corpus("parse_check") {
        let loader = MemLoader::new().with("fuzz/main.situ", input_at(&path)).with("fuzz/lib.situ", LIB);
        if let Some(content) = bundle_of(&loader, "fuzz/main.situ", &[]) {
            programs += 1;
            fired += both_engines(content, &path.display().to_string());
        }
    }
    // `script`: the bytes as a script after the target's fixed rules, read
    // from its source.
    let source = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz/fuzz_targets/script.rs"))
        .expect("the script target");
    let rules = source.split("r#\"").nth(1).and_then(|s| s.split("\"#").next()).expect("the target's rules");
    for path in corpus("script") {
        let loader = MemLoader::new().with("fuzz/rules.situ", rules).with("fuzz/script.situ", input_at(&path));
        if let Some(content) = bundle_of(&loader, "fuzz/rules.situ", &["fuzz/script.situ"]) {
            programs += 1;
            fired += both_engines(content, &path.display().to_string());
        }
    }
    // `bundle_decode`: the bytes as a bundle.
    for path in corpus("bundle_decode") {
        if let Ok(content) = situ_compiler::bundle::decode(&input_at(&path)) {
            programs += 1;
            fired += both_engines(content, &path.display().to_string());
        }
    }
    assert!(programs >= 50, "only {programs} programs of the corpora build: the test tests little");
    assert!(fired > 0, "no rule fired on the corpora's programs");
}

fn input_at(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}
