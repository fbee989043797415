//! `situ check --watch`: check again on every save of a root or of any file
//! it includes, until Ctrl-C.
//!
//! A round checks every root through a loader that notes each path it is
//! asked for (read or not: an include that is missing today is watched for
//! tomorrow), then prints a separator line with the time and the round's
//! summary; the screen is never cleared. The directories of those files are
//! watched (an editor that saves by renaming a new file over the old one is
//! seen; so is a file that comes back), and a burst of events is one round
//! once it has been quiet for [`DEBOUNCE`].

use super::{CliError, Outcome, OK};
use notify::event::{AccessKind, AccessMode, EventKind};
use notify::{RecursiveMode, Watcher};
use situ_compiler::loader::{normalize, FsLoader, Loader};
use std::cell::RefCell;
use std::collections::{BTreeMap, BTreeSet};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;

/// How long the files must be quiet before a round starts.
pub const DEBOUNCE: Duration = Duration::from_millis(100);

/// Runs `round` (one check of everything, printing its report; it returns
/// the summary for the separator line) now and after every change of the
/// files it read. `machine` output (JSON, SARIF) keeps standard output for
/// the documents: the separator and the notes go to standard error.
/// Ends with [`OK`] on Ctrl-C (or SIGTERM).
pub fn run(mut round: impl FnMut(&dyn Loader) -> String, machine: bool) -> Outcome {
    let (tx, rx) = mpsc::channel::<Message>();
    let stop = tx.clone();
    if let Err(e) = ctrlc::set_handler(move || {
        let _ = stop.send(Message::Stop);
    }) {
        return Err(CliError::Usage(format!("cannot catch Ctrl-C: {e}")));
    }
    let mut watcher = match notify::recommended_watcher(move |event| {
        let _ = tx.send(Message::Fs(event));
    }) {
        Ok(watcher) => watcher,
        Err(e) => return Err(CliError::Usage(format!("cannot watch files: {e}"))),
    };
    let say = |line: &str| {
        if machine {
            eprintln!("{line}");
        } else {
            println!("{line}");
        }
    };
    // Every file a round asked for (by key), with its name as given and
    // whether it was there after the last round.
    let mut files: BTreeMap<PathBuf, (String, bool)> = BTreeMap::new();
    let mut watched: BTreeSet<PathBuf> = BTreeSet::new();
    loop {
        let loader = Recording::default();
        let summary = round(&loader);
        for path in loader.asked.into_inner() {
            let key = key(&path);
            let present = key.is_file();
            files.entry(key).or_insert_with(|| (path.display().to_string(), present));
        }
        for (key, (name, present)) in &mut files {
            let now = key.is_file();
            if *present && !now {
                say(&format!("note: `{name}` is gone; watching for it to come back"));
            }
            *present = now;
        }

        // Watch the directory of each file, or its nearest ancestor that
        // exists, before saying so: a save right after the line is seen.
        let targets: BTreeSet<PathBuf> =
            files.keys().filter_map(|f| f.parent()).filter_map(existing_ancestor).collect();
        for gone in watched.difference(&targets) {
            let _ = watcher.unwatch(gone);
        }
        watched.retain(|d| targets.contains(d));
        for dir in &targets {
            if !watched.contains(dir) {
                match watcher.watch(dir, RecursiveMode::NonRecursive) {
                    Ok(()) => {
                        watched.insert(dir.clone());
                    }
                    Err(e) => eprintln!("warning: cannot watch `{}`: {e}", dir.display()),
                }
            }
        }
        say(&format!(
            "---- {} ---- {summary} ---- watching {} (Ctrl-C ends) ----",
            clock(),
            count(files.len(), "file")
        ));
        let _ = std::io::stdout().flush();

        // Wait for a change to one of the files, then for quiet.
        loop {
            match rx.recv() {
                Ok(Message::Fs(Ok(event))) if concerns(&event, &files) => break,
                Ok(Message::Fs(Ok(_))) => {}
                Ok(Message::Fs(Err(e))) => eprintln!("warning: watching: {e}"),
                Ok(Message::Stop) | Err(_) => return Ok(OK),
            }
        }
        loop {
            match rx.recv_timeout(DEBOUNCE) {
                Ok(Message::Stop) | Err(mpsc::RecvTimeoutError::Disconnected) => return Ok(OK),
                Ok(Message::Fs(_)) => {}
                Err(mpsc::RecvTimeoutError::Timeout) => break,
            }
        }
    }
}

