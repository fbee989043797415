//! Arbitrary text as a TOML scenario (`sim::scenario::parse`, what
//! `situ run --scenario FILE` reads): refused with a place and a reason, or
//! a valid scenario, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let _ = situ_sim::scenario::parse(text);
});
