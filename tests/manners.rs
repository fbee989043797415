//! The manners of a command-line tool: shell completions, man pages,
//! `check --watch`, unreadable files that tools cannot take for clean ones,
//! and quiet ends on a closed pipe. They run the real `situ` binary.

mod common;

use common::{code, situ, stderr, stdout, write};
use std::io::{BufRead, BufReader, Read};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

const VALID: &str = "states { IT initial RD final }\nagent Ready sensor { event RDY }\nrule ready { when state == IT and RDY then RD }\n";

/// The longest any wait on the child may take before the test fails.
const PATIENCE: Duration = Duration::from_secs(20);

/// The subcommands `situ --help` lists (but `help`).
fn subcommands() -> Vec<String> {
    let help = stdout(&situ(&["--help"]));
    let list = help.split("Commands:\n").nth(1).expect("a list of commands");
    list.lines()
        .take_while(|l| !l.trim().is_empty())
        .filter_map(|l| l.split_whitespace().next())
        .filter(|name| *name != "help")
        .map(str::to_string)
        .collect()
}

#[test]
fn bash_completions_know_the_subcommands_and_their_options() {
    let o = situ(&["completions", "bash"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let script = stdout(&o);
    assert!(script.contains("_situ()"), "{script}");
    for word in ["check", "--watch", "--deny-warnings", "explain", "man", "completions"] {
        assert!(script.contains(word), "no `{word}` in the bash completions");
    }
    for shell in ["zsh", "fish", "powershell", "elvish"] {
        let o = situ(&["completions", shell]);
        assert_eq!(code(&o), 0, "{shell}: {}", stderr(&o));
        assert!(stdout(&o).contains("watch"), "{shell}");
    }
    assert_eq!(code(&situ(&["completions", "tcsh"])), 2);
}

#[test]
fn the_man_page_is_roff_and_names_every_subcommand() {
    let o = situ(&["man"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let page = stdout(&o);
    // roff: clap_mangen's two-line preamble (`.ie`/`.el`, the apostrophe
    // string for groff and the others), then the title.
    let first = page.lines().find(|l| !l.starts_with(".ie ") && !l.starts_with(".el ")).unwrap();
    assert!(first.starts_with(".TH situ 1"), "{page}");
    let names = subcommands();
    assert!(names.len() >= 15, "{names:?}");
    for name in &names {
        assert!(page.contains(name.as_str()), "the man page does not mention `{name}`");
    }
}

#[test]
fn man_into_a_directory_writes_a_page_per_subcommand() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("man1");
    let o = situ(&["man", "-o", out.to_str().unwrap()]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let top = std::fs::read_to_string(out.join("situ.1")).expect("situ.1");
    assert!(top.contains(".TH situ 1"), "{top}");
    for name in subcommands() {
        let page = std::fs::read_to_string(out.join(format!("situ-{name}.1")))
            .unwrap_or_else(|e| panic!("situ-{name}.1: {e}"));
        assert!(page.contains(&format!(".TH situ-{name} 1")), "situ-{name}.1:\n{page}");
    }
    let check = std::fs::read_to_string(out.join("situ-check.1")).unwrap();
    assert!(check.contains("watch"), "{check}");
    assert!(out.join("situ-gen-agent.1").is_file(), "nested subcommands get pages too");
    assert!(!out.join("situ-help.1").exists());
    let names: Vec<String> =
        std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert!(names.iter().all(|n| n.ends_with(".1") && !n.starts_with('.')), "no temporary files left: {names:?}");
}

fn sarif_of(args: &[&str]) -> (i32, serde_json::Value) {
    let o = situ(args);
    let log = serde_json::from_str(&stdout(&o)).unwrap_or_else(|e| panic!("one SARIF document: {e}\n{}", stdout(&o)));
    (code(&o), log)
}

#[test]
fn sarif_of_an_unreadable_file_is_an_unsuccessful_run() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.situ");
    let missing = missing.to_str().unwrap();
    let directory = dir.path().to_str().unwrap();
    for path in [missing, directory] {
        let (code, log) = sarif_of(&["check", "--format", "sarif", path]);
        assert_eq!(code, 2, "{path}");
        assert_eq!(log["version"], "2.1.0");
        let invocation = &log["runs"][0]["invocations"][0];
        assert_eq!(invocation["executionSuccessful"], false, "{path}: {invocation}");
        let note = &invocation["toolExecutionNotifications"][0];
        assert_eq!(note["level"], "error");
        assert!(note["message"]["text"].as_str().unwrap().contains(path), "{note}");
        assert_eq!(note["locations"][0]["physicalLocation"]["artifactLocation"]["uri"], path);
    }
    // A readable file next to an unreadable one: its findings and the failure.
    let good = write(dir.path(), "good.situ", VALID);
    let (code, log) = sarif_of(&["check", "--format", "sarif", &good, missing]);
    assert_eq!(code, 2);
    assert_eq!(log["runs"][0]["invocations"][0]["executionSuccessful"], false);
    assert_eq!(log["runs"][0]["invocations"][0]["toolExecutionNotifications"].as_array().unwrap().len(), 1);
    // A clean run says it ran well; the rules carry their documentation, not a made-up address.
    let (code, log) = sarif_of(&["check", "--format", "sarif", &good]);
    assert_eq!(code, 0);
    let run = &log["runs"][0];
    assert_eq!(run["invocations"][0]["executionSuccessful"], true);
    assert!(run["invocations"][0].get("toolExecutionNotifications").is_none());
    let driver = &run["tool"]["driver"];
    assert!(driver.get("informationUri").is_none());
    assert!(!log.to_string().contains("example.invalid"));
    for rule in driver["rules"].as_array().unwrap() {
        assert!(rule["fullDescription"]["text"].as_str().is_some_and(|t| !t.is_empty()), "{}", rule["id"]);
        assert!(rule["help"]["text"].as_str().is_some_and(|t| t.contains("What it does")), "{}", rule["id"]);
        assert!(rule["help"]["markdown"].as_str().is_some_and(|t| t.contains("## Example")), "{}", rule["id"]);
    }
}

#[test]
fn sarif_of_a_root_that_is_not_utf8_is_not_clean() {
    // Not UTF-8 is a finding (E0002), not an I/O error: the run went well and found an error.
    let dir = tempfile::tempdir().unwrap();
    let latin = write(dir.path(), "latin.situ", b"states { IT initial \xb0 }\n");
    let (code, log) = sarif_of(&["check", "--format", "sarif", &latin]);
    assert_eq!(code, 1);
    let result = &log["runs"][0]["results"][0];
    assert_eq!(result["ruleId"], "situ::E0002");
    assert_eq!(result["level"], "error");
}

#[test]
fn json_of_an_unreadable_file_is_an_error_line() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.situ");
    let missing = missing.to_str().unwrap();
    let bad = write(dir.path(), "bad.situ", "states { IT initial }\nrule r { when state == IT then RX }\n");
    let o = situ(&["check", "--format", "json", missing, &bad]);
    assert_eq!(code(&o), 2);
    let lines: Vec<serde_json::Value> =
        stdout(&o).lines().map(|l| serde_json::from_str(l).expect("each line is a JSON object")).collect();
    assert_eq!(lines.len(), 2, "{}", stdout(&o));
    let error = &lines[0]["error"];
    assert_eq!(error["kind"], "io");
    assert_eq!(error["file"], missing);
    assert!(error["message"].as_str().unwrap().contains("missing.situ"));
    assert_eq!(lines[1]["code"], "situ::E0101");
    assert!(stderr(&o).contains("missing.situ"), "people read standard error: {}", stderr(&o));
}

/// Runs `situ ARGS` with standard output a pipe, reads one line, closes the
/// pipe, and returns standard error once the child has ended.
fn closed_after_one_line(args: &[&str]) -> String {
    let mut child = Command::new(env!("CARGO_BIN_EXE_situ"))
        .args(args)
        .env("NO_COLOR", "1")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    let mut out = BufReader::new(child.stdout.take().unwrap());
    let mut line = String::new();
    out.read_line(&mut line).expect("one line");
    assert!(!line.is_empty(), "{args:?} printed nothing");
    drop(out);
    let mut err = child.stderr.take().unwrap();
    let status = wait_bounded(&mut child, args);
    let mut text = String::new();
    err.read_to_string(&mut text).unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::process::ExitStatusExt;
        assert!(status.success() || status.signal() == Some(libc::SIGPIPE), "{args:?}: {status:?}\n{text}");
    }
    #[cfg(not(unix))]
    let _ = status;
    text
}

fn wait_bounded(child: &mut Child, what: &[&str]) -> std::process::ExitStatus {
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return status;
        }
        if start.elapsed() > PATIENCE {
            let _ = child.kill();
            panic!("{what:?} did not end within {PATIENCE:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn a_closed_pipe_ends_the_output_quietly() {
    for args in [
        &["check", "rules/outdoor.situ"][..],
        &["explain", "E0101"],
        &["explain"],
        &["man"],
        &["completions", "bash"],
        &["graph", "rules/outdoor.situ", "--view", "states"],
        // Hundreds of kilobytes: larger than a pipe's buffer, so the write after the close happens.
        &["check", "--format", "sarif", "rules/outdoor.situ"],
    ] {
        let err = closed_after_one_line(args);
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(!err.to_lowercase().contains("broken pipe"), "{args:?}: {err}");
    }
}

/// `situ check --watch` as a child, its standard output read line by line.
struct Watching {
    child: Child,
    lines: mpsc::Receiver<String>,
    /// Everything read so far, for failure messages.
    seen: Vec<String>,
}

impl Watching {
    fn start(args: &[&str]) -> Watching {
        let mut child = Command::new(env!("CARGO_BIN_EXE_situ"))
            .args(args)
            .env("NO_COLOR", "1")
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("the binary runs");
        let out = BufReader::new(child.stdout.take().unwrap());
        let (tx, lines) = mpsc::channel();
        std::thread::spawn(move || {
            for line in out.lines().map_while(Result::ok) {
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        Watching { child, lines, seen: Vec::new() }
    }

    /// The lines of the next round, up to and with its separator line.
    fn round(&mut self) -> Vec<String> {
        let deadline = Instant::now() + PATIENCE;
        let mut round = Vec::new();
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.lines.recv_timeout(left) {
                Ok(line) => {
                    self.seen.push(line.clone());
                    let end = line.starts_with("---- ");
                    round.push(line);
                    if end {
                        return round;
                    }
                }
                Err(_) => panic!("no report within {PATIENCE:?}; so far:\n{}", self.seen.join("\n")),
            }
        }
    }
}

impl Drop for Watching {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

#[test]
fn check_watch_reports_every_save_until_ctrl_c() {
    let dir = tempfile::tempdir().unwrap();
    let part = write(dir.path(), "part.situ", "agent Ready sensor { event RDY }\n");
    let root_text =
        "include \"part.situ\"\nstates { IT initial RD final }\nrule ready { when state == IT and RDY then RD }\n";
    let root = write(dir.path(), "root.situ", root_text);
    let mut w = Watching::start(&["check", "--watch", &root]);

    let first = w.round();
    let last = first.last().unwrap();
    assert!(first.iter().any(|l| l.contains("no findings")), "{first:?}");
    assert!(last.contains("no findings") && last.contains("watching 2 files"), "{last}");
    let hms = last.split_whitespace().nth(1).unwrap();
    assert!(hms.len() >= 8 && hms.as_bytes()[2] == b':', "a time on the separator line: {last}");

    // The root saved with an error.
    write(dir.path(), "root.situ", root_text.replace("then RD", "then RX"));
    let broken = w.round();
    assert!(broken.iter().any(|l| l.contains("situ::E0101")), "{broken:?}");
    assert!(broken.last().unwrap().contains("1 error, 0 warnings"), "{broken:?}");

    // Fixed again.
    write(dir.path(), "root.situ", root_text);
    let fixed = w.round();
    assert!(fixed.last().unwrap().contains("no findings"), "{fixed:?}");

    // An included file saved with an error.
    write(dir.path(), "part.situ", "agent Ready sensor { event RDZ }\n");
    let broken = w.round();
    assert!(broken.iter().any(|l| l.contains("situ::E0104")), "{broken:?}");
    std::fs::write(&part, "agent Ready sensor { event RDY }\n").unwrap();
    assert!(w.round().last().unwrap().contains("no findings"), "{:?}", w.seen);

    // The root disappears: reported, then watched for again.
    std::fs::remove_file(&root).unwrap();
    let gone = w.round();
    assert!(gone.iter().any(|l| l.contains("is gone")), "{gone:?}");
    assert!(gone.last().unwrap().contains("cannot read"), "{gone:?}");
    write(dir.path(), "root.situ", root_text);
    let back = w.round();
    assert!(back.last().unwrap().contains("no findings"), "{back:?}");

    // Ctrl-C ends it with exit 0.
    #[cfg(unix)]
    {
        // SAFETY: a signal to our own child, whose id we hold.
        assert_eq!(unsafe { libc::kill(w.child.id() as libc::pid_t, libc::SIGINT) }, 0);
        let status = wait_bounded(&mut w.child, &["check", "--watch"]);
        assert_eq!(status.code(), Some(0), "{status:?}");
    }
}

#[test]
fn watch_with_a_machine_format_keeps_standard_output_for_documents() {
    let dir = tempfile::tempdir().unwrap();
    let root = write(dir.path(), "root.situ", "states { IT initial }\nrule r { when state == IT then RX }\n");
    let mut child = Command::new(env!("CARGO_BIN_EXE_situ"))
        .args(["check", "--watch", "--format", "json", &root])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = BufReader::new(child.stderr.take().unwrap());
    let mut out = BufReader::new(child.stdout.take().unwrap());
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let mut line = String::new();
        let _ = err.read_line(&mut line);
        let _ = tx.send(line);
    });
    let separator = rx.recv_timeout(PATIENCE).expect("a separator on standard error");
    assert!(separator.starts_with("---- ") && separator.contains("1 error"), "{separator}");
    let mut line = String::new();
    out.read_line(&mut line).unwrap();
    let finding: serde_json::Value = serde_json::from_str(&line).expect("a JSON line");
    assert_eq!(finding["code"], "situ::E0101");
    let _ = child.kill();
    let _ = child.wait();
}
