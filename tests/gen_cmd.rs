//! `situ gen agent`: golden tests of the real binary. The generated Python
//! must pass `mypy --strict` and be stable under `black`; the generated Rust
//! must be stable under rustfmt (the workspace's settings); the committed
//! `examples/mower/agents/battery.rs` must be exactly what `situ gen`
//! writes today. The Python packages (`pip install -r
//! examples/python/requirements.txt`) must be installed: a missing one fails.

mod common;

use common::{code, situ, stderr, stdout, text};
use situ_compiler::codegen::Lang;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The rule files and their agents.
const FILES: &[(&str, &[&str])] = &[
    ("examples/fig5/fig5.situ", &["RFCCD", "LADAR", "Fusion", "LPL", "Drive"]),
    ("examples/mower/mower.situ", &["Bumper", "Rain", "Battery", "GPS", "Blades", "Drive"]),
    ("tests/gen/robot.situ", &["Sonar", "Planner", "Motor", "Operator"]),
    ("tests/gen/launch.situ", &["Mission", "Flight"]),
];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `situ ARGS…` run from the repository's root (the sources' names, and so
/// the bundles' hashes, are the relative paths).
fn situ_at_root(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_situ"))
        .args(args)
        .current_dir(root())
        .env("NO_COLOR", "1")
        .output()
        .expect("the binary runs")
}

/// The `sha256` of the JSON bundle `situ build` writes for `file`.
fn bundle_sha256(file: &str, dir: &Path) -> String {
    let out = dir.join("bundle.json");
    let o = situ_at_root(&["build", file, "-o", out.to_str().unwrap()]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
    json["sha256"].as_str().unwrap().to_string()
}

/// Generates every agent of every file in both languages into `dir/<lang>`.
fn generate_all(dir: &Path) -> Vec<(String, PathBuf)> {
    let mut written = Vec::new();
    for (file, agents) in FILES {
        let hash = bundle_sha256(file, dir);
        for agent in *agents {
            for lang in ["python", "rust"] {
                let sub = dir.join(lang).join(Path::new(file).file_stem().unwrap());
                let o = situ_at_root(&["gen", "agent", agent, file, "--lang", lang, "-o", sub.to_str().unwrap()]);
                assert_eq!(code(&o), 0, "{agent} {lang}: {}", text(&o));
                let name = situ_compiler::codegen::file_name(agent, Lang::parse(lang).unwrap());
                let path = sub.join(&name);
                assert!(stderr(&o).contains(&name), "{}", text(&o));
                let generated = std::fs::read_to_string(&path).unwrap();
                let header: String = generated.lines().take(4).collect::<Vec<_>>().join("\n");
                assert!(header.contains(&format!("from bundle sha256 {hash}")), "{header}");
                assert!(header.contains(&format!("situ {}", env!("CARGO_PKG_VERSION"))), "{header}");
                assert!(header.contains("Do not edit by hand"), "{header}");
                written.push((format!("{file}:{agent}:{lang}"), path));
            }
        }
    }
    written
}

fn python(args: &[&str], dir: &Path) -> std::process::Output {
    let o = Command::new("python3").args(args).current_dir(dir).output().expect("python3 runs");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !err.contains("No module named"),
        "a Python package is missing: pip install -r examples/python/requirements.txt\n{err}"
    );
    o
}

#[test]
fn every_agent_generates_checked_and_formatted_code() {
    let tmp = tempfile::tempdir().unwrap();
    let written = generate_all(tmp.path());
    assert_eq!(written.len(), 2 * FILES.iter().map(|(_, a)| a.len()).sum::<usize>());
    for (file, _) in FILES {
        let stem = Path::new(file).file_stem().unwrap().to_str().unwrap();
        let py = tmp.path().join("python").join(stem);
        // mypy --strict, one directory (one module set) at a time.
        let o = python(&["-m", "mypy", "--strict", "--no-incremental", "."], &py);
        assert!(o.status.success(), "mypy --strict on {file}:\n{}", text(&o));
        assert!(stdout(&o).contains("Success: no issues found"), "{}", text(&o));
        // black leaves it as it is.
        let o = python(&["-m", "black", "--check", "--diff", "."], &py);
        assert!(o.status.success(), "black would reformat the Python of {file}:\n{}", text(&o));
        // rustfmt leaves the Rust as it is.
        for entry in std::fs::read_dir(tmp.path().join("rust").join(stem)).unwrap() {
            let path = entry.unwrap().path();
            let o = Command::new("rustfmt")
                .args(["--edition", "2021", "--check", "--config-path"])
                .arg(root().join("rustfmt.toml"))
                .arg(&path)
                .output()
                .expect("rustfmt runs");
            assert!(o.status.success(), "rustfmt would reformat {}:\n{}", path.display(), text(&o));
        }
    }
}

