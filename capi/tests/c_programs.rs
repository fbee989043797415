//! The C API as a user meets it: `capi/install.sh` lays it out under a
//! prefix, CMake finds it with `find_package(situ)`, gcc and g++ build the
//! C test (`tests/c/situ_test.c`, shared and static) and the C++17 example
//! node (`examples/cpp/`), and they run, also under valgrind (no leak, no
//! invalid read). The tools come from Debian's packages
//! (`scripts/install-capi-tools.sh`); a missing one fails the test.

use situ_bundle::sign::SecretKey;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("the workspace").to_path_buf()
}

fn need(tool: &str) {
    let found = Command::new(tool).arg("--version").output().is_ok_and(|o| o.status.success());
    assert!(
        found,
        "`{tool}` is missing: run `bash scripts/install-capi-tools.sh` (Debian's cmake, gcc, g++, valgrind)"
    );
}

fn run(cmd: &mut Command) -> Output {
    let out = cmd.output().unwrap_or_else(|e| panic!("cannot start {cmd:?}: {e}"));
    assert!(
        out.status.success(),
        "{cmd:?} failed ({}):\n{}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// What every test here shares, made once: the installed prefix, the
/// built programs and the C test's input files.
struct Built {
    inputs: PathBuf,
    c_test: PathBuf,
    c_test_static: PathBuf,
    node: PathBuf,
}

fn built() -> &'static Built {
    static BUILT: OnceLock<Built> = OnceLock::new();
    BUILT.get_or_init(|| {
        for tool in ["cmake", "gcc", "g++", "valgrind"] {
            need(tool);
        }
        // One folder, emptied first: a static is never dropped, so a temp
        // dir would stay behind after every run.
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("situ-capi");
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("a folder under target/tmp");
        let prefix = dir.join("prefix");
        // The libraries this test run built (target/PROFILE/deps, where
        // the test runs from), with its features: a nested cargo build of
        // other features would rebuild the dependencies.
        let exe = std::env::current_exe().expect("the test's path");
        let libs = exe.parent().expect("target/PROFILE/deps");
        run(Command::new("bash").arg(root().join("capi/install.sh")).arg(&prefix).env("SITU_LIB_DIR", libs));
        for file in ["include/situ.h", "lib/libsitu.so", "lib/libsitu.a", "lib/cmake/situ/situConfig.cmake"] {
            assert!(prefix.join(file).is_file(), "capi/install.sh did not lay out {file}");
        }
        let c = cmake(&root().join("capi/tests/c"), &dir.join("c"), &prefix);
        let cpp = cmake(&root().join("examples/cpp"), &dir.join("cpp"), &prefix);
        let inputs = dir.join("inputs");
        write_inputs(&inputs);
        Built {
            inputs,
            c_test: c.join("situ_test"),
            c_test_static: c.join("situ_test_static"),
            node: cpp.join("mower_node"),
        }
    })
}

/// Configures and builds a CMake project against the prefix; its build dir.
fn cmake(source: &Path, build: &Path, prefix: &Path) -> PathBuf {
    run(Command::new("cmake")
        .arg("-S")
        .arg(source)
        .arg("-B")
        .arg(build)
        .arg(format!("-DCMAKE_PREFIX_PATH={}", prefix.display()))
        .arg("-DCMAKE_BUILD_TYPE=Debug"));
    run(Command::new("cmake").arg("--build").arg(build));
    build.to_path_buf()
}

/// The picker rules, their bundles (unsigned, signed, damaged) and the
/// signing key's public half.
fn write_inputs(dir: &Path) {
    std::fs::create_dir_all(dir).unwrap();
    let text = std::fs::read_to_string(root().join("api/tests/fixtures/picker.situ")).unwrap();
    std::fs::write(dir.join("picker.situ"), &text).unwrap();
    let checked = situ_api::check(situ_api::Input::Text { name: "picker.situ", text: &text }).unwrap();
    let key = SecretKey::from_seed(&[7; 32]);
    situ_bundle::key::write_pair(&dir.join("trusted"), &key).unwrap();
    let unsigned = situ_api::build(&checked, &Default::default()).unwrap();
    let options = situ_api::BuildOptions { key: Some(key), ..Default::default() };
    let signed = situ_api::build(&checked, &options).unwrap();
    std::fs::write(dir.join("unsigned.bundle"), &unsigned.bytes).unwrap();
    std::fs::write(dir.join("signed.bundle"), &signed.bytes).unwrap();
    let mut damaged = signed.bytes.clone();
    let middle = damaged.len() / 2;
    damaged[middle] ^= 0x5A;
    std::fs::write(dir.join("damaged.bundle"), damaged).unwrap();
}

fn valgrind(program: &Path) -> Command {
    let mut cmd = Command::new("valgrind");
    cmd.args(["--leak-check=full", "--error-exitcode=1", "--errors-for-leak-kinds=definite,indirect,possible", "-q"]);
    cmd.arg(program);
    cmd
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

#[test]
fn the_c_test_passes_every_check_linked_shared_and_static() {
    let b = built();
    for program in [&b.c_test, &b.c_test_static] {
        let out = run(Command::new(program).arg(&b.inputs));
        let text = stdout(&out);
        assert!(text.trim_end().ends_with(" 0 failed"), "{text}");
        let passed: usize = text.split_whitespace().rev().nth(3).and_then(|n| n.parse().ok()).unwrap_or(0);
        assert!(passed > 150, "fewer checks ran than written: {text}");
    }
}

#[test]
fn the_c_test_runs_clean_under_valgrind() {
    let b = built();
    let out = run(valgrind(&b.c_test).arg(&b.inputs));
    assert!(stdout(&out).contains(" 0 failed"), "{}", stdout(&out));
}

/// The states the node prints, in order.
fn states(text: &str) -> Vec<String> {
    text.lines()
        .filter_map(|l| l.split_once(" -> ").map(|(_, to)| to.split_whitespace().next().unwrap().to_string()))
        .collect()
}

#[test]
fn the_cpp_node_prints_the_mowers_changes_and_its_agents() {
    let b = built();
    let out = run(Command::new(&b.node).arg(root().join("examples/mower/mower.situ")));
    let text = stdout(&out);
    assert_eq!(states(&text), ["RAIN_PAUSE", "MOWING", "STUCK", "MOWING", "DOCKING", "CHARGING", "MOWING"], "{text}");
    assert!(text.contains("Drive running/home"), "the agents' modes are printed:\n{text}");
    assert!(text.contains("Blades sleeping"), "{text}");
    assert!(text.contains("end: MOWING;"), "{text}");
}

#[test]
fn the_cpp_node_runs_clean_under_valgrind() {
    let b = built();
    let out = run(valgrind(&b.node).arg(root().join("examples/mower/mower.situ")));
    assert_eq!(states(&stdout(&out)).len(), 7, "{}", stdout(&out));
}

#[test]
fn the_node_reports_a_rules_error_with_its_place() {
    let b = built();
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.situ");
    std::fs::write(&bad, "states { A initial }\nrule r { when state == B then A }\n").unwrap();
    let out = Command::new(&b.node).arg(&bad).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.situ:2:") && err.contains("(rules)"), "{err}");
}
