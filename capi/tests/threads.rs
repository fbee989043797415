//! The C API from several threads at once, called as C calls it (through
//! the rlib's `extern "C"` functions): handles made, used and freed on
//! many threads, one board shared by several threads behind its lock.

use situ::*;
use std::ffi::{c_void, CString};
use std::ptr;
use std::sync::atomic::{AtomicUsize, Ordering};

const RULES: &str = "states { Closed initial Open }\n\
                     agent Door sensor { event OPENED { width: f64 } event CLOSED }\n\
                     rule opened { when state == Closed and OPENED(width > 0.1) then Open }\n\
                     rule closed { when state == Open and CLOSED then Closed }\n";

fn program() -> *mut situ_program {
    let (name, text) = (CString::new("door.situ").unwrap(), CString::new(RULES).unwrap());
    let mut p = ptr::null_mut();
    assert_eq!(unsafe { situ_program_from_source(name.as_ptr(), text.as_ptr(), &mut p) }, situ_status::SITU_OK);
    p
}

unsafe extern "C" fn count(_: *const situ_change, user: *mut c_void) {
    (*(user as *const AtomicUsize)).fetch_add(1, Ordering::Relaxed);
}

#[test]
fn one_board_shared_by_threads_sees_every_change_once() {
    let p = program();
    let mut b = ptr::null_mut();
    assert_eq!(unsafe { situ_board_new(p, SITU_CLOCK_MANUAL, &mut b) }, situ_status::SITU_OK);
    let changes = Box::new(AtomicUsize::new(0));
    let user = &*changes as *const AtomicUsize as *mut c_void;
    assert_eq!(unsafe { situ_board_on_change(b, Some(count), user) }, situ_status::SITU_OK);
    let (opened, closed) = {
        let (mut o, mut c) = (0, 0);
        let (on, cn) = (CString::new("OPENED").unwrap(), CString::new("CLOSED").unwrap());
        unsafe {
            situ_board_event(b, on.as_ptr(), &mut o);
            situ_board_event(b, cn.as_ptr(), &mut c);
        }
        (o, c)
    };
    let board = b as usize;
    std::thread::scope(|s| {
        for _ in 0..4 {
            s.spawn(move || {
                for _ in 0..500 {
                    let v = [situ_f64(1.0)];
                    let b = board as *mut situ_board;
                    unsafe {
                        assert_eq!(
                            situ_board_post_values(b, opened, v.as_ptr(), 1, SITU_NOW, ptr::null_mut()),
                            situ_status::SITU_OK
                        );
                        assert_eq!(
                            situ_board_post_values(b, closed, ptr::null(), 0, SITU_NOW, ptr::null_mut()),
                            situ_status::SITU_OK
                        );
                    }
                }
            });
        }
    });
    let mut c = situ_counters::default();
    assert_eq!(unsafe { situ_board_counters(b, &mut c) }, situ_status::SITU_OK);
    assert_eq!(c.accepted, 4000);
    assert_eq!(c.changes as usize, changes.load(Ordering::Relaxed), "the callback saw every change");
    assert!(c.changes >= 2);
    assert_eq!(situ_board_free(b), situ_status::SITU_OK);
    assert_eq!(situ_program_free(p), situ_status::SITU_OK);
}

#[test]
fn handles_made_and_freed_on_many_threads_stay_apart() {
    let p = program() as usize;
    std::thread::scope(|s| {
        for _ in 0..4 {
            s.spawn(move || {
                for _ in 0..200 {
                    let mut b = ptr::null_mut();
                    unsafe {
                        assert_eq!(
                            situ_board_new(p as *const situ_program, SITU_CLOCK_MANUAL, &mut b),
                            situ_status::SITU_OK
                        );
                        let mut state = ptr::null();
                        assert_eq!(situ_board_state(b, &mut state), situ_status::SITU_OK);
                    }
                    assert_eq!(situ_board_free(b), situ_status::SITU_OK);
                    // Freed: this thread's handle is dead, whatever the others made since.
                    let mut state = ptr::null();
                    assert_eq!(unsafe { situ_board_state(b, &mut state) }, situ_status::SITU_ERR_HANDLE);
                }
            });
        }
    });
    assert_eq!(situ_program_free(p as *mut situ_program), situ_status::SITU_OK);
}
