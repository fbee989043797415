//! The distributed stack through the real binary (built with `--features
//! zenoh`): `situ up` starts a deployment's processes; a process killed
//! mid-run is seen by the Bulletinboard through staleness; the recording
//! keeps what was recorded. Loopback only, on free ports.
#![cfg(feature = "zenoh")]

mod common;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

fn situ() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_situ"));
    c.env("NO_COLOR", "1");
    c
}

fn port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

fn deployment(dir: &Path) -> String {
    let (b, s, p) = (port(), port(), port());
    let text = format!(
        "robot = \"t{b}\"\n\
         [[process]]\nname = \"board\"\nboard = true\nlisten = [\"tcp/127.0.0.1:{b}\"]\n\
         [[process]]\nname = \"sensors\"\nagents = [\"RFCCD\", \"LADAR\"]\nlisten = [\"tcp/127.0.0.1:{s}\"]\nconnect = [\"tcp/127.0.0.1:{b}\"]\n\
         [[process]]\nname = \"pipeline\"\nagents = [\"Fusion\", \"LPL\", \"Drive\"]\nlisten = [\"tcp/127.0.0.1:{p}\"]\nconnect = [\"tcp/127.0.0.1:{b}\", \"tcp/127.0.0.1:{s}\"]\n"
    );
    let path = dir.join("deploy.toml");
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

#[test]
fn up_runs_figure_5_through_a_router_process_and_stops_it_last() {
    let dir = tempfile::tempdir().unwrap();
    let r = port();
    let client = |name: &str, extra: &str| {
        format!("[[process]]\nname = \"{name}\"\n{extra}mode = \"client\"\nconnect = [\"tcp/127.0.0.1:{r}\"]\n")
    };
    let text = format!(
        "robot = \"t{r}\"\n[[process]]\nname = \"router\"\nmode = \"router\"\nlisten = [\"tcp/127.0.0.1:{r}\"]\n{}{}{}",
        client("board", "board = true\n"),
        client("sensors", "agents = [\"RFCCD\", \"LADAR\"]\n"),
        client("pipeline", "agents = [\"Fusion\", \"LPL\", \"Drive\"]\n"),
    );
    let deploy = dir.path().join("deploy.toml");
    std::fs::write(&deploy, text).unwrap();
    let deploy = deploy.display().to_string();
    let o =
        situ().args(["up", &deploy, "examples/fig5/fig5.situ", "--stack", "demo", "--duration", "4"]).output().unwrap();
    let (out, err) = (String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    assert!(o.status.success(), "{out}\n{err}");
    assert_eq!(
        out.matches("path: RS → RO").count(),
        3,
        "every process followed RS -> RO through the router:\n{out}\n{err}"
    );
    assert!(err.contains(&format!("router: routes situ/t{r}/… (Zenoh router on tcp/127.0.0.1:{r}")), "{err}");
    let ended = |p: &str| err.find(&format!("`{p}` ended (exit status: 0)")).unwrap_or_else(|| panic!("{p}: {err}"));
    assert!(["board", "sensors", "pipeline"].iter().all(|p| ended(p) < ended("router")), "the router ends last: {err}");
}

#[test]
fn up_starts_the_three_processes_of_figure_5() {
    let dir = tempfile::tempdir().unwrap();
    let deploy = deployment(dir.path());
    let o =
        situ().args(["up", &deploy, "examples/fig5/fig5.situ", "--stack", "demo", "--duration", "4"]).output().unwrap();
    let (out, err) = (String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    assert!(o.status.success(), "{out}\n{err}");
    assert_eq!(out.matches("path: RS → RO").count(), 3, "every process followed RS -> RO:\n{out}\n{err}");
    for p in ["board", "sensors", "pipeline"] {
        assert!(err.contains(&format!("`{p}` ended (exit status: 0)")), "{err}");
    }
}

#[test]
fn a_killed_process_is_stale_and_the_recording_keeps_what_came_before() {
    let dir = tempfile::tempdir().unwrap();
    let deploy = deployment(dir.path());
    let rec = dir.path().join("board.mcap");
    let run = |process: &str, extra: &[&str]| {
        situ()
            .args(["run", "examples/fig5/fig5.situ", "--stack", "demo", "--transport", "zenoh", "--deploy", &deploy])
            .args(["--process", process, "--duration", "6"])
            .args(extra)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap()
    };
    let board = run("board", &["--record", rec.to_str().unwrap()]);
    let mut sensors = run("sensors", &[]);
    let pipeline = run("pipeline", &[]);
    std::thread::sleep(Duration::from_millis(2500));
    sensors.kill().unwrap(); // SIGKILL: no goodbye
    let _ = sensors.wait();
    let board = board.wait_with_output().unwrap();
    let _ = pipeline.wait_with_output().unwrap();
    let out = String::from_utf8_lossy(&board.stdout);
    // RFCCD and LADAR fall silent: stale after 500 ms, an emergency; Drive
    // at standstill stops the mission (EM -> SP in one cascade).
    assert!(out.contains("path: RS → RO → SP"), "{out}\n{}", String::from_utf8_lossy(&board.stderr));
    assert!(out.contains("ladar_silent") || out.contains("camera_silent"), "{out}");
    let bytes = std::fs::read(&rec).unwrap();
    let (messages, _) = situ_runtime::record::mcap::read_messages(&bytes).unwrap();
    let events = messages.iter().filter(|(t, _, m)| t == "/situ/events" && m["agent"] == "LADAR").count();
    assert!(events >= 15, "LADAR's events before the kill are in the recording ({events})");
    let states: Vec<&str> = messages
        .iter()
        .filter(|(t, _, m)| t == "/state" && m["from"] != m["state"])
        .filter_map(|(_, _, m)| m["state"].as_str())
        .collect();
    assert_eq!(states, ["RO", "SP"]);
}

#[test]
fn the_bulletinboard_process_serves_the_live_page() {
    use std::io::{BufRead, BufReader};
    let dir = tempfile::tempdir().unwrap();
    let deploy = deployment(dir.path());
    let run = |process: &str, extra: &[&str]| {
        situ()
            .args(["run", "examples/fig5/fig5.situ", "--stack", "demo", "--transport", "zenoh", "--deploy", &deploy])
            .args(["--process", process, "--duration", "4"])
            .args(extra)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap()
    };
    // Only the process of the Bulletinboard has the state to serve.
    let o = situ()
        .args(["run", "examples/fig5/fig5.situ", "--stack", "demo", "--transport", "zenoh", "--deploy", &deploy])
        .args(["--process", "sensors", "--duration", "1", "--serve"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("process `sensors` has no Bulletinboard"));

    let mut board = run("board", &["--serve"]);
    let mut out = BufReader::new(board.stdout.take().unwrap());
    let mut line = String::new();
    out.read_line(&mut line).unwrap();
    let url = line.trim().strip_prefix("serving ").unwrap_or_else(|| panic!("{line}")).to_string();
    let others = [run("sensors", &[]), run("pipeline", &[])];
    // The page's requests, as the page makes them: the program, then the
    // run's entries as they come.
    assert!(common::http_get(&format!("{url}api/program")).contains("\"RO\""));
    let mut since = 0;
    let mut states = Vec::new();
    loop {
        let a: serde_json::Value =
            serde_json::from_str(&common::http_get(&format!("{url}api/live?since={since}"))).unwrap();
        for e in a["entries"].as_array().unwrap() {
            if e["kind"] == "change" {
                states.push(e["to"].as_str().unwrap().to_string());
            }
        }
        since = a["next"].as_u64().unwrap();
        if a["over"] == true {
            break;
        }
    }
    assert_eq!(states, ["RO"], "the page heard RS -> RO over Zenoh");
    let mut rest = String::new();
    std::io::Read::read_to_string(&mut out, &mut rest).unwrap();
    assert!(board.wait().unwrap().success());
    assert!(rest.contains("path: RS → RO"), "{rest}");
    for o in others {
        let _ = o.wait_with_output();
    }
}
