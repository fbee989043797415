//! Arbitrary bytes as a message of the Zenoh wire protocol
//! (`bus-zenoh/src/wire.rs`, compiled here from its source file so that the
//! fuzz build does not build Zenoh): `parse` as an event, a status or a data
//! message (the first byte chooses), then an event is read against the
//! outdoor rules' bundle (`event_of`), as the Bulletinboard's subscriber
//! does. Garbage is refused at the boundary; an event that is accepted
//! goes back to the same ids through `event_wire`.
#![no_main]

#[allow(dead_code)]
#[path = "../../bus-zenoh/src/wire.rs"]
mod wire;

use libfuzzer_sys::fuzz_target;
use situ_compiler::bundle::Content;
use std::sync::OnceLock;
use wire::{DataWire, EventWire, StatusWire};

fn content() -> &'static Content {
    static CONTENT: OnceLock<Content> = OnceLock::new();
    CONTENT.get_or_init(|| {
        let checked = situ_compiler::check_source("outdoor.situ", include_str!("../../rules/outdoor.situ"));
        assert_eq!(checked.errors(), 0, "rules/outdoor.situ has errors");
        situ_compiler::bundle::build(&checked)
    })
}

fuzz_target!(|data: &[u8]| {
    let Some((&mode, rest)) = data.split_first() else { return };
    match mode % 3 {
        0 => {
            let Ok(w) = wire::parse::<EventWire>(rest) else { return };
            let c = content();
            if let Ok((agent, event, payload)) = wire::event_of(c, &w.agent, &w) {
                let back = wire::event_wire(c, agent, event, w.time_ns, &payload, w.urgent);
                let again =
                    wire::event_of(c, &back.agent, &back).expect("an accepted event, written back, is accepted");
                assert_eq!((again.0, again.1), (agent, event));
            }
        }
        1 => {
            let _ = wire::parse::<StatusWire>(rest);
        }
        _ => {
            let _ = wire::parse::<DataWire>(rest);
        }
    }
});
