//! Boards: a `situ_api::Board` per handle, its calls, and the callback on
//! every change of the state.

use crate::error::{call, situ_status, Failure};
use crate::handle::{self, Kind};
use crate::program::{situ_program, ProgramItem};
use crate::value::{arg, c_string, place, situ_arg, situ_value, slice, text};
use situ_api::{Arg, Board, Change, Clock, Posted};
use situ_bundle::Value;
use std::ffi::{c_char, c_void, CString};
use std::sync::{Arc, Mutex, MutexGuard};

/// A Bulletinboard in the caller's process: post events, read the
/// situation. Free it with `situ_board_free`.
pub struct situ_board {
    _opaque: [u8; 0],
}

/// Where a board's time comes from (one of the `SITU_CLOCK_*` constants).
pub type situ_clock = u32;
/// Time is what the caller stamps; it moves only with stamps and
/// `situ_board_advance`. For tests and replays.
pub const SITU_CLOCK_MANUAL: situ_clock = 0;
/// The system's clock (UNIX time, ns): an event without a stamp is
/// stamped now; one stamped too far ahead is not taken.
pub const SITU_CLOCK_SYSTEM: situ_clock = 1;

/// A time argument meaning "now, by the board's clock".
pub const SITU_NOW: u64 = u64::MAX;

/// The size of `situ_posted.reason`, its NUL included.
pub const SITU_REASON_LEN: usize = 256;

/// Why an event was not taken (`SITU_TAKEN` when it was).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum situ_not_taken {
    SITU_TAKEN = 0,
    /// Its agent sleeps in the current situation.
    SITU_NOT_TAKEN_SLEEPING = 1,
    /// Stamped before its agent's latest accepted event.
    SITU_NOT_TAKEN_OUT_OF_ORDER = 2,
    /// Stamped further ahead of the system clock than the skew bound.
    SITU_NOT_TAKEN_FROM_THE_FUTURE = 3,
    /// Refused by the engine's own payload check.
    SITU_NOT_TAKEN_PAYLOAD = 4,
    /// Any other reason the runtime gives (`reason` says it).
    SITU_NOT_TAKEN_OTHER = 5,
}

/// What a post did. Not taken is not an error (the call returns
/// `SITU_OK`): a running board drops such events too, and counts them.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct situ_posted {
    pub taken: bool,
    /// Taken, and the state changed (the callback was called).
    pub changed: bool,
    /// Taken, but the rules did not come to rest (a cascade): the board
    /// is in the state where they stopped; `reason` says why.
    pub cascade: bool,
    pub not_taken: situ_not_taken,
    /// Why it was not taken, or the cascade; `""` otherwise. Cut to fit.
    pub reason: [c_char; SITU_REASON_LEN],
}

/// A change of the state, as the callback sees it. Every pointer is
/// valid during the callback only.
#[repr(C)]
#[derive(Debug)]
pub struct situ_change {
    pub from: *const c_char,
    pub to: *const c_char,
    /// The board's time (ns).
    pub time: u64,
    /// The rules that fired, in order.
    pub rules: *const *const c_char,
    pub rule_count: usize,
}

/// Called on every change of the state (posts, advances, reloads), on the
/// thread of the call that made the change, after the board is unlocked:
/// it may call any function on the board, post and free included. It must
/// not unwind (a C++ exception must be caught inside it).
pub type situ_on_change = Option<unsafe extern "C" fn(change: *const situ_change, user_data: *mut c_void)>;

/// What the board did so far.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default)]
pub struct situ_counters {
    pub accepted: u64,
    pub changes: u64,
    pub sleeping: u64,
    pub out_of_order: u64,
    pub from_the_future: u64,
    pub payload: u64,
    pub other_not_taken: u64,
}

/// What a reload kept.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default)]
pub struct situ_reloaded {
    /// Agents whose facts carried over to the new rules.
    pub carried: usize,
    /// Agents whose facts were dropped (they do not fit the new rules).
    pub dropped: usize,
    /// The new rules fired at once on the facts kept.
    pub changed: bool,
}

#[derive(Clone, Copy)]
struct Callback {
    f: unsafe extern "C" fn(*const situ_change, *mut c_void),
    data: *mut c_void,
}

pub(crate) struct BoardCell {
    pub board: Board,
    callback: Option<Callback>,
    /// The payload of the fast path, reused.
    payload: Vec<Value>,
    /// The state names for `situ_board_state`, by state id.
    states: Vec<CString>,
}

// The user data pointer is the caller's: situ only hands it back to the
// callback, on the thread of the call, as the caller registered it.
unsafe impl Send for BoardCell {}

type Cell = Mutex<BoardCell>;

impl Kind for Cell {
    const WHAT: &'static str = "situ_board";
}

