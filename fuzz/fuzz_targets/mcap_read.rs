//! Arbitrary bytes as an MCAP recording, read as `situ replay` reads one
//! (`runtime::record::mcap::read_recording`) and searched for the attached
//! bundle (`attached_bundle`): a damaged or cut file is an error that says
//! where, never a panic, a hang or an allocation the size a length field
//! claims.
#![no_main]

use libfuzzer_sys::fuzz_target;
use situ_runtime::record::mcap::{attached_bundle, read_recording};

fuzz_target!(|data: &[u8]| {
    let _ = read_recording(data);
    if let Some(bundle) = attached_bundle(data) {
        let _ = situ_compiler::bundle::decode(&bundle);
    }
});
