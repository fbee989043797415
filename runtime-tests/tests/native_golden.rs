//! The native modules of `runtime-tests/native/` are what
//! `situ_runtime::rete::native::generate` writes today for their rules
//! files, byte for byte. After a change of the generator,
//! `SITU_BLESS=1 cargo test -p situ-runtime-tests --test native_golden`
//! writes them again (then `native.rs` runs the new ones). A test of its
//! own, apart from `native.rs`, so that it builds however stale the
//! modules are.

mod native_modules;

use std::path::Path;

#[test]
fn each_module_is_what_the_generator_writes_today() {
    let bless = std::env::var_os("SITU_BLESS").is_some_and(|v| v == "1");
    let mut stale = Vec::new();
    for (name, source) in native_modules::SOURCES {
        let file = Path::new(source).file_name().unwrap().to_string_lossy().into_owned();
        let code = situ_runtime::rete::native::generate(&native_modules::content(source), &file)
            .unwrap_or_else(|e| panic!("{source}: {e}"));
        let path = native_modules::root().join("runtime-tests/native").join(format!("{name}.rs"));
        let committed = std::fs::read_to_string(&path).unwrap_or_default();
        if committed != code {
            if bless {
                std::fs::write(&path, &code).unwrap();
            }
            stale.push(path.display().to_string());
        }
    }
    assert!(
        stale.is_empty(),
        "native code not what the generator writes today{}: {stale:?}",
        if bless { " (written again: run the test once more)" } else { " (SITU_BLESS=1 writes it again)" }
    );
}
