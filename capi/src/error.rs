//! Status codes, the thread-local last error, and [`call`]: every entry
//! point's frame, which catches panics and records the error.

use situ_api::BoardError;
use std::cell::RefCell;
use std::ffi::{c_char, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// What a call did. `SITU_OK` is 0; every other value is an error, whose
/// message `situ_last_error()` gives on the same thread.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum situ_status {
    SITU_OK = 0,
    /// A pointer that must not be null was null.
    SITU_ERR_NULL = 1,
    /// A string is not valid UTF-8.
    SITU_ERR_UTF8 = 2,
    /// A handle that is freed, unknown, or of another kind.
    SITU_ERR_HANDLE = 3,
    /// An argument out of its range: an index past the end, an unknown
    /// value type or clock.
    SITU_ERR_ARGUMENT = 4,
    /// A bug in situ, caught before it reached the caller; the handle it
    /// happened on may be unusable (free it).
    SITU_ERR_PANIC = 5,
    /// A file could not be read (missing, not a regular file, too large).
    SITU_ERR_READ = 10,
    /// A trusted public-key file could not be read.
    SITU_ERR_KEY = 11,
    /// The rules have errors (the message names the first and its place).
    SITU_ERR_RULES = 12,
    /// A bundle is damaged, of another format version, or was changed.
    SITU_ERR_BUNDLE = 13,
    /// Not signed by a trusted key (or a source where only signed bundles
    /// are trusted).
    SITU_ERR_TRUST = 14,
    /// No event of that name (or id) in the rules.
    SITU_ERR_UNKNOWN_EVENT = 20,
    /// `AGENT.EVENT` where the agent does not report the event.
    SITU_ERR_NOT_ITS_AGENT = 21,
    /// The event has no such field (or fewer fields than values given).
    SITU_ERR_UNKNOWN_FIELD = 22,
    /// A field of the event was not given.
    SITU_ERR_MISSING_FIELDS = 23,
    /// A field was given twice.
    SITU_ERR_FIELD_TWICE = 24,
    /// A value of the wrong type for its field (or a symbol not in its
    /// enumeration).
    SITU_ERR_FIELD_TYPE = 25,
    /// A time that is not a whole number of nanoseconds from 0.
    SITU_ERR_BAD_TIME = 26,
    /// New rules that cannot take over; the old rules stay.
    SITU_ERR_RELOAD = 27,
}

use situ_status::*;

/// An error on its way to the caller: the status and the message.
#[derive(Debug)]
pub(crate) struct Failure {
    pub status: situ_status,
    pub message: String,
}

impl Failure {
    pub fn new(status: situ_status, message: impl Into<String>) -> Failure {
        Failure { status, message: message.into() }
    }
}

impl From<BoardError> for Failure {
    fn from(e: BoardError) -> Failure {
        let status = match &e {
            BoardError::UnknownEvent { .. } => SITU_ERR_UNKNOWN_EVENT,
            BoardError::NotItsAgent { .. } => SITU_ERR_NOT_ITS_AGENT,
            BoardError::UnknownField { .. } => SITU_ERR_UNKNOWN_FIELD,
            BoardError::MissingFields { .. } => SITU_ERR_MISSING_FIELDS,
            BoardError::FieldTwice { .. } => SITU_ERR_FIELD_TWICE,
            BoardError::FieldType { .. } => SITU_ERR_FIELD_TYPE,
            BoardError::BadTime(_) => SITU_ERR_BAD_TIME,
            BoardError::Reload(_) => SITU_ERR_RELOAD,
        };
        Failure::new(status, e.to_string())
    }
}

impl From<situ_api::Error> for Failure {
    fn from(e: situ_api::Error) -> Failure {
        use situ_api::Error as E;
        let status = match &e {
            E::Read { .. } | E::Root(_) | E::Write { .. } => SITU_ERR_READ,
            E::Findings { .. } | E::Syntax(_) | E::Script(_) => SITU_ERR_RULES,
            E::UnsignedSource { .. } | E::Trust(_) => SITU_ERR_TRUST,
            E::Bundle(_) | E::Attached(_) | E::NoAttachedBundle | E::Recording(_) | E::Replay(_) => SITU_ERR_BUNDLE,
        };
        let first = match &e {
            E::Findings { checked, .. } => checked
                .visible()
                .find(|d| d.severity == situ_api::Severity::Error)
                .map(|d| (checked.sources.get(d.primary.file), d)),
            _ => None,
        };
        let message = match first {
            Some((file, d)) => {
                let (line, col) = file.line_col(d.primary.span.start);
                format!("{e}; the first: {}:{line}:{col}: {}: {}", file.name, d.code, d.message)
            }
            None => e.to_string(),
        };
        Failure::new(status, message)
    }
}

