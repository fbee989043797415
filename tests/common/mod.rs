//! What the CLI golden tests share: running the real `situ` binary and
//! reading what it did.

// Each test binary uses a part of these.
#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

/// Runs `situ ARGS…` to its end, without colours.
pub fn situ(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_situ")).args(args).env("NO_COLOR", "1").output().expect("the binary runs")
}

pub fn code(o: &Output) -> i32 {
    o.status.code().expect("exited normally, not by a signal")
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8(o.stdout.clone()).expect("UTF-8 output")
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8(o.stderr.clone()).expect("UTF-8 output")
}

/// Standard output then standard error, for failure messages.
pub fn text(o: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}

/// Writes `content` to `dir/name`; its path.
pub fn write(dir: &Path, name: &str, content: impl AsRef<[u8]>) -> String {
    let path = dir.join(name);
    std::fs::write(&path, content).expect("temp file written");
    path.display().to_string()
}