fn lock(cell: &Cell) -> Result<MutexGuard<'_, BoardCell>, Failure> {
    cell.lock()
        .map_err(|_| Failure::new(situ_status::SITU_ERR_PANIC, "an internal error left this board unusable: free it"))
}

fn state_names(board: &Board) -> Vec<CString> {
    board.content().states.iter().map(|s| c_string(&s.name)).collect()
}

/// Makes a board of a program with a clock (`SITU_CLOCK_MANUAL` or
/// `SITU_CLOCK_SYSTEM`), in the initial state with no facts.
#[no_mangle]
pub unsafe extern "C" fn situ_board_new(
    program: *const situ_program,
    clock: situ_clock,
    out: *mut *mut situ_board,
) -> situ_status {
    call(|| {
        let out = place(out, "the place for the board (out)")?;
        *out = std::ptr::null_mut();
        let program = handle::get::<ProgramItem>(program as usize)?;
        let clock = match clock {
            SITU_CLOCK_MANUAL => Clock::Manual,
            SITU_CLOCK_SYSTEM => Clock::System,
            other => return Err(Failure::new(situ_status::SITU_ERR_ARGUMENT, format!("no clock {other}"))),
        };
        let board = Board::new(program.content.clone(), clock);
        let states = state_names(&board);
        let cell = BoardCell { board, callback: None, payload: Vec::new(), states };
        *out = handle::insert(Mutex::new(cell)) as *mut situ_board;
        Ok(())
    })
}

/// Frees a board (null: nothing to do). `SITU_ERR_HANDLE` if it was
/// freed already. A callback may free its own board.
#[no_mangle]
pub extern "C" fn situ_board_free(board: *mut situ_board) -> situ_status {
    call(|| handle::remove::<Cell>(board as usize))
}

fn board(board: *const situ_board) -> Result<Arc<Cell>, Failure> {
    handle::get::<Cell>(board as usize)
}

/// Registers the callback called on every change of the state, with
/// `user_data`; a null callback removes it. One callback per board.
#[no_mangle]
pub unsafe extern "C" fn situ_board_on_change(
    board: *mut situ_board,
    callback: situ_on_change,
    user_data: *mut c_void,
) -> situ_status {
    call(|| {
        let cell = self::board(board)?;
        lock(&cell)?.callback = callback.map(|f| Callback { f, data: user_data });
        Ok(())
    })
}

/// An event's id by name: `EVENT`, or `AGENT.EVENT` (which also checks
/// that the agent reports it). The id is the fast path's
/// (`situ_board_post_values`); it stays valid until a reload.
#[no_mangle]
pub unsafe extern "C" fn situ_board_event(board: *const situ_board, name: *const c_char, id: *mut u32) -> situ_status {
    call(|| {
        let cell = self::board(board)?;
        let name = text(name, "the event's name")?;
        let id = place(id, "the place for the id")?;
        *id = lock(&cell)?.board.event(name)?;
        Ok(())
    })
}

fn at(time: u64) -> Option<u64> {
    (time != SITU_NOW).then_some(time)
}

/// Posts an event by name with its payload by field name (`count`
/// fields; every field once, each of its type; an integer is taken for a
/// number), stamped `at` ns (`SITU_NOW`: now, by the board's clock).
/// `out` may be null. An unknown event or field, a missing field, a value
/// of the wrong type: an error, and nothing changed. NaN is taken and
/// matches no comparison.
#[no_mangle]
pub unsafe extern "C" fn situ_board_post(
    board: *mut situ_board,
    event: *const c_char,
    args: *const situ_arg,
    count: usize,
    at: u64,
    out: *mut situ_posted,
) -> situ_status {
    call(|| {
        let cell = self::board(board)?;
        let name = text(event, "the event's name")?;
        let mut named = Vec::with_capacity(count);
        for (i, a) in slice(args, count, "the arguments")?.iter().enumerate() {
            let field = text(a.field, &format!("the name of field {i}"))?;
            named.push((field, arg(&a.value, field)?));
        }
        let mut g = lock(&cell)?;
        let id = g.board.event(name)?;
        let payload = g.board.payload(id, &named)?;
        let posted = g.board.post(id, self::at(at), &payload)?;
        finish(g, posted, out)
    })
}