enum Message {
    Fs(notify::Result<notify::Event>),
    Stop,
}

/// The file system's loader, noting every path the compiler asks about.
#[derive(Default)]
struct Recording {
    asked: RefCell<BTreeSet<PathBuf>>,
}

impl Loader for Recording {
    fn read(&self, path: &Path) -> std::io::Result<Vec<u8>> {
        self.asked.borrow_mut().insert(path.to_path_buf());
        FsLoader.read(path)
    }

    fn identity(&self, path: &Path) -> std::io::Result<PathBuf> {
        self.asked.borrow_mut().insert(path.to_path_buf());
        FsLoader.identity(path)
    }
}

/// A path as the watcher reports it: absolute, its directory resolved when
/// it exists (the file itself may be gone), otherwise without `.` and `..`.
fn key(path: &Path) -> PathBuf {
    let absolute = normalize(&std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf()));
    match (absolute.parent(), absolute.file_name()) {
        (Some(dir), Some(name)) => dir.canonicalize().map_or(absolute.clone(), |d| d.join(name)),
        _ => absolute,
    }
}

fn existing_ancestor(dir: &Path) -> Option<PathBuf> {
    dir.ancestors().find(|d| d.is_dir()).map(Path::to_path_buf)
}

/// Whether an event may change what a round reads: a change (not a mere
/// open or read, which the round's own reading causes) of one of the files,
/// or of a directory on the way to one.
fn concerns(event: &notify::Event, files: &BTreeMap<PathBuf, (String, bool)>) -> bool {
    let change = match event.kind {
        EventKind::Access(AccessKind::Close(AccessMode::Write)) => true,
        EventKind::Access(_) => false,
        _ => true,
    };
    change
        && event.paths.iter().map(|p| key(p)).any(|p| files.contains_key(&p) || files.keys().any(|f| f.starts_with(&p)))
}

/// The local time of day, `HH:MM:SS` (UTC where the local zone is unknown).
fn clock() -> String {
    let secs = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs());
    #[cfg(unix)]
    {
        let t = secs as libc::time_t;
        // SAFETY: `tm` is plain data that localtime_r fills; both pointers are valid.
        let mut tm: libc::tm = unsafe { std::mem::zeroed() };
        if !unsafe { libc::localtime_r(&t, &mut tm) }.is_null() {
            return format!("{:02}:{:02}:{:02}", tm.tm_hour, tm.tm_min, tm.tm_sec);
        }
    }
    let day = secs % 86_400;
    format!("{:02}:{:02}:{:02} UTC", day / 3600, day / 60 % 60, day % 60)
}

fn count(n: usize, what: &str) -> String {
    if n == 1 {
        format!("1 {what}")
    } else {
        format!("{n} {what}s")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_agree_for_two_spellings_of_one_file() {
        let dir = std::env::temp_dir();
        let a = key(&dir.join("x.situ"));
        let b = key(&dir.join("sub/../x.situ"));
        assert_eq!(a, b);
        assert!(a.is_absolute());
    }

    #[test]
    fn the_clock_reads_like_a_time_of_day() {
        let t = clock();
        assert_eq!(&t[2..3], ":");
        assert_eq!(&t[5..6], ":");
    }

    #[test]
    fn reading_a_file_is_not_a_change() {
        let mut files = BTreeMap::new();
        let f = key(Path::new("rules/outdoor.situ"));
        files.insert(f.clone(), ("rules/outdoor.situ".to_string(), true));
        let open = notify::Event::new(EventKind::Access(AccessKind::Open(AccessMode::Any))).add_path(f.clone());
        let write = notify::Event::new(EventKind::Modify(notify::event::ModifyKind::Any)).add_path(f.clone());
        let other =
            notify::Event::new(EventKind::Modify(notify::event::ModifyKind::Any)).add_path(f.with_extension("x"));
        let dir = notify::Event::new(EventKind::Create(notify::event::CreateKind::Folder))
            .add_path(f.parent().unwrap().to_path_buf());
        assert!(!concerns(&open, &files));
        assert!(concerns(&write, &files));
        assert!(!concerns(&other, &files));
        assert!(concerns(&dir, &files));
    }
}