thread_local! {
    static LAST: RefCell<(situ_status, CString)> = RefCell::new((SITU_OK, CString::default()));
}

fn record(status: situ_status, message: &str) {
    let message = CString::new(message.replace('\0', " ")).unwrap_or_default();
    LAST.with(|l| *l.borrow_mut() = (status, message));
}

/// Runs an entry point: catches a panic, records the error of a failure
/// or clears the last one on success (at the end, so that a failed call
/// made by a callback inside this one is not what the caller reads after
/// this one succeeded), and returns the status.
pub(crate) fn call(f: impl FnOnce() -> Result<(), Failure>) -> situ_status {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(())) => {
            LAST.with(|l| {
                let mut l = l.borrow_mut();
                if l.0 != SITU_OK {
                    *l = (SITU_OK, CString::default());
                }
            });
            SITU_OK
        }
        Ok(Err(failure)) => {
            record(failure.status, &failure.message);
            failure.status
        }
        Err(panic) => {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            record(SITU_ERR_PANIC, &format!("internal error in situ (please report it): {what}"));
            SITU_ERR_PANIC
        }
    }
}

/// The status of the last call on this thread that failed, or `SITU_OK`
/// if the last call succeeded.
#[no_mangle]
pub extern "C" fn situ_last_status() -> situ_status {
    LAST.with(|l| l.borrow().0)
}

/// The message of the last call on this thread that failed (`""` after a
/// success). Owned by situ: valid until the next situ call on this thread.
#[no_mangle]
pub extern "C" fn situ_last_error() -> *const c_char {
    LAST.with(|l| l.borrow().1.as_ptr())
}

/// A status's stable name (`"ok"`, `"unknown-event"`, …: the codes of
/// situ_api's `BoardError::code()` where there is one); `"?"` for a number
/// that is no status. Static: never freed.
#[no_mangle]
pub extern "C" fn situ_status_name(status: i32) -> *const c_char {
    let name: &'static str = match status {
        0 => "ok\0",
        1 => "null\0",
        2 => "utf8\0",
        3 => "handle\0",
        4 => "argument\0",
        5 => "panic\0",
        10 => "read\0",
        11 => "key\0",
        12 => "rules\0",
        13 => "bundle\0",
        14 => "trust\0",
        20 => "unknown-event\0",
        21 => "not-its-agent\0",
        22 => "unknown-field\0",
        23 => "missing-fields\0",
        24 => "field-twice\0",
        25 => "field-type\0",
        26 => "bad-time\0",
        27 => "reload\0",
        _ => "?\0",
    };
    name.as_ptr().cast()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ffi::CStr;

    fn last() -> (situ_status, String) {
        let message = unsafe { CStr::from_ptr(situ_last_error()) }.to_string_lossy().into_owned();
        (situ_last_status(), message)
    }

    #[test]
    fn a_panic_is_caught_and_answered_with_its_status_and_message() {
        let status = call(|| panic!("a bug in the engine"));
        assert_eq!(status, SITU_ERR_PANIC);
        let (code, message) = last();
        assert_eq!(code, SITU_ERR_PANIC);
        assert!(message.contains("a bug in the engine"), "{message}");
        // The next success clears it.
        assert_eq!(call(|| Ok(())), SITU_OK);
        assert_eq!(last(), (SITU_OK, String::new()));
    }

    #[test]
    fn a_failure_records_its_status_and_message_on_its_thread_only() {
        assert_eq!(call(|| Err(Failure::new(SITU_ERR_KEY, "no key"))), SITU_ERR_KEY);
        let other = std::thread::spawn(last).join().unwrap();
        assert_eq!(other, (SITU_OK, String::new()));
        assert_eq!(last(), (SITU_ERR_KEY, "no key".to_string()));
    }

    #[test]
    fn every_status_has_the_name_of_its_board_error_code() {
        let names = [
            (SITU_ERR_UNKNOWN_EVENT, "unknown-event"),
            (SITU_ERR_NOT_ITS_AGENT, "not-its-agent"),
            (SITU_ERR_UNKNOWN_FIELD, "unknown-field"),
            (SITU_ERR_MISSING_FIELDS, "missing-fields"),
            (SITU_ERR_FIELD_TWICE, "field-twice"),
            (SITU_ERR_FIELD_TYPE, "field-type"),
            (SITU_ERR_BAD_TIME, "bad-time"),
            (SITU_ERR_RELOAD, "reload"),
        ];
        for (status, name) in names {
            let got = unsafe { CStr::from_ptr(situ_status_name(status as i32)) }.to_str().unwrap();
            assert_eq!(got, name);
        }
    }
}
