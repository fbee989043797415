//! Inputs at the edges of what the CLI reads: findings far to the right of
//! a line, files that are not regular files (FIFOs, devices), files over
//! the size limit, and include chains without end. Each must end quickly
//! with a report or a clear error, never a panic (exit 101) or a hang.

mod common;

use common::{code, stderr, stdout, text, write};
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Runs `situ ARGS…`, killed (and the test failed) if it has not ended
/// after a minute: what these tests guard against is a hang.
fn situ_bounded(args: &[&str]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_situ"))
        .args(args)
        .env("NO_COLOR", "1")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    // Read the pipes on threads, so that a full pipe cannot stall the child.
    let mut out = child.stdout.take().expect("piped");
    let mut err = child.stderr.take().expect("piped");
    let out = std::thread::spawn(move || {
        let mut bytes = Vec::new();
        std::io::Read::read_to_end(&mut out, &mut bytes).map(|_| bytes)
    });
    let err = std::thread::spawn(move || {
        let mut bytes = Vec::new();
        std::io::Read::read_to_end(&mut err, &mut bytes).map(|_| bytes)
    });
    let started = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("the child can be waited for") {
            break status;
        }
        if started.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("`situ {}` did not end within a minute", args.join(" "));
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let stdout = out.join().expect("reader thread").expect("stdout read");
    let stderr = err.join().expect("reader thread").expect("stderr read");
    Output { status, stdout, stderr }
}

fn no_panic(o: &Output, what: &str) {
    let code = o.status.code().unwrap_or_else(|| panic!("{what}: killed by a signal\n{}", text(o)));
    assert_ne!(code, 101, "{what} panicked:\n{}", text(o));
    assert!(!stderr(o).contains("panicked"), "{what}:\n{}", text(o));
}

#[test]
fn a_syntax_error_past_column_65536_is_reported() {
    let dir = tempfile::tempdir().unwrap();
    // 16,384 tabs are 65,536 columns as drawn.
    let f = write(dir.path(), "a.situ", format!("{}x\n", "\t".repeat(16_384)));
    let out = dir.path().join("a.json");
    let out = out.to_str().unwrap();
    for command in ["check", "fmt", "build", "test"] {
        let o = if command == "build" { situ_bounded(&[command, &f, "-o", out]) } else { situ_bounded(&[command, &f]) };
        no_panic(&o, command);
        assert_eq!(code(&o), 1, "{command}:\n{}", text(&o));
        let out = stdout(&o);
        assert!(out.contains("situ::E0001") && out.contains("a.situ:1:16385]"), "{command}:\n{out}");
        assert!(out.len() < 4_000, "{command}: the long line is drawn as a window, not whole ({} bytes)", out.len());
    }
}

#[test]
fn a_name_error_past_column_65536_is_reported() {
    let dir = tempfile::tempdir().unwrap();
    let source = format!("states {{ A initial B }}\nrule r {{ when state == A then{} C }}\n", " ".repeat(70_000));
    let f = write(dir.path(), "a.situ", &source);
    let out = dir.path().join("a.json");
    let out = out.to_str().unwrap();
    for command in ["check", "build", "test"] {
        let o = if command == "build" { situ_bounded(&[command, &f, "-o", out]) } else { situ_bounded(&[command, &f]) };
        no_panic(&o, command);
        assert_eq!(code(&o), 1, "{command}:\n{}", text(&o));
        let out = stdout(&o);
        assert!(out.contains("situ::E0101") && out.contains("a.situ:2:70031]"), "{command}:\n{out}");
        let window = format!("…{}C }}", " ".repeat(64));
        assert!(out.contains(&window), "{command}: the window around the name:\n{out}");
    }
    // Formatting such a file is no finding at all.
    let o = situ_bounded(&["fmt", &f]);
    no_panic(&o, "fmt");
    assert_eq!(code(&o), 0, "{}", text(&o));
}

/// Makes a FIFO at `path`.
#[cfg(unix)]
fn mkfifo(path: &Path) {
    use std::os::unix::ffi::OsStrExt;
    let name = std::ffi::CString::new(path.as_os_str().as_bytes()).expect("no NUL in a temp path");
    // SAFETY: `name` is a valid NUL-terminated string that outlives the call.
    let made = unsafe { libc::mkfifo(name.as_ptr(), 0o600) };
    assert_eq!(made, 0, "mkfifo {}: {}", path.display(), std::io::Error::last_os_error());
}

