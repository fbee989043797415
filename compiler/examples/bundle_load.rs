//! How long reading a bundle takes, JSON against binary (decoding, hash
//! check and validation: everything before a runtime can build its network).
//! `cargo run --release -p situ-compiler --example bundle_load [-- FILE.situ]`

use situ_compiler::bundle::{self, Encoding};
use std::time::Instant;

fn main() {
    let path = std::env::args().nth(1).unwrap_or_else(|| "rules/outdoor.situ".into());
    let checked = situ_compiler::check(path.as_ref(), &situ_compiler::loader::FsLoader).expect("readable");
    let content = bundle::build(&checked);
    for (name, enc) in [("json", Encoding::Json), ("binary", Encoding::Binary)] {
        let bytes = bundle::encode(&content, enc);
        let rounds = 2_000;
        let start = Instant::now();
        for _ in 0..rounds {
            std::hint::black_box(bundle::decode(std::hint::black_box(&bytes)).expect("loads"));
        }
        let each = start.elapsed().as_secs_f64() / rounds as f64;
        println!("{name:>6}: {:>6} bytes, load {:>8.1} µs", bytes.len(), each * 1e6);
    }
}
