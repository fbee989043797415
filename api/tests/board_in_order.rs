//! `Board::payload_in_order`: the bindings' fast path, values in field
//! order without names, typed as `Board::payload` types them.

use situ_api::{Arg, Board, Clock};
use std::sync::Arc;

fn picker() -> Board {
    let text = include_str!("fixtures/picker.situ");
    let checked = situ_api::check(situ_api::Input::Text { name: "picker.situ", text }).expect("the rules check");
    let built = situ_api::build(&checked, &Default::default()).expect("the rules build");
    let program = situ_api::load(&built.bytes, &situ_api::Trust::Any).expect("the bundle loads");
    Board::new(Arc::new(program.content), Clock::Manual)
}

#[test]
fn values_in_field_order_make_the_same_payload_as_names() {
    let b = picker();
    let obst = b.event("OBST").unwrap();
    let mut into = Vec::new();
    b.payload_in_order(obst, &[Arg::I64(2), Arg::Symbol("right")], &mut into).unwrap();
    let by_name = b.payload(obst, &[("side", Arg::Symbol("right")), ("distance", Arg::F64(2.0))]).unwrap();
    assert_eq!(into, by_name);
    // The buffer is cleared first.
    b.payload_in_order(obst, &[Arg::F64(1.0), Arg::Symbol("left")], &mut into).unwrap();
    assert_eq!(into.len(), 2);
}

#[test]
fn too_few_too_many_a_wrong_type_or_an_unknown_id_is_an_error_with_its_code() {
    let b = picker();
    let obst = b.event("OBST").unwrap();
    let mut into = Vec::new();
    let code = |args: &[Arg], event: u32, into: &mut Vec<_>| b.payload_in_order(event, args, into).unwrap_err();
    let missing = code(&[Arg::F64(1.0)], obst, &mut into);
    assert_eq!(missing.code(), "missing-fields");
    assert!(missing.to_string().contains("side"), "{missing}");
    let extra = code(&[Arg::F64(1.0), Arg::Symbol("left"), Arg::Bool(true)], obst, &mut into);
    assert_eq!(extra.code(), "unknown-field");
    assert!(extra.to_string().contains("#2"), "{extra}");
    assert_eq!(code(&[Arg::Symbol("left"), Arg::F64(1.0)], obst, &mut into).code(), "field-type");
    assert_eq!(code(&[Arg::F64(1.0), Arg::Symbol("up")], obst, &mut into).code(), "field-type");
    assert_eq!(code(&[], 9_999, &mut into).code(), "unknown-event");
}