#[test]
fn the_python_has_typed_events_symbol_enums_and_the_behaviour_as_data() {
    let tmp = tempfile::tempdir().unwrap();
    let o = situ_at_root(&["gen", "agent", "Sonar", "tests/gen/robot.situ", "--lang", "python", "-o", "-"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let sonar = stdout(&o);
    for needle in [
        "class SorangeQuality(_enum.Enum):",
        "    NO_ECHO = \"no_echo\"",
        "def sorange(\n    distance: float,\n    echoes: int,\n    valid: bool,\n    quality: SorangeQuality,\n) -> Event:",
        "def sofail(code: int, reason: SofailReason) -> Event:",
        "TABLE: dict[str, Action | None] | None = {",
        "    \"OFF\": Action(\n        mode=Mode.SLEEPING,",
        "FSM: Fsm | None = None",
        "    def ping(self, step: Step) -> None:",
        // Planner's FSM decides whether it reads from the Sonar.
        "OTHER_FSMS: dict[str, Fsm] = {\n    \"Planner\": Fsm(",
    ] {
        assert!(sonar.contains(needle), "missing {needle:?} in:\n{sonar}");
    }
    let o = situ_at_root(&["gen", "agent", "Operator", "tests/gen/robot.situ", "--lang", "python", "-o", "-"]);
    let operator = stdout(&o);
    // Keywords as field names get a trailing underscore; the wire keeps the rules' names.
    assert!(operator.contains("def opstop(type_: OpstopType, self_: int, class_: bool) -> Event:"), "{operator}");
    assert!(
        operator.contains(
            "\"type\": type_.value,\n            \"self\": _i64(self_),\n            \"class\": bool(class_),"
        ),
        "{operator}"
    );
    let o = situ_at_root(&["gen", "agent", "Planner", "tests/gen/robot.situ", "--lang", "python", "-o", "-"]);
    let planner = stdout(&o);
    assert!(planner.contains("FSM: Fsm | None = Fsm(\n    initial=\"Planning\","), "{planner}");
    assert!(planner.contains("on_event=\"PLDONE\""), "{planner}");

    // The module's logic, without a network: a session that records, status
    // samples fed by hand. Operator has no table (running, no links of its
    // own), but Planner reads from it in its FSM state Replanning, which
    // ALARM enters: its receivers follow Planner's FSM.
    std::fs::write(tmp.path().join("operator_agent.py"), operator).unwrap();
    std::fs::write(tmp.path().join("sonar_agent.py"), sonar).unwrap();
    std::fs::write(tmp.path().join("planner_agent.py"), planner).unwrap();
    let script = r#"
import importlib, json, time

def load(name):
    return importlib.import_module(name + "_agent")

class Payload:
    def __init__(self, text): self.text = text
    def to_string(self): return self.text

class Sample:
    def __init__(self, obj): self.payload = Payload(json.dumps(obj))

class Session:
    def __init__(self): self.puts, self.keys = [], []
    def declare_subscriber(self, key, callback): self.keys.append(key); return key
    def put(self, key, value): self.puts.append((key, json.loads(value)))

def status(runner, state, seq):
    runner._on_status(Sample({"v": 1, "state": state, "time_ns": time.time_ns(), "seq": seq}))

op = load("operator")
s = Session()
r = op.Runner(op.Handlers(), s, "t")
assert "situ/t/event/Planner" in s.keys, s.keys
assert r.receivers() == (), r.receivers()
status(r, "WORKING", 1); assert r.receivers() == (), r.receivers()
status(r, "ALARM", 2); assert r.receivers() == ("Planner",), r.receivers()
# Planner reports PLDONE: Replanning has no transition on it, Planner still reads.
r._on_event(Sample({"v": 1, "agent": "Planner", "event": "PLDONE", "time_ns": 1, "payload": {}}))
assert r.receivers() == ("Planner",)
status(r, "IDLE", 3); assert r.receivers() == (), r.receivers()
r.step_once()
r.report(op.opstop(op.OpstopType.HARD, 7, True))
key, msg = s.puts[-1]
assert key == "situ/t/event/Operator", key
assert msg["event"] == "OPSTOP" and msg["payload"] == {"type": "hard", "self": 7, "class": True}, msg

sonar = load("sonar")
s = Session()
seen = []
class Mine(sonar.Handlers):
    def ping(self, step):
        seen.append((step.state, step.mode, step.receivers))
        step.report(sonar.sorange(float("nan"), 2, True, sonar.SorangeQuality.NO_ECHO))
        step.send({"range": 1.5})
    def without_function(self, step):
        seen.append((step.state, step.mode, step.receivers))
r = sonar.Runner(Mine(), s, "t")
status(r, "IDLE", 1); r.step_once()
assert seen[-1] == ("IDLE", sonar.Mode.WAITING, ()), seen
assert [k for k, _ in s.puts] == ["situ/t/event/Sonar"], s.puts  # waiting: the datum is dropped
assert s.puts[0][1]["payload"]["distance"] == "NaN"
status(r, "WORKING", 2); s.puts.clear(); r.step_once()
assert seen[-1] == ("WORKING", sonar.Mode.RUNNING, ("Planner",)), seen
assert [k for k, _ in s.puts] == ["situ/t/event/Sonar", "situ/t/data/Sonar/Planner"], s.puts
assert s.puts[1][1]["body"] == {"range": 1.5}
status(r, "ALARM", 3); assert not r.step_once(), "asleep in ALARM"
r._last_status -= 1.0; status_free = r.safe_mode(); assert status_free

pl = load("planner")
r = pl.Runner(pl.Handlers(), Session(), "t")
assert r.fsm_state == "Planning"
try:
    r.step_once(); raise SystemExit("plan is not implemented: it must raise")
except NotImplementedError as e:
    assert "Planner.plan" in str(e)
r.report(pl.pldone(3, 2.5)); assert r.fsm_state == "Resting", r.fsm_state
status(r, "ALARM", 1); assert r.fsm_state == "Resting"
status(r, "WORKING", 2); assert r.fsm_state == "Planning"
status(r, "ALARM", 3); assert r.fsm_state == "Replanning"
assert r.receivers() == ("Motor",), r.receivers()
print("python logic ok")
"#;
    std::fs::write(tmp.path().join("check.py"), script).unwrap();
    let o = python(&["check.py"], tmp.path());
    assert!(o.status.success(), "{}", text(&o));
    assert!(stdout(&o).contains("python logic ok"), "{}", text(&o));
}

/// The running cycle's behaviour without a network (a session that records,
/// statuses fed by hand), as the Rust agent runtime behaves and as issue 30
/// asked: safe mode from the start until the first status, with the reports
/// of that time held and sent in order once the Bulletinboard is there (the
/// oldest dropped and counted past `HELD_CAPACITY`); `on_status` for every
/// new status, the first included; the safe-mode and restart hooks; the end
/// at a final state.
#[test]
fn the_python_runner_holds_events_until_the_board_and_ends_at_a_final_state() {
    let tmp = tempfile::tempdir().unwrap();
    for agent in ["Mission", "Flight"] {
        let o = situ_at_root(&["gen", "agent", agent, "tests/gen/launch.situ", "--lang", "python", "-o", "-"]);
        assert_eq!(code(&o), 0, "{}", text(&o));
        std::fs::write(tmp.path().join(format!("{}_agent.py", agent.to_lowercase())), stdout(&o)).unwrap();
    }
    let script = r#"
import json, time
import mission_agent as mission, flight_agent as flight

class Payload:
    def __init__(self, text): self.text = text
    def to_string(self): return self.text

class Sample:
    def __init__(self, obj): self.payload = Payload(json.dumps(obj))

class Session:
    def __init__(self): self.puts = []
    def declare_subscriber(self, key, callback): return key
    def put(self, key, value): self.puts.append((key, json.loads(value)))

def status(runner, state, seq):
    runner._on_status(Sample({"v": 1, "state": state, "time_ns": time.time_ns(), "seq": seq}))

log = []
class Fc(flight.Handlers):
    def on_status(self, state, seq): log.append(("status", state, seq))
    def on_safe_mode(self, entered): log.append(("safe", entered))
    def on_board_restart(self): log.append(("restart",))
    def hold(self, step):
        log.append(("hold", step.mode.value, step.safe_mode))
        step.report(flight.fcarmed(True))
    def fly(self, step): log.append(("fly", step.mode.value))

s = Session()
r = flight.Runner(Fc(), s, "t")
# Safe mode from the start: waiting, the report held, nothing on the wire.
assert r.safe_mode() and r.step_once()
assert log == [("safe", True), ("hold", "waiting", True)], log
assert s.puts == [] and r.counters["held"] == 1 and r.held() == 1, (s.puts, r.counters)
# The first status, whose state is the initial one: on_status, safe mode
# ends, the held event goes out.
status(r, "GROUND", 1); r.follow()
assert log[2:] == [("status", "GROUND", 1), ("safe", False)], log
assert [(k, m["event"]) for k, m in s.puts] == [("situ/t/event/Flight", "FCARMED")], s.puts
assert r.held() == 0
# A repetition is not a new status; a change is.
status(r, "GROUND", 1); status(r, "PLANNED", 2); r.follow()
assert log[4:] == [("status", "PLANNED", 2)], log
# A restarted board: seq goes back.
status(r, "GROUND", 1); r.follow()
assert log[5:] == [("restart",), ("status", "GROUND", 1)], log
assert r.counters["restarts"] == 1
# Silence: safe mode again, and reports are held again, in order.
r._last_status -= 1.0; r.follow()
assert log[7:] == [("safe", True)], log
n = len(s.puts)
for _ in range(flight.HELD_CAPACITY + 3):
    r.report(flight.fcarmed(False))
assert len(s.puts) == n and r.counters["held_dropped"] == 3 and r.held() == flight.HELD_CAPACITY
status(r, "FLYING", 2); r.follow()
assert len(s.puts) == n + flight.HELD_CAPACITY and r.held() == 0
assert not r.finished
status(r, "DONE", 3); r.follow()
assert r.finished and r.states_seen == ["GROUND", "PLANNED", "GROUND", "FLYING", "DONE"], r.states_seen
r.loop(duration=5.0)  # returns at once: a final state
print("python runtime ok")
"#;
    std::fs::write(tmp.path().join("logic.py"), script).unwrap();
    let o = python(&["logic.py"], tmp.path());
    assert!(o.status.success(), "{}", text(&o));
    assert!(stdout(&o).contains("python runtime ok"), "{}", text(&o));
}

#[test]
fn the_python_runner_follows_only_the_highest_epoch() {
    let tmp = tempfile::tempdir().unwrap();
    let o = situ_at_root(&["gen", "agent", "Flight", "tests/gen/launch.situ", "--lang", "python", "-o", "-"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    std::fs::write(tmp.path().join("flight_agent.py"), stdout(&o)).unwrap();
    let script = r#"
import json, time
import flight_agent as flight

class Payload:
    def __init__(self, text): self.text = text
    def to_string(self): return self.text

class Sample:
    def __init__(self, obj): self.payload = Payload(json.dumps(obj))

class Session:
    def declare_subscriber(self, key, callback): return key
    def put(self, key, value): pass

def status(runner, state, seq, **more):
    runner._on_status(Sample({"v": 1, "state": state, "time_ns": time.time_ns(), "seq": seq, **more}))

log = []
class Fc(flight.Handlers):
    def on_status(self, state, seq): log.append((state, seq))
    def on_board_restart(self): log.append("restart")

r = flight.Runner(Fc(), Session(), "t")
# No epoch: 0, as a board without a standby says it.
status(r, "GROUND", 1); status(r, "PLANNED", 2); r.follow()
assert (r.epoch, r.board) == (0, None) and log == [("GROUND", 1), ("PLANNED", 2)], log
# A board leads at epoch 7: followed, though its seq is lower (a takeover,
# not a restart).
status(r, "PLANNED", 1, epoch=7, board="b"); status(r, "FLYING", 2, epoch=7, board="b"); r.follow()
assert (r.epoch, r.board) == (7, "b") and log[2:] == [("PLANNED", 1), ("FLYING", 2)], log
assert r.counters["restarts"] == 0
# The old leader (epoch 0, then 5) says another state: ignored, and it
# does not keep the agent out of safe mode.
r._last_status -= 1.0
status(r, "GROUND", 3); status(r, "GROUND", 9, epoch=5, board="a"); r.follow()
assert r.state == "FLYING" and r.epoch == 7 and r.counters["old_epoch"] == 2, (r.state, r.counters)
assert r.safe_mode() and log[4:] == [], log
# The leader again, then a restart within its epoch (seq back).
status(r, "FLYING", 3, epoch=7, board="b"); status(r, "FLYING", 1, epoch=7, board="b"); r.follow()
assert not r.safe_mode() and log[4:] == [("FLYING", 3), "restart", ("FLYING", 1)], log
# A bad epoch or board is refused.
status(r, "DONE", 4, epoch=-1); status(r, "DONE", 4, epoch="x"); status(r, "DONE", 4, epoch=8, board=3)
assert r.state == "FLYING" and r.counters["refused"] == 3, r.counters
print("epochs ok")
"#;
    std::fs::write(tmp.path().join("epochs.py"), script).unwrap();
    let o = python(&["epochs.py"], tmp.path());
    assert!(o.status.success(), "{}", text(&o));
    assert!(stdout(&o).contains("epochs ok"), "{}", text(&o));
}

#[test]
fn the_committed_battery_agent_is_what_gen_writes() {
    let o = situ_at_root(&["gen", "agent", "Battery", "examples/mower/mower.situ", "--lang", "rust", "-o", "-"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let committed = std::fs::read_to_string(root().join("examples/mower/agents/battery.rs")).unwrap();
    assert!(
        stdout(&o) == committed,
        "examples/mower/agents/battery.rs is not what `situ gen` writes; regenerate it:\n  \
         situ gen agent Battery examples/mower/mower.situ --lang rust -o examples/mower/agents"
    );
}

#[test]
fn the_same_code_from_a_bundle_as_from_its_source() {
    let tmp = tempfile::tempdir().unwrap();
    let bundle = tmp.path().join("mower.bundle");
    let o = situ_at_root(&["build", "examples/mower/mower.situ", "-o", bundle.to_str().unwrap()]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let from_bundle = situ_at_root(&["gen", "agent", "GPS", bundle.to_str().unwrap(), "--lang", "python", "-o", "-"]);
    let from_source =
        situ_at_root(&["gen", "agent", "GPS", "examples/mower/mower.situ", "--lang", "python", "-o", "-"]);
    assert_eq!(code(&from_bundle), 0, "{}", text(&from_bundle));
    assert_eq!(stdout(&from_bundle), stdout(&from_source));
}

#[test]
fn unknown_agents_and_languages_are_usage_errors() {
    let o = situ(&[
        "gen",
        "agent",
        "Batery",
        &root().join("examples/mower/mower.situ").display().to_string(),
        "--lang",
        "rust",
    ]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(stderr(&o).contains("no agent `Batery` in the rules; did you mean `Battery`?"), "{}", text(&o));
    assert!(stdout(&o).is_empty());

    let o = situ(&[
        "gen",
        "agent",
        "Battery",
        &root().join("examples/mower/mower.situ").display().to_string(),
        "--lang",
        "go",
    ]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(stderr(&o).contains("unknown language `go` for --lang; expected one of: python, rust"), "{}", text(&o));

    let o = situ(&["gen", "agent", "Battery", "no/such/file.situ", "--lang", "rust"]);
    assert_eq!(code(&o), 2, "{}", text(&o));
}

#[test]
fn a_file_with_errors_gets_its_diagnostics_and_exit_1() {
    let tmp = tempfile::tempdir().unwrap();
    let bad = common::write(
        tmp.path(),
        "bad.situ",
        "states { A initial }\nagent X sensor { event E }\nrule r { when F then B }\n",
    );
    let o = situ(&["gen", "agent", "X", &bad, "--lang", "python", "-o", tmp.path().to_str().unwrap()]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(stdout(&o).contains("E0"), "the diagnostics: {}", text(&o));
    assert!(!tmp.path().join("x.py").exists(), "nothing written");
}

#[test]
fn it_writes_into_the_current_directory_by_default() {
    let tmp = tempfile::tempdir().unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_situ"))
        .args(["gen", "agent", "Blades"])
        .arg(root().join("examples/mower/mower.situ"))
        .args(["--lang", "rust"])
        .current_dir(tmp.path())
        .output()
        .unwrap();
    assert_eq!(code(&o), 0, "{}", text(&o));
    let written = std::fs::read_to_string(tmp.path().join("blades.rs")).unwrap();
    assert!(written.contains("pub trait BladesFunctions: Send {"));
    assert!(written.contains("fn cut(&mut self, io: &mut BladesIo<'_, '_>);"));
    assert!(written.contains("pub const FSM_INITIAL: &str = \"Spinning\";"));
    let leftovers: Vec<_> = std::fs::read_dir(tmp.path()).unwrap().collect();
    assert_eq!(leftovers.len(), 1, "no temporary file left");
}
