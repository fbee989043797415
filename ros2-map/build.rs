//! Embeds the interface definitions situ carries (`interfaces/<pkg>/{msg,srv,action}/*`)
//! as `FILES: &[(package, folder, file name, text)]`, sorted by package.

use std::fmt::Write as _;
use std::path::Path;
use std::{env, fs};

fn main() {
    let root = Path::new(&env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR")).join("interfaces");
    println!("cargo:rerun-if-changed={}", root.display());
    let mut files = Vec::new();
    let mut packages: Vec<_> = fs::read_dir(&root).expect("ros2-map/interfaces").flatten().map(|e| e.path()).collect();
    packages.sort();
    for pkg in packages.iter().filter(|p| p.is_dir()) {
        println!("cargo:rerun-if-changed={}", pkg.display());
        for folder in ["msg", "srv", "action"] {
            let dir = pkg.join(folder);
            let Ok(entries) = fs::read_dir(&dir) else { continue };
            println!("cargo:rerun-if-changed={}", dir.display());
            let mut names: Vec<_> = entries.flatten().map(|e| e.path()).collect();
            names.sort();
            for f in names {
                println!("cargo:rerun-if-changed={}", f.display());
                let name = |p: &Path| p.file_name().and_then(|n| n.to_str()).unwrap_or_default().to_string();
                files.push((name(pkg), folder, name(&f), f.display().to_string()));
            }
        }
    }
    let mut out = String::from("pub const FILES: &[(&str, &str, &str, &str)] = &[\n");
    for (pkg, folder, name, path) in files {
        writeln!(out, "    ({pkg:?}, {folder:?}, {name:?}, include_str!({path:?})),").expect("a String");
    }
    out.push_str("];\n");
    fs::write(Path::new(&env::var("OUT_DIR").expect("cargo sets OUT_DIR")).join("carried.rs"), out).expect("OUT_DIR");
}