/// Posts an event by id (from `situ_board_event`) with its values in
/// field order, without names: the fast path. Typed as `situ_board_post`
/// types them; too few values is `SITU_ERR_MISSING_FIELDS`, too many
/// `SITU_ERR_UNKNOWN_FIELD`.
#[no_mangle]
pub unsafe extern "C" fn situ_board_post_values(
    board: *mut situ_board,
    event: u32,
    values: *const situ_value,
    count: usize,
    at: u64,
    out: *mut situ_posted,
) -> situ_status {
    call(|| {
        let cell = self::board(board)?;
        let values = slice(values, count, "the values")?;
        let mut stack = [Arg::Bool(false); 16];
        let mut heap = Vec::new();
        let args: &[Arg] = if values.len() <= stack.len() {
            for (i, v) in values.iter().enumerate() {
                stack[i] = arg(v, "a field")?;
            }
            &stack[..values.len()]
        } else {
            for v in values {
                heap.push(arg(v, "a field")?);
            }
            &heap
        };
        let mut g = lock(&cell)?;
        let BoardCell { board, payload, .. } = &mut *g;
        board.payload_in_order(event, args, payload)?;
        let posted = board.post(event, self::at(at), payload)?;
        finish(g, posted, out)
    })
}

/// Writes what a post did, unlocks the board and calls the callback.
unsafe fn finish(g: MutexGuard<'_, BoardCell>, posted: Posted, out: *mut situ_posted) -> Result<(), Failure> {
    let callback = g.callback;
    // A refusal's text is made only for a caller that reads it.
    let reason = match &posted {
        Posted::NotTaken(r) if !out.is_null() => r.reason(g.board.content()),
        _ => String::new(),
    };
    drop(g);
    let change = match posted {
        Posted::Taken { change, error } => {
            if let Some(out) = out.as_mut() {
                out.taken = true;
                out.changed = change.is_some();
                out.cascade = error.is_some();
                out.not_taken = situ_not_taken::SITU_TAKEN;
                write_reason(out, error.as_deref().unwrap_or(""));
            }
            change
        }
        Posted::NotTaken(r) => {
            if let Some(out) = out.as_mut() {
                out.taken = false;
                out.changed = false;
                out.cascade = false;
                out.not_taken = not_taken(r.key);
                write_reason(out, &reason);
            }
            None
        }
    };
    notify(callback, change.as_ref());
    Ok(())
}

fn not_taken(key: &str) -> situ_not_taken {
    match key {
        "sleeping" => situ_not_taken::SITU_NOT_TAKEN_SLEEPING,
        "out of order" => situ_not_taken::SITU_NOT_TAKEN_OUT_OF_ORDER,
        "from the future" => situ_not_taken::SITU_NOT_TAKEN_FROM_THE_FUTURE,
        "payload" => situ_not_taken::SITU_NOT_TAKEN_PAYLOAD,
        _ => situ_not_taken::SITU_NOT_TAKEN_OTHER,
    }
}

/// Copies a reason into the fixed buffer, cut at a character boundary.
fn write_reason(out: &mut situ_posted, reason: &str) {
    let mut end = reason.len().min(SITU_REASON_LEN - 1);
    while !reason.is_char_boundary(end) {
        end -= 1;
    }
    // One copy (a `c_char` is a byte); a NUL inside, which no reason has,
    // would only cut the text short.
    let bytes = &reason.as_bytes()[..end];
    let dst = &mut out.reason[..end];
    dst.copy_from_slice(unsafe { &*(bytes as *const [u8] as *const [c_char]) });
    out.reason[end] = 0;
}

/// Calls the callback with a change, if both are there.
fn notify(callback: Option<Callback>, change: Option<&Change>) {
    let (Some(cb), Some(change)) = (callback, change) else { return };
    let from = c_string(&change.from);
    let to = c_string(&change.to);
    let rules: Vec<CString> = change.rules.iter().map(|r| c_string(r)).collect();
    let pointers: Vec<*const c_char> = rules.iter().map(|r| r.as_ptr()).collect();
    let c = situ_change {
        from: from.as_ptr(),
        to: to.as_ptr(),
        time: change.time,
        rules: if pointers.is_empty() { std::ptr::null() } else { pointers.as_ptr() },
        rule_count: pointers.len(),
    };
    // The caller's function, with the caller's data, as registered.
    unsafe { (cb.f)(&c, cb.data) }
}

/// Lets time pass to `to` ns (`SITU_NOW`: now, by the board's clock):
/// facts age and silent agents go stale. `changed` (may be null) says
/// whether the state changed (the callback was called).
#[no_mangle]
pub unsafe extern "C" fn situ_board_advance(board: *mut situ_board, to: u64, changed: *mut bool) -> situ_status {
    call(|| {
        let cell = self::board(board)?;
        let mut g = lock(&cell)?;
        let change = g.board.advance(at(to));
        let callback = g.callback;
        drop(g);
        if let Some(changed) = changed.as_mut() {
            *changed = change.is_some();
        }
        notify(callback, change.as_ref());
        Ok(())
    })
}

