//! Generates situ.h from the crate's source with cbindgen (into OUT_DIR);
//! the test `header` compares it with the committed capi/include/situ.h.

fn main() {
    let dir = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let out = std::env::var("OUT_DIR").expect("cargo sets OUT_DIR");
    println!("cargo:rerun-if-changed=src");
    println!("cargo:rerun-if-changed=cbindgen.toml");
    // libsitu.so names itself, so that a program linked to it finds it by
    // that name (on its RPATH or the loader's path), not by a build path.
    if std::env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("linux") {
        println!("cargo:rustc-cdylib-link-arg=-Wl,-soname,libsitu.so");
    }
    let config = cbindgen::Config::from_file(format!("{dir}/cbindgen.toml")).expect("capi/cbindgen.toml reads");
    cbindgen::Builder::new()
        .with_crate(&dir)
        .with_config(config)
        .generate()
        .expect("cbindgen generates situ.h")
        .write_to_file(format!("{out}/situ.h"));
}
