//! Arbitrary bytes as a script file read after a fixed rules file, as
//! `situ run RULES --script FILE` reads them (`compiler::check_with`): the
//! script's items are checked against the rules' declarations (names,
//! types, time order, overlaps); a clean program builds, decodes and runs.
#![no_main]

use libfuzzer_sys::fuzz_target;
use situ_compiler::loader::MemLoader;
use situ_fuzz::check_all;

const RULES: &str = r#"
states {
    FLYING initial "following the mission"
    HOLD           "hovering in place: no link"
    LANDED final   "on the ground"
}

agent Radio sensor "the ground link" {
    rate 10Hz
    stale after 300ms
    event HB "heartbeat"
    event RSSI { dbm: f64, band: {low, high}, ok: bool, n: i64 }
}

agent Autopilot actuator "flight control" {
    rate 50Hz
    event TOUCHDOWN "on the ground"
    function mission "fly the mission"
    function hover "hold position"
    table {
        FLYING => run mission() from Radio
        HOLD   => run hover()
        LANDED => sleep
    }
}

rule link_lost salience 50 {
    when state == FLYING and stale Radio
    then HOLD
}

rule link_back salience 50 {
    when state == HOLD and HB x3
    then FLYING
}

rule landed salience 10 {
    when state == FLYING and TOUCHDOWN
    then LANDED
}
"#;

fuzz_target!(|data: &[u8]| {
    let loader = MemLoader::new().with("fuzz/rules.situ", RULES).with("fuzz/script.situ", data.to_vec());
    check_all(&loader, "fuzz/rules.situ", &["fuzz/script.situ"]);
});