/// The state at rest, by name. Owned by the board: valid until it is
/// reloaded or freed.
#[no_mangle]
pub unsafe extern "C" fn situ_board_state(board: *const situ_board, out: *mut *const c_char) -> situ_status {
    call(|| {
        let cell = self::board(board)?;
        let out = place(out, "the place for the state")?;
        let g = lock(&cell)?;
        *out = g.states[g.board.state_id() as usize].as_ptr();
        Ok(())
    })
}

/// Whether the state at rest is final (declared `final` in the rules): no
/// rule leaves it, so no event changes it again.
#[no_mangle]
pub unsafe extern "C" fn situ_board_is_final(board: *const situ_board, out: *mut bool) -> situ_status {
    call(|| {
        let cell = self::board(board)?;
        let out = place(out, "the place for the answer")?;
        let g = lock(&cell)?;
        *out = g.board.is_final();
        Ok(())
    })
}

/// The board's latest time (ns).
#[no_mangle]
pub unsafe extern "C" fn situ_board_now(board: *const situ_board, out: *mut u64) -> situ_status {
    call(|| {
        let cell = self::board(board)?;
        *place(out, "the place for the time")? = lock(&cell)?.board.now();
        Ok(())
    })
}

/// How far ahead of the system clock an event may be stamped (ns).
#[no_mangle]
pub unsafe extern "C" fn situ_board_set_max_skew(board: *mut situ_board, ns: u64) -> situ_status {
    call(|| {
        let cell = self::board(board)?;
        lock(&cell)?.board.set_max_skew(ns);
        Ok(())
    })
}

/// What the board did so far.
#[no_mangle]
pub unsafe extern "C" fn situ_board_counters(board: *const situ_board, out: *mut situ_counters) -> situ_status {
    call(|| {
        let cell = self::board(board)?;
        let out = place(out, "the place for the counters")?;
        let g = lock(&cell)?;
        let c = g.board.counters();
        let mut counters = situ_counters { accepted: c.accepted, changes: c.changes, ..Default::default() };
        for (&key, &n) in &c.not_taken {
            match not_taken(key) {
                situ_not_taken::SITU_NOT_TAKEN_SLEEPING => counters.sleeping += n,
                situ_not_taken::SITU_NOT_TAKEN_OUT_OF_ORDER => counters.out_of_order += n,
                situ_not_taken::SITU_NOT_TAKEN_FROM_THE_FUTURE => counters.from_the_future += n,
                situ_not_taken::SITU_NOT_TAKEN_PAYLOAD => counters.payload += n,
                _ => counters.other_not_taken += n,
            }
        }
        *out = counters;
        Ok(())
    })
}

/// Takes a program's rules in place of the board's, keeping the state and
/// the facts that still fit (a hot swap); the new rules may fire at once
/// (the callback is called). On `SITU_ERR_RELOAD` the old rules stay.
/// Event ids and `situ_board_state`'s string are the new rules' after it.
/// `out` may be null.
#[no_mangle]
pub unsafe extern "C" fn situ_board_reload(
    board: *mut situ_board,
    program: *const situ_program,
    out: *mut situ_reloaded,
) -> situ_status {
    call(|| {
        let cell = self::board(board)?;
        let program = handle::get::<ProgramItem>(program as usize)?;
        let mut g = lock(&cell)?;
        let reloaded = g.board.reload(program.content.clone())?;
        g.states = state_names(&g.board);
        let callback = g.callback;
        drop(g);
        if let Some(out) = out.as_mut() {
            *out = situ_reloaded {
                carried: reloaded.carried.len(),
                dropped: reloaded.dropped.len(),
                changed: reloaded.change.is_some(),
            };
        }
        notify(callback, reloaded.change.as_ref());
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn posted() -> situ_posted {
        situ_posted {
            taken: false,
            changed: false,
            cascade: false,
            not_taken: situ_not_taken::SITU_TAKEN,
            reason: [1; SITU_REASON_LEN],
        }
    }

    fn text(p: &situ_posted) -> String {
        let bytes: Vec<u8> = p.reason.iter().take_while(|&&c| c != 0).map(|&c| c as u8).collect();
        String::from_utf8(bytes).expect("a whole UTF-8 text")
    }

    #[test]
    fn a_reason_is_copied_whole_when_it_fits_and_cut_at_a_character_when_not() {
        let mut p = posted();
        write_reason(&mut p, "`Arm` sleeps in CHARGING");
        assert_eq!(text(&p), "`Arm` sleeps in CHARGING");
        write_reason(&mut p, "");
        assert_eq!(text(&p), "");
        // 'é' is two bytes: 200 of them do not fit in 255, and the cut
        // falls between two characters.
        let long = "é".repeat(200);
        write_reason(&mut p, &long);
        assert_eq!(text(&p), "é".repeat(127));
    }
}
