//! `situ run … --foxglove [ADDR]`: a Foxglove WebSocket client (Python's
//! `websockets`, tests/python/foxglove_client.py) receives the run's
//! channels and messages live, the same as the recording's; a port in use
//! is a clear error naming it (exit 2). The Python packages
//! (`pip install -r examples/python/requirements.txt`) must be installed:
//! a missing one fails.

mod common;

use common::{code, situ, stderr, stdout, text};
use std::net::TcpListener;
use std::path::Path;
use std::process::{Child, Command, Stdio};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A port free a moment ago.
fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0").expect("a free port").local_addr().unwrap().port()
}

/// Kills the run if the test fails before it ends.
struct Run(Option<Child>);

impl Drop for Run {
    fn drop(&mut self) {
        if let Some(mut c) = self.0.take() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

/// `situ run FILE ARGS… --foxglove ADDR --record F` watched by the Python
/// client (with `client_args`); the client's report and the run's output.
fn watched(file: &str, args: &[&str], client_args: &[&str]) -> (String, std::process::Output, String) {
    let tmp = tempfile::tempdir().unwrap();
    let recording = tmp.path().join("run.mcap");
    let port = free_port();
    let addr = format!("127.0.0.1:{port}");
    let child = Command::new(env!("CARGO_BIN_EXE_situ"))
        .args(["run", file])
        .args(args)
        .args(["--foxglove", &addr, "--record"])
        .arg(&recording)
        .current_dir(root())
        .env("NO_COLOR", "1")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    let mut run = Run(Some(child));
    let client = Command::new("python3")
        .arg(root().join("tests/python/foxglove_client.py"))
        .arg(format!("ws://{addr}"))
        .arg("--recording")
        .arg(&recording)
        .args(client_args)
        .output()
        .expect("python3 runs");
    let client_text = text(&client);
    assert!(
        !client_text.contains("ModuleNotFoundError"),
        "a Python package is missing: pip install -r examples/python/requirements.txt\n{client_text}"
    );
    if !client.status.success() {
        drop(run); // a run still waiting for its client
        panic!("the client failed:\n{client_text}");
    }
    let out = run.0.take().unwrap().wait_with_output().unwrap();
    assert!([0, 1].contains(&code(&out)), "{}", text(&out));
    (client_text, out, addr)
}

#[test]
fn a_foxglove_client_receives_the_runs_channels_and_messages_live() {
    let (client_text, out, addr) = watched("rules/outdoor.situ", &["--until", "4"], &[]);
    for topic in ["/pose", "/obstacles", "/state", "/events", "/situ/events"] {
        assert!(client_text.contains(topic), "{topic} not received:\n{client_text}");
    }
    assert!(client_text.contains("messages received live"), "{client_text}");
    let err = stderr(&out);
    assert!(err.contains(&format!("foxglove: serving ws://{addr}")), "{err}");
    assert!(err.contains("a client subscribed"), "{err}");
}

#[test]
fn a_users_scripted_run_is_watched_in_foxglove_too() {
    // A greenhouse of our own, on its script: no vehicle, the rules' channels.
    let (client_text, out, _) = watched("tests/view/greenhouse.situ", &[], &["--rules-only"]);
    for topic in ["/state", "/events", "/situ/events", "/situ/modes"] {
        assert!(client_text.contains(topic), "{topic} not received:\n{client_text}");
    }
    assert!(!client_text.contains("/pose"), "no vehicle, no pose:\n{client_text}");
    assert!(stdout(&out).contains("path: GROWING → VENTING"), "{}", text(&out));
}

#[test]
fn a_port_in_use_is_an_error_naming_it() {
    let busy = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = busy.local_addr().unwrap().to_string();
    let o = situ(&["run", "rules/outdoor.situ", "--until", "1", "--foxglove", &addr]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    let err = stderr(&o);
    assert!(err.contains(&addr) && err.contains("in use"), "{err}");
}

#[test]
fn a_bad_address_is_a_usage_error() {
    let o = situ(&["run", "rules/outdoor.situ", "--until", "1", "--foxglove", "nowhere"]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(stderr(&o).contains("`nowhere` is not an address"), "{}", text(&o));
}
