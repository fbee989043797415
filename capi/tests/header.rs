//! The committed `capi/include/situ.h` is what cbindgen generates from the
//! crate now (capi/build.rs writes it to OUT_DIR at every build).
//! `SITU_BLESS=1 cargo test -p situ-capi --test header` rewrites it.

const GENERATED: &str = include_str!(concat!(env!("OUT_DIR"), "/situ.h"));

#[test]
fn the_committed_header_is_the_generated_one() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/include/situ.h");
    if std::env::var_os("SITU_BLESS").is_some() {
        std::fs::write(path, GENERATED).expect("writes capi/include/situ.h");
    }
    let committed = std::fs::read_to_string(path).unwrap_or_default();
    assert!(
        committed == GENERATED,
        "capi/include/situ.h differs from what cbindgen generates now: run \
         `SITU_BLESS=1 cargo test -p situ-capi --test header` and commit it"
    );
    // The header declares every entry point of the crate.
    for name in ["situ_board_post_values", "situ_last_error", "situ_program_from_bytes", "situ_why_free"] {
        assert!(GENERATED.contains(&format!("{name}(")), "{name} is not in situ.h");
    }
}
