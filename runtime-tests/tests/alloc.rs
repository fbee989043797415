//! A step allocates nothing once the engine is warm (docs/performance.md):
//! `Engine::step` records its firings, with the facts they matched, in
//! buffers it reuses, and every memory of the network is of fixed size.
//!
//! The global allocator of this test binary (and only of it: this file is
//! its own test target) counts the allocations of the threads that ask it
//! to. The engine is warmed on the outdoor rules by a seeded stream, then
//! steps the next events of the same stream, a mission reset after each
//! final state as `situ bench` does, with every allocation counted.

use situ_compiler::bundle::{Content, Value};
use situ_runtime::rete::{Engine, Step, StepError};
use situ_runtime::stream::Generator;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::Arc;

struct Counting;

thread_local! {
    /// Whether this thread's allocations are counted, and how many were
    /// (per thread: the tests of this file run at once).
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

fn note() {
    if COUNTING.with(Cell::get) {
        ALLOCATIONS.with(|n| n.set(n.get() + 1));
    }
}

// SAFETY: every call is forwarded to `System` unchanged; counting only
// touches `const`-initialised thread-local `Cell`s, which allocate nothing.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note();
        // SAFETY: the caller's contract is `System::alloc`'s.
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note();
        // SAFETY: as `alloc`.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note();
        // SAFETY: the caller's contract is `System::realloc`'s.
        unsafe { System.realloc(ptr, layout, new_size) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: the caller's contract is `System::dealloc`'s.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Counts the allocations `f` makes on this thread.
fn allocations(f: impl FnOnce()) -> u64 {
    let before = ALLOCATIONS.with(Cell::get);
    COUNTING.with(|c| c.set(true));
    f();
    COUNTING.with(|c| c.set(false));
    ALLOCATIONS.with(Cell::get) - before
}

fn outdoor() -> Arc<Content> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../rules/outdoor.situ");
    let checked = situ_compiler::check(&path, &situ_compiler::loader::FsLoader).expect("readable");
    assert_eq!(checked.errors(), 0, "{:?}", checked.diagnostics);
    Arc::new(situ_compiler::bundle::build(&checked))
}

/// Events, flat: `(event, time, payload start, end)` into a payload arena.
type Events = Vec<(u32, u64, usize, usize)>;

/// `n` events of the seeded stream, and their payloads.
fn stream(content: &Arc<Content>, seed: u64, n: usize) -> (Events, Vec<Value>) {
    let mut g = Generator::new(content.clone(), seed);
    let mut values = Vec::new();
    let mut events = Vec::with_capacity(n);
    for _ in 0..n {
        let s = values.len();
        let (event, time) = g.next_into(&mut values).expect("the outdoor agents report events");
        events.push((event, time, s, values.len()));
    }
    (events, values)
}

// The native code of `rules/outdoor.situ` (`situ build --native`).
#[rustfmt::skip]
#[path = "../native/outdoor.rs"]
mod outdoor_native;

type StepFn = fn(&mut Engine, u32, u64, &[Value]) -> Result<Step, StepError>;

/// Steps the events as `situ bench` does; returns the firings and the
/// missions ended.
fn steps(engine: &mut Engine, events: &[(u32, u64, usize, usize)], values: &[Value]) -> (usize, usize) {
    steps_by(engine, events, values, |e, event, time, payload| e.step(event, time, payload))
}

/// [`steps`], each step by `step`.
fn steps_by(
    engine: &mut Engine,
    events: &[(u32, u64, usize, usize)],
    values: &[Value],
    step: StepFn,
) -> (usize, usize) {
    let (mut firings, mut missions) = (0, 0);
    for &(event, time, s, e) in events {
        firings += step(engine, event, time, &values[s..e]).expect("the stream's events are accepted").firings;
        if engine.reset_if_final() {
            missions += 1;
        }
    }
    (firings, missions)
}

#[test]
fn a_warm_step_allocates_nothing() {
    let content = outdoor();
    let (warm, counted) = (20_000, 5_000);
    let (events, values) = stream(&content, 1, warm + counted);
    let mut engine = Engine::new(content);
    steps(&mut engine, &events[..warm], &values);

    let mut done = (0, 0);
    let n = allocations(|| done = steps(&mut engine, &events[warm..], &values));
    let (firings, missions) = done;
    // The counted steps did work: rules fired, missions ended and reset.
    assert!(firings > 200 && missions > 50, "{firings} firings, {missions} missions");
    assert_eq!(n, 0, "{n} allocations in {counted} warm steps ({firings} firings, {missions} missions)");
}

#[test]
fn the_counter_counts() {
    // The test above cannot pass by a counter that never counts.
    let n = allocations(|| drop(std::hint::black_box(vec![1u8; 64])));
    assert_eq!(n, 1);
}

/// The same with native code, through `Engine::step` and through the
/// module's own `step`.
#[test]
fn a_warm_native_step_allocates_nothing() {
    let content = outdoor();
    let (warm, counted) = (20_000, 5_000);
    let (events, values) = stream(&content, 2, warm + counted);
    let through: StepFn = |e, event, time, payload| e.step(event, time, payload);
    for step in [through, outdoor_native::step as StepFn] {
        let mut engine = Engine::with_native(content.clone(), &outdoor_native::NATIVE).expect("its bundle");
        steps_by(&mut engine, &events[..warm], &values, step);
        let mut done = (0, 0);
        let n = allocations(|| done = steps_by(&mut engine, &events[warm..], &values, step));
        let (firings, missions) = done;
        assert!(firings > 200 && missions > 50, "{firings} firings, {missions} missions");
        assert_eq!(n, 0, "{n} allocations in {counted} warm native steps ({firings} firings, {missions} missions)");
    }
}
