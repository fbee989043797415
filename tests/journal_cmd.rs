//! A deployment's Bulletinboard with `journal = …`, killed (SIGKILL) in the
//! middle of the mission and started again: it resumes from the state its
//! journal holds, not from the initial one (`situ_runtime::journal`).
//! The real binary over Zenoh, on loopback, on free ports; and
//! `situ run --journal` in one process.

use std::process::Command;
#[cfg(feature = "zenoh")]
use std::{
    io::{BufRead, BufReader},
    path::Path,
    process::{Child, Stdio},
    sync::mpsc,
    time::{Duration, Instant},
};

#[cfg(feature = "zenoh")]
fn port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

#[cfg(feature = "zenoh")]
/// Fig. 5 in three processes; the board journals to `board.journal` next
/// to the file.
fn deployment(dir: &Path) -> String {
    let (b, s, p) = (port(), port(), port());
    let text = format!(
        "robot = \"j{b}\"\n\
         [[process]]\nname = \"board\"\nboard = true\njournal = \"board.journal\"\nlisten = [\"tcp/127.0.0.1:{b}\"]\n\
         [[process]]\nname = \"sensors\"\nagents = [\"RFCCD\", \"LADAR\"]\nlisten = [\"tcp/127.0.0.1:{s}\"]\nconnect = [\"tcp/127.0.0.1:{b}\"]\n\
         [[process]]\nname = \"pipeline\"\nagents = [\"Fusion\", \"LPL\", \"Drive\"]\nlisten = [\"tcp/127.0.0.1:{p}\"]\nconnect = [\"tcp/127.0.0.1:{b}\", \"tcp/127.0.0.1:{s}\"]\n"
    );
    let path = dir.join("deploy.toml");
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

#[cfg(feature = "zenoh")]
fn run(deploy: &str, process: &str, duration: &str, extra: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_situ"))
        .env("NO_COLOR", "1")
        .args(["run", "examples/fig5/fig5.situ", "--stack", "demo", "--transport", "zenoh", "--deploy", deploy])
        .args(["--process", process, "--duration", duration])
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

#[cfg(feature = "zenoh")]
/// The lines of a child's standard error, as they come.
fn lines(child: &mut Child) -> mpsc::Receiver<String> {
    let (tx, rx) = mpsc::channel();
    let err = child.stderr.take().unwrap();
    std::thread::spawn(move || {
        for line in BufReader::new(err).lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    rx
}

#[cfg(feature = "zenoh")]
/// Waits (10 s at most) for a line with `what`; every line seen.
fn wait_for(rx: &mpsc::Receiver<String>, what: &str, seen: &mut Vec<String>) -> bool {
    let end = Instant::now() + Duration::from_secs(10);
    while let Some(left) = end.checked_duration_since(Instant::now()) {
        match rx.recv_timeout(left) {
            Ok(line) => {
                let hit = line.contains(what);
                seen.push(line);
                if hit {
                    return true;
                }
            }
            Err(_) => return false,
        }
    }
    false
}

#[test]
fn situ_run_journal_resumes_in_one_process_and_refuses_another_bundle() {
    let dir = tempfile::tempdir().unwrap();
    let journal = dir.path().join("fig5.journal");
    let j = journal.to_str().unwrap();
    let situ = |args: &[&str]| {
        let o = Command::new(env!("CARGO_BIN_EXE_situ")).env("NO_COLOR", "1").args(args).output().unwrap();
        (o.status.code(), String::from_utf8_lossy(&o.stderr).into_owned())
    };
    let (code, err) = situ(&["run", "examples/fig5/fig5.situ", "--stack", "demo", "--duration", "3", "--journal", j]);
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains("holds no entry"), "{err}");
    // Without agents: the journal's state, then LADAR and the camera are
    // stale at the first heartbeat (their 500 ms passed long ago).
    let (code, err) = situ(&["run", "examples/fig5/fig5.situ", "--stack", "none", "--duration", "0.5", "--journal", j]);
    assert_eq!(code, Some(0), "{err}");
    let line = err.lines().find(|l| l.starts_with("board: recovered ")).unwrap_or_else(|| panic!("{err}"));
    assert!(line.contains(": state RO, facts of ") && line.contains("LADAR"), "{line}");
    let before = std::fs::read(&journal).unwrap();
    let (code, err) = situ(&["run", "rules/outdoor.situ", "--stack", "none", "--duration", "0.5", "--journal", j]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("was written for the bundle") && err.contains("move it away"), "{err}");
    assert_eq!(std::fs::read(&journal).unwrap(), before, "left as it was");
}

#[cfg(feature = "zenoh")]
#[test]
fn a_board_killed_mid_mission_resumes_from_its_journal() {
    let dir = tempfile::tempdir().unwrap();
    let deploy = deployment(dir.path());
    let mut first = run(&deploy, "board", "20", &[]);
    let mut sensors = run(&deploy, "sensors", "20", &[]);
    let mut pipeline = run(&deploy, "pipeline", "20", &[]);
    let rx = lines(&mut first);
    let mut seen = Vec::new();
    let reached = wait_for(&rx, "board: state RO", &mut seen);
    first.kill().unwrap(); // SIGKILL: no goodbye, no flush
    let _ = first.wait();
    assert!(reached, "the first board reaches RO: {seen:#?}");
    assert!(seen.iter().any(|l| l.contains("holds no entry: the board starts from its initial state")), "{seen:#?}");

    let rec = dir.path().join("second.mcap");
    let mut second = run(&deploy, "board", "2", &["--record", rec.to_str().unwrap()]);
    let rx = lines(&mut second);
    let mut said = Vec::new();
    let recovered = wait_for(&rx, "board: recovered", &mut said);
    let out = second.wait_with_output().unwrap();
    said.extend(rx.try_iter());
    for c in [&mut sensors, &mut pipeline] {
        let _ = c.kill();
        let _ = c.wait();
    }
    assert!(recovered, "{said:#?}");
    let line = said.iter().find(|l| l.contains("board: recovered")).unwrap();
    assert!(line.contains("board.journal: state RO, facts of "), "{line}");
    // It never went back to the initial state: no change to RS, and the
    // recording's first state is the journal's.
    assert!(!said.iter().any(|l| l == "board: state RS"), "{said:#?}");
    let bytes = std::fs::read(&rec).unwrap();
    let (messages, _) = situ_runtime::record::mcap::read_messages(&bytes).unwrap();
    let diag = messages.iter().filter(|(t, _, _)| t == "/diagnostics").map(|(_, _, m)| m.to_string());
    assert!(diag.clone().any(|m| m.contains("recovered")), "{:?}", diag.collect::<Vec<_>>());
    // The changes it recorded: the journal's own (to RO), none back to RS
    // (then, at times, the rules' own: the camera's and LADAR's facts, 500 ms,
    // may have expired while it was down: EM, SP).
    let states: Vec<&str> = messages
        .iter()
        .filter(|(t, _, m)| t == "/state" && m["from"] != m["state"])
        .filter_map(|(_, _, m)| m["state"].as_str())
        .collect();
    let out = String::from_utf8_lossy(&out.stdout);
    assert!(states.first() == Some(&"RO") && !states.contains(&"RS"), "{states:?}\n{out}");
    assert!(out.contains("path: RO"), "the summary starts where the journal left it:\n{out}");
}