#[cfg(unix)]
#[test]
fn a_fifo_is_refused_not_waited_on() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("pipe.situ");
    mkfifo(&fifo);
    let fifo = fifo.to_str().unwrap();
    for args in [
        &["check", fifo][..],
        &["fmt", fifo],
        &["build", fifo, "-o", "unused.json"],
        &["run", fifo],
        &["graph", fifo, "--view", "rete"],
    ] {
        let o = situ_bounded(args);
        no_panic(&o, args[0]);
        assert_eq!(code(&o), 2, "{args:?}:\n{}", text(&o));
        let err = stderr(&o);
        assert!(err.contains(fifo) && err.contains("is a FIFO, not a regular file"), "{args:?}:\n{err}");
    }
    // As a bundle.
    let bundle = dir.path().join("pipe.json");
    mkfifo(&bundle);
    let o = situ_bounded(&["bench", bundle.to_str().unwrap()]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(stderr(&o).contains("is a FIFO, not a regular file"), "{}", text(&o));
    // Included: a finding at the include.
    let root = write(dir.path(), "root.situ", "include \"pipe.situ\"\nstates { A initial }\n");
    let o = situ_bounded(&["check", &root]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    let out = stdout(&o);
    assert!(out.contains("situ::E0003") && out.contains("is a FIFO, not a regular file"), "{out}");
}

#[cfg(unix)]
#[test]
fn a_device_is_refused_not_read_forever() {
    for args in [
        &["fmt", "/dev/zero"][..],
        &["graph", "/dev/zero", "--view", "rete"],
        &["bench", "/dev/zero"],
        &["run", "/dev/zero"],
    ] {
        let o = situ_bounded(args);
        no_panic(&o, args[0]);
        assert_eq!(code(&o), 2, "{args:?}:\n{}", text(&o));
        let err = stderr(&o);
        assert!(
            err.contains("/dev/zero") && err.contains("is a character device, not a regular file"),
            "{args:?}:\n{err}"
        );
    }
    // A scenario.
    let o = situ_bounded(&["run", "rules/outdoor.situ", "--scenario", "/dev/zero"]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(stderr(&o).contains("is a character device, not a regular file"), "{}", text(&o));
}

#[test]
fn fmt_refuses_a_file_over_the_limit_and_leaves_it() {
    let dir = tempfile::tempdir().unwrap();
    // 17 MiB that formatting would change: badly spaced states, then comments.
    let mut source = String::from("states {A initial}\n");
    let line = "// a comment that pads the file to over the limit of a source\n";
    while source.len() < 17 * 1024 * 1024 {
        source.push_str(line);
    }
    let f = write(dir.path(), "big.situ", &source);
    for args in [&["fmt", &f][..], &["fmt", "--check", &f]] {
        let o = situ_bounded(args);
        assert_eq!(code(&o), 2, "{args:?}:\n{}", text(&o));
        let err = stderr(&o);
        assert!(err.contains("big.situ") && err.contains("larger than the limit of 16 MiB"), "{err}");
    }
    assert!(std::fs::read(&f).unwrap() == source.as_bytes(), "the file is left as it was");
}

#[test]
fn a_long_include_chain_is_e0009_at_the_include_too_deep() {
    let dir = tempfile::tempdir().unwrap();
    let n = 20_000;
    for i in 0..n {
        let content =
            if i + 1 < n { format!("include \"a{}.situ\"\n", i + 1) } else { "states { A initial }\n".into() };
        write(dir.path(), &format!("a{i}.situ"), content);
    }
    let root = dir.path().join("a0.situ");
    let o = situ_bounded(&["check", "--format", "json", root.to_str().unwrap()]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    let findings: Vec<serde_json::Value> =
        stdout(&o).lines().map(|l| serde_json::from_str(l).expect("a JSON line")).collect();
    let codes: Vec<&str> = findings.iter().map(|f| f["code"].as_str().unwrap()).collect();
    assert!(codes.contains(&"situ::E0009") && !codes.contains(&"situ::E0001"), "{codes:?}");
    let deep = findings.iter().find(|f| f["code"] == "situ::E0009").unwrap();
    // The root is level 0: a64 is the 64th level, its include the 65th.
    assert!(deep["file"].as_str().unwrap().ends_with("a64.situ"), "{deep}");
    assert_eq!(deep["witness"]["limit"], 64);
    assert_eq!(deep["witness"]["chain"].as_array().unwrap().len(), 66);
    assert!(deep["help"].as_str().unwrap().contains("a2.situ -> … -> "), "{deep}");
}
