//! The real-time scheduling of the runtime's own threads
//! ([`RealtimeConfig::priority`](crate::realtime::RealtimeConfig::priority)):
//! each thread asks the kernel for `SCHED_FIFO` at a priority for itself
//! (`sched_setscheduler(2)` on the calling thread). A thread under
//! `SCHED_FIFO` runs as soon as it is woken, ahead of every thread of the
//! normal scheduler: the status fan-out's tail is then the kernel's
//! wake-up latency alone (docs/performance.md, "The agents' side of the
//! latency"). The kernel refuses it without `CAP_SYS_NICE` or an `rtprio`
//! limit; a refusal is an error the caller says, never a reason to stop.

use std::io;

/// A thread's scheduling policy and priority, as it was before [`enter`].
#[derive(Debug, Clone, Copy)]
pub struct Previous {
    policy: i32,
    priority: i32,
}

/// Puts the calling thread under `SCHED_FIFO` at `priority` (1 to 99 on
/// Linux); returns what it was, for [`leave`].
pub fn enter(priority: i32) -> io::Result<Previous> {
    // SAFETY: sched_getscheduler(2), sched_getparam(2) and
    // sched_setscheduler(2) on the calling thread (pid 0), with a
    // sched_param that lives across the calls.
    unsafe {
        let policy = libc::sched_getscheduler(0);
        if policy < 0 {
            return Err(io::Error::last_os_error());
        }
        let mut param: libc::sched_param = std::mem::zeroed();
        if libc::sched_getparam(0, &mut param) != 0 {
            return Err(io::Error::last_os_error());
        }
        let previous = Previous { policy, priority: param.sched_priority };
        let fifo = libc::sched_param { sched_priority: priority };
        if libc::sched_setscheduler(0, libc::SCHED_FIFO, &fifo) != 0 {
            return Err(io::Error::last_os_error());
        }
        Ok(previous)
    }
}

/// Gives the calling thread back the policy [`enter`] found.
pub fn leave(previous: Previous) {
    let param = libc::sched_param { sched_priority: previous.priority };
    // SAFETY: sched_setscheduler(2) on the calling thread with a valid
    // sched_param. Going back to the normal scheduler is always allowed.
    unsafe {
        libc::sched_setscheduler(0, previous.policy, &param);
    }
}

/// Whether the calling thread runs under `SCHED_FIFO`, and at which
/// priority (`None`: another policy).
pub fn current() -> Option<i32> {
    // SAFETY: as in `enter`.
    unsafe {
        if libc::sched_getscheduler(0) != libc::SCHED_FIFO {
            return None;
        }
        let mut param: libc::sched_param = std::mem::zeroed();
        (libc::sched_getparam(0, &mut param) == 0).then_some(param.sched_priority)
    }
}

/// What a refusal says (once per run, in the recording's `/diagnostics`
/// and on standard error by the caller).
pub fn refused(priority: i32, whose: &str, e: &io::Error) -> String {
    format!(
        "SCHED_FIFO at priority {priority} refused for {whose}: {e}; it runs under the normal scheduler (the \
         kernel grants it with CAP_SYS_NICE or an rtprio limit, `ulimit -r`)"
    )
}
