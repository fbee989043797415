//! A bundle written and read back behaves as the program it was built
//! from: the same firings on the same stream, JSON or binary.

use situ_compiler::bundle::{self, Encoding};
use situ_runtime::rete::Engine;
use situ_runtime::stream::Generator;
use std::sync::Arc;

#[test]
fn built_written_and_loaded_bundles_behave_the_same() {
    for file in ["outdoor.situ", "ugv.situ"] {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../rules").join(file);
        let checked = situ_compiler::check(&path, &situ_compiler::loader::FsLoader).unwrap();
        let direct = Arc::new(bundle::build(&checked));
        for enc in [Encoding::Json, Encoding::Binary] {
            let loaded = Arc::new(bundle::decode(&bundle::encode(&direct, enc)).unwrap());
            let (mut a, mut b) = (Engine::new(direct.clone()), Engine::new(loaded));
            let mut g = Generator::new(direct.clone(), 11);
            let mut fired = 0;
            for _ in 0..20_000 {
                let e = g.next_event().unwrap();
                let (x, y) = (a.post(e.event, e.time, &e.payload), b.post(e.event, e.time, &e.payload));
                assert_eq!(x, y, "{file} {enc:?}");
                fired += x.ok().flatten().map_or(0, |c| c.firings.len());
                if direct.states[a.state() as usize].is_final {
                    a.reset();
                    b.reset();
                }
            }
            assert!(fired > 100, "{file}: only {fired} firings");
        }
    }
}
